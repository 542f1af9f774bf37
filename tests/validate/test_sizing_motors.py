"""The sizing report's motor-side columns and checks, the gear-ratio sweep, and the joint-side
values of a UR5 trajectory against Pinocchio's RNEA.

Motor-side tests use a rotor of load inertia I about a vertical axis driven by q = A sin(ω t)
(see test_sizing.py) with a stand-in actuator (the attributes of ``model.actuators`` entries):
the run's joint torque is the rotor-free one plus the reflected rotor term N² J q̈, as a model
with the actuator reports it. With η = 1 and no friction the motor torque is
T = (J N + I / N) q̈ = −(J N + I / N) A ω² sin(ω t) and its speed ω_m = N A ω cos(ω t).
"""

import base64
from types import SimpleNamespace

import armdyn as ad
import numpy as np
import pytest
from armdyn import _core, sizing
from armdyn.sizing import motor as sizing_motor  # the home of _mass_matrix, patched below

I_Z, AMP, FREQ, H = 0.2, 1.0, 0.5, 1e-3
OMEGA = 2.0 * np.pi * FREQ
N, J = 25.0, 1e-4


def rotor_model():
    b = ad.ModelBuilder(gravity=(0.0, 0.0, 0.0))
    b.add_body("rotor", 1.0, [0.5, 0.5, I_Z], position=(0, 0, 0))
    b.add_revolute("spin", "ground", "rotor", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_drive("spin", ad.profiles.sine(AMP, FREQ))
    return b.finalize()


class WithActuators:
    """A finalized model seen with stand-in actuators (the C++ actuator model is not used)."""

    def __init__(self, model, actuators):
        self._model, self.actuators = model, actuators

    def __getattr__(self, name):
        return getattr(self._model, name)


def motor(**kw):
    fields = [f for f in ad.sizing.MOTOR_FIELDS if f != "name"]
    return SimpleNamespace(name="m", **{f: kw.get(f) for f in fields})


def stand_in(m, n=N, j=J):
    return SimpleNamespace(
        joint="spin",
        rotor_joint="spin_rotor",
        dof=0,
        gear_ratio=n,
        rotor_inertia=j,
        efficiency=1.0,
        friction_viscous=0.0,
        friction_coulomb=0.0,
        motor=m,
        gyroscopic=False,
    )


@pytest.fixture(scope="module")
def run():
    model = rotor_model()
    res = ad.simulate(model, 4.0, output_dt=H)
    tau = res.drive_forces[:, :1] + N * N * J * res.qdd
    geared = SimpleNamespace(t=res.t, q=res.q, qd=res.qd, qdd=res.qdd, joint_torques=tau)
    return model, res, geared


K_T, R_W, V = 0.05, 0.4, 24.0
PEAK_T = (J * N + I_Z / N) * AMP * OMEGA**2  # motor torque amplitude
PEAK_W = N * AMP * OMEGA


def full_motor(**over):
    kw = dict(
        torque_constant=K_T,
        resistance=R_W,
        voltage=V,
        no_load_speed=V / K_T,
        continuous_torque=1.5 * PEAK_T / np.sqrt(2.0),
        peak_torque=2.0 * PEAK_T,
        max_speed=4.0 * PEAK_W,
        thermal_resistance=2.0,
        thermal_time_constant=30.0,
    )
    kw.update(over)
    return motor(**kw)


def test_motor_columns_against_the_closed_form(run, monkeypatch):
    model, _, geared = run
    m = full_motor()
    proxy = WithActuators(model, [stand_in(m)])
    # the mass matrix of a model with the actuator: the rotor-free one plus N² J (contract)
    monkeypatch.setattr(
        sizing_motor, "_mass_matrix", lambda md, q: _core.mass_matrix(md._model, q) + N * N * J
    )
    row = ad.sizing_report(geared, proxy).table.loc["spin"]
    # joint side includes the reflected rotor: (I + N² J) A ω²
    assert row["peak_torque"] == pytest.approx((I_Z + N * N * J) * AMP * OMEGA**2, rel=1e-12)
    # and its two shares on their own: the load's I A ω², the rotor's N² J A ω² (by hand:
    # q̈ = −A ω² sin ω t, both in phase, so the peaks add)
    assert row["peak_load_torque"] == pytest.approx(I_Z * AMP * OMEGA**2, rel=1e-12)
    assert row["peak_rotor_torque"] == pytest.approx(N * N * J * AMP * OMEGA**2, rel=1e-12)
    assert row["gear_ratio"] == N
    assert row["motor_peak_torque"] == pytest.approx(PEAK_T, rel=1e-12)
    assert row["motor_rms_torque"] == pytest.approx(PEAK_T / np.sqrt(2.0), rel=1e-12)
    assert row["motor_peak_speed"] == pytest.approx(PEAK_W, rel=1e-12)
    assert row["motor_rms_speed"] == pytest.approx(PEAK_W / np.sqrt(2.0), rel=1e-12)
    assert row["peak_current"] == pytest.approx(PEAK_T / K_T, rel=1e-12)
    assert row["continuous_torque_margin"] == pytest.approx(1.5, rel=1e-12)
    assert row["peak_torque_margin"] == pytest.approx(2.0, rel=1e-12)
    assert row["motor_speed_margin"] == pytest.approx(4.0, rel=1e-12)
    assert row["inertia_ratio"] == pytest.approx(I_Z / (N * N * J), rel=1e-12)
    # envelope: max over t of |−P sin + (T0 S / ω0) cos| = √(P² + (T0 S/ω0)²) (the samples
    # miss the maximum by at most a relative (ω h)² / 2)
    t0, w0 = K_T * V / R_W, V / K_T
    exact = t0 / np.hypot(PEAK_T, t0 * PEAK_W / w0)
    assert exact <= row["envelope_margin"] <= exact * (1 + (OMEGA * H) ** 2)
    # electrical: P = T ω + R i²; over whole periods ∫ T ω = 0 (a pure inertia) and
    # ∫ R i² = R (P/k)² T / 2 (exact on this grid, see test_sizing.py)
    copper = R_W * (PEAK_T / K_T) ** 2 * 4.0 / 2.0
    assert row["electrical_energy"] == pytest.approx(copper, rel=1e-10)
    assert row["temperature_rise_steady"] == pytest.approx(2.0 * copper / 4.0, rel=1e-10)
    assert 0.0 < row["temperature_rise_peak"] < row["temperature_rise_steady"]
    assert row["motor_energy_regenerated"] > 0.0
    assert bool(row["ok"]) and row["unchecked"] == ""


def test_what_if_actuators_equal_the_stand_in_model(run, monkeypatch):
    """sizing_report(run, model, actuators={...}) on the rotor-free run equals the report of
    the run with the rotor in its torques and the actuator in the model, column by column."""
    model, res, geared = run
    m = full_motor()
    monkeypatch.setattr(
        sizing_motor, "_mass_matrix", lambda md, q: _core.mass_matrix(md._model, q) + N * N * J
    )
    a = ad.sizing_report(geared, WithActuators(model, [stand_in(m)])).table
    monkeypatch.setattr(sizing_motor, "_mass_matrix", lambda md, q: _core.mass_matrix(md, q))
    spec = {"gear_ratio": N, "rotor_inertia": J, "motor": m}
    b = ad.sizing_report(res, model, actuators={"spin": spec}).table
    # the what-if rotor is not hidden in peak_torque: the run's own (rotor-free) peak is
    # peak_load_torque, the rotor's N² J A ω² is peak_rotor_torque, peak_torque their sum here
    plain = ad.sizing_report(res, model).table.loc["spin"]
    assert "peak_load_torque" not in plain.index
    assert b.loc["spin", "peak_load_torque"] == pytest.approx(plain["peak_torque"], rel=1e-12)
    assert b.loc["spin", "peak_rotor_torque"] == pytest.approx(
        N * N * J * AMP * OMEGA**2, rel=1e-12
    )
    assert b.loc["spin", "peak_torque"] == pytest.approx(
        plain["peak_torque"] + b.loc["spin", "peak_rotor_torque"], rel=1e-12
    )
    assert list(a.columns) == list(b.columns)
    num = [c for c in a.columns if c not in ("ok", "unchecked")]
    np.testing.assert_allclose(a[num].to_numpy(float), b[num].to_numpy(float), rtol=1e-12)
    assert a["ok"].tolist() == b["ok"].tolist() == [True]
    # a motor given as a dict of datasheet keywords
    spec["motor"] = {"peak_torque": 2.0 * PEAK_T}
    row = ad.sizing_report(res, model, actuators={"spin": spec}).table.loc["spin"]
    assert row["peak_torque_margin"] == pytest.approx(2.0, rel=1e-12)
    with pytest.raises(ad.ModelError, match=r"'elbow' is not a joint coordinate"):
        ad.sizing_report(res, model, actuators={"elbow": spec})
    with pytest.raises(ad.ModelError, match=r"\[spin\] needs rotor_inertia"):
        ad.sizing_report(res, model, actuators={"spin": {"gear_ratio": 3.0}})
    with pytest.raises(ad.ModelError, match=r"unknown datasheet key\(s\) \['kt'\]"):
        ad.sizing_report(res, model, actuators={"spin": {**spec, "motor": {"kt": 1.0}}})


def test_a_failing_or_missing_check_is_not_ok(run, monkeypatch):
    model, _, geared = run
    monkeypatch.setattr(sizing_motor, "_mass_matrix", lambda md, q: _core.mass_matrix(md._model, q))
    tight = WithActuators(model, [stand_in(full_motor(peak_torque=0.9 * PEAK_T))])
    row = ad.sizing_report(geared, tight).table.loc["spin"]
    assert row["peak_torque_margin"] == pytest.approx(0.9, rel=1e-12) and not row["ok"]
    assert row["unchecked"] == ""
    missing = WithActuators(model, [stand_in(full_motor(continuous_torque=None))])
    row = ad.sizing_report(geared, missing).table.loc["spin"]
    assert np.isnan(row["continuous_torque_margin"]) and not row["ok"]
    assert row["unchecked"] == "continuous_torque"
    # no voltage data and no peak torque: the envelope cannot be drawn
    bare = full_motor(resistance=None, peak_torque=None)
    row = ad.sizing_report(geared, WithActuators(model, [stand_in(bare)])).table.loc["spin"]
    assert row["unchecked"] == "peak_torque,envelope" and not row["ok"]
    assert np.isnan(row["temperature_rise_steady"])  # no resistance: no copper loss
    nomotor = WithActuators(model, [stand_in(None)])
    row = ad.sizing_report(geared, nomotor).table.loc["spin"]
    assert row["unchecked"] == "motor" and not row["ok"]


def test_thermal_model_closed_forms():
    """τ dΔT/dt = R_th P − ΔT from 0: a constant loss gives R_th P (1 − e^(−t/τ)); a ramp
    P = k t gives R_th k (t − τ (1 − e^(−t/τ))); both exact on any grid (P linear per step)."""
    t = np.concatenate([[0.0], np.cumsum(np.random.default_rng(2).uniform(0.01, 0.5, 200))])
    r_th, tau = 1.7, 12.0
    np.testing.assert_allclose(
        sizing.thermal_rise(t, np.full_like(t, 30.0), r_th, tau),
        r_th * 30.0 * (1 - np.exp(-t / tau)),
        rtol=1e-12,
        atol=1e-12,
    )
    np.testing.assert_allclose(
        sizing.thermal_rise(t, 3.0 * t, r_th, tau),
        r_th * 3.0 * (t - tau * (1 - np.exp(-t / tau))),
        rtol=1e-10,
        atol=1e-10,
    )


def test_save_draws_the_speed_torque_plane(run, tmp_path, monkeypatch):
    pytest.importorskip("matplotlib")
    model, _, geared = run
    monkeypatch.setattr(sizing_motor, "_mass_matrix", lambda md, q: _core.mass_matrix(md._model, q))
    report = ad.sizing_report(geared, WithActuators(model, [stand_in(full_motor())]), out=tmp_path)
    html = (tmp_path / "report.html").read_text("utf-8")
    for name in ("motor_0.png", "torque_0.png"):  # written, and embedded in the page
        png = (tmp_path / name).read_bytes()
        assert png[:8] == b"\x89PNG\r\n\x1a\n"
        assert f'src="data:image/png;base64,{base64.b64encode(png).decode()}"' in html
    fig = report.envelope_figure("spin")
    ax = fig.axes[0]
    x, y = ax.lines[0].get_data()
    np.testing.assert_allclose(x, report.motors["spin"].speed)
    np.testing.assert_allclose(y, report.motors["spin"].torque)


def test_gear_ratio_sweep_pure_inertia_optimum(run):
    """Pure inertia, η = 1: T(N) = (J N + I / N) q̈, so RMS T = (J N + I/N) rms(q̈) is least at
    N* = √(I / J) with 2 √(I J) rms(q̈); with a continuous torque C (the only binding check)
    the passing ratios are the roots' interval of J N² − (C / rms q̈) N + I ≤ 0."""
    model, res, _ = run
    n_star = np.sqrt(I_Z / J)
    rms_qdd = AMP * OMEGA**2 / np.sqrt(2.0)
    c = 1.3 * 2.0 * np.sqrt(I_Z * J) * rms_qdd
    m = motor(
        continuous_torque=c, peak_torque=1e3, max_speed=1e6, no_load_speed=1e6, torque_constant=0.1
    )
    disc = np.sqrt((c / rms_qdd) ** 2 - 4.0 * J * I_Z)
    lo, hi = (c / rms_qdd - disc) / (2 * J), (c / rms_qdd + disc) / (2 * J)
    # steps of 1 over [10, 100], and of 0.01 (the 0.01 lattice) within 0.5 of N*, lo and hi: the
    # answers are resolved as by a 0.01 step everywhere (9001 ratios, 26 s of the suite), and a
    # sweep that found them elsewhere would land on the coarse steps and fail
    fine = [
        np.round(np.arange(np.floor(x) - 1.0, np.ceil(x) + 1.0, 0.01), 2) for x in (n_star, lo, hi)
    ]
    ratios = np.unique(np.concatenate([np.linspace(10.0, 100.0, 91), *fine]))
    sweep = ad.gear_ratio_sweep(res, model, ratios, {"spin": {"rotor_inertia": J, "motor": m}})
    s = sweep.summary.loc["spin"]
    assert abs(s["best_ratio"] - n_star) <= 0.005 + 1e-12
    best = (J * s["best_ratio"] + I_Z / s["best_ratio"]) * rms_qdd
    assert s["best_rms_torque"] == pytest.approx(best, rel=1e-12)
    assert s["best_rms_torque"] >= 2.0 * np.sqrt(I_Z * J) * rms_qdd * (1 - 1e-12)
    assert lo - 0.01 < s["ok_ratio_min"] - 0.0 <= lo + 0.01
    assert hi - 0.01 <= s["ok_ratio_max"] < hi + 0.01
    assert bool(s["ok_contiguous"]) and bool(s["best_ok"])
    with pytest.raises(ad.ModelError, match=r"\[spin\] unknown key\(s\) \['inertia'\]"):
        ad.gear_ratio_sweep(res, model, ratios, {"spin": {"inertia": J}})
    with pytest.raises(ad.ModelError, match="'spin' needs a rotor_inertia"):
        ad.gear_ratio_sweep(res, model, ratios, {"spin": {"efficiency": 0.9}})
    grid = sweep.table.loc["spin"]
    n = grid.index.to_numpy()
    np.testing.assert_allclose(grid["motor_rms_torque"], (J * n + I_Z / n) * rms_qdd, rtol=1e-12)
    np.testing.assert_allclose(grid["inertia_ratio"], I_Z / (n * n * J), rtol=1e-12)


def test_gear_ratio_sweep_strips_the_models_own_rotor(run, monkeypatch):
    """Sweeping a model that already has an actuator (N = 25): its rotor term is removed
    first, so the sweep at any ratio equals the sweep of the rotor-free run."""
    model, res, geared = run
    m = full_motor()
    proxy = WithActuators(model, [stand_in(m)])
    monkeypatch.setattr(
        sizing_motor, "_mass_matrix", lambda md, q: _core.mass_matrix(md._model, q) + N * N * J
    )
    ratios = [5.0, 25.0, 60.0]
    a = ad.gear_ratio_sweep(geared, proxy, ratios).table
    monkeypatch.setattr(sizing_motor, "_mass_matrix", lambda md, q: _core.mass_matrix(md, q))
    b = ad.gear_ratio_sweep(res, model, ratios, {"spin": stand_in(m)}).table
    cols = ["motor_rms_torque", "motor_peak_torque", "peak_torque", "inertia_ratio"]
    np.testing.assert_allclose(a[cols].to_numpy(), b[cols].to_numpy(), rtol=1e-12)


def test_gear_ratio_sweep_equals_rebuilding_the_model():
    """The closed-form re-evaluation at ratio N equals a model rebuilt with add_actuator(N)."""
    model = rotor_model()
    res = ad.simulate(model, 2.0, output_dt=0.01)
    spec = {"rotor_inertia": J, "efficiency": 0.85, "friction_viscous": 1e-4}
    sweep = ad.gear_ratio_sweep(res, model, [10.0, 40.0], {"spin": spec}).table
    for n in (10.0, 40.0):
        b = ad.ModelBuilder(gravity=(0.0, 0.0, 0.0))
        b.add_body("rotor", 1.0, [0.5, 0.5, I_Z], position=(0, 0, 0))
        b.add_revolute("spin", "ground", "rotor", point=(0, 0, 0), axis=(0, 0, 1))
        b.add_drive("spin", ad.profiles.sine(AMP, FREQ))
        b.add_actuator("spin", n, J, efficiency=0.85, friction_viscous=1e-4)
        geared = b.finalize()
        sim = ad.simulate(geared, 2.0, output_dt=0.01)
        row = ad.sizing_report(sim, geared).table
        # the driven inverse dynamics carries the same motor side
        idr = ad.driven_inverse_dynamics(geared, sim.t)
        np.testing.assert_allclose(
            idr.actuators["spin"].torque,
            ad.actuators.motor_side_of_result(geared, sim)["spin"].torque,
            rtol=1e-9,
            atol=1e-12,
        )
        for col in ("motor_rms_torque", "motor_peak_torque", "peak_torque"):
            assert row.loc["spin", col] == pytest.approx(sweep.loc[("spin", n), col], rel=1e-9)


def test_ur5_trajectory_peak_and_rms_equal_pinocchio_rnea():
    """The report's joint-side peak and RMS torque of a UR5 quintic move from
    armdyn.trajectory_run equal an independent computation: Pinocchio's rnea (plus the URDF's
    joint friction, which Pinocchio leaves out) on the same samples, peak by max |τ| and RMS by
    numpy's trapezoid rule."""
    pytest.importorskip("pinocchio")
    from benchmarks import common
    from benchmarks.peers.pinocchio import PinPair

    pair = PinPair(common.robot_urdf("ur5"))
    model = pair.am
    t = np.linspace(0.0, 2.0, 401)
    s = t / t[-1]
    q0 = np.array([0.0, -1.2, 1.0, -0.5, 0.3, 0.0])
    q1 = np.array([1.5, -0.4, 2.0, -1.5, 1.2, 0.8])
    shape = 10 * s**3 - 15 * s**4 + 6 * s**5
    dshape = (30 * s**2 - 60 * s**3 + 30 * s**4) / t[-1]
    ddshape = (60 * s - 180 * s**2 + 120 * s**3) / t[-1] ** 2
    q = q0 + np.outer(shape, q1 - q0)
    qd, qdd = np.outer(dshape, q1 - q0), np.outer(ddshape, q1 - q0)
    tab = ad.sizing_report(ad.trajectory_run(model, t, q, qd, qdd), model).table
    p = pair.perm
    ref = np.array([pair.to_armdyn(pair.rnea(q[i, p], qd[i, p], qdd[i, p])) for i in range(len(t))])
    names = list(model.dof_names)
    assert list(tab.index) == names
    peak = np.max(np.abs(ref), axis=0)
    rms = np.sqrt(np.trapezoid(ref**2, t, axis=0) / t[-1])
    np.testing.assert_allclose(tab["peak_torque"].to_numpy(), peak, rtol=1e-9)
    np.testing.assert_allclose(tab["rms_torque"].to_numpy(), rms, rtol=1e-9)
    np.testing.assert_allclose(tab["peak_speed"].to_numpy(), np.max(np.abs(qd), axis=0), rtol=0)
    assert np.all(peak > 1e-3)  # every joint carries a load


def test_motor_side_from_driven_inverse_dynamics(run):
    """armdyn.actuators.motor_side_of_result reads an InverseDynamicsResult (drive efforts):
    with the stand-in actuator (η = 1, no friction) and the drive effort as the joint torque,
    T = τ / N (J enters only through τ, which here is the rotor-free I q̈)."""
    from armdyn.actuators import motor_side_of_result

    model, _, _ = run
    t = np.linspace(0.0, 2.0, 81)
    idr = ad.driven_inverse_dynamics(model, t)
    assert idr.actuators == {}  # the model has no actuators
    sides = motor_side_of_result(WithActuators(model, [stand_in(None, j=0.0)]), idr)
    tau = -I_Z * AMP * OMEGA**2 * np.sin(OMEGA * t)
    np.testing.assert_allclose(sides["spin"].torque, tau / N, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(sides["spin"].speed, N * AMP * OMEGA * np.cos(OMEGA * t), atol=1e-9)
