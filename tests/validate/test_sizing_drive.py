"""Drive, holding-brake and DC-bus values (armdyn.sizing.drive) against hand calculations from
the formulas, computed here independently in plain Python loops: the bus by running the
repeated cycle period after period until its stored energy repeats."""

from __future__ import annotations

import math
from types import SimpleNamespace

import armdyn as ad
import numpy as np
import pytest
from armdyn.sizing import drive as dv
from armdyn.sizing.options import SizingOptions


def test_drive_margins_equal_the_ratios():
    motor = {
        "peak_current": [10.0, 4.0, np.nan, 3.0],
        "rms_current": [3.0, 1.0, 2.0, 0.0],
        "peak_terminal_voltage": [40.0, -50.0, 20.0, 10.0],
    }
    drives = {
        "peak_current": [12.0, 2.0, 9.0, np.nan],
        "continuous_current": [4.0, 0.5, 1.0, 1.0],
        "bus_voltage": [48.0, 48.0, np.nan, 24.0],
    }
    out = dv.drive_values(motor, drives)
    want = {
        "drive_peak_current_margin": [1.2, 0.5, math.nan, math.nan],
        "drive_rms_current_margin": [4.0 / 3.0, 0.5, 0.5, math.inf],
        "drive_voltage_margin": [1.2, 48.0 / 50.0, math.nan, 2.4],
    }
    for key, values in want.items():
        for i, value in enumerate(values):
            got = out[key][i]
            assert (math.isnan(got) and math.isnan(value)) or got == pytest.approx(value, rel=1e-14)
    np.testing.assert_array_equal(out["drive_peak_current"], drives["peak_current"])
    np.testing.assert_array_equal(out["drive_continuous_current"], drives["continuous_current"])
    np.testing.assert_array_equal(out["bus_voltage"], drives["bus_voltage"])


def test_brake_holding_against_the_safety_factor_times_the_worst_gravity_torque():
    t = np.linspace(0.0, 2.0, 41)
    gravity = 12.0 * np.cos(3.0 * t) - 4.0
    load = SimpleNamespace(t=t, gravity_torque=gravity)
    ratio, brake = [100.0, -50.0, 80.0], [0.5, 0.2, np.nan]
    out = dv.brake_values(load, ratio, brake, SizingOptions(brake_safety_factor=2.5))
    worst = max(abs(float(g)) for g in gravity)
    for i in range(3):
        holding = abs(ratio[i]) * brake[i]
        assert out["brake_required_torque"][i] == pytest.approx(2.5 * worst, rel=1e-14)
        if math.isnan(holding):
            assert math.isnan(out["brake_holding_torque"][i])
            assert math.isnan(out["brake_holding_margin"][i])
        else:
            assert out["brake_holding_torque"][i] == pytest.approx(holding, rel=1e-14)
            assert out["brake_holding_margin"][i] == pytest.approx(
                holding / (2.5 * worst), rel=1e-14
            )


def hand_bus(t, powers, cap, periods=10000):
    """Run the repeated cycle: per interval the net energy e of the summed power; the stored
    energy s takes −e up to cap (the overflow goes to the resistor) and gives e down to 0.
    Returns the resistor's energy and peak power over the first period whose start state
    repeats the previous one's (the periodic steady state), and the regenerated energy."""
    total = [sum(p[i] for p in powers) for i in range(len(t))]
    e = [0.5 * (total[i] + total[i + 1]) * (t[i + 1] - t[i]) for i in range(len(t) - 1)]
    s = 0.0
    for _ in range(periods):
        start, energy, peak = s, 0.0, 0.0
        for i, ei in enumerate(e):
            s = s - ei
            if s > cap:
                energy += s - cap
                peak = max(peak, -total[i], -total[i + 1], 0.0)
                s = cap
            s = max(s, 0.0)
        if s == start:
            break
    else:
        raise AssertionError("no periodic steady state")
    return energy, peak, sum(max(-ei, 0.0) for ei in e), total, e


