"""Gearbox, output-bearing and emergency-stop values (armdyn.sizing.gearbox) against hand
calculations from the vendors' formulas, computed here independently: loops over the samples
(or the vendors' load segments) in plain Python floats, never the module's vectorised numpy.

The joint loads are :class:`armdyn.JointLoad` built from arrays (``make_load``), so that each case
controls its samples; one test takes them from a real :func:`armdyn.duty_cycle`.
"""

from __future__ import annotations

import math
from dataclasses import replace

import armdyn as ad
import numpy as np
import pytest
from armdyn.sizing import drive as dv
from armdyn.sizing import gearbox as gb
from armdyn.sizing.cycle import JointLoad
from armdyn.sizing.options import SizingOptions

RPM = 2.0 * math.pi / 60.0  # rad/s per rpm


def make_load(t, speed, torque, gravity_torque, force, moment, axis, inertia, period=None):
    """A :class:`armdyn.JointLoad` from its arrays (the acceleration and the dwell flags are not
    read by the functions tested here: zeros, and moving where the speed is non-zero)."""
    t = np.asarray(t, dtype=float)
    speed = np.asarray(speed, dtype=float)
    return JointLoad(
        joint="j",
        t=t,
        speed=speed,
        acceleration=np.zeros_like(t),
        torque=np.asarray(torque, dtype=float),
        gravity_torque=np.asarray(gravity_torque, dtype=float),
        force=force,
        moment=moment,
        axis=np.asarray(axis, dtype=float),
        inertia=np.asarray(inertia, dtype=float),
        moving=speed != 0.0,
        period=float(t[-1] - t[0]) if period is None else period,
        repeat=None,
    )


def cycle(n=61, dwell=0.5, seed=1):
    """A motion of n samples over 1.5 s then a dwell at rest (speed 0, holding torque)."""
    rng = np.random.default_rng(seed)
    tm = np.linspace(0.0, 1.5, n)
    speed = 2.0 * np.sin(2.0 * np.pi * tm / 1.5) + 0.3 * np.sin(7.0 * tm)
    speed[-1] = 0.0
    torque = 20.0 * np.cos(2.0 * np.pi * tm / 1.5) + 5.0 + rng.normal(0.0, 1.0, n)
    t = np.concatenate([tm, [1.5, 1.5 + dwell]])
    speed = np.concatenate([speed, [0.0, 0.0]])
    torque = np.concatenate([torque, [torque[-1], torque[-1]]])
    m = t.size
    return make_load(
        t=t,
        speed=speed,
        torque=torque,
        gravity_torque=7.0 * np.cos(t) + 1.0,
        force=rng.normal(0.0, 50.0, (m, 3)),
        moment=rng.normal(0.0, 5.0, (m, 3)),
        axis=np.array([1.0, 2.0, 2.0]),  # not unit: the functions normalise it
        inertia=0.4 + 0.1 * np.sin(t),
        period=float(t[-1] - t[0]),
    )


def hand_integral(f, t):
    """∫ f dt by the trapezoid rule, a plain loop."""
    return sum(0.5 * (f[i] + f[i + 1]) * (t[i + 1] - t[i]) for i in range(len(t) - 1))


GEARS = {
    "rated_torque": [30.0, 60.0, np.nan],
    "rated_input_speed": [2000 * RPM, 3000 * RPM, 2000 * RPM],
    "rated_life": [35000.0, 50000.0, 35000.0],
    "life_exponent": [3.0, 10.0 / 3.0, np.nan],
    "average_torque_limit": [15.0, 40.0, np.nan],
    "average_input_speed_limit": [3000 * RPM, np.nan, 100.0],
    "repeated_peak_torque": [20.0, 80.0, 30.0],
    "momentary_peak_count": [500.0, 2e4, np.nan],
    "max_input_speed": [6000 * RPM, 50.0, np.nan],
}


def test_gearbox_values_equal_a_hand_calculation():
    load = cycle()
    ratio = [50.0, -100.0, 80.0]
    opts = SizingOptions(required_life=20000.0, emergency_stops=1000.0)
    out = gb.gearbox_cycle_values(load, np.array(ratio), GEARS, opts)
    t = [float(x) for x in load.t]
    w = [abs(float(x)) for x in load.speed]
    tq = [abs(float(x)) for x in load.torque]
    period = t[-1] - t[0]
    out_speed = hand_integral(w, t) / period
    for i in range(3):
        n = abs(ratio[i])
        n_av = n * out_speed
        p = GEARS["life_exponent"][i]
        p = 3.0 if math.isnan(p) else p
        # the mean torque of the gearbox's own life law (exponent p)
        weighted = [wi * ti**p for wi, ti in zip(w, tq, strict=True)]
        t_av = (hand_integral(weighted, t) / hand_integral(w, t)) ** (1.0 / p)
        assert out["gear_average_torque"][i] == pytest.approx(t_av, rel=1e-12)
        assert out["gear_average_input_speed"][i] == pytest.approx(n_av, rel=1e-12)
        assert out["gear_peak_input_speed"][i] == pytest.approx(n * max(w), rel=1e-12)
        assert out["gear_repeated_peak_torque"][i] == pytest.approx(max(tq), rel=1e-12)
        life = GEARS["rated_life"][i] * (GEARS["rated_torque"][i] / t_av) ** p
        life *= GEARS["rated_input_speed"][i] / n_av
        if math.isnan(life):
            assert math.isnan(out["gear_life"][i]) and math.isnan(out["gear_life_margin"][i])
        else:
            assert out["gear_life"][i] == pytest.approx(life, rel=1e-12)
            assert out["gear_life_margin"][i] == pytest.approx(life / 20000.0, rel=1e-12)
        pairs = {
            "gear_average_torque_margin": GEARS["average_torque_limit"][i] / t_av,
            "gear_average_input_speed_margin": GEARS["average_input_speed_limit"][i] / n_av,
            "gear_repeated_peak_margin": GEARS["repeated_peak_torque"][i] / max(tq),
            "gear_momentary_count_margin": GEARS["momentary_peak_count"][i] / 1000.0,
            "gear_input_speed_margin": GEARS["max_input_speed"][i] / (n * max(w)),
        }
        for key, want in pairs.items():
            if math.isnan(want):  # a column not given: not checked
                assert math.isnan(out[key][i]), key
            else:
                assert out[key][i] == pytest.approx(want, rel=1e-12), key
    assert np.all(out["emergency_stops"] == 1000.0)
    assert np.all(out["gear_cycles_per_hour"] == 3600.0 / period)


