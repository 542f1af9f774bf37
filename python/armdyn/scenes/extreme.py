"""Scenes of the extreme-case studies (docs/extreme_cases.md) and of the solver-path checks: an
overconstrained Bricard linkage, a fast heavy top, random spatial chains (open or closed), random
spatial serial arms with their geometry (for independent models of the same arm), a chain with a
large mass ratio, and a pendulum whose force turns NaN. SI units, z up."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import numpy.typing as npt

from armdyn import _core
from armdyn._rotation import quat_to_rot


def bricard(side: float = 0.3, mass: float = 1.0) -> _core.Model:
    """Orthogonal Bricard 6R linkage on the edges of a cube of edge ``side``: six equal links,
    consecutive joint axes perpendicular, one link is ground. 6 revolutes = 30 rows on 5 bodies
    (nv = 30), so Grübler's count gives 0 DOF; the linkage moves with 1, and its joint angles keep
    the threefold symmetry J0 = J2 = J4, J1 = J3 = J5."""
    p = np.array([(1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 1, 1), (0, 0, 1), (1, 0, 1)], float) * side
    d = [p[(i + 1) % 6] - p[i] for i in range(6)]
    b = _core.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    links = [f"link{i}" for i in range(5)]
    for i in range(5):
        b.add_body(links[i], mass, [2e-3, 2e-3, 1e-3], position=(p[i] + p[i + 1]) / 2)
    for i in range(6):
        axis = np.cross(d[i - 1], d[i])
        parent = "ground" if i == 0 else links[i - 1]
        child = links[i] if i < 5 else "ground"
        b.add_revolute(f"J{i}", parent, child, point=p[i], axis=axis / np.linalg.norm(axis))
    return b.finalize()


def heavy_top(
    spin: float = 1000.0,
    tilt: float = np.pi / 6,
    mass: float = 1.0,
    length: float = 0.05,
    i1: float = 1.5e-3,
    i3: float = 2e-3,
) -> tuple[_core.Model, npt.NDArray[np.float64], npt.NDArray[np.float64], float]:
    """Symmetric top on a spherical joint at the origin, centre of mass ``length`` up its axis,
    tilted by ``tilt`` about x. Returns (model, u0, v0, omega_p): the initial state spins at
    ``spin`` about the symmetry axis and precesses at the gyroscopic rate
    omega_p = m g l / (I3 spin) (steady precession of the fast top)."""
    g = 9.81
    omega_p = mass * g * length / (i3 * spin)
    e = np.array([np.cos(tilt / 2), np.sin(tilt / 2), 0.0, 0.0])
    c, s = np.cos(tilt), np.sin(tilt)
    rot = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    r = rot @ np.array([0.0, 0.0, length])
    b = _core.ModelBuilder(gravity=(0.0, 0.0, -g))
    b.add_body("top", mass, [i1, i1, i3], position=r, orientation=e)
    b.add_spherical("tip", "ground", "top", point=(0, 0, 0))
    model = b.finalize()
    w_world = rot @ np.array([0.0, 0.0, spin]) + np.array([0.0, 0.0, omega_p])
    u0 = np.concatenate([r, e])
    v0 = np.concatenate([np.cross(w_world, r), rot.T @ w_world])
    return model, u0, v0, omega_p


def random_chain(
    n: int, close_loop: bool = False, seed: int = 1, masses: npt.ArrayLike | None = None
) -> _core.Model:
    """A spatial chain of n revolute links with random axes, steps of about 0.2 m along x and
    random masses (or ``masses``). ``close_loop`` ties the tip back to the first link with a
    spherical joint: one loop closure between moving bodies, mobility n − 3. (A closure to
    ground would couple no moving bodies and add no fill to the KKT factor.)"""
    rng = np.random.default_rng(seed)
    b = _core.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    p = np.zeros(3)
    for i in range(n):
        step = np.array([0.2, 0.0, 0.0]) + 0.05 * rng.normal(size=3)
        m = 1.0 + rng.uniform() if masses is None else float(masses[i])
        b.add_body(f"l{i}", m, 1e-2 * (1 + rng.uniform(size=3)), position=p + step / 2)
        axis = rng.normal(size=3)
        parent = "ground" if i == 0 else f"l{i - 1}"
        b.add_revolute(f"j{i}", parent, f"l{i}", p, axis / np.linalg.norm(axis))
        p = p + step
    if close_loop:
        b.add_spherical("close", f"l{n - 1}", "l0", point=p)
    return b.finalize()


def random_unit(rng: np.random.Generator, n: int = 3) -> np.ndarray:
    """A random unit vector of length ``n``."""
    v = rng.normal(size=n)
    return v / np.linalg.norm(v)


def random_quat(rng: np.random.Generator) -> np.ndarray:
    """Random unit Euler parameters, scalar-first, e0 >= 0."""
    e = random_unit(rng, 4)
    return e if e[0] >= 0 else -e


def random_inertia(
    rng: np.random.Generator, mass: float, lo: float = 0.002, hi: float = 0.03
) -> np.ndarray:
    """A random FULL inertia tensor (body axes, about the CoM): R diag(principal) R^T with the
    principal moments built from second moments s_k > 0 (I1 = s2 + s3, ...), so it is symmetric,
    positive-definite and satisfies the triangle inequality strictly."""
    s = mass * rng.uniform(lo, hi, size=3)
    principal = np.array([s[1] + s[2], s[0] + s[2], s[0] + s[1]])
    e = rng.normal(size=4)
    r = quat_to_rot(e / np.linalg.norm(e))
    inertia = r @ np.diag(principal) @ r.T
    return 0.5 * (inertia + inertia.T)


def random_spatial_arm(
    rng: np.random.Generator,
    n: int = 6,
    prismatic: bool = False,
    gravity: npt.ArrayLike = (0.0, 0.0, -9.81),
    masses: npt.ArrayLike | None = None,
) -> SimpleNamespace:
    """Random spatial serial arm ground - link1 - ... - linkn, built with the builder.

    Random link masses, random FULL inertias (R diag R^T, SPD, triangle inequality), random CoM
    offsets, random body orientations, random joint points and random joint axes. With
    ``prismatic=True`` every joint with index % 3 == 1 is prismatic (e.g. R P R R P R for
    n = 6). ``masses`` (n values) replaces the random link masses.

    Returns a namespace with ``model``, ``builder`` and the arm's geometry in world coordinates
    at q = 0, from which an independent model of the same arm can be built: ``types`` ('R' /
    'P'), ``points``, ``axes`` (joint points and axes), ``coms``, ``masses``, ``inertias_body``
    (body axes), ``quats`` (body → world), ``joint_names``, ``body_names``, ``n``, and ``perm``
    such that q_armdyn[perm[i]] = q_arm[i] (q_arm in link order).
    """
    types = ["P" if (prismatic and i % 3 == 1) else "R" for i in range(n)]
    points = np.zeros((n, 3))
    steps = np.zeros((n, 3))
    p = np.array([0.0, 0.0, 0.1])
    for i in range(n):
        points[i] = p
        d = random_unit(rng) * rng.uniform(0.15, 0.4)
        steps[i] = d
        p = p + d
    axes = np.array([random_unit(rng) for _ in range(n)])
    coms = points + 0.5 * steps + 0.05 * rng.normal(size=(n, 3))
    drawn = rng.uniform(0.5, 3.0, size=n)  # drawn either way: the same geometry for a seed
    masses = drawn if masses is None else np.asarray(masses, dtype=float)
    inertias_body = np.array([random_inertia(rng, m) for m in masses])
    quats = np.array([random_quat(rng) for _ in range(n)])
    body_names = [f"link{i + 1}" for i in range(n)]
    joint_names = [f"j{i + 1}" for i in range(n)]
    b = _core.ModelBuilder(gravity=gravity)
    for i in range(n):
        b.add_body(
            body_names[i],
            float(masses[i]),
            inertias_body[i],
            position=coms[i],
            orientation=quats[i],
        )
    for i in range(n):
        parent = "ground" if i == 0 else body_names[i - 1]
        add = b.add_revolute if types[i] == "R" else b.add_prismatic
        add(joint_names[i], parent, body_names[i], points[i], axes[i])
    model = b.finalize()
    perm = np.array([list(model.coord_names).index(jn) for jn in joint_names])
    return SimpleNamespace(
        model=model,
        builder=b,
        types=types,
        points=points,
        axes=axes,
        coms=coms,
        masses=masses,
        inertias_body=inertias_body,
        quats=quats,
        joint_names=joint_names,
        body_names=body_names,
        perm=perm,
        n=n,
        gravity=gravity,
    )


def mass_ratio_chain(ratio: float = 1e6, n: int = 5, seed: int = 3) -> SimpleNamespace:
    """A random spatial chain of n revolute links (:func:`random_spatial_arm`: random axes,
    steps, full inertias and body orientations) whose masses alternate √ratio and 1/√ratio kg.
    Returns the arm's namespace (``model``, its geometry and ``perm``)."""
    masses = [np.sqrt(ratio) if i % 2 == 0 else 1 / np.sqrt(ratio) for i in range(n)]
    return random_spatial_arm(np.random.default_rng(seed), n, masses=masses)


def nan_force_pendulum(t_nan: float = 0.31) -> _core.Model:
    """A pendulum ('bob' on revolute 'pivot', at rest) whose user force turns NaN after
    ``t_nan``: a run must stop with a SolverError naming the body and the time."""
    b = _core.ModelBuilder()
    b.add_body("bob", 1.0, [1e-3] * 3, position=(0.0, 0.0, -1.0))
    b.add_revolute("pivot", "ground", "bob", point=(0, 0, 0), axis=(0, 1, 0))
    b.add_body_force(
        "bob",
        force=(1.0, 0.0, 0.0),
        profile=lambda t: (float("nan") if t > t_nan else 0.0, 0.0, 0.0),
    )
    return b.finalize()
