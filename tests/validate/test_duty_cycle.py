"""Duty cycles (armdyn.duty_cycle, DutyCycle, JointLoad) and the vectorised motor side
(armdyn.sizing.motor.motor_cycle_values / motor_cycle_series) against hand calculations and
the single-actuator path (armdyn.actuators.motor_side).

Reference arm: one link of mass m, centre of mass at distance L from a horizontal shoulder
(axis y, gravity −z), inertia I_yy about its centre. At angle q the centre is at (L cos q, 0,
−L sin q), so the shoulder's torque is τ = (I_yy + m L²) q̈ − m g L cos q and its holding
torque −m g L cos q. The motion: a quintic from 0 to Q1 in T1 seconds (at rest at both ends).
"""

from types import SimpleNamespace

import armdyn as ad
import numpy as np
import pytest
from armdyn.actuators import motor_side
from armdyn.sizing import motor as sizing_motor
from armdyn.sizing import thermal

M, L, IYY, G = 2.0, 0.5, 0.05, 9.81
Q1, T1 = 1.0, 1.0


def arm(mass=M, actuator=None):
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -G))
    b.add_body("link", mass, [0.01, IYY, IYY], position=(L, 0.0, 0.0))
    b.add_revolute("shoulder", "ground", "link", point=(0, 0, 0), axis=(0, 1, 0))
    if actuator:
        b.add_actuator("shoulder", **actuator)
    return b.finalize()


def quintic(n=201):
    t = np.linspace(0.0, T1, n)
    s = t / T1
    q = Q1 * (10 * s**3 - 15 * s**4 + 6 * s**5)
    qd = Q1 * (30 * s**2 - 60 * s**3 + 30 * s**4) / T1
    qdd = Q1 * (60 * s - 180 * s**2 + 120 * s**3) / T1**2
    return t, q[:, None], qd[:, None], qdd[:, None]


def hand_torque(q, qdd, mass=M):
    return (IYY + mass * L * L) * qdd - mass * G * L * np.cos(q)


def test_cycle_torques_and_the_dwell_hold():
    t, q, qd, qdd = quintic()
    cycle = ad.duty_cycle(arm(), (t, q, qd, qdd), dwell=2.0, repeat=5)
    hold = -M * G * L * np.cos(Q1)
    assert cycle.period == pytest.approx(T1 + 2.0, rel=1e-15)
    np.testing.assert_array_equal(cycle.t[-2:], [T1, T1 + 2.0])
    np.testing.assert_allclose(cycle.torque[:-2, 0], hand_torque(q[:, 0], qdd[:, 0]), rtol=1e-12)
    np.testing.assert_allclose(cycle.torque[-2:, 0], hold, rtol=1e-12)
    np.testing.assert_allclose(cycle.gravity_torque[:, 0], -M * G * L * np.cos(cycle.q[:, 0]))
    np.testing.assert_allclose(cycle.inertia[:, 0], IYY + M * L * L, rtol=1e-12)
    # a TrajectoryRun of the motion (on another model: the cycle recomputes) gives the same
    run = ad.trajectory_run(arm(mass=5.0), t, q, qd, qdd)
    again = ad.duty_cycle(arm(), run, dwell=2.0, repeat=5)
    np.testing.assert_array_equal(again.torque, cycle.torque)
    load = cycle.joint_load("shoulder")
    assert load.repeat == 5 and load.period == cycle.period
    np.testing.assert_array_equal(load.moving, [True] * len(t) + [False, False])
    np.testing.assert_array_equal(load.axis, [0.0, 0.0, 1.0])


