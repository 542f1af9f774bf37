"""The MuJoCo and Exudyn peers of the closed-loop standard problems (benchmarks.peers.closed_loops)
are the same mechanisms as the references: accelerations at the start, and errors that fall
under step refinement."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks import references
from benchmarks.peers import closed_loops as pcl
from benchmarks.workprecision import PROBLEMS

SQUEEZER_T, SQUEEZER_OUT = 0.03, 300
A02_T, A02_OUT = 2.0, 40  # 2 s: crank 0 passes the flat (singular) position at t = 0.7 s


@pytest.fixture(scope="module")
def squeezer_ref():
    return references.squeezer_angles(np.linspace(0.0, SQUEEZER_T, SQUEEZER_OUT + 1))


@pytest.fixture(scope="module")
def a02_ref():
    return references.a02_points(np.linspace(0.0, A02_T, A02_OUT + 1), pcl.A02_N)


def _squeezer_qdd0():
    f, y0 = references.squeezer_rhs()
    return f(0.0, y0)[7:]


def _a02_qdd(phi0):
    f, _y0 = references.a02_rhs(pcl.A02_N)
    return f(0.0, np.array([phi0, 0.0]))[1]


def test_mujoco_squeezer_is_the_same_mechanism_at_the_start():
    pytest.importorskip("mujoco")
    soft, hard = pcl.mujoco_squeezer().accelerations()
    ref = _squeezer_qdd0()  # (14222.4, -10666.8, 0, 0, 0, 0, 0)
    scale = np.abs(ref).max()
    # MuJoCo's mass matrix, spring, torque and loop Jacobian with exact constraints (KKT):
    # measured 1.8e-12
    assert np.abs(hard - ref).max() / scale < 1e-9
    # its own soft-constraint accelerations: the impedance is capped at 0.9999 (mjMAXIMP), so
    # about 1e-4 of the unconstrained accelerations remains; measured 1.3e-3
    assert np.abs(soft - ref).max() / scale < 3e-3


def test_mujoco_squeezer_converges_to_the_reference(squeezer_ref):
    pytest.importorskip("mujoco")
    peer = pcl.mujoco_squeezer()
    errors, residuals = [], []
    for h in (2.5e-5, 6.25e-6):
        peer.set_step(h)
        qpos = peer.run(peer.mujoco.MjData(peer.model), SQUEEZER_T, SQUEEZER_OUT)
        errors.append(np.abs(peer.observe(qpos) - squeezer_ref).max())
        residuals.append(peer.loop_residual(qpos))
    # measured 3.2e-6 and 6.7e-7 rad; loop violations fall with the time constant 2 h
    assert errors[1] < errors[0] / 3
    assert errors[1] < 1.5e-6
    assert residuals[1] < residuals[0] / 4


def test_exudyn_squeezer_is_the_same_mechanism_at_the_start():
    pytest.importorskip("exudyn")
    acc = pcl.squeezer_to_angles(pcl.exudyn_squeezer().initial_accelerations())
    ref = _squeezer_qdd0()
    assert np.abs(acc - ref).max() / np.abs(ref).max() < 1e-10  # measured 7e-15


@pytest.mark.parametrize("method", pcl.EXUDYN_METHODS)
def test_exudyn_squeezer_converges_at_second_order(method, squeezer_ref):
    pytest.importorskip("exudyn")
    peer = pcl.exudyn_squeezer()
    errors = []
    for n in (1200, 4800):
        obs, _cpu, stats = peer.trajectory(SQUEEZER_T, SQUEEZER_OUT, n, method)
        assert stats["steps"] == n
        errors.append(np.abs(obs - squeezer_ref).max())
    # 4x smaller step: measured 16x smaller error (6.7e-4 -> 4.2e-5 generalized-alpha,
    # 3.0e-4 -> 1.9e-5 index-2 trapezoidal)
    assert errors[1] < errors[0] / 10
    assert errors[1] < 1e-4


def test_mujoco_a02_is_the_same_mechanism():
    pytest.importorskip("mujoco")
    phi0 = 1.0  # at rest on the branch, away from the singular positions
    soft, hard = pcl.mujoco_a02(phi0=phi0, speed=0.0).accelerations()
    ref = _a02_qdd(phi0)
    assert abs(hard[0] - ref) < 1e-9 * abs(ref)  # exact-constraint KKT on MuJoCo's terms
    assert abs(soft[0] - ref) < 2e-3 * abs(ref)  # soft constraints: measured 5e-4


def test_mujoco_a02_through_a_singular_position_converges(a02_ref):
    pytest.importorskip("mujoco")
    peer = pcl.mujoco_a02()
    errors = []
    for h in (5e-3, 1.25e-3):
        peer.set_step(h)
        qpos = peer.run(peer.mujoco.MjData(peer.model), A02_T, A02_OUT)
        errors.append(np.abs(peer.observe(qpos) - a02_ref).max())
    # measured 5.0e-5 and 2.4e-6 m
    assert errors[1] < errors[0] / 5
    assert errors[1] < 1e-5


def test_exudyn_a02_is_the_same_mechanism():
    pytest.importorskip("exudyn")
    phi0 = 1.0
    acc = pcl.exudyn_a02(phi0=phi0, speed=0.0).initial_accelerations()
    ref = _a02_qdd(phi0)
    assert abs(acc[0] - ref) < 1e-10 * abs(ref)


def test_exudyn_a02_generalized_alpha_through_a_singular_position(a02_ref):
    pytest.importorskip("exudyn")
    peer = pcl.exudyn_a02()
    errors = []
    for n in (200, 800):
        obs, _cpu, _stats = peer.trajectory(A02_T, A02_OUT, n, "GeneralizedAlpha")
        errors.append(np.abs(obs - a02_ref).max())
    # measured 2.8e-3 and 1.8e-4 m: second order through the flat position
    assert errors[1] < errors[0] / 8
    assert errors[1] < 5e-4


def test_exudyn_failed_run_carries_its_reason():
    pytest.importorskip("exudyn")
    peer = pcl.exudyn_a02()
    # index-2 trapezoidal rule: Newton fails near the flat position at t = 1.245 s
    with pytest.raises(RuntimeError, match=r"stopped at t = .*Newton"):
        peer.trajectory(A02_T, A02_OUT, 400, "TrapezoidalIndex2")


def test_workprecision_hook_returns_the_peer_curves(squeezer_ref):
    pytest.importorskip("mujoco")
    pytest.importorskip("exudyn")
    problem = PROBLEMS["squeezer"]
    assert problem.more_peers is not None and PROBLEMS["a02"].more_peers is not None
    curves = problem.more_peers(problem, squeezer_ref, True, 1)
    assert len(curves) == 3
    for key, points in curves.items():
        assert key.startswith(("MuJoCo", "Exudyn"))
        for point in points:
            assert "failed" not in point
            assert point["cpu_s"] > 0 and point["repeats"] == 1 and point["steps"] > 0
            assert point["error"] < 1e-3  # quick settings: 2e-6 (MuJoCo) to 1.7e-4


def test_pinocchio_a02_is_the_same_mechanism():
    """The SciPy-on-Pinocchio peer (index-1 equations with Baumgarte terms) against the
    reference's one-DOF branch equation, in motion on the branch away from the flat positions:
    every crank accelerates at phi'' = -c cos(phi), every coupler's relative angle at -phi''."""
    pytest.importorskip("pinocchio")
    n = pcl.A02_N
    peer = pcl.PinocchioA02(n)
    phi, rate = 0.7, -1.3
    q, v = peer.joint_vector(phi, -phi), peer.joint_vector(rate, -rate)
    acc = peer.accelerations(q, v)
    f, _y0 = references.a02_rhs(n)
    ref = f(0.0, np.array([phi, rate]))[1]
    assert abs(ref) > 1.0
    # measured 3.7e-14 (cranks) and 7.9e-14 (couplers) relative
    assert np.abs(acc[peer.crank_v] - ref).max() < 1e-10 * abs(ref)
    assert np.abs(acc[peer.coupler_v] + ref).max() < 1e-10 * abs(ref)
    # off the branch the velocity terms differ: the check above is not a static identity
    acc2 = peer.accelerations(q, peer.joint_vector(rate, 0.0))
    assert np.abs(acc2[peer.crank_v] - ref).max() > 1e-3 * abs(ref)
