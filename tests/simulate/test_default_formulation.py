"""simulate's default formulation (coordinates="auto"): the cheaper exact one for the scene, with
the same result fields either way."""

import armdyn as ad
import numpy as np
import pytest
from armdyn.scenes import double_pendulum, four_bar

FIELDS = (
    "q",
    "qd",
    "qdd",
    "reaction_forces",
    "reaction_torques",
    "joint_torques",
    "kinetic_energy",
    "potential_energy",
)


def test_plain_run_of_a_tree_takes_joint_space_and_reports_the_cartesian_tables():
    """A tree without drives or limits: the plain run is the joint-space one (the cost model's
    choice, stated in the stats), bit for bit the coordinates="auto" run, and its tables equal
    the Cartesian run's (the paper's KKT multipliers) to the integration tolerance."""
    model = double_pendulum()
    kw = dict(rtol=1e-11, atol=1e-12, output_dt=0.05, q0=[0.9, -0.4], qd0=[0.0, 0.0])
    plain = ad.simulate(model, 1.0, **kw)
    auto = ad.simulate(model, 1.0, coordinates="auto", **kw)
    cart = ad.simulate(model, 1.0, coordinates="cartesian", **kw)
    assert plain.stats["formulation"].startswith("joint space")
    assert "auto: cost model" in plain.stats["formulation"]
    assert cart.stats["formulation"].startswith("cartesian")
    assert plain.stats["kkt_solves"] == 0 and cart.stats["kkt_solves"] > 0
    for f in FIELDS:
        np.testing.assert_array_equal(getattr(plain, f), getattr(auto, f))
        a, c = getattr(plain, f), getattr(cart, f)
        assert a.shape == c.shape, f
        assert np.abs(a - c).max() <= 1e-7 * max(1.0, np.abs(c).max()), f
    # the constraint residuals of the Cartesian state each run reports: round-off either way
    for r in (plain, cart):
        assert r.position_residual.shape == (len(r.t),)
        assert r.position_residual.max() < 1e-12 and r.velocity_residual.max() < 1e-12


def test_plain_run_of_a_loop_is_cartesian():
    """Joint space does not apply to a closed loop: the plain run is the Cartesian one."""
    model = four_bar()
    plain = ad.simulate(model, 0.5, output_dt=0.1)
    cart = ad.simulate(model, 0.5, output_dt=0.1, coordinates="cartesian")
    assert plain.stats["formulation"].startswith("cartesian")
    assert "joint space does not apply" in plain.stats["formulation"]
    for f in ("q", "reaction_forces", "reaction_torques", "position_residual"):
        np.testing.assert_array_equal(getattr(plain, f), getattr(cart, f))


@pytest.mark.parametrize("limits", ["enforce", "ignore"])
def test_limit_stops_leave_the_plain_run_in_joint_space(limits):
    """A joint with a position limit: with its stop in play (limits="enforce", the default) or
    not, the plain run is the joint-space one (the cost model's choice; the joint-space stops
    hold a joint resting on its stop with as few events as the Cartesian ones). Enforced, the
    rod falls onto its stop and rests there, held by the static torque of inverse dynamics,
    as in the Cartesian run; ignored, it swings through the limit."""
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("rod", 1.0, [0.02, 0.02, 1e-3], position=(0.25, 0, 0))
    b.add_revolute("pivot", "ground", "rod", point=(0, 0, 0), axis=(0, 1, 0))
    b.set_joint_limits("pivot", -0.5, 0.5)
    model = b.finalize()
    kw = dict(output_dt=0.1, limits=limits)
    res = ad.simulate(model, 1.0, **kw)
    joint = ad.simulate(model, 1.0, coordinates="joint", **kw)
    assert res.stats["formulation"].startswith("joint space")
    assert "auto: cost model" in res.stats["formulation"]
    for f in ("q", "qd", "reaction_forces", "reaction_torques"):
        np.testing.assert_array_equal(getattr(res, f), getattr(joint, f))
    if limits == "enforce":
        cart = ad.simulate(model, 1.0, coordinates="cartesian", **kw)
        assert res.q[-1, 0] == 0.5  # exactly on the limit
        assert list(res.limit_forces["names"]) == ["pivot"]
        hold = ad.inverse_dynamics(model, [0.5], [0.0], [0.0])[0]
        assert hold != 0.0
        assert res.limit_forces["force"][-1, 0] == pytest.approx(hold, rel=1e-9)
        assert cart.limit_forces["force"][-1, 0] == pytest.approx(hold, rel=1e-9)
        assert len(res.events["limits"]["t"]) == len(cart.events["limits"]["t"])
    else:
        assert res.q[:, 0].max() > 0.5  # it swings through the limit