def test_dwell_holding_torque_counted_in_rms():
    """A shoulder holding against gravity: the RMS motor torque over the cycle is
    √((∫_motion T² + D T_hold²) / (T1 + D)) with T = τ / N (η = 1, no rotor), the motion's
    integral by the trapezoid rule on its samples; without the dwell it is the motion's alone.
    A dwell at zero torque would give √(∫_motion T² / (T1 + D)): the hold is counted."""
    t, q, qd, qdd = quintic()
    n, dwell = 50.0, 3.0
    hand = hand_torque(q[:, 0], qdd[:, 0]) / n
    motion_sq = np.trapezoid(hand**2, t)
    hold = M * G * L * np.cos(Q1) / n
    rms_hand = np.sqrt((motion_sq + dwell * hold**2) / (T1 + dwell))
    motors = {"continuous_torque": np.array([0.1])}
    with_dwell = ad.duty_cycle(arm(), (t, q, qd, qdd), dwell=dwell).joint_load("shoulder")
    v = sizing_motor.motor_cycle_values(with_dwell, n, 1.0, 0.0, motors)
    assert v["motor_rms_torque"][0] == pytest.approx(rms_hand, rel=1e-12)
    assert v["continuous_torque"][0] == pytest.approx(0.1 / rms_hand, rel=1e-12)
    assert v["motor_peak_torque"][0] == pytest.approx(np.max(np.abs(hand)), rel=1e-12)
    no_dwell = ad.duty_cycle(arm(), (t, q, qd, qdd)).joint_load("shoulder")
    v0 = sizing_motor.motor_cycle_values(no_dwell, n, 1.0, 0.0, motors)
    assert v0["motor_rms_torque"][0] == pytest.approx(np.sqrt(motion_sq / T1), rel=1e-12)
    assert v["motor_rms_torque"][0] > 1.3 * np.sqrt(motion_sq / (T1 + dwell))


def test_motion_not_ending_at_rest_names_the_joint():
    t, q, qd, qdd = quintic()
    with pytest.raises(ad.ModelError, match=r"not end at rest: joint 'shoulder' moves"):
        ad.duty_cycle(arm(), (t[:150], q[:150], qd[:150], qdd[:150]), dwell=1.0)


@pytest.mark.parametrize(
    "kw, name",
    [
        ({"dwell": np.nan}, "dwell"),
        ({"dwell": -1.0}, "dwell"),
        ({"dwell": 1e300}, "dwell"),
        ({"dwell": np.inf}, "dwell"),
        ({"dwell": "2"}, "dwell"),
        ({"repeat": 0}, "repeat"),
        ({"repeat": -1}, "repeat"),
        ({"repeat": 1.5}, "repeat"),
        ({"repeat": True}, "repeat"),
        ({"repeat": "forever"}, "repeat"),
    ],
)
def test_hostile_dwell_and_repeat(kw, name):
    with pytest.raises(ad.ModelError, match=name):
        ad.duty_cycle(arm(), quintic(), **kw)


def test_largest_dwell_stays_finite():
    """The largest dwell allowed (MAX_DWELL): finite RMS and temperatures (the hold's)."""
    load = ad.duty_cycle(arm(), quintic(), dwell=1e8).joint_load("shoulder")
    motors = {
        "torque_constant": np.array([0.1]),
        "resistance": np.array([1.0]),
        "thermal_resistance": np.array([2.0]),
        "thermal_time_constant": np.array([30.0]),
    }
    v = sizing_motor.motor_cycle_values(load, 50.0, 1.0, 0.0, motors)
    hold = M * G * L * np.cos(Q1) / 50.0
    assert v["motor_rms_torque"][0] == pytest.approx(hold, rel=1e-6)
    assert np.all(np.isfinite([v[k][0] for k in sizing_motor.CYCLE_VALUES if k not in (
        "housing_temperature_peak", "envelope_worst", "stall_torque", "peak_terminal_voltage"
    )]))  # fmt: skip


def write_csv(path, rows, header="t,shoulder,shoulder.qd,shoulder.qdd"):
    path.write_text(header + "\n" + "\n".join(",".join(str(x) for x in r) for r in rows) + "\n")
    return path


