"""simulate's kinematic path: a model whose drives leave no degree of freedom has nothing to
integrate, so each output state is solved from the constraints (position, velocity and
acceleration problems). Checked against the integrated run of the same model (DOPRI5 at tight
tolerance, with projection), against the independent Euler-Lagrange equations, and for the
choice of path and its errors."""

import armdyn as ad
import numpy as np
import pytest
from armdyn import _core
from armdyn.papers import five_dof
from conftest import rel_err

FIELDS = ("q", "qd", "qdd", "drive_forces", "reaction_forces", "reaction_torques")


def _compare(a, b, rel=1e-11):
    for name in (*FIELDS, "kinetic_energy", "potential_energy"):
        x, y = getattr(a, name), getattr(b, name)
        assert x.shape == y.shape, name
        assert rel_err(x, y, floor=1e-12) <= rel, name


def test_five_dof_run_is_kinematic_and_equals_the_integrated_run():
    model = five_dof.five_dof_arm()
    kin = ad.simulate(model, 5.0, output_dt=0.01)
    assert kin.stats["integrator"] == "kinematic"
    assert "no degree of freedom" in kin.stats["integrator_reason"]
    assert kin.stats["steps"] == 0 and kin.stats["newton_iterations"] == 0
    assert len(kin.t) == 501
    dop = ad.simulate(model, 5.0, integrator="dopri5", rtol=1e-10, atol=1e-12, output_dt=0.01)
    assert dop.stats["integrator"] == "dopri5" and dop.stats["steps"] > 0
    np.testing.assert_array_equal(kin.t, dop.t)
    _compare(kin, dop)
    assert np.max(kin.position_residual) <= 1e-13
    assert np.max(kin.velocity_residual) <= 1e-12
    # the drive efforts against the complete Euler-Lagrange equations (independent derivation)
    ref = ad.LagrangeValidator(model).torques(kin.q, kin.qd, kin.qdd, kin.t)
    assert rel_err(kin.drive_forces, ref) <= 1e-10
    # auto picks it too; inverse_dynamics gives the same numbers
    assert ad.simulate(model, 1.0, integrator="auto", output_dt=0.1).stats["integrator"] == (
        "kinematic"
    )
    idr = ad.driven_inverse_dynamics(model, kin.t)
    assert rel_err(idr.drive_forces, kin.drive_forces) <= 1e-14


def test_driven_four_bar_loop_kinematic_equals_integrated():
    """A closed loop (Newton path, redundant rows): the crank driven by a spline."""
    drive = _core.profiles.spline([0.0, 0.5, 1.0], [0.0, 0.6, 1.5])
    model = ad.scenes.four_bar(crank_drive=drive)
    assert model.mobility_driven == 0
    kin = ad.simulate(model, 1.0, output_dt=0.02)
    assert kin.stats["integrator"] == "kinematic"
    assert kin.stats["newton_iterations"] > 0
    dop = ad.simulate(model, 1.0, integrator="dopri5", rtol=1e-11, atol=1e-12, output_dt=0.02)
    _compare(kin, dop, rel=1e-9)
    assert np.max(kin.position_residual) <= 1e-12


def test_models_with_freedom_are_integrated_and_kinematic_says_why_not():
    model = five_dof.three_dof_arm(drives=False)
    assert model.mobility_driven > 0
    res = ad.simulate(model, 0.1, output_dt=0.05)
    assert res.stats["integrator"] == "dopri5"
    with pytest.raises(ad.ModelError, match="degree"):
        ad.simulate(model, 0.1, integrator="kinematic", output_dt=0.05)
    driven = five_dof.five_dof_arm()
    with pytest.raises(ad.ModelError, match="output_dt"):
        ad.simulate(driven, 0.1, integrator="kinematic")
    # without an output grid the default integrates (outputs at its accepted steps)
    assert ad.simulate(driven, 0.1).stats["integrator"] == "dopri5"