def segments(ts, ns, torques):
    """The vendors' load segments (T_i, n_i, t_i) as samples: each segment's two ends, equal
    times at the jumps (a zero-length trapezoid), so the trapezoid integrals are the sums."""
    t, speed, torque, now = [], [], [], 0.0
    for dt, n, tq in zip(ts, ns, torques, strict=True):
        t += [now, now + dt]
        speed += [n, n]
        torque += [tq, tq]
        now += dt
    m = len(t)
    z = np.zeros(m)
    return make_load(
        t=np.array(t),
        speed=np.array(speed),
        torque=np.array(torque),
        gravity_torque=z,
        force=np.zeros((m, 3)),
        moment=np.zeros((m, 3)),
        axis=np.array([0.0, 0.0, 1.0]),
        inertia=z + 1.0,
    )


def test_vendor_segment_formulas_and_worked_example():
    """A four-segment cycle (start, constant speed, stop, pause) in the form of the vendors'
    worked examples: T_av = (Σ|n_i| t_i |T_i|³ / Σ|n_i| t_i)^(1/3), n_av = N Σ|n_i| t_i / Σ t_i
    with the pause in Σ t_i, L = L_N (T_N/T_av)³ (n_N/n_av). The numbers (150 N m 0.2 s 10 rpm,
    82 N m 3 s 20 rpm, 130 N m 0.3 s 10 rpm, a 0.2 s pause) give T_av = 89 N m as the
    published example says (Honpine, "How to select a harmonic reduction gear"); N = 100."""
    ts, ns, torques = [0.2, 3.0, 0.3, 0.2], [10.0, 20.0, 10.0, 0.0], [150.0, 82.0, 130.0, 0.0]
    load = segments(ts, [n * RPM for n in ns], torques)
    gears = {"rated_torque": [100.0], "rated_input_speed": [2000 * RPM], "rated_life": [35000.0]}
    out = gb.gearbox_cycle_values(load, [100.0], gears)
    num = sum(n * t * tq**3 for t, n, tq in zip(ts, ns, torques, strict=True))
    den = sum(n * t for t, n in zip(ts, ns, strict=True))
    t_av = (num / den) ** (1.0 / 3.0)
    n_av_rpm = 100.0 * den / sum(ts)
    assert round(t_av) == 89
    assert out["gear_average_torque"][0] == pytest.approx(t_av, rel=1e-12)
    assert out["gear_average_input_speed"][0] / RPM == pytest.approx(n_av_rpm, rel=1e-12)
    life = 35000.0 * (100.0 / t_av) ** 3 * (2000.0 / n_av_rpm)
    assert out["gear_life"][0] == pytest.approx(life, rel=1e-12)


def test_a_joint_at_rest_holds_its_cubic_mean_and_never_wears():
    load = segments([1.0, 2.0], [0.0, 0.0], [10.0, 20.0])
    gears = {"rated_torque": [50.0], "rated_input_speed": [200.0], "rated_life": [1e4]}
    out = gb.gearbox_cycle_values(load, [30.0], gears)
    want = ((10.0**3 * 1.0 + 20.0**3 * 2.0) / 3.0) ** (1.0 / 3.0)
    assert out["gear_average_torque"][0] == pytest.approx(want, rel=1e-12)
    assert out["gear_average_input_speed"][0] == 0.0
    assert out["gear_life"][0] == math.inf and out["gear_life_margin"][0] == math.inf


# --- output bearing ---------------------------------------------------------------------------


def perpendicular_basis(a):
    """Two unit vectors ⊥ a and each other (Gram-Schmidt, plain floats)."""
    seed = (1.0, 0.0, 0.0) if abs(a[0]) < 0.9 else (0.0, 1.0, 0.0)
    d = sum(s * x for s, x in zip(seed, a, strict=True))
    e1 = [s - d * x for s, x in zip(seed, a, strict=True)]
    n1 = math.sqrt(sum(x * x for x in e1))
    e1 = [x / n1 for x in e1]
    e2 = [a[1] * e1[2] - a[2] * e1[1], a[2] * e1[0] - a[0] * e1[2], a[0] * e1[1] - a[1] * e1[0]]
    return e1, e2


def hand_bearing(load, b):
    """Per sample (F_a, F_r, M) at the reference point b along the unit axis, by components."""
    a = [float(x) for x in load.axis]
    na = math.sqrt(sum(x * x for x in a))
    a = [x / na for x in a]
    e1, e2 = perpendicular_basis(a)
    rows = []
    for f, m in zip(load.force.tolist(), load.moment.tolist(), strict=True):
        r = [-b * x for x in a]  # from the reference point P = O + b a back to O
        rxf = [r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]]
        mp = [mi + ci for mi, ci in zip(m, rxf, strict=True)]
        dot = lambda u, v: sum(x * y for x, y in zip(u, v, strict=True))  # noqa: E731
        rows.append(
            (
                dot(f, a),
                math.hypot(dot(f, e1), dot(f, e2)),
                math.hypot(dot(mp, e1), dot(mp, e2)),
            )
        )
    return rows


def hand_mean(values, w, t, p=10.0 / 3.0):
    return (
        hand_integral([wi * abs(v) ** p for wi, v in zip(w, values, strict=True)], t)
        / hand_integral(w, t)
    ) ** (1.0 / p)