def test_csv_motion_and_its_bad_inputs(tmp_path):
    t, q, qd, qdd = quintic(21)
    rows = np.column_stack([t, q, qd, qdd])
    good = write_csv(tmp_path / "good.csv", rows.tolist())
    cycle = ad.duty_cycle(arm(), str(good), dwell=1.0)
    np.testing.assert_allclose(cycle.torque[:-2, 0], hand_torque(q[:, 0], qdd[:, 0]), rtol=1e-12)
    bad_nan = rows.tolist()
    bad_nan[3][1] = "nan"
    cases = {
        "nan.csv": (bad_nan, None, "'shoulder', data row 4"),
        "order.csv": (rows[::-1].tolist(), None, "strictly increasing"),
        "missing.csv": (rows[:, [0, 2, 3]].tolist(), "t,shoulder.qd,shoulder.qdd", "missing"),
        "short.csv": ([rows[0].tolist()], None, "two data rows"),
    }
    for name, (data, header, message) in cases.items():
        path = write_csv(tmp_path / name, data, *(header,) if header else ())
        with pytest.raises(ad.ModelError, match=message):
            ad.duty_cycle(arm(), path)
    with pytest.raises(ad.ModelError, match=r"regular file|directory"):
        ad.duty_cycle(arm(), tmp_path)
    with pytest.raises(ad.ModelError, match="motion must be"):
        ad.duty_cycle(arm(), 42)


def test_actuated_model_load_is_rotor_free():
    """With an actuator (N, J) in the model the joint torque gains N² J q̈; the JointLoad's
    torque and inertia are the rotor-free ones (the arm without it)."""
    n, j = 80.0, 3e-5
    motion = quintic()
    geared = ad.duty_cycle(arm(actuator={"gear_ratio": n, "rotor_inertia": j}), motion, 1.0)
    plain = ad.duty_cycle(arm(), motion, 1.0)
    np.testing.assert_allclose(
        geared.torque[:, 0], plain.torque[:, 0] + n * n * j * geared.qdd[:, 0], rtol=1e-12
    )
    a, b = geared.joint_load("shoulder"), plain.joint_load("shoulder")
    np.testing.assert_allclose(a.torque, b.torque, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(a.inertia, b.inertia, rtol=1e-12)


def test_with_model_recomputes_the_loads():
    """A heavier link (a payload's mass at the same centre): the same motion's torques follow
    the hand formula with the new mass; dwell and repeat are kept."""
    cycle = ad.duty_cycle(arm(), quintic(), dwell=1.5, repeat=3)
    heavy = cycle.with_model(arm(mass=3.0))
    assert (heavy.dwell, heavy.repeat, heavy.period) == (1.5, 3, cycle.period)
    q, qdd = heavy.q[:, 0], heavy.qdd[:, 0]
    np.testing.assert_allclose(heavy.torque[:, 0], hand_torque(q, qdd, 3.0), rtol=1e-12)
    assert cycle.torque[0, 0] == pytest.approx(hand_torque(0.0, cycle.qdd[0, 0]), rel=1e-12)


def test_joint_load_bad_joint():
    cycle = ad.duty_cycle(arm(), quintic())
    with pytest.raises(ad.ModelError, match="'elbow'"):
        cycle.joint_load("elbow")


def simulated():
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -G))
    b.add_body("link", M, [0.01, IYY, IYY], position=(L, 0.0, 0.0))
    b.add_revolute("shoulder", "ground", "link", point=(0, 0, 0), axis=(0, 1, 0))
    b.add_drive("shoulder", ad.profiles.quintic(0.0, Q1, 0.0, T1))
    model = b.finalize()
    return model, ad.simulate(model, T1, output_dt=0.01)


