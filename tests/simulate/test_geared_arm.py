"""The 44-body geared arm: structure, and the drive torque through backlash-free gears equal to
the arm's inverse-dynamics torque divided by the gear ratio (power through ideal gears), plus a
short run with backlash that shows tooth impacts while the motors hold the arm."""

import armdyn as ad
import numpy as np
import pytest
from armdyn.papers.geared_arm import RATIOS, geared_arm_6dof


def test_structure():
    m = geared_arm_6dof()
    assert m.nb == 44 and len(m.joint_names) == 44
    assert m.mobility == 6  # 18 revolutes minus 12 ideal gear rows
    assert geared_arm_6dof(backlash=1e-4).mobility == 12  # stage-2 play adds one DOF per train
    assert geared_arm_6dof(n_motors=4).nb == 44 + 3 * 4


def test_drive_torque_through_ideal_gears_equals_inverse_dynamics_over_the_ratio():
    """Rotor angles prescribed (control="drive"), gear trains at 1e-6 of their mass: the rotor
    torque is τ_joint / N, τ_joint the inverse dynamics of the arm alone along the same motion."""
    times = np.linspace(0.0, 5.0, 11)
    geared = geared_arm_6dof(control="drive", gear_mass_scale=1e-6)
    arm = geared_arm_6dof(trains=False, gear_mass_scale=1e-6)
    idg = ad.driven_inverse_dynamics(geared, times)
    ida = ad.driven_inverse_dynamics(arm, times)
    for k, name in enumerate(arm.drive_names):
        rotor = list(geared.drive_names).index(f"{name}_motor")
        expected = ida.drive_forces[:, k] / RATIOS[name]
        scale = max(np.max(np.abs(expected)), 1e-3)
        assert np.max(np.abs(idg.drive_forces[:, rotor] - expected)) <= 1e-5 * scale, name
    # with real masses the trains' own inertia adds to it: visible during the motion
    full = ad.driven_inverse_dynamics(geared_arm_6dof(control="drive"), times)
    arm_full = ad.driven_inverse_dynamics(geared_arm_6dof(trains=False), times)
    rotor = list(geared.drive_names).index("shoulder_motor")
    k = list(arm.drive_names).index("shoulder")
    gap = full.drive_forces[:, rotor] - arm_full.drive_forces[:, k] / RATIOS["shoulder"]
    assert np.max(np.abs(gap)) > 1e-4


def test_backlash_run_has_tooth_impacts_and_holds_the_arm():
    m = geared_arm_6dof(backlash=1e-4)
    res = ad.simulate(m, 0.3, rtol=1e-6, atol=1e-8, output_dt=0.05)
    assert res.stats["events"] > 0
    assert all(g.endswith("stage_2") for g in res.events["gear"])
    names = list(m.joint_coord_names)
    shoulder = res.q[:, names.index("shoulder")]
    assert np.max(np.abs(shoulder)) < 0.02  # held near its start under gravity
    assert np.max(res.position_residual) <= 1e-12
    with pytest.raises(ad.ModelError, match="n_motors"):
        geared_arm_6dof(n_motors=7)


def test_welded_run_reports_gear_residuals_over_many_rotor_turns():
    """The 44 bodies integrate as 18 welded composites; the residuals are reported on the full
    model, whose gear rows need the run's multi-turn rotor angles (a rotor past +-pi once gave
    r1 * 2 pi, 0.19 m, as the residual)."""
    m = geared_arm_6dof(backlash=0.0)
    res = ad.simulate(m, 5.0, integrator="dopri5", rtol=1e-6, atol=1e-6, output_dt=0.05)
    assert res.stats["solver_bodies"] < 44  # the welded path
    names = list(m.joint_coord_names)
    rotor = res.q[:, names.index("shoulder_motor")]
    assert np.max(np.abs(rotor)) > 4 * np.pi  # N = 25 times 0.6 rad: 15 rad, over two turns
    assert np.max(res.position_residual) <= 1e-10  # measured 9.5e-14
    assert np.max(res.velocity_residual) <= 1e-10