def hand_life(load, b, c_rating, d_p, f_w):
    """Harmonic Drive's cross-roller L10 [h] with rpm, from the hand wrench."""
    rows = hand_bearing(load, b)
    t = [float(x) for x in load.t]
    w = [abs(float(x)) for x in load.speed]
    f_a, f_r, m = (hand_mean([r[i] for r in rows], w, t) for i in range(3))
    radial = f_r + 2.0 * m / d_p
    x, y = (1.0, 0.45) if f_a / radial <= 1.5 else (0.67, 0.67)
    p_c = x * radial + y * f_a
    n_av_rpm = hand_integral(w, t) / (t[-1] - t[0]) / RPM
    return 1e6 / (60.0 * n_av_rpm) * (c_rating / (f_w * p_c)) ** (10.0 / 3.0), (x, y)


BEARINGS = {
    "bearing_offset": [0.0, 0.035, -0.02, np.nan],
    "bearing_moment_allowable": [40.0, 10.0, np.nan, 40.0],
    "bearing_axial_allowable": [300.0, 100.0, 200.0, np.nan],
    "bearing_radial_allowable": [np.nan, 150.0, 200.0, 300.0],
    "bearing_dynamic_load_rating": [20e3, 15e3, 10e3, 20e3],
    "bearing_pitch_diameter": [0.06, 0.05, np.nan, 0.06],
}


@pytest.mark.parametrize("axial", [0.0, 400.0])  # both (x, y) branches of P_c
def test_bearing_values_equal_a_hand_calculation(axial):
    load = cycle(seed=3)
    a = load.axis / np.linalg.norm(load.axis)
    load = replace(load, force=load.force + axial * a)
    opts = SizingOptions(bearing_load_factor=1.3, required_life=20000.0)
    out = gb.bearing_cycle_values(load, BEARINGS, opts)
    branches = set()
    for i, b in enumerate(BEARINGS["bearing_offset"]):
        rows = hand_bearing(load, 0.0 if math.isnan(b) else b)
        assert out["bearing_peak_axial"][i] == pytest.approx(
            max(abs(r[0]) for r in rows), rel=1e-12
        )
        assert out["bearing_peak_radial"][i] == pytest.approx(max(r[1] for r in rows), rel=1e-12)
        want = {
            "bearing_axial_margin": BEARINGS["bearing_axial_allowable"][i]
            / max(abs(r[0]) for r in rows),
            "bearing_radial_margin": BEARINGS["bearing_radial_allowable"][i]
            / max(r[1] for r in rows),
        }
        if math.isnan(b):  # no reference point: the moment and the life are not given
            assert math.isnan(out["bearing_peak_moment"][i])
            assert math.isnan(out["bearing_moment_margin"][i])
            assert math.isnan(out["bearing_life_margin"][i])
        else:
            peak_m = max(r[2] for r in rows)
            assert out["bearing_peak_moment"][i] == pytest.approx(peak_m, rel=1e-12)
            want["bearing_moment_margin"] = BEARINGS["bearing_moment_allowable"][i] / peak_m
            d_p = BEARINGS["bearing_pitch_diameter"][i]
            if math.isnan(d_p):
                assert math.isnan(out["bearing_life"][i])
            else:
                c = BEARINGS["bearing_dynamic_load_rating"][i]
                life, xy = hand_life(load, b, c, d_p, 1.3)
                branches.add(xy)
                assert out["bearing_life"][i] == pytest.approx(life, rel=1e-12)
                want["bearing_life_margin"] = life / 20000.0
        for key, value in want.items():
            if math.isnan(value):
                assert math.isnan(out[key][i]), key
            else:
                assert out[key][i] == pytest.approx(value, rel=1e-12), key
    assert branches == {(1.0, 0.45)} if axial == 0.0 else {(0.67, 0.67)}


def test_bearing_moment_is_the_radial_load_times_its_lever_from_the_reference_point():
    """A weight W hanging at a distance c along a horizontal joint axis x from the joint point:
    the reaction on the child is F = W z, M_O = −c W y; at the bearing's reference point b
    along the axis the tilting moment is |c − b| W (Harmonic Drive's F_r (L_r + R) with the
    lever measured from the reference point), the radial load W, no axial load."""
    w_load, c = 120.0, 0.08
    m = 3
    load = make_load(
        t=np.array([0.0, 1.0, 2.0]),
        speed=np.array([0.0, 1.0, 0.0]),
        torque=np.zeros(m),
        gravity_torque=np.zeros(m),
        force=np.tile([0.0, 0.0, w_load], (m, 1)),
        moment=np.tile([0.0, -c * w_load, 0.0], (m, 1)),
        axis=np.array([1.0, 0.0, 0.0]),
        inertia=np.ones(m),
    )
    offsets = [0.0, 0.03, 0.08, -0.05]
    out = gb.bearing_cycle_values(load, {"bearing_offset": offsets})
    for i, b in enumerate(offsets):
        assert out["bearing_peak_moment"][i] == pytest.approx(abs(c - b) * w_load, abs=1e-12)
    assert np.all(out["bearing_peak_radial"] == w_load)
    assert np.all(out["bearing_peak_axial"] == 0.0)
    assert np.all(np.isnan(out["bearing_life"]))  # no rating given


# --- emergency stop ---------------------------------------------------------------------------


def hand_stop(n, eta, j, j_l, g, qd, t_s):
    """Solve the two equations of the stop (link: J_L q̈ = τ − g; rotor:
    J N q̈ = T_m − c τ / N) for (q̈, τ) by Cramer's rule, trying both power-flow branches and
    keeping the consistent one (c = η when τ q̇ < 0)."""
    t_m = -math.copysign(t_s, qd)
    found = []
    for c in (eta, 1.0 / eta):
        # [J_L, -1; J N, c / N] [q̈, τ] = [-g, T_m]
        a11, a12, a21, a22 = j_l, -1.0, j * n, c / n
        det = a11 * a22 - a12 * a21
        tau = (a11 * t_m - a21 * (-g)) / det
        if (tau * qd < 0.0) == (c == eta):
            found.append(tau)
    assert len(found) == 1
    return found[0]


