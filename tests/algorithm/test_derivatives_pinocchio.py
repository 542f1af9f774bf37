"""armdyn's analytical derivatives of the dynamics against Pinocchio's (issue 34):
``armdyn.inverse_dynamics_derivatives`` against ``pin.computeRNEADerivatives`` and
``armdyn.forward_dynamics_derivatives`` against ``pin.computeABADerivatives``, to 1e-10 relative
to each matrix's largest entry, on the UR5 and the Panda on a fixed base and solo12 (and the UR5)
on a free flyer, at random states; one state per call and 2-D batches.

The map between the two libraries' conventions (``benchmarks.derivatives.DerivativePair``):
joints matched by name, the quaternion scalar first in armdyn and last in Pinocchio, the base
velocity (v, ω) of the base frame in its own axes in both, the q-derivatives along the velocity
coordinates (tangent space, Pinocchio's ``integrate``), so that every matrix maps by the velocity
permutation; the URDF's joint damping/friction, which armdyn includes and Pinocchio leaves out,
added to Pinocchio's answers. The first test checks that map itself, without armdyn's
derivatives: central finite differences of armdyn's ``inverse_dynamics`` / ``forward_dynamics``
along Pinocchio's ``integrate`` equal Pinocchio's derivatives.
"""

import armdyn as ad
import numpy as np
import pytest

pytest.importorskip("pinocchio")

from benchmarks.derivatives import ROBOTS, DerivativePair, rel_error, robot_path

# (robot, fixed base): the three robots, and the UR5 on a free flyer
CASES = [("ur5", True), ("panda", True), ("solo12", False), ("ur5", False)]
IDS = [f"{r}-{'fixed' if f else 'floating'}" for r, f in CASES]
TOL = 1e-10  # measured on the seeded states: ≤ 2.5e-15 (RNEA), ≤ 9.4e-12 (ABA, free flyers)
_PAIRS: dict = {}


def _pair(robot, fixed) -> DerivativePair:
    if (robot, fixed) not in _PAIRS:
        _PAIRS[robot, fixed] = DerivativePair(robot_path(robot), fixed_base=fixed)
    return _PAIRS[robot, fixed]


def test_the_three_robots_and_their_bases():
    assert {r: f for r, (_, f) in ROBOTS.items()} == {"ur5": True, "panda": True, "solo12": False}
    solo = _pair("solo12", False)
    assert (solo.am.n_coords, solo.am.n_dofs, solo.pm.nq, solo.pm.nv) == (19, 18, 19, 18)
    assert solo.am.coord_names[3:7] == [f"root_free:e{i}" for i in range(4)]
    panda = _pair("panda", True)
    assert panda.am.n_dofs == panda.pm.nv == 9  # the fingers each their own coordinate
    assert np.any(panda.pm.damping > 0)  # so the friction term of the map is exercised


def _finite_differences(pair, fn, q, qd, x, h=1e-5):
    """Central differences of ``fn(model, q, qd, x)`` along each velocity coordinate: q moved
    by Pinocchio's ``integrate`` (the tangent space), qd and x along their entries."""
    am, n = pair.am, pair.am.n_dofs
    steps = h * np.eye(n)
    d_q = [
        fn(am, pair.integrate(q, s), qd, x) - fn(am, pair.integrate(q, -s), qd, x) for s in steps
    ]
    d_qd = [fn(am, q, qd + s, x) - fn(am, q, qd - s, x) for s in steps]
    d_x = [fn(am, q, qd, x + s) - fn(am, q, qd, x - s) for s in steps]
    return tuple(np.stack(d, axis=1) / (2 * h) for d in (d_q, d_qd, d_x))


