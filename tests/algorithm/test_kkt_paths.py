"""The KKT solver paths chosen at finalize() (issue 5): every path gives the answers of the dense
reference (one dense Cholesky of the Schur complement, `model.with_kkt_path("dense")`), the path
is the one the topology calls for and is shown in `summary()`, and the tree path's work grows
linearly with the number of bodies."""

import armdyn as ad
import numpy as np
import pytest
from armdyn.papers.five_dof import five_dof_arm
from armdyn.papers.geared_arm import geared_arm_6dof

chain = ad.scenes.random_chain


def run(model, t_end, dt):
    # fixed steps, so that both paths take the same steps and differ by round-off alone
    return ad.simulate(model, t_end, integrator="rk4", dt=dt, output_dt=t_end / 5)


def assert_same_run(model, t_end=0.05, dt=1e-3):
    dense = model.with_kkt_path("dense")
    assert dense.kkt_path == "dense"
    a, b = run(model, t_end, dt), run(dense, t_end, dt)
    assert np.max(np.abs(a.u - b.u)) <= 1e-12
    assert np.max(np.abs(a.v - b.v)) <= 1e-10 * max(1.0, np.max(np.abs(b.v)))
    scale = max(1.0, np.max(np.abs(b.reaction_forces)))
    assert np.max(np.abs(a.reaction_forces - b.reaction_forces)) <= 1e-9 * scale
    if b.drive_forces.size:
        scale = max(1.0, np.max(np.abs(b.drive_forces)))
        assert np.max(np.abs(a.drive_forces - b.drive_forces)) <= 1e-9 * scale
    return a


def test_tree_path_matches_dense_on_a_chain():
    model = chain(20)
    assert model.kkt_path == "tree"
    assert "KKT path: tree" in model.summary()
    res = assert_same_run(model)
    assert np.max(res.position_residual) <= 1e-12
    rng = np.random.default_rng(0)
    q, qd, tau = rng.normal(size=(3, 20))
    a = ad.forward_dynamics(model, q, qd, tau)
    b = ad.forward_dynamics(model.with_kkt_path("dense"), q, qd, tau)
    assert np.max(np.abs(a - b)) <= 1e-10 * np.max(np.abs(b))


def test_loop_path_matches_dense_on_a_closed_chain():
    model = chain(12, close_loop=True)
    assert model.kkt_path == "tree+loops"
    assert model.kkt_plan["fill_blocks"] > 0
    assert_same_run(model)


def test_geared_arm_is_a_tree_of_row_blocks_and_matches_dense():
    # the ideal gears couple bodies already sharing a link, so they add no fill (ideal gears
    # in both stages here: the stiff backlash mesh wants steps far below RK4's 0.1 ms)
    model = geared_arm_6dof(n_motors=1, backlash=0.0)
    assert model.kkt_path == "tree" and model.nb == 44
    assert_same_run(model, t_end=0.02, dt=1e-4)


def test_driven_model_and_joint_only_solves_match_dense():
    # drives: the all-rows plan (forward runs) and the joint-rows plan (inverse dynamics)
    model = geared_arm_6dof(n_motors=2, backlash=0.0, control="drive")
    assert model.kkt_path in ("tree", "tree+loops")
    assert_same_run(model, t_end=0.02, dt=1e-4)
    arm = geared_arm_6dof(trains=False)
    t = np.linspace(0.0, 5.0, 11)
    a = ad.driven_inverse_dynamics(arm, t)
    b = ad.driven_inverse_dynamics(arm.with_kkt_path("dense"), t)
    assert np.max(np.abs(a.drive_forces - b.drive_forces)) <= 1e-9 * np.max(np.abs(b.drive_forces))


def test_small_models_take_the_block_path_and_redundant_ones_stay_dense():
    # the block elimination is faster than the dense Cholesky down to 15 rows
    # (benchmarks/kkt_paths.py), so even the 5-link paper arm takes it, with the dense answers
    five = five_dof_arm()
    assert five.kkt_path == "tree"
    assert_same_run(five, t_end=0.5, dt=1e-3)
    four_bar = ad.scenes.four_bar()
    assert four_bar.redundant_rows and four_bar.kkt_path == "dense"


@pytest.mark.parametrize("n", [50, 200])
def test_tree_work_is_linear_in_the_bodies(n):
    # the plan's flop count (exact for the block elimination it drives) doubles with the chain
    small, big = chain(n).kkt_plan, chain(2 * n).kkt_plan
    assert small["fill_blocks"] == 0 and big["fill_blocks"] == 0
    assert big["flops"] / small["flops"] == pytest.approx(2.0, rel=0.02)
    assert big["factor_entries"] / small["factor_entries"] == pytest.approx(2.0, rel=0.02)


def test_with_kkt_path_rejects_unknown_paths():
    with pytest.raises(ad.ModelError, match="'dense' or 'auto'"):
        chain(3).with_kkt_path("banded")