def test_emergency_stop_torque_equals_a_hand_calculation():
    load = cycle(seed=5)
    ratio = np.array([50.0, -80.0, 120.0, 100.0])
    eta = np.array([0.8, 0.7, 0.95, 0.9])
    j_rot = np.array([2e-5, 1e-4, 5e-6, np.nan])
    t_s = np.array([1.5, 0.4, 3.0, 1.0])
    gears = {"momentary_peak_torque": [200.0, 150.0, np.nan, 100.0]}
    out = gb.emergency_stop_values(load, ratio, eta, j_rot, t_s, gears)
    for i in range(3):
        best, when = -1.0, None
        for s in range(len(load.t)):
            qd = float(load.speed[s])
            if qd == 0.0:
                continue
            tau = hand_stop(
                float(ratio[i]),
                float(eta[i]),
                float(j_rot[i]),
                float(load.inertia[s]),
                float(load.gravity_torque[s]),
                qd,
                float(t_s[i]),
            )
            if abs(tau) > best:
                best, when = abs(tau), float(load.t[s])
        assert out["gear_momentary_torque"][i] == pytest.approx(best, rel=1e-12)
        assert out["emergency_stop_time"][i] == when
        limit = gears["momentary_peak_torque"][i]
        if math.isnan(limit):
            assert math.isnan(out["gear_momentary_peak_margin"][i])
        else:
            assert out["gear_momentary_peak_margin"][i] == pytest.approx(limit / best, rel=1e-12)
    # the rotor inertia not given: not checked
    assert math.isnan(out["gear_momentary_torque"][3])
    assert math.isnan(out["gear_momentary_peak_margin"][3])


def test_emergency_stop_limits():
    """No rotor inertia: the gear passes the stop torque, back-driven: τ = N T_s / η.
    No load inertia and no gravity: the rotor's inertia takes it all, τ = 0. No inertia on
    either side: the gravity torque (at the moving samples). A cycle at rest has no stop: the
    largest cycle torque."""
    m = 4
    base = make_load(
        t=np.arange(m, dtype=float),
        speed=np.array([0.0, 1.0, -2.0, 0.0]),
        torque=np.array([1.0, -9.0, 2.0, 0.0]),
        gravity_torque=np.zeros(m),
        force=np.zeros((m, 3)),
        moment=np.zeros((m, 3)),
        axis=np.array([0.0, 0.0, 1.0]),
        inertia=np.full(m, 0.3),
    )
    out = gb.emergency_stop_values(base, [60.0], [0.75], [0.0], [2.0])
    assert out["gear_momentary_torque"][0] == pytest.approx(60.0 * 2.0 / 0.75, rel=1e-14)
    light = replace(base, inertia=np.zeros(m))
    out = gb.emergency_stop_values(light, [60.0], [0.75], [1e-4], [2.0])
    assert out["gear_momentary_torque"][0] == 0.0
    heavy = replace(light, gravity_torque=np.array([0.0, 4.0, -6.5, 9.0]))
    out = gb.emergency_stop_values(heavy, [60.0, 30.0], [0.75, 0.9], [0.0, np.nan], [2.0, 1.0])
    assert out["gear_momentary_torque"][0] == 6.5  # no inertia at all: gravity alone
    assert math.isnan(out["gear_momentary_torque"][1])
    rest = replace(base, speed=np.zeros(m))
    out = gb.emergency_stop_values(rest, [60.0], [0.75], [1e-4], [2.0])
    assert out["gear_momentary_torque"][0] == 9.0 and math.isnan(out["emergency_stop_time"][0])


# --- hostile inputs ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda L: gb.gearbox_cycle_values(L, [0.0], {}), r"ratio\[0\] must be non-zero"),
        (lambda L: gb.gearbox_cycle_values(L, [np.nan], {}), r"ratio\[0\] must be given"),
        (lambda L: gb.gearbox_cycle_values(L, [10.0, np.inf], {}), r"ratio\[1\] must be finite"),
        (lambda L: gb.gearbox_cycle_values(L, "ten", {}), r"ratio must be numbers"),
        (
            lambda L: gb.gearbox_cycle_values(L, [10.0, 20.0], {"rated_torque": [1.0, -2.0]}),
            r"gearboxes\['rated_torque'\]\[1\] must be > 0",
        ),
        (
            lambda L: gb.gearbox_cycle_values(L, [10.0, 20.0], {"rated_torque": [1.0]}),
            r"gearboxes\['rated_torque'\] must have shape \(2,\)",
        ),
        (
            lambda L: gb.gearbox_cycle_values(L, [10.0], {"max_input_speed": [-1.0]}),
            r"\['max_input_speed'\]\[0\] must be >= 0",
        ),
        (
            lambda L: gb.gearbox_cycle_values(replace(L, t=L.t[:1], speed=L.speed[:1]), [1.0], {}),
            r"load.t must hold at least two samples",
        ),
        (
            lambda L: gb.gearbox_cycle_values(replace(L, t=L.t[::-1]), [1.0], {}),
            r"load.t decreases",
        ),
        (
            lambda L: gb.gearbox_cycle_values(replace(L, t=0.0 * L.t), [1.0], {}),
            r"load.t spans no time",
        ),
        (
            lambda L: gb.gearbox_cycle_values(
                replace(L, speed=np.where(L.t > 1.0, np.nan, L.speed)), [1.0], {}
            ),
            r"load.speed has a non-finite value",
        ),
        (
            lambda L: gb.gearbox_cycle_values(replace(L, torque=L.torque[:-1]), [1.0], {}),
            r"load.torque must have shape",
        ),
        (
            lambda L: gb.bearing_cycle_values(
                replace(L, axis=np.zeros(3)), {"bearing_offset": [0]}
            ),
            r"load.axis must be a non-zero vector",
        ),
        (
            lambda L: gb.bearing_cycle_values(
                L, {"bearing_offset": [0.0], "bearing_pitch_diameter": [1.0, 2.0]}
            ),
            r"gearboxes must hold \(k,\) columns of one length",
        ),
        (
            lambda L: gb.bearing_cycle_values(L, {}),
            r"gearboxes must hold \(k,\) columns of one length",
        ),
        (
            lambda L: gb.bearing_cycle_values(L, {"bearing_pitch_diameter": [0.0]}),
            r"\['bearing_pitch_diameter'\]\[0\] must be > 0",
        ),
        (
            lambda L: gb.emergency_stop_values(L, [10.0], [1.2], [0.0], [1.0]),
            r"efficiency\[0\] must be in \(0, 1\]",
        ),
        (
            lambda L: gb.emergency_stop_values(L, [10.0], [0.0], [0.0], [1.0]),
            r"efficiency\[0\] must be > 0",
        ),
        (
            lambda L: gb.emergency_stop_values(L, [10.0], [0.9], [-1e-5], [1.0]),
            r"rotor_inertia\[0\] must be >= 0",
        ),
        (
            lambda L: gb.emergency_stop_values(L, [10.0], [0.9], [1e-5], [-1.0]),
            r"stop_torque\[0\] must be >= 0",
        ),
        (
            lambda L: gb.emergency_stop_values(
                replace(L, inertia=-L.inertia), [10.0], [0.9], [0], [1]
            ),
            r"load.inertia\[0\] is < 0",
        ),
        (
            lambda L: gb.gearbox_cycle_values(L, [10.0], {}, options="fast"),
            r"options must be a SizingOptions",
        ),
    ],
)
def test_hostile_inputs_name_the_culprit(call, match):
    load = cycle()
    with pytest.raises(ad.ModelError, match=match):
        call(load)


