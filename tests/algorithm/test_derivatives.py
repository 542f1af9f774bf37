"""Analytical first-order derivatives of the dynamics (issue 34): ``inverse_dynamics_derivatives``
(dtau/dq, dtau/dqd) and ``forward_dynamics_derivatives`` (dqdd/dq, dqdd/dqd, dqdd/dtau), checked
against central finite differences of the public ``inverse_dynamics`` / ``forward_dynamics`` on
the UR5 and the Panda (its fingers coupled: a mimic joint), a floating solo12 (q perturbed along
the base's qd block through the exponential map: Pinocchio's free-flyer convention), arms with
actuators (rotors on follower joints: gear-reduced and gyroscopic) and a cylindrical joint; and
against properties that need no differencing (dtau/dqd vanishes at rest, gravity's dtau/dq is a
symmetric Hessian on a fixed base, dqdd/dtau is the inverse mass matrix)."""

import re
from pathlib import Path

import armdyn as ad
import numpy as np
import pytest

from benchmarks import common

EXAMPLE_ROBOTS = {
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "panda": "panda_description/urdf/panda.urdf",
    "solo12": "solo_description/robots/solo12.urdf",
}


def _urdf(robot, tmp_path):
    """The example-robot-data URDF without its ``<dynamics damping friction>`` (armdyn imports
    them as joint friction: force elements, whose derivatives are part forcederiv's)."""
    ur5 = common.robot_urdf("ur5")
    assert ur5 is not None, "example-robot-data is part of the test extra"
    robots = next(p for p in ur5.parents if p.name == "robots")
    path = robots / EXAMPLE_ROBOTS[robot]
    text = re.sub(r"<dynamics\b[^>]*/>", "", Path(path).read_text())
    out = Path(tmp_path) / Path(path).name
    out.write_text(text)
    return str(out)


def _quat_mul(a, b):
    w1, v1 = a[0], a[1:]
    w2, v2 = b[0], b[1:]
    return np.concatenate([[w1 * w2 - v1 @ v2], w1 * v2 + w2 * v1 + np.cross(v1, v2)])


def _rot(e):
    w, x, y, z = e
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def _step(model, q, k, eps):
    """q moved by eps along degree of freedom k: a coordinate by eps; a floating base (the
    leading 7 entries of q per base) by the exponential map of eps times its k-th velocity
    (linear in its own axes, or angular in its own axes)."""
    q = np.array(q, dtype=float)
    n_free = _n_free(model)
    if k >= 6 * n_free:
        q[7 * n_free + k - 6 * n_free] += eps
        return q
    b, i = divmod(k, 6)
    e = q[7 * b + 3 : 7 * b + 7]
    if i < 3:
        q[7 * b : 7 * b + 3] += eps * _rot(e)[:, i]
    else:
        axis = np.zeros(3)
        axis[i - 3] = 1.0
        dq = np.concatenate([[np.cos(eps / 2)], np.sin(eps / 2) * axis])
        q[7 * b + 3 : 7 * b + 7] = _quat_mul(e, dq)
    return q


def _n_free(model):
    return model.n_coords - model.n_dofs  # 7 entries of q, 6 of qd per floating base


def _fd(model, f, q, qd, x, h=1e-3):
    """Central differences of f(q, qd, x) (n_dofs,) along each degree of freedom of q and of
    qd, (df/dq, df/dqd), Richardson-extrapolated from steps h and h/2 (error O(h^4): a step
    large against the round-off of f, which a floating robot's light legs make 1e-11 of qdd)."""
    n = model.n_dofs

    def central(k, eps):
        e = np.zeros(n)
        e[k] = eps
        dq = f(_step(model, q, k, eps), qd, x) - f(_step(model, q, k, -eps), qd, x)
        dqd = f(q, qd + e, x) - f(q, qd - e, x)
        return dq / (2 * eps), dqd / (2 * eps)

    dq, dqd = np.empty((n, n)), np.empty((n, n))
    for k in range(n):
        (a, b), (c, d) = central(k, h), central(k, h / 2)
        dq[:, k] = (4 * c - a) / 3
        dqd[:, k] = (4 * d - b) / 3
    return dq, dqd


def _rel(a, b):
    return float(np.abs(a - b).max() / max(1.0, np.abs(b).max()))


def _state(model, rng):
    nf = _n_free(model)
    q = rng.uniform(-1.5, 1.5, model.n_coords)
    for b in range(nf):
        e = rng.normal(size=4)
        q[7 * b + 3 : 7 * b + 7] = e / np.linalg.norm(e)
    n = model.n_dofs
    return q, rng.normal(size=n), rng.normal(size=n)


def _check_model(model, seed=3, states=2):
    rng = np.random.default_rng(seed)
    for _ in range(states):
        q, qd, qdd = _state(model, rng)
        dq, dqd = ad.inverse_dynamics_derivatives(model, q, qd, qdd)
        fq, fqd = _fd(model, lambda a, b, c: ad.inverse_dynamics(model, a, b, c), q, qd, qdd)
        assert _rel(dq, fq) <= 1e-7, _rel(dq, fq)
        assert _rel(dqd, fqd) <= 1e-7, _rel(dqd, fqd)
        tau = rng.normal(size=model.n_dofs) * 10
        aq, aqd, atau = ad.forward_dynamics_derivatives(model, q, qd, tau)
        fd = lambda a, b, c: ad.forward_dynamics(model, a, b, c)  # noqa: E731
        gq, gqd = _fd(model, fd, q, qd, tau)
        assert _rel(aq, gq) <= 1e-7, _rel(aq, gq)
        assert _rel(aqd, gqd) <= 1e-7, _rel(aqd, gqd)
        np.testing.assert_allclose(atau @ ad.mass_matrix(model, q), np.eye(model.n_dofs), atol=1e-9)


@pytest.mark.parametrize("robot", ["ur5", "panda"])
def test_arms_equal_finite_differences(robot, tmp_path):
    model = ad.load_urdf(_urdf(robot, tmp_path))
    if robot == "panda":
        assert model.n_coords < len(model.coord_names) or model.n_dofs == 8  # the mimic finger
    _check_model(model)


def test_floating_solo12_equals_finite_differences(tmp_path):
    model = ad.load_urdf(_urdf("solo12", tmp_path), fixed_base=False)
    assert model.n_coords == model.n_dofs + 1
    _check_model(model, states=1)
