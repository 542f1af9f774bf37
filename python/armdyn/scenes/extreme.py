"""Scenes of the extreme-case studies (docs/extreme_cases.md) and of the solver-path checks: an
overconstrained Bricard linkage, a fast heavy top, random spatial chains (open or closed), a
chain with a large mass ratio and its independent reference, and a pendulum whose force turns
NaN. SI units, z up."""

from __future__ import annotations

import numpy as np

from armdyn import _core


def bricard(side=0.3, mass=1.0):
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


def heavy_top(spin=1000.0, tilt=np.pi / 6, mass=1.0, length=0.05, i1=1.5e-3, i3=2e-3):
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


def random_chain(n, close_loop=False, seed=1, masses=None):
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


def mass_ratio_chain(ratio=1e6, n=5, seed=3):
    """A random spatial chain of n revolute links (:func:`armdyn.reference.random_serial_arm`:
    random axes, steps, full inertias and body orientations) whose masses alternate √ratio and
    1/√ratio kg. Returns the arm's namespace: ``model``, ``chain`` (the same arm as the
    independent numpy RNEA/CRBA model) and ``perm`` (q_armdyn[perm[i]] = q_reference[i])."""
    from armdyn.reference import random_serial_arm

    masses = [np.sqrt(ratio) if i % 2 == 0 else 1 / np.sqrt(ratio) for i in range(n)]
    return random_serial_arm(np.random.default_rng(seed), n, masses=masses)


def nan_force_pendulum(t_nan=0.31):
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