def test_missing_field_and_dataframe_columns():
    pd = pytest.importorskip("pandas")
    load = cycle()

    class NoForce:
        t, speed, axis = load.t, load.speed, load.axis

    with pytest.raises(ad.ModelError, match=r"load has no field 'force'"):
        gb.bearing_cycle_values(NoForce(), {"bearing_offset": [0.0]})
    table = pd.DataFrame(BEARINGS, index=["a", "b", "c", "d"])
    from_frame = gb.bearing_cycle_values(load, table)
    from_dict = gb.bearing_cycle_values(load, BEARINGS)
    for key, value in from_dict.items():
        np.testing.assert_array_equal(from_frame[key], value, err_msg=key)


def test_bearing_loads_from_a_simulated_reaction_equal_the_statics_of_the_held_link():
    """A link held at rest by its drive on a tilted axis a (gravity has an axial part): the
    reaction armdyn reports (on the child at the joint point, child's joint frame, z = the
    axis) moved to the bearing point P = b a gives F_a = |W · a|, F_r = |W − (W · a) a| and the
    tilting moment |[(c − P) × W]⊥| of the weight W at the centre of mass c, worked out in
    world coordinates (the norms do not depend on the frame)."""
    mass, g = 2.0, 9.81
    com = np.array([0.08, -0.05, 0.3])
    axis = np.array([1.0, 0.0, 1.0]) / math.sqrt(2.0)
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -g))
    b.add_body("link", mass, np.diag([0.01, 0.02, 0.03]), position=tuple(com))
    b.add_revolute("hinge", "ground", "link", (0.0, 0.0, 0.0), tuple(axis))
    b.add_drive("hinge", ad.profiles.cubic(0.0, 0.0, 0.0, 1.0))
    run = ad.simulate(b.finalize(), 0.2, output_dt=0.1)
    n = run.t.size
    load = make_load(
        t=run.t,
        speed=np.zeros(n),
        torque=np.zeros(n),
        gravity_torque=np.zeros(n),
        force=run.reaction_forces[:, 0, :],
        moment=run.reaction_torques[:, 0, :],
        axis=np.array([0.0, 0.0, 1.0]),
        inertia=np.ones(n),
    )
    offsets = [0.0, 0.05, -0.04]
    out = gb.bearing_cycle_values(load, {"bearing_offset": offsets})
    weight = [0.0, 0.0, -mass * g]
    w_a = sum(x * y for x, y in zip(weight, axis, strict=True))
    w_perp = [x - w_a * y for x, y in zip(weight, axis, strict=True)]
    assert out["bearing_peak_axial"][0] == pytest.approx(abs(w_a), rel=1e-10)
    assert out["bearing_peak_radial"][0] == pytest.approx(math.hypot(*w_perp), rel=1e-10)
    for i, off in enumerate(offsets):
        r = [c - off * y for c, y in zip(com, axis, strict=True)]
        m = [
            r[1] * weight[2] - r[2] * weight[1],
            r[2] * weight[0] - r[0] * weight[2],
            r[0] * weight[1] - r[1] * weight[0],
        ]
        m_a = sum(x * y for x, y in zip(m, axis, strict=True))
        m_perp = math.sqrt(sum((x - m_a * y) ** 2 for x, y in zip(m, axis, strict=True)))
        assert out["bearing_peak_moment"][i] == pytest.approx(m_perp, rel=1e-10)


def test_emergency_stop_blocks_equal_one_block(monkeypatch):
    """Candidates are evaluated in blocks of bounded size; any block size gives the same."""
    load = cycle(seed=7)
    rng = np.random.default_rng(7)
    k = 23
    args = (
        rng.uniform(20.0, 160.0, k) * rng.choice([-1.0, 1.0], k),
        rng.uniform(0.5, 1.0, k),
        rng.uniform(0.0, 1e-4, k),
        rng.uniform(0.0, 5.0, k),
        {"momentary_peak_torque": rng.uniform(10.0, 500.0, k)},
    )
    whole = gb.emergency_stop_values(load, *args)
    monkeypatch.setattr(gb, "_BLOCK", 3 * int(np.count_nonzero(load.speed)))  # blocks of 3
    blocks = gb.emergency_stop_values(load, *args)
    for key, value in whole.items():
        np.testing.assert_array_equal(blocks[key], value, err_msg=key)