def reaction_by_hand(cycle):
    """The shoulder's reaction force on the link at the joint, in the link's joint frame: the
    link's m (a_c − g) (no other force acts on it), a_c of its centre on the circle of radius
    L. The joint frame's axes in the link's frame are model.joint_frame's frame_child; the
    link's frame turns by q about y."""
    q, qd, qdd = cycle.q[:, 0], cycle.qd[:, 0], cycle.qdd[:, 0]
    c, s = np.cos(q), np.sin(q)
    # centre (L c, 0, −L s): a = L (−s q̈ − c q̇², 0, −c q̈ + s q̇²)
    a = L * np.stack([-s * qdd - c * qd**2, 0 * q, -c * qdd + s * qd**2], axis=1)
    f_world = M * (a - np.array([0.0, 0.0, -G]))
    rot = np.zeros((len(q), 3, 3))  # link axes in world: rotation about y by q
    rot[:, 0, 0], rot[:, 0, 2], rot[:, 1, 1], rot[:, 2, 0], rot[:, 2, 2] = c, s, 1, -s, c
    frame = cycle.model.joint_frame("shoulder")["frame_child"]
    return np.einsum("ji,nkj,nk->ni", frame, rot, f_world)


def test_reactions_from_a_simulation():
    """The cycle's reaction wrench (armdyn.joint_reactions along the motion) equals the hand
    calculation and the simulation's own reactions; no moment about the other axes (a hinge
    through the centre's plane)."""
    model, res = simulated()
    cycle = ad.duty_cycle(model, res)
    load = cycle.joint_load("shoulder")
    np.testing.assert_allclose(load.force, reaction_by_hand(cycle), rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(load.moment[:, :2], 0.0, atol=1e-9)
    # joint_reactions along the motion (part 1) equals the simulation's own reactions
    np.testing.assert_allclose(cycle.reaction_forces, res.reaction_forces, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(cycle.reaction_torques, res.reaction_torques, atol=1e-9)


def test_reactions_in_the_dwell():
    """With a dwell the hold's reactions (armdyn.joint_reactions at rest) follow the hand
    calculation: the support carries the weight."""
    model, res = simulated()
    cycle = ad.duty_cycle(model, res, dwell=2.0)
    load = cycle.joint_load("shoulder")
    np.testing.assert_allclose(load.force, reaction_by_hand(cycle), rtol=1e-9, atol=1e-9)
    assert np.linalg.norm(load.force[-1]) == pytest.approx(M * G, rel=1e-12)


def stand_in(n, j, eta, motor=None):
    return SimpleNamespace(
        joint="shoulder",
        gear_ratio=n,
        rotor_inertia=j,
        efficiency=eta,
        friction_viscous=0.0,
        friction_coulomb=0.0,
        friction_smoothing=None,
        motor=motor,
    )


def test_vectorised_motor_side_equals_motor_side():
    """k candidates at once against armdyn.actuators.motor_side one by one (the joint torque
    it takes is the load's plus N² J q̈), the copper's resistance constant (α = 0, no thermal
    model): torques, speeds, currents, voltage, electrical power, regenerated energy and the
    envelope (motor_envelope)."""
    t, q, qd, qdd = quintic()
    load = ad.duty_cycle(arm(), (t, q, qd, qdd), dwell=0.5).joint_load("shoulder")
    rng = np.random.default_rng(4)
    k = 7
    ratio, eta, j = rng.uniform(20, 150, k), rng.uniform(0.6, 1.0, k), rng.uniform(0, 1e-4, k)
    motors = {
        "torque_constant": rng.uniform(0.05, 0.2, k),
        "resistance": rng.uniform(0.3, 2.0, k),
        "voltage": np.full(k, 48.0),
        "peak_torque": rng.uniform(0.2, 1.0, k),
    }
    opts = ad.sizing.options.SizingOptions(copper_temperature_coefficient=0.0)
    v = sizing_motor.motor_cycle_values(load, ratio, eta, j, motors, opts)
    for c in range(k):
        m = SimpleNamespace(**{f: motors[f][c] for f in motors}, no_load_speed=None)
        act = stand_in(ratio[c], j[c], eta[c], m)
        tau = load.torque + ratio[c] ** 2 * j[c] * load.acceleration
        side = motor_side(act, load.t, load.speed, load.acceleration, tau)
        rms = np.sqrt(np.trapezoid(side.torque**2, load.t) / load.period)
        assert v["motor_rms_torque"][c] == pytest.approx(rms, rel=1e-12)
        assert v["motor_peak_torque"][c] == pytest.approx(np.max(np.abs(side.torque)), rel=1e-12)
        assert v["motor_peak_speed"][c] == pytest.approx(np.max(np.abs(side.speed)), rel=1e-12)
        assert v["peak_current"][c] == pytest.approx(np.max(np.abs(side.current)), rel=1e-12)
        p_el = side.electrical_power
        assert v["peak_electrical_power"][c] == pytest.approx(np.max(np.abs(p_el)), rel=1e-12)
        assert v["energy_regenerated"][c] == pytest.approx(
            side.energy_regenerated[-1], rel=1e-12, abs=1e-12
        )
        volt = m.resistance * side.current + m.torque_constant * side.speed
        assert v["peak_terminal_voltage"][c] == pytest.approx(np.max(np.abs(volt)), rel=1e-12)
        t0, w0 = sizing_motor.motor_envelope(m)
        worst = np.max(np.abs(side.torque + t0 * side.speed / w0))
        assert v["envelope_worst"][c] == pytest.approx(worst, rel=1e-12)
        assert v["envelope"][c] == pytest.approx(t0 / worst, rel=1e-12)
    assert np.all(v["energy_regenerated"] > 0.0)  # the lowering half regenerates
    assert np.all(np.isnan(v["winding_temperature_peak"]))  # no thermal data: not checked


def test_one_node_fallback_equals_thermal_rise():
    """A motor with only R_th and τ_th, one period from ambient (repeat=1) and a constant
    resistance: the winding temperature is the report's first-order thermal_rise of
    motor_side's copper loss, plus the ambient."""
    t, q, qd, qdd = quintic()
    load = ad.duty_cycle(arm(), (t, q, qd, qdd), dwell=2.0, repeat=1).joint_load("shoulder")
    m = SimpleNamespace(
        torque_constant=0.08, resistance=1.2, thermal_resistance=1.5, thermal_time_constant=20.0
    )
    opts = ad.sizing.options.SizingOptions(copper_temperature_coefficient=0.0)
    series = sizing_motor.motor_cycle_series(load, 60.0, 0.9, 2e-5, m, opts)
    tau = load.torque + 60.0**2 * 2e-5 * load.acceleration
    side = motor_side(stand_in(60.0, 2e-5, 0.9, m), load.t, load.speed, load.acceleration, tau)
    rise = thermal.thermal_rise(load.t, side.loss_copper, 1.5, 20.0)
    np.testing.assert_allclose(series["winding_temperature"] - 40.0, rise, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(series["copper_loss"], side.loss_copper, rtol=1e-12)
    assert np.all(np.isnan(series["housing_temperature"]))


def test_repeat_is_the_brute_force_last_period():
    """``repeat=N`` from ambient: the peak winding temperature equals stepping through the N
    periods one after another (a long cycle of N copies, repeat=1)."""
    t, q, qd, qdd = quintic(41)
    reps = 30
    load = ad.duty_cycle(arm(), (t, q, qd, qdd), dwell=1.0, repeat=reps).joint_load("shoulder")
    period = load.period
    long = SimpleNamespace(
        t=np.concatenate([load.t + i * period for i in range(reps)]),
        speed=np.tile(load.speed, reps),
        acceleration=np.tile(load.acceleration, reps),
        torque=np.tile(load.torque, reps),
        repeat=1,
    )
    motors = {
        "torque_constant": np.array([0.05, 0.1]),
        "resistance": np.array([1.0, 0.8]),
        "thermal_resistance_winding": np.array([0.8, np.nan]),
        "thermal_resistance_housing": np.array([1.2, np.nan]),
        "thermal_time_constant_winding": np.array([15.0, np.nan]),
        "thermal_time_constant_housing": np.array([200.0, np.nan]),
        "thermal_resistance": np.array([np.nan, 2.0]),
        "thermal_time_constant": np.array([np.nan, 25.0]),
        "max_winding_temperature": np.array([155.0, 100.0]),
    }
    args = ([40.0, 40.0], 1.0, [3e-5, 3e-5], motors)
    a = sizing_motor.motor_cycle_values(load, *args)
    b = sizing_motor.motor_cycle_values(long, *args)
    for key in ("winding_temperature_peak", "housing_temperature_peak"):
        np.testing.assert_allclose(a[key], b[key], rtol=1e-10)
    rise = a["winding_temperature_peak"] - 40.0
    assert a["winding_temperature"] == pytest.approx(
        (motors["max_winding_temperature"] - 40) / rise
    )
    assert np.all(rise > 1.0)


@pytest.mark.parametrize(
    "change, name",
    [
        ({"ratio": [0.0]}, "ratio"),
        ({"ratio": [np.nan]}, "ratio"),
        ({"efficiency": [1.5]}, "efficiency"),
        ({"efficiency": [0.0]}, "efficiency"),
        ({"rotor_inertia": [-1.0]}, "rotor_inertia"),
        ({"ratio": [10.0, 20.0], "efficiency": [0.9, 0.9, 0.9]}, "one length"),
        ({"motors": {"resistance": [-1.0]}}, "resistance"),
        ({"motors": {"resistance": [np.inf]}}, "resistance"),
        ({"ratio": [10.0, 20.0, 30.0], "motors": {"resistance": [1.0, 2.0]}}, "resistance"),
        ({"ratio": [10.0, 20.0], "motors": {"resistance": [1.0, 2.0, 3.0]}}, "2 gears"),
        ({"motors": {"torque_constant": ["a"]}}, "torque_constant"),
        ({"motors": [1.0]}, "motors"),
    ],
)
def test_motor_cycle_values_hostile(change, name):
    load = ad.duty_cycle(arm(), quintic(21)).joint_load("shoulder")
    kw = {"ratio": [50.0], "efficiency": [0.9], "rotor_inertia": [1e-5], "motors": {}} | change
    with pytest.raises(ad.ModelError, match=name):
        sizing_motor.motor_cycle_values(load, **kw)


def test_motors_as_a_catalog_frame():
    """``motors`` may be a pandas DataFrame of catalog rows (columns = motor fields, NaN =
    blank, extra columns ignored): the same values as the dict of its columns."""
    pd = pytest.importorskip("pandas")
    load = ad.duty_cycle(arm(), quintic(41), dwell=1.0).joint_load("shoulder")
    frame = pd.DataFrame(
        {
            "torque_constant": [0.05, 0.1],
            "resistance": [1.0, np.nan],
            "continuous_torque": [0.2, 0.3],
            "thermal_resistance": [2.0, 2.0],
            "thermal_time_constant": [20.0, 20.0],
            "source": ["illustrative", "illustrative"],
        },
        index=pd.Index(["small", "large"], name="name"),
    )
    a = sizing_motor.motor_cycle_values(load, 40.0, 0.9, 2e-5, frame)
    b = sizing_motor.motor_cycle_values(
        load, 40.0, 0.9, 2e-5, {c: frame[c].to_numpy() for c in frame.columns[:-1]}
    )
    for key, value in a.items():
        np.testing.assert_array_equal(value, b[key])
    assert np.isfinite(a["winding_temperature_peak"][0])
    assert np.isnan(a["winding_temperature_peak"][1])  # no resistance: not checked
