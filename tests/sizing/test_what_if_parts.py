"""What-if actuators from catalog parts: a motor row and a gearbox (a catalog Gearbox or its
row) stand for the numbers of the spec, and give the report of the same actuator written out
by hand (gear ratio = the gearbox's ratio, efficiency its efficiency, rotor inertia = the motor's
rotor inertia + the gearbox's input inertia)."""

import armdyn as ad
import numpy as np
import pytest


def _arm_run():
    b = ad.ModelBuilder(gravity=(0, 0, -9.81))
    b.add_body("link", mass=2.0, inertia=[0.02, 0.1, 0.1], position=(0.4, 0, 0))
    b.add_revolute("pivot", "ground", "link", point=(0, 0, 0), axis=(0, 1, 0))
    model = b.finalize()
    t = np.linspace(0.0, 1.0, 201)
    q, qd, qdd = ad.profiles.quintic(0.0, 1.2, 0.0, 1.0).eval(t)
    return ad.trajectory_run(model, t, q[:, None], qd[:, None], qdd[:, None])


@pytest.mark.parametrize("as_row", [False, True])
def test_catalog_parts_equal_the_spec_written_out(as_row):
    catalog = ad.load_catalog(ad.sizing.EXAMPLE_CATALOG)
    run = _arm_run()
    motor_row = catalog.motors.loc["FL-70x10"]
    gear = catalog.gearboxes.loc["SW-20-120"] if as_row else catalog.gearbox("SW-20-120")
    ratio = gear["ratio"] if as_row else gear.ratio
    eff = gear["efficiency"] if as_row else gear.efficiency
    j_in = gear["input_inertia"] if as_row else gear.input_inertia
    by_parts = ad.sizing_report(run, actuators={"pivot": {"motor": motor_row, "gearbox": gear}})
    written = {
        "gear_ratio": float(ratio),
        "efficiency": float(eff),
        "rotor_inertia": float(motor_row["rotor_inertia"] + j_in),
        "motor": catalog.motor("FL-70x10"),
    }
    by_hand = ad.sizing_report(run, actuators={"pivot": written})
    cols = ["gear_ratio", "motor_rms_torque", "motor_peak_torque", "peak_current", "ok"]
    a, b = by_parts.table.loc["pivot", cols], by_hand.table.loc["pivot", cols]
    assert a["gear_ratio"] == 120.0
    for c in cols:
        assert a[c] == b[c], c


def test_a_value_in_the_spec_wins_and_a_bad_part_is_named():
    catalog = ad.load_catalog(ad.sizing.EXAMPLE_CATALOG)
    run = _arm_run()
    gear = catalog.gearbox("SW-20-120")
    spec = {"motor": catalog.motor("FL-70x10"), "gearbox": gear, "gear_ratio": 80.0}
    report = ad.sizing_report(run, actuators={"pivot": spec})
    assert report.table.loc["pivot", "gear_ratio"] == 80.0
    # a gearbox without a motor: no rotor inertia to add its input inertia to
    with pytest.raises(ad.ModelError, match=r"\[pivot\] needs rotor_inertia"):
        ad.sizing_report(run, actuators={"pivot": {"gearbox": gear}})
    # a motor row with a bad value is named by its field
    bad = catalog.motors.loc["FL-70x10"].copy()
    bad["resistance"] = -1.0
    with pytest.raises(ad.ModelError, match="resistance"):
        ad.sizing_report(run, actuators={"pivot": {"motor": bad, "gearbox": gear}})