def test_margins_by_check_feed_the_verdict():
    from armdyn.sizing.checks import verdict

    load = cycle()
    values = gb.gearbox_cycle_values(load, [50.0, -100.0, 80.0], GEARS)
    values.update(gb.bearing_cycle_values(load, {"bearing_offset": [0.0, 0.01, np.nan]}))
    margins = gb.margins_by_check(values)
    assert set(margins) == {
        "gear_life",
        "gear_average_torque",
        "gear_average_input_speed",
        "gear_repeated_peak",
        "gear_momentary_count",
        "gear_input_speed",
        "bearing_moment",
        "bearing_axial",
        "bearing_radial",
        "bearing_life",
    }
    ok, binding, least = verdict(margins)
    for i in range(3):
        checked = {k: v[i] for k, v in margins.items() if not math.isnan(v[i])}
        name = min(checked, key=checked.get)
        assert binding[i] == name and least[i] == checked[name]
        assert ok[i] == all(v >= 1.0 for v in checked.values())


@pytest.mark.parametrize("ratio", [80.0, -50.0])
def test_emergency_stop_equals_the_dynamics_of_a_model_with_its_actuator(ratio):
    """Second method, η = 1: a pendulum with the actuator in its dynamics (rotor J behind the
    gear N) and the stop torque T_s on the rotor (a joint-side torque N T_m) accelerates by
    armdyn's forward dynamics; the gear output torque on the link is then J_L q̈ + g (the
    rotor-free model's inertia and gravity torque), which the module's closed form must give
    at every moving sample."""
    j_rot, t_s = 3e-5, 0.8

    def pendulum(actuated):
        b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
        b.add_body("link", 1.5, np.diag([0.01, 0.02, 0.015]), position=(0.25, 0.0, 0.05))
        b.add_revolute("hinge", "ground", "link", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
        if actuated:
            b.add_actuator("hinge", ratio, j_rot)
        return b.finalize()

    bare, geared = pendulum(False), pendulum(True)
    q = np.linspace(-1.0, 2.0, 7)
    qd = np.array([0.5, -1.0, 2.0, -0.3, 1.2, -2.5, 0.7])
    gravity = np.array([ad.inverse_dynamics(bare, [x], [0.0], [0.0])[0] for x in q])
    j_load = np.array([ad.mass_matrix(bare, [x])[0, 0] for x in q])
    taus = []
    for x, v, g, jl in zip(q, qd, gravity, j_load, strict=True):
        t_m = -math.copysign(t_s, v)
        qdd = ad.forward_dynamics(geared, [x], [v], [ratio * t_m])[0]
        taus.append(jl * qdd + g)
    n = q.size
    load = make_load(
        t=np.arange(n, dtype=float),
        speed=qd,
        torque=np.zeros(n),
        gravity_torque=gravity,
        force=np.zeros((n, 3)),
        moment=np.zeros((n, 3)),
        axis=np.array([0.0, 0.0, 1.0]),
        inertia=j_load,
    )
    out = gb.emergency_stop_values(load, [ratio], [1.0], [j_rot], [t_s])
    worst = int(np.argmax(np.abs(taus)))
    assert out["gear_momentary_torque"][0] == pytest.approx(abs(taus[worst]), rel=1e-10)
    assert out["emergency_stop_time"][0] == load.t[worst]


def test_a_cycle_without_reactions_leaves_the_bearing_not_checked():
    """JointLoad's force/moment are None when the build cannot compute the reactions."""
    load = replace(cycle(), force=None, moment=None)
    out = gb.bearing_cycle_values(load, BEARINGS)
    assert set(out) >= {"bearing_peak_moment", "bearing_life", "bearing_life_margin"}
    for key, value in out.items():
        assert value.shape == (4,) and np.all(np.isnan(value)), key


def test_extreme_finite_inputs_give_no_nan():
    """|x|^p of large loads and the lives' powers overflow in a naive form (inf * 0 = NaN):
    finite inputs give finite, zero or infinite values, never NaN."""
    base = cycle()
    for scale, speed_scale in ((1e150, 1.0), (1e-150, 1e-300), (1.0, 1e250)):
        load = replace(
            base,
            torque=base.torque * scale,
            force=base.force * scale,
            moment=base.moment * scale,
            speed=base.speed * speed_scale,
        )
        gears = {c: [1.0] for c in ("rated_torque", "rated_input_speed", "rated_life")}
        values = gb.gearbox_cycle_values(load, [100.0], gears)
        bearings = {"bearing_offset": [0.01], "bearing_dynamic_load_rating": [1e4]}
        values.update(gb.bearing_cycle_values(load, {**bearings, "bearing_pitch_diameter": [0.05]}))
        for key in ("gear_average_torque", "gear_life", "bearing_average_moment", "bearing_life"):
            assert not np.isnan(values[key][0]), (scale, speed_scale, key)
        assert values["gear_average_torque"][0] == pytest.approx(
            scale * gb.gearbox_cycle_values(base, [100.0], gears)["gear_average_torque"][0],
            rel=1e-12,
        )


def test_the_example_catalog_vectorised_equals_one_part_at_a_time():
    """The example catalog's gearboxes (a DataFrame, its column names) evaluated at once equal
    each row evaluated alone: the vectorisation mixes no candidates."""
    catalog = ad.load_catalog(ad.sizing.EXAMPLE_CATALOG)
    gears = catalog.gearboxes
    k = len(gears)
    load = cycle(seed=11)
    rotor = gears["input_inertia"].to_numpy() + 2e-5
    stop = np.linspace(0.2, 3.0, k)
    together = gb.gearbox_cycle_values(load, gears["ratio"], gears)
    together.update(gb.bearing_cycle_values(load, gears))
    together.update(
        gb.emergency_stop_values(load, gears["ratio"], gears["efficiency"], rotor, stop, gears)
    )
    assert all(v.shape == (k,) for v in together.values())
    assert np.all(np.isfinite(together["gear_life"])) and np.all(together["gear_life"] > 0.0)
    for i in range(k):
        row = gears.iloc[i : i + 1]
        alone = gb.gearbox_cycle_values(load, row["ratio"], row)
        alone.update(gb.bearing_cycle_values(load, row))
        alone.update(
            gb.emergency_stop_values(
                load, row["ratio"], row["efficiency"], rotor[i : i + 1], stop[i : i + 1], row
            )
        )
        for key, value in alone.items():
            np.testing.assert_array_equal(together[key][i], value[0], err_msg=f"{key} row {i}")


def test_one_catalog_part_as_a_dataclass():
    catalog = ad.load_catalog(ad.sizing.EXAMPLE_CATALOG)
    name = catalog.gearboxes.index[3]
    part, row = catalog.gearbox(name), catalog.gearboxes.loc[[name]]
    load = cycle(seed=2)
    for fn in (
        lambda g: gb.gearbox_cycle_values(load, [part.ratio], g),
        lambda g: gb.bearing_cycle_values(load, g),
        lambda g: gb.emergency_stop_values(load, [part.ratio], [0.8], [1e-5], [1.0], g),
    ):
        by_part, by_row = fn(part), fn(row)
        for key, value in by_row.items():
            np.testing.assert_array_equal(by_part[key], value, err_msg=key)


def rotation(axis, angle):
    """Rodrigues' rotation matrix (plain floats, rows of lists)."""
    x, y, z = axis
    c, s, v = math.cos(angle), math.sin(angle), 1.0 - math.cos(angle)
    return [
        [c + x * x * v, x * y * v - z * s, x * z * v + y * s],
        [y * x * v + z * s, c + y * y * v, y * z * v - x * s],
        [z * x * v - y * s, z * y * v + x * s, c + z * z * v],
    ]


def newton_euler_bearing(mass, com0, inertia0, axis, g, q, qd, qdd, b):
    """(F_a, F_r, M) at the bearing point b along the axis of a body on a revolute joint
    through the origin, from Newton-Euler in world coordinates: F = m (a_c − g_vec),
    M_O = I α + ω × I ω + c × F, M_P = M_O − b a × F, the axial part of M_P dropped."""
    cross = lambda u, v: [  # noqa: E731
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ]
    dot = lambda u, v: sum(x * y for x, y in zip(u, v, strict=True))  # noqa: E731
    r = rotation(axis, q)
    c = [dot(row, com0) for row in r]
    inertia = [
        [
            sum(r[i][k] * inertia0[k][m] * r[j][m] for k in range(3) for m in range(3))
            for j in range(3)
        ]
        for i in range(3)
    ]
    w = [qd * x for x in axis]
    al = [qdd * x for x in axis]
    a_c = [x + y for x, y in zip(cross(al, c), cross(w, cross(w, c)), strict=True)]
    f = [mass * (x - gv) for x, gv in zip(a_c, g, strict=True)]
    iw = [dot(row, w) for row in inertia]
    ia = [dot(row, al) for row in inertia]
    m_o = [x + y + z for x, y, z in zip(ia, cross(w, iw), cross(c, f), strict=True)]
    m_p = [x - b * y for x, y in zip(m_o, cross(axis, f), strict=True)]
    f_a, m_a = dot(f, axis), dot(m_p, axis)
    f_r = math.sqrt(sum((x - f_a * y) ** 2 for x, y in zip(f, axis, strict=True)))
    m = math.sqrt(sum((x - m_a * y) ** 2 for x, y in zip(m_p, axis, strict=True)))
    return f_a, f_r, m


def test_bearing_loads_along_a_motion_equal_newton_euler():
    """Inertial loads included: a body spinning up and down about a tilted axis through the
    joint (centre of mass off the axis, a full inertia tensor), the reactions by
    ``armdyn.joint_reactions`` moved to the bearing point, against Newton-Euler by hand; the
    peaks and the 10/3 means (weights |q̇|) of F_a, F_r and M."""
    mass, g = 3.0, 9.81
    com0 = [0.12, -0.04, 0.2]
    inertia0 = [[0.03, 0.004, -0.002], [0.004, 0.05, 0.006], [-0.002, 0.006, 0.04]]
    axis = [1.0 / math.sqrt(3.0)] * 3
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -g))
    b.add_body("link", mass, np.array(inertia0), position=tuple(com0))
    b.add_revolute("hinge", "ground", "link", (0.0, 0.0, 0.0), tuple(axis))
    model = b.finalize()
    t = np.linspace(0.0, 2.0, 81)
    q = 1.5 * np.sin(np.pi * t) ** 2
    qd = 1.5 * np.pi * np.sin(2.0 * np.pi * t)
    qdd = 3.0 * np.pi**2 * np.cos(2.0 * np.pi * t)
    forces, torques = ad.joint_reactions(model, q[:, None], qd[:, None], qdd[:, None])
    n = t.size
    load = make_load(
        t=t,
        speed=qd,
        torque=np.zeros(n),
        gravity_torque=np.zeros(n),
        force=forces[:, 0, :],
        moment=torques[:, 0, :],
        axis=np.array([0.0, 0.0, 1.0]),
        inertia=np.ones(n),
    )
    offsets = [0.0, 0.04, -0.03]
    out = gb.bearing_cycle_values(load, {"bearing_offset": offsets})
    w = [abs(float(x)) for x in qd]
    tl = [float(x) for x in t]
    for i, off in enumerate(offsets):
        rows = [
            newton_euler_bearing(mass, com0, inertia0, axis, (0.0, 0.0, -g), *s, off)
            for s in zip(q.tolist(), qd.tolist(), qdd.tolist(), strict=True)
        ]
        f_a, f_r, m = ([r[j] for r in rows] for j in range(3))
        assert out["bearing_peak_axial"][i] == pytest.approx(max(map(abs, f_a)), rel=1e-10)
        assert out["bearing_peak_radial"][i] == pytest.approx(max(f_r), rel=1e-10)
        assert out["bearing_peak_moment"][i] == pytest.approx(max(m), rel=1e-10)
        assert out["bearing_average_axial"][i] == pytest.approx(hand_mean(f_a, w, tl), rel=1e-10)
        assert out["bearing_average_radial"][i] == pytest.approx(hand_mean(f_r, w, tl), rel=1e-10)
        assert out["bearing_average_moment"][i] == pytest.approx(hand_mean(m, w, tl), rel=1e-10)