@pytest.mark.parametrize(("robot", "fixed"), CASES, ids=IDS)
def test_the_convention_map_by_finite_differences(robot, fixed):
    pair = _pair(robot, fixed)
    rng = np.random.default_rng(34)
    for _ in range(2):
        q, qd, x = pair.random_state(rng)
        # the states map: the same point, the same torques (Pinocchio's less the friction)
        np.testing.assert_array_equal(pair.q_armdyn(pair.q_pin(q)), q)
        qp, vp = pair.q_pin(q), pair.v_pin(qd)
        ref_tau = pair.pin.rnea(pair.pm, pair.pd, qp, vp, pair.v_pin(x)) - pair.friction(vp)[0]
        assert rel_error(ad.inverse_dynamics(pair.am, q, qd, x), ref_tau[pair.iv]) <= 1e-12
        fd_q, fd_qd, _ = _finite_differences(pair, ad.inverse_dynamics, q, qd, x)
        ref_q, ref_qd = pair.rnea_derivatives(q, qd, x)
        # measured (these seeded states): <= 2.5e-10; the finite differences limit it
        assert rel_error(fd_q, ref_q) <= 1e-8 and rel_error(fd_qd, ref_qd) <= 1e-8
        fds = _finite_differences(pair, ad.forward_dynamics, q, qd, x)
        # measured: <= 2.9e-8 on the free flyers (M's condition number ~1e4 amplifies the
        # differences' round-off), <= 7.8e-10 on the fixed bases
        for fd, ref in zip(fds, pair.aba_derivatives(q, qd, x), strict=True):
            assert rel_error(fd, ref) <= 1e-7


@pytest.mark.parametrize(("robot", "fixed"), CASES, ids=IDS)
def test_inverse_dynamics_derivatives_equal_pinocchio(robot, fixed):
    pair = _pair(robot, fixed)
    rng = np.random.default_rng(10)
    for _ in range(10):
        q, qd, qdd = pair.random_state(rng)
        dq, dqd = ad.inverse_dynamics_derivatives(pair.am, q, qd, qdd)
        ref_q, ref_qd = pair.rnea_derivatives(q, qd, qdd)
        assert dq.shape == dqd.shape == (pair.am.n_dofs, pair.am.n_dofs)
        assert rel_error(dq, ref_q) <= TOL, rel_error(dq, ref_q)
        assert rel_error(dqd, ref_qd) <= TOL, rel_error(dqd, ref_qd)


@pytest.mark.parametrize(("robot", "fixed"), CASES, ids=IDS)
def test_forward_dynamics_derivatives_equal_pinocchio(robot, fixed):
    pair = _pair(robot, fixed)
    rng = np.random.default_rng(11)
    for _ in range(10):
        q, qd, tau = pair.random_state(rng)
        ours = ad.forward_dynamics_derivatives(pair.am, q, qd, tau)
        refs = pair.aba_derivatives(q, qd, tau)
        assert len(ours) == 3
        for name, a, b in zip(("dqdd_dq", "dqdd_dqd", "dqdd_dtau"), ours, refs, strict=True):
            assert a.shape == (pair.am.n_dofs, pair.am.n_dofs), name
            assert rel_error(a, b) <= TOL, (name, rel_error(a, b))


@pytest.mark.parametrize(("robot", "fixed"), CASES, ids=IDS)
def test_batches_equal_pinocchio_row_by_row(robot, fixed):
    pair = _pair(robot, fixed)
    am, n, rows = pair.am, pair.am.n_dofs, 7
    q, qd, x = pair.random_state(np.random.default_rng(12), rows)
    data = ad.Data(am)
    inv = ad.inverse_dynamics_derivatives(am, q, qd, x, t=np.linspace(0.0, 1.0, rows), data=data)
    fwd = ad.forward_dynamics_derivatives(am, q, qd, x, t=0.5, data=data)
    assert [m.shape for m in (*inv, *fwd)] == [(rows, n, n)] * 5
    for i in range(rows):
        for a, b in zip(inv, pair.rnea_derivatives(q[i], qd[i], x[i]), strict=True):
            assert rel_error(a[i], b) <= TOL, (i, rel_error(a[i], b))
        for a, b in zip(fwd, pair.aba_derivatives(q[i], qd[i], x[i]), strict=True):
            assert rel_error(a[i], b) <= TOL, (i, rel_error(a[i], b))
