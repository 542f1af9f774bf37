"""Cross-check against Pinocchio on real URDF arms (issue 5): the same URDF loaded by armdyn
(urdfdom, Cartesian Newton–Euler KKT path) and by Pinocchio (its own URDF parser, articulated-
body and recursive Newton–Euler algorithms). Forward dynamics must equal ``pin.aba`` and
inverse dynamics ``pin.rnea`` to 1e-9 relative over random states; this is the check
``armdyn bench`` also runs next to its timings."""

import numpy as np
import pytest
from armdyn import bench

pytest.importorskip("pinocchio")


@pytest.mark.parametrize("robot", ["ur5", "panda"])
def test_forward_and_inverse_dynamics_equal_pinocchio(robot):
    path = bench.robot_urdf(robot)
    assert path is not None, "example-robot-data is part of the test extra"
    pair = bench.PinPair(path)
    assert pair.am.nb == pair.pm.nq  # one body per joint: both parsers read the same tree
    errors = pair.cross_check(n=50, seed=7)
    assert errors["fd_rel_error"] <= 1e-9
    assert errors["id_rel_error"] <= 1e-9


def test_whole_run_agrees_with_scipy_on_pinocchio():
    # 5 s of the UR5 falling from a bent pose: armdyn's DOPRI5 at rtol 1e-8 lands within 1e-5 rad
    # of a DOP853 (rtol 1e-13) integration of Pinocchio's ABA
    r = bench.bench_whole_run(t_end=1.0, rtol=1e-8)
    assert r["armdyn_dopri5"]["error_rad"] <= 1e-5
    assert np.isfinite(r["scipy_DOP853_on_pin_aba"]["error_rad"])
