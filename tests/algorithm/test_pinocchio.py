"""Cross-check against Pinocchio on real URDF arms (issue 5): the same URDF loaded by armdyn
(urdfdom) and by Pinocchio (its own URDF parser, articulated-body, recursive Newton–Euler and
composite-rigid-body algorithms), through :class:`benchmarks.peers.pinocchio.PinPair`. The public
``forward_dynamics`` (default and Cartesian KKT path) must equal ``pin.aba``,
``inverse_dynamics`` ``pin.rnea`` and ``mass_matrix`` ``pin.crba`` to 1e-9 relative over random
states; this is the check ``python -m benchmarks.bench`` also runs next to its timings. The UR5
work-precision problem and its peers are checked here too."""

import numpy as np
import pytest

from benchmarks import common
from benchmarks.peers.pinocchio import PinPair

pytest.importorskip("pinocchio")


@pytest.mark.parametrize("robot", ["ur5", "panda"])
def test_forward_and_inverse_dynamics_equal_pinocchio(robot):
    path = common.robot_urdf(robot)
    assert path is not None, "example-robot-data is part of the test extra"
    pair = PinPair(path)
    assert pair.am.nb == pair.pm.nq  # one body per joint: both parsers read the same tree
    errors = pair.cross_check(n=50, seed=7)
    assert errors["fd_rel_error"] <= 1e-9
    assert errors["fd_kkt_rel_error"] <= 1e-9
    assert errors["id_rel_error"] <= 1e-9
    assert errors["mass_matrix_rel_error"] <= 1e-9


def test_ur5_run_agrees_with_pinocchio_and_mujoco_solves_the_same_arm():
    # 5 s of the UR5 falling from a bent pose (workprecision ur5, quick sweeps): armdyn's
    # DOPRI5 at rtol 1e-8 stays within 1e-5 rad (measured 4.9e-6) of a DOP853 (rtol 1e-13)
    # integration of Pinocchio's ABA over all 100 outputs, and MuJoCo's import of the same URDF
    # has Pinocchio's accelerations (so its curve in the benchmark is the same problem)
    # (the curves the benchmark's quick sweep draws, computed alone: not the whole sweep, whose
    # other integrators and peers took 133 s of the suite on a busy machine)
    pytest.importorskip("mujoco")
    from benchmarks import workprecision as wp

    problem = wp.PROBLEMS["ur5"]
    ref = problem.reference(common.output_times(problem))
    curve = wp.sweep_armdyn(problem, "dopri5", [1e-6, 1e-8], ref, repeats=1)
    dopri = {p["setting"]: p["error"] for p in curve}
    assert dopri[1e-8] <= 1e-5  # measured 2.0e-6
    assert dopri[1e-8] < dopri[1e-6] / 10  # converges with the tolerance
    (mj,) = wp.sweep_mujoco(problem, "rk4", [1e-3], ref, repeats=1)
    assert mj["error"] <= 1e-5  # RK4 at 1 ms: measured 1.7e-6
    check = wp._Ur5.get().check(None)
    assert check["armdyn_qdd_vs_pin_aba_rel"] <= 1e-9
    assert check["mujoco_qacc_vs_pin_aba_rel"] <= 1e-9


def test_exudyn_peer_converges_to_the_pinocchio_reference():
    # the Exudyn peer of the UR5 problem (redundant coordinates: Euler-parameter bodies, revolute
    # joints as constraints) solves the same UR5 problem: TrapezoidalIndex2 at fixed steps
    # converges at second order to the DOP853 (rtol 1e-13) integration of Pinocchio's ABA, over
    # the first 2.5 s of the problem's 5 s at its steps of 1 ms and 0.5 ms (measured 1.8e-4 rad
    # at 2500 steps, 4.6e-5 at 5000; over 5 s, 6.1e-4 and 1.5e-4, twice the time)
    pytest.importorskip("exudyn")
    import pinocchio as pin

    from benchmarks import workprecision
    from benchmarks.peers import exudyn

    pm = pin.buildModelFromUrdf(str(common.robot_urdf("ur5")))
    arm = exudyn.build_ur5_like(pm, np.asarray(common.UR5_Q0))
    ref = workprecision._Ur5.get().reference(np.linspace(0.0, 2.5, 2))[-1]
    errors = []
    for n in (2500, 5000):
        q, _cpu = arm.run(2.5, n, "TrapezoidalIndex2")
        errors.append(np.abs(q - ref).max())
    assert errors[0] <= 3e-4
    assert 3.0 <= errors[0] / errors[1] <= 5.0