def axes_powers(net):
    """Two axes on one grid: a motoring axis and a regenerating one, net shifting the balance."""
    t = np.linspace(0.0, 1.0, 101)
    p1 = 300.0 * np.sin(2.0 * np.pi * t) + 40.0
    p2 = -250.0 * np.sin(2.0 * np.pi * t) ** 2 - net
    return t, np.stack([p1, p2])


@pytest.mark.parametrize("net", [60.0, 200.0])  # net drawn (A < 0) and net returned (A > 0)
def test_bus_values_equal_the_repeated_cycle_run_by_hand(net):
    t, p = axes_powers(net)
    drives = {
        "bus_voltage": [48.0, 48.0, 48.0],
        "max_bus_voltage": [60.0, 56.0, np.nan],
        "bus_capacitance": [0.05, 0.2, 0.05],
        "braking_resistor_power": [100.0, np.nan, 50.0],
        "braking_resistor_peak_power": [500.0, 100.0, np.nan],
    }
    out = dv.bus_values(t, np.stack([p, p, p]), drives=drives)
    tl = [float(x) for x in t]
    pl = [[float(x) for x in row] for row in p]
    period = tl[-1] - tl[0]
    for i in range(3):
        v_max = drives["max_bus_voltage"][i]
        cap = (
            0.0 if math.isnan(v_max) else 0.5 * drives["bus_capacitance"][i] * (v_max**2 - 48.0**2)
        )
        energy, peak, regen, total, e = hand_bus(tl, pl, cap)
        assert energy > 0.0  # the resistor conducts in every case here
        assert out["bus_capacitor_energy"][i] == pytest.approx(cap, rel=1e-14)
        assert out["resistor_energy"][i] == pytest.approx(energy, rel=1e-12)
        assert out["resistor_mean_power"][i] == pytest.approx(energy / period, rel=1e-12)
        assert out["resistor_peak_power"][i] == pytest.approx(peak, rel=1e-12)
        assert out["bus_energy_regenerated"][i] == pytest.approx(regen, rel=1e-12)
        assert out["bus_mean_power"][i] == pytest.approx(sum(e) / period, rel=1e-12)
        assert out["bus_peak_power"][i] == pytest.approx(max(total), rel=1e-14)
        assert out["bus_peak_regenerative_power"][i] == pytest.approx(-min(total), rel=1e-14)
        for key, rating, value in (
            ("braking_resistor_power_margin", "braking_resistor_power", energy / period),
            ("braking_resistor_peak_margin", "braking_resistor_peak_power", peak),
        ):
            want = drives[rating][i] / value
            got = out[key][i]
            assert (math.isnan(got) and math.isnan(want)) or got == pytest.approx(want, rel=1e-12)
    # without a capacitance every regenerated joule goes to the resistor
    assert out["resistor_energy"][2] == pytest.approx(out["bus_energy_regenerated"][2], rel=1e-12)


def test_axes_that_exchange_power_on_the_bus_regenerate_nothing():
    t = np.linspace(0.0, 2.0, 51)
    p = 100.0 * np.sin(np.pi * t)
    out = dv.bus_values(t, [p + 5.0, -p], drives={"braking_resistor_power": 1.0})
    assert out["bus_energy_regenerated"][0] == 0.0
    assert out["resistor_energy"][0] == 0.0 and out["resistor_peak_power"][0] == 0.0
    assert out["braking_resistor_power_margin"][0] == math.inf
    assert out["bus_mean_power"][0] == pytest.approx(5.0, rel=1e-12)