def two_link_cycle(dwell):
    """A two-link arm in a vertical plane, a rest-to-rest quintic move of 1 s, then ``dwell``
    seconds holding the last pose: :func:`armdyn.duty_cycle`."""
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("upper", 4.0, np.diag([0.05, 0.05, 0.01]), position=(0.2, 0.0, 0.0))
    b.add_revolute("shoulder", "ground", "upper", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    b.add_body("fore", 2.0, np.diag([0.02, 0.02, 0.005]), position=(0.55, 0.03, 0.0))
    b.add_revolute("elbow", "upper", "fore", (0.4, 0.0, 0.0), (0.0, 1.0, 0.0))
    model = b.finalize()
    t = np.linspace(0.0, 1.0, 101)
    s = 10 * t**3 - 15 * t**4 + 6 * t**5
    sd = 30 * t**2 - 60 * t**3 + 30 * t**4
    sdd = 60 * t - 180 * t**2 + 120 * t**3
    delta = np.array([1.2, -0.8])
    q = np.array([-0.3, 0.5]) + np.outer(s, delta)
    return ad.duty_cycle(model, (t, q, np.outer(sd, delta), np.outer(sdd, delta)), dwell=dwell)


def test_a_duty_cycle_with_a_dwell_averages_the_input_speed_over_the_pause():
    """The real JointLoad of a duty cycle: a dwell adds no speed weight, so the cubic-mean
    torque, the peaks, the bearing loads and the emergency stop are those of the motion alone,
    while the average input speed is spread over the longer period (life x period ratio); the
    brake holds the largest gravity torque of the cycle, dwell included."""
    dwell = 1.5
    moving, holding = two_link_cycle(0.0), two_link_cycle(dwell)
    gears = {"rated_torque": [30.0], "rated_input_speed": [200.0], "rated_life": [1e4]}
    bearings = {
        "bearing_offset": [0.02],
        "bearing_dynamic_load_rating": [8e3],
        "bearing_pitch_diameter": [0.05],
    }
    values = []
    for dc in (moving, holding):
        load = dc.joint_load("shoulder")
        assert isinstance(load, JointLoad) and load.force is not None
        v = gb.gearbox_cycle_values(load, [100.0], gears)
        v.update(gb.bearing_cycle_values(load, bearings))
        v.update(gb.emergency_stop_values(load, [100.0], [0.9], [2e-5], [1.0]))
        values.append(v)
    a, b = values
    period_a = moving.joint_load("shoulder").t[-1] - moving.joint_load("shoulder").t[0]
    ratio = (period_a + dwell) / period_a
    assert b["gear_average_input_speed"][0] == pytest.approx(
        a["gear_average_input_speed"][0] / ratio, rel=1e-12
    )
    assert b["gear_life"][0] == pytest.approx(a["gear_life"][0] * ratio, rel=1e-12)
    for key in (
        "gear_average_torque",
        "gear_repeated_peak_torque",
        "gear_peak_input_speed",
        "bearing_peak_moment",
        "bearing_peak_axial",
        "bearing_peak_radial",
        "bearing_average_moment",
        "gear_momentary_torque",
    ):
        assert b[key][0] == pytest.approx(a[key][0], rel=1e-12), key
    assert b["bearing_life"][0] == pytest.approx(a["bearing_life"][0] * ratio, rel=1e-12)
    load = holding.joint_load("shoulder")
    out = dv.brake_values(load, [100.0], [0.5], SizingOptions(brake_safety_factor=2.0))
    worst = max(abs(float(g)) for g in load.gravity_torque)
    assert out["brake_required_torque"][0] == pytest.approx(2.0 * worst, rel=1e-14)
    assert out["brake_holding_margin"][0] == pytest.approx(50.0 / (2.0 * worst), rel=1e-14)


def test_drive_and_bus_from_the_motor_side_of_a_real_duty_cycle():
    """End to end on a real cycle: the motor side of both joints (``motor_cycle_values`` /
    ``motor_cycle_series``, the example catalog's first motor and drive) into the drive check
    and the common bus. The bus regenerates at most what the axes regenerate alone (the axes
    exchange power on the bus), and without a capacitance the resistor takes all of it."""
    from armdyn.sizing.motor import motor_cycle_series, motor_cycle_values

    catalog = ad.load_catalog(ad.sizing.EXAMPLE_CATALOG)
    motor = catalog.motors.iloc[-1]
    fields = {f: np.array([motor[f]]) for f in ad.sizing.MOTOR_FIELDS if f in motor.index}
    drive = catalog.drives.iloc[[-1]]
    dc = two_link_cycle(0.5)
    powers, regenerated = [], 0.0
    for joint in ("shoulder", "elbow"):
        load = dc.joint_load(joint)
        values = motor_cycle_values(load, [100.0], [0.85], [motor["rotor_inertia"]], fields)
        out = dv.drive_values(values, drive)
        for check, value, rating in (
            ("drive_peak_current_margin", "peak_current", "peak_current"),
            ("drive_rms_current_margin", "rms_current", "continuous_current"),
        ):
            want = drive[rating].iloc[0] / values[value][0]
            assert out[check][0] == pytest.approx(want, rel=1e-14), check
        series = motor_cycle_series(load, 100.0, 0.85, motor["rotor_inertia"], motor.to_dict())
        np.testing.assert_array_equal(series["t"], load.t)
        powers.append(series["electrical_power"])
        e = 0.5 * (series["electrical_power"][1:] + series["electrical_power"][:-1])
        regenerated += float(np.sum(np.maximum(-e * np.diff(load.t), 0.0)))
    bus = dv.bus_values(load.t, np.stack(powers), drives={"bus_voltage": 48.0})
    assert 0.0 < bus["bus_energy_regenerated"][0] <= regenerated
    assert bus["resistor_energy"][0] == pytest.approx(bus["bus_energy_regenerated"][0], rel=1e-12)
