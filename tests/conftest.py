"""Shared builders and helpers for the armdyn test-suite.

Every model here is built through the public builder API (docs/api.md). Geometry is always
generated in WORLD coordinates at the assembly pose, which is also what the independent numpy
oracle (tests/oracles/numpy_rne.py) consumes, so the two never share code paths.

Helpers are plain functions (import them with ``from conftest import ...``; pytest puts this
directory on sys.path, so the oracles import as ``oracles.numpy_rne``) and a few are also exposed
as fixtures. The repository root is put on sys.path too, for the tests of ``benchmarks/`` (the
benchmark harness and peer models, not installed with armdyn).
"""

from __future__ import annotations

import os
import re
import sys
from pathlib import Path
from types import SimpleNamespace

import armdyn as ad
import numpy as np
import pytest
from armdyn.scenes.extreme import random_inertia, random_quat, random_unit
from oracles.numpy_rne import (
    SerialChain,
    quat_exp,
    quat_mul,
    quat_to_rot,
    random_serial_arm,
    rot_axis_angle,
    rot_to_quat,
)

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

G = 9.81
GRAVITY = (0.0, 0.0, -G)

__all__ = [
    "GRAVITY",
    "G",
    "body_index",
    "body_pose",
    "body_vel",
    "coord_index",
    "double_pendulum",
    "from_armdyn",
    "name_regex",
    "quat_exp",
    "quat_mul",
    "quat_to_rot",
    "random_inertia",
    "random_quat",
    "random_unit",
    "rel_err",
    "rot_to_quat",
    "simple_pendulum",
    "spatial_arm",
    "to_armdyn",
    "tol",
]


# ----------------------------------------------------------------------------------------------
# tolerances and small utilities
# ----------------------------------------------------------------------------------------------


def tol(x: float) -> float:
    """A tolerance, scaled by the environment variable ARMDYN_TOL_SCALE (default 1)."""
    return float(x) * float(os.environ.get("ARMDYN_TOL_SCALE", "1"))