def test_candidate_sets_equal_one_call_each_and_the_period_scales_the_means():
    t, p = axes_powers(120.0)
    sets = np.stack([p, 0.5 * p, 2.0 * p])
    caps = [0.01, 0.1, 0.0]
    drives = {"bus_voltage": 48.0, "max_bus_voltage": 58.0, "bus_capacitance": caps}
    together = dv.bus_values(t, sets, drives=drives)
    for i in range(3):
        one = dv.bus_values(t, sets[i], drives={**drives, "bus_capacitance": caps[i]})
        for key, value in one.items():
            np.testing.assert_array_equal(together[key][i], value[0], err_msg=key)
    longer = dv.bus_values(t, p, period=4.0, drives=drives)  # one set against 3 drives
    np.testing.assert_allclose(
        longer["bus_capacitor_energy"], [0.5 * c * (58.0**2 - 48.0**2) for c in caps], rtol=1e-14
    )
    assert longer["resistor_mean_power"][0] == pytest.approx(
        together["resistor_energy"][0] / 4.0, rel=1e-14
    )


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: dv.bus_values([], [[]]), r"t must hold at least two samples"),
        (lambda: dv.bus_values([0.0, 1.0], [[1.0, 2.0, 3.0]]), r"electrical_power must have shape"),
        (lambda: dv.bus_values([0.0, 1.0], [[1.0, np.nan]]), r"electrical_power has a non-finite"),
        (lambda: dv.bus_values([1.0, 0.0], [[1.0, 1.0]]), r"t decreases"),
        (lambda: dv.bus_values([0.0, 1.0], [[1.0, 1.0]], period=0.5), r"period .* shorter"),
        (lambda: dv.bus_values([0.0, 1.0], [[1.0, 1.0]], period=-1.0), r"period\[0\] must be > 0"),
        (
            lambda: dv.bus_values(
                [0.0, 1.0], [[1.0, 1.0]], drives={"bus_voltage": 48.0, "max_bus_voltage": 40.0}
            ),
            r"drives\['max_bus_voltage'\]\[0\] is below",
        ),
        (
            lambda: dv.bus_values([0.0, 1.0], [[1.0, 1.0]], drives={"bus_capacitance": -1.0}),
            r"drives\['bus_capacitance'\]\[0\] must be >= 0",
        ),
        (
            lambda: dv.drive_values({"peak_current": [1.0]}, {"peak_current": [-1.0]}),
            r"drives\['peak_current'\]\[0\] must be >= 0",
        ),
        (
            lambda: dv.drive_values({"peak_current": [1.0, 2.0]}, {"bus_voltage": [1.0]}),
            r"drives\['bus_voltage'\] must have shape \(2,\)",
        ),
        (lambda: dv.drive_values([1.0], {}), r"motor_values must be a mapping"),
        (
            lambda: dv.brake_values(
                SimpleNamespace(t=[0.0, 1.0], gravity_torque=[1.0]), [1.0], [1.0]
            ),
            r"load.gravity_torque must have shape",
        ),
        (
            lambda: dv.brake_values(
                SimpleNamespace(t=[0.0, 1.0], gravity_torque=[1, 1]), [0.0], [1]
            ),
            r"ratio\[0\] must be non-zero",
        ),
        (
            lambda: dv.brake_values(
                SimpleNamespace(t=[0.0, 1.0], gravity_torque=[1, 1]), [5], [-1]
            ),
            r"brake_torque\[0\] must be >= 0",
        ),
    ],
)
def test_hostile_inputs_name_the_culprit(call, match):
    with pytest.raises(ad.ModelError, match=match):
        call()


def test_the_example_catalog_drives_vectorised_equal_one_drive_at_a_time():
    drives = ad.load_catalog(ad.sizing.EXAMPLE_CATALOG).drives
    k = len(drives)
    rng = np.random.default_rng(4)
    motor = {
        "peak_current": rng.uniform(1.0, 20.0, k),
        "rms_current": rng.uniform(0.5, 8.0, k),
        "peak_terminal_voltage": rng.uniform(10.0, 60.0, k),
    }
    t, p = axes_powers(150.0)
    together = dv.drive_values(motor, drives)
    together.update(dv.bus_values(t, p, drives=drives))
    assert np.all(np.isfinite(together["resistor_energy"]))
    for i in range(k):
        row = drives.iloc[i : i + 1]
        alone = dv.drive_values({key: v[i : i + 1] for key, v in motor.items()}, row)
        alone.update(dv.bus_values(t, p, drives=row))
        for key, value in alone.items():
            np.testing.assert_array_equal(together[key][i], value[0], err_msg=f"{key} row {i}")
