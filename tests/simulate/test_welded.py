"""Welded bodies: simulate integrates bodies joined by fixed joints as one composite body
(Model.welded) and reports every body and joint of the model. Checked against the same run
without merging (every body and fixed joint integrated: a second formulation of the same
mechanism) and against a closed-form fixed-joint reaction."""

import armdyn as ad
import numpy as np
import pytest
from armdyn.papers.geared_arm import geared_arm_6dof
from conftest import rel_err
from welded_scene import welded_pendulums

FIELDS = (
    "q",
    "qd",
    "qdd",
    "u",
    "v",
    "drive_forces",
    "reaction_forces",
    "reaction_torques",
    "kinetic_energy",
    "potential_energy",
)


def _compare(a, b, rel_first, rel_run):
    """Row 0 is the same state in both runs (formulation only); later rows add each run's own
    integration error (different step sequences)."""
    for name in FIELDS:
        x, y = getattr(a, name), getattr(b, name)
        assert x.shape == y.shape, name
        if x.size == 0:
            continue
        assert rel_err(x[0], y[0], floor=1e-9) <= rel_first, name
        assert rel_err(x, y, floor=1e-9) <= rel_run, name


def _pair(model, t_end, **kw):
    # the Cartesian formulation, whose welded bodies are what these tests are about (a plain
    # simulate may take joint space: coordinates="auto")
    kw.setdefault("coordinates", "cartesian")
    merged = ad.simulate(model, t_end, **kw)
    full = ad.simulate(model, t_end, merge_welded=False, **kw)
    assert full.stats["solver_bodies"] == model.nb
    return merged, full


def test_welded_model_is_the_same_mechanism_with_fewer_bodies():
    model = welded_pendulums()
    merged, full = _pair(model, 1.0, rtol=1e-11, atol=1e-12, output_dt=0.02)
    # bracket -> ground; weight and sensor -> link1; tip -> link2
    assert merged.stats["solver_bodies"] == 2 and merged.stats["solver_rows"] == 10
    assert full.stats["solver_rows"] == 5 * 2 + 6 * 4
    _compare(merged, full, 1e-12, 1e-10)
    assert np.max(merged.position_residual) <= 1e-12  # every fixed joint of the full model
    assert np.max(merged.velocity_residual) <= 1e-12


def test_geared_arm_welded_run_matches_the_full_run():
    # the first 0.02 s: the arm sags onto its motors, 9 tooth contact events in each run (41 in
    # 0.1 s, at five times the cost); later rows differ by 1.4e-10 (2.1e-7 over 0.1 s)
    model = geared_arm_6dof(n_motors=1, backlash=1e-4)
    merged, full = _pair(model, 0.02, rtol=1e-10, atol=1e-12, output_dt=0.005)
    assert merged.events["t"].size >= 5
    assert merged.stats["solver_bodies"] == 18 and full.stats["solver_bodies"] == 44
    _compare(merged, full, 1e-12, 5e-7)
    np.testing.assert_array_equal(merged.events["t"].shape, full.events["t"].shape)


def test_fixed_joint_reaction_of_a_hanging_weight_is_its_weight():
    """A pendulum hanging at rest with a weight welded below its tip: the weld carries the
    weight's gravity, m g upwards on the weight, and no torque about the weld point when the
    weight's centre of mass is below it."""
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("rod", 1.0, [0.01, 0.01, 1e-4], position=(0, 0, -0.5))
    b.add_revolute("pivot", "ground", "rod", point=(0, 0, 0), axis=(0, 1, 0))
    b.add_body("weight", 2.5, [1e-3, 1e-3, 1e-3], position=(0, 0, -1.1))
    b.add_fixed("weld", "rod", "weight", point=(0, 0, -1.0))
    model = b.finalize()
    res = ad.simulate(model, 0.5, output_dt=0.25)
    assert res.stats["solver_bodies"] == 1
    j = list(model.joint_names).index("weld")
    # child joint frame of a fixed joint: the world axes here (bodies unrotated)
    f = res.reaction_forces[:, j, :]
    assert np.abs(f - [0.0, 0.0, 2.5 * 9.81]).max() <= 1e-9
    assert np.abs(res.reaction_torques[:, j, :]).max() <= 1e-9
    pivot = res.reaction_forces[:, list(model.joint_names).index("pivot"), :]
    assert np.linalg.norm(pivot, axis=1) == pytest.approx(3.5 * 9.81, rel=1e-12)


@pytest.mark.parametrize("merge", [True, False])
def test_joint_space_run_reports_the_cartesian_tables_without_a_kkt_solve(merge):
    """A joint-space run records its outputs from the tree's recursive sweeps: accelerations
    from the joint-space dynamics, every joint's multipliers (the fixed joints' too) from the
    bodies' Newton-Euler balances. Its tables equal the Cartesian run's (the paper's KKT
    multipliers) and it makes no KKT solve."""
    model = welded_pendulums()
    kw = dict(rtol=1e-11, atol=1e-12, output_dt=0.02, merge_welded=merge)
    cart = ad.simulate(model, 1.0, coordinates="cartesian", **kw)
    joint = ad.simulate(model, 1.0, coordinates="joint", **kw)
    assert joint.stats["formulation"].startswith("joint space")
    assert joint.stats["kkt_solves"] == 0 and cart.stats["kkt_solves"] > 0
    # the joint angles start at 0 (round-off: 1e-16 apart); measured: row 0 (the same state)
    # 1.6e-15, the run (each its own integration error) 5.8e-12
    assert np.abs(joint.q - cart.q).max() <= 1e-11
    for name in ("qdd", "u", "v", "reaction_forces", "reaction_torques", "kinetic_energy"):
        assert rel_err(getattr(joint, name)[0], getattr(cart, name)[0], floor=1e-9) <= 1e-13, name
        assert rel_err(getattr(joint, name), getattr(cart, name), floor=1e-9) <= 1e-10, name
    assert joint.position_residual.max() <= 1e-13 and joint.velocity_residual.max() <= 1e-13