def rel_err(a, b, floor: float = 1e-300) -> float:
    """max-norm relative error of a against the reference b."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), floor))


_SEPARATORS = ".:/_[( -#"


def coord_index(model, joint: str, sub: int = 0) -> int:
    """Index (into q / qd / coord_names) of coordinate `sub` of joint `joint`.

    API assumption: coordinate names are the joint name, or start with the joint name followed
    by a separator (e.g. 'elbow', 'elbow.angle', 'elbow[1]'). Coordinates of one joint are listed
    in order (cylindrical: angle first, then displacement)."""
    names = list(model.coord_names)
    hits = [i for i, n in enumerate(names) if n == joint]
    hits += [
        i
        for i, n in enumerate(names)
        if n != joint and n.startswith(joint) and n[len(joint)] in _SEPARATORS
    ]
    hits = sorted(set(hits))
    if len(hits) <= sub:
        raise KeyError(f"no coordinate {sub} for joint {joint!r} in {names}")
    return hits[sub]


def body_index(model, name: str) -> int:
    return list(model.body_names).index(name)


def body_pose(u, k: int):
    """CoM position and Euler parameters of body k from a state u (or a stack of states)."""
    u = np.asarray(u)
    return u[..., 7 * k : 7 * k + 3], u[..., 7 * k + 3 : 7 * k + 7]


def body_vel(v, k: int):
    """CoM velocity (world) and angular velocity (body frame) of body k."""
    v = np.asarray(v)
    return v[..., 6 * k : 6 * k + 3], v[..., 6 * k + 3 : 6 * k + 6]


# ----------------------------------------------------------------------------------------------
# model builders
# ----------------------------------------------------------------------------------------------


def simple_pendulum(
    L: float = 1.0, m: float = 1.0, theta0: float = 0.1, r: float = 1e-3, gravity=GRAVITY
):
    """Physical pendulum: a small solid sphere (radius r, I_cm = 2/5 m r^2) on a massless arm of
    length L, revolute about world +y at the origin, gravity -z.

    The bob is assembled at angle theta0 from the hanging position, i.e. at
    Ry(theta0) (0, 0, -L) = (-L sin theta0, 0, -L cos theta0); with q = 0 at assembly and a
    positive q being a right-handed rotation about +y, the angle from vertical is theta0 + q.
    """
    i_cm = 0.4 * m * r * r
    pos = rot_axis_angle([0, 1, 0], theta0) @ np.array([0.0, 0.0, -L])
    orient = quat_exp(np.array([0.0, theta0, 0.0]))
    b = ad.ModelBuilder(gravity=gravity)
    b.add_body("bob", m, np.diag([i_cm, i_cm, i_cm]), position=pos, orientation=orient)
    b.add_revolute("hinge", "ground", "bob", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    model = b.finalize()
    L_eq = (i_cm + m * L * L) / (m * L)  # equivalent simple-pendulum length
    return SimpleNamespace(
        model=model,
        builder=b,
        L=L,
        m=m,
        r=r,
        theta0=theta0,
        I_cm=i_cm,
        L_eq=L_eq,
        g=-float(gravity[2]),
    )


def double_pendulum(
    phi1: float = np.pi / 4,
    phi2: float = np.pi / 3,
    l1: float = 1.0,
    l2: float = 0.8,
    m1: float = 1.0,
    m2: float = 0.6,
    rho: float = 0.02,
    gravity=GRAVITY,
):
    """Planar double pendulum of two solid rods (radius rho) in the x-z plane, revolute joints
    about world +y, pivot at the origin. Absolute assembly angles phi1, phi2 from hanging
    (right-handed about +y). Each rod lies along its body z axis (body orientation = Ry(phi)).
    Returns the model and the numpy reference chain (oracles.numpy_rne) of the same
    geometry."""
    yhat = np.array([0.0, 1.0, 0.0])
    r1 = rot_axis_angle(yhat, phi1)
    r2 = rot_axis_angle(yhat, phi2)
    down = np.array([0.0, 0.0, -1.0])
    p1 = np.zeros(3)
    p2 = p1 + l1 * (r1 @ down)
    c1 = p1 + 0.5 * l1 * (r1 @ down)
    c2 = p2 + 0.5 * l2 * (r2 @ down)

    def rod(m, length):
        it = m * (3 * rho * rho + length * length) / 12.0
        return np.diag([it, it, 0.5 * m * rho * rho])

    i1, i2 = rod(m1, l1), rod(m2, l2)
    e1, e2 = quat_exp(phi1 * yhat), quat_exp(phi2 * yhat)
    b = ad.ModelBuilder(gravity=gravity)
    b.add_body("link1", m1, i1, position=c1, orientation=e1)
    b.add_body("link2", m2, i2, position=c2, orientation=e2)
    b.add_revolute("shoulder", "ground", "link1", p1, yhat)
    b.add_revolute("elbow", "link1", "link2", p2, yhat)
    model = b.finalize()
    chain = SerialChain(
        "RR",
        [-1, 0],
        [p1, p2],
        [yhat, yhat],
        [c1, c2],
        [m1, m2],
        [r1 @ i1 @ r1.T, r2 @ i2 @ r2.T],
        rotations=[r1, r2],
        gravity=gravity,
    )
    return SimpleNamespace(
        model=model,
        builder=b,
        chain=chain,
        points=np.array([p1, p2]),
        coms=np.array([c1, c2]),
        rotations=np.array([r1, r2]),
        joint_names=["shoulder", "elbow"],
        body_names=["link1", "link2"],
        l1=l1,
        l2=l2,
        m1=m1,
        m2=m2,
    )


def spatial_arm(rng, n: int = 6, prismatic: bool = False, gravity=GRAVITY):
    """Random spatial serial arm (see oracles.numpy_rne.random_serial_arm)."""
    return random_serial_arm(rng, n, prismatic=prismatic, gravity=gravity)


def to_armdyn(perm, x_ref):
    """Reorder a joint-space vector from reference order to armdyn coordinate order."""
    out = np.empty(len(perm))
    out[perm] = x_ref
    return out


def from_armdyn(perm, x_ad):
    return np.asarray(x_ad)[perm]


def name_regex(*names: str) -> str:
    """Regex matching any of the given literal names (for pytest.raises(match=...))."""
    return "|".join(re.escape(n) for n in names)


# ----------------------------------------------------------------------------------------------
# fixtures
# ----------------------------------------------------------------------------------------------


@pytest.fixture
def rng(request):
    """A numpy Generator seeded from the test's name, so every test is reproducible and
    independent of the execution order. ARMDYN_TEST_SEED (default 0) shifts all seeds, to run
    the randomised tests on other draws."""
    seed = sum(ord(ch) * (i + 1) for i, ch in enumerate(request.node.name))
    seed += 7919 * int(os.environ.get("ARMDYN_TEST_SEED", "0"))
    return np.random.default_rng(seed % (2**32))


@pytest.fixture
def pendulum_factory():
    return simple_pendulum


@pytest.fixture
def double_pendulum_model():
    return double_pendulum()


# ---------------------------------------------------------------------- runs compared bit for bit

RESULT_TABLES = (
    "t",
    "u",
    "v",
    "q",
    "qd",
    "qdd",
    "drive_forces",
    "joint_torques",
    "reaction_forces",
    "reaction_torques",
    "position_residual",
    "velocity_residual",
    "kinetic_energy",
    "potential_energy",
)


def assert_same_run(a, b, stats=False):
    """Two SimulationResults equal bit for bit: every table, the gear and limit forces, the
    events; with stats, the step statistics too (the run time aside)."""
    for name in RESULT_TABLES:
        x, y = getattr(a, name), getattr(b, name)
        assert x.shape == y.shape, name
        assert np.array_equal(x, y), name
    for group in ("gear_forces", "limit_forces"):
        assert getattr(a, group)["names"] == getattr(b, group)["names"]
        assert np.array_equal(getattr(a, group)["force"], getattr(b, group)["force"]), group
    assert np.array_equal(a.events["t"], b.events["t"])
    assert a.events["limits"]["joint"] == b.events["limits"]["joint"]
    if stats:
        sa = {k: v for k, v in a.stats.items() if k != "seconds"}
        sb = {k: v for k, v in b.stats.items() if k != "seconds"}
        assert sa == sb


@pytest.fixture(scope="session")
def doc_file_blocks(tmp_path_factory):
    """``doc_file_blocks("README.md")``: the ```python blocks of one file (README.md or
    docs/<name>.md), run once per session on first use (tests/docs/doc_blocks.py says how),
    each file in its own working directory. A test needing one file's blocks waits for that file
    only. It lives here, not in a tests/docs/conftest.py: two conftest modules would shadow each
    other's ``from conftest import ...``."""
    from doc_blocks import run_blocks  # tests/docs, on sys.path for its tests

    done: dict = {}

    def blocks(file: str) -> list:
        if file not in done:
            done[file] = run_blocks([ROOT / file], tmp_path_factory.mktemp("doc-blocks"))
        return done[file]

    return blocks


@pytest.fixture(scope="session")
def doc_blocks(doc_file_blocks):
    """Every ```python block of README.md and docs/*.md (those of files already run are not run
    again)."""
    from doc_blocks import doc_files

    return [b for path in doc_files() for b in doc_file_blocks(path.relative_to(ROOT).as_posix())]
