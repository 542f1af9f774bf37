"""Limit violations and the joint-side sizing report against closed forms.

Reference: a rotor of inertia I about a fixed vertical axis (no gravity, so no load but its
inertia), driven by q = A sin(ω t), ω = 2π f. Then
    q̇ = A ω cos(ω t),  τ = I q̈ = −I A ω² sin(ω t),  P = τ q̇ = −(I A² ω³ / 2) sin(2 ω t).
With f = 0.5 Hz and an output step h = 1e-3 s every extremum of q̇, τ and P (t = k/4 s) is an
output sample, so the sampled peaks are the exact peaks. Over whole periods on a uniform grid
the trapezoid rule integrates sin² exactly (a trigonometric polynomial of degree < the number
of samples per period): the RMS values are then exact up to the samples' own error. Elsewhere
the trapezoid rule's error bound (b − a) h² / 12 · max|f''| gives the tolerance.
"""

import base64

import armdyn as ad
import numpy as np
import pandas as pd
import pytest

I_Z, AMP, FREQ, H = 0.2, 1.0, 0.5, 1e-3
OMEGA = 2.0 * np.pi * FREQ
TAU0 = I_Z * AMP * OMEGA**2  # torque amplitude [N m]
SPEED0 = AMP * OMEGA  # speed amplitude [rad/s]
POWER0 = 0.5 * I_Z * AMP**2 * OMEGA**3  # power amplitude [W]
# the samples are solved from the constraints: their error is round-off (checked below)
SAMPLE_RTOL = 1e-12
# runs report every joint's applied torque (result.joint_torques, zero where nothing acts) once
# the actuator model is in; before, only the drives' efforts (no torque elsewhere: NaN)
HAS_JOINT_TORQUES = "joint_torques" in ad.SimulationResult.__dataclass_fields__
UNACTUATED = 0.0 if HAS_JOINT_TORQUES else np.nan


def unactuated(value) -> bool:
    return bool(np.isnan(value)) if np.isnan(UNACTUATED) else value == 0.0


def rotor(effort=0.0, velocity=0.0, passive=False):
    b = ad.ModelBuilder(gravity=(0.0, 0.0, 0.0))
    b.add_body("rotor", 1.0, [0.5, 0.5, I_Z], position=(0, 0, 0))
    b.add_revolute("spin", "ground", "rotor", point=(0, 0, 0), axis=(0, 0, 1))
    if effort or velocity:
        b.set_joint_limits("spin", -100.0, 100.0, effort=effort, velocity=velocity)
    b.add_drive("spin", ad.profiles.sine(AMP, FREQ))
    if passive:  # a second rotor on an undriven joint, at rest (no gravity, no load)
        b.add_body("idle", 1.0, [0.5, 0.5, I_Z], position=(1, 0, 0))
        b.add_revolute("idle_spin", "ground", "idle", point=(1, 0, 0), axis=(0, 0, 1))
    return b.finalize()


def run(model, t_end=4.0):
    return ad.simulate(model, t_end, output_dt=H)


@pytest.fixture(scope="module")
def two_periods():
    model = rotor()
    return model, run(model)


def test_samples_follow_the_closed_form(two_periods):
    _, res = two_periods
    t = res.t
    assert res.stats["integrator"] == "kinematic"
    assert np.abs(np.diff(t) - H).max() <= 1e-14 and t[-1] == pytest.approx(4.0, abs=1e-14)
    np.testing.assert_allclose(res.drive_forces[:, 0], -TAU0 * np.sin(OMEGA * t), atol=1e-13)
    np.testing.assert_allclose(res.qd[:, 0], SPEED0 * np.cos(OMEGA * t), atol=1e-13)


def test_peak_and_rms_over_whole_periods(two_periods):
    model, res = two_periods
    row = ad.sizing_report(res, model).table.loc["spin"]
    assert row["peak_torque"] == pytest.approx(TAU0, rel=SAMPLE_RTOL)
    assert row["peak_speed"] == pytest.approx(SPEED0, rel=SAMPLE_RTOL)
    assert row["rms_torque"] == pytest.approx(TAU0 / np.sqrt(2.0), rel=SAMPLE_RTOL)
    assert row["rms_speed"] == pytest.approx(SPEED0 / np.sqrt(2.0), rel=SAMPLE_RTOL)
    assert row["peak_power"] == pytest.approx(POWER0, rel=SAMPLE_RTOL)


def test_rms_over_a_partial_period_within_the_trapezoid_bound():
    """Over T = 1.3 s (not whole periods): (1/T)∫ a² sin²(ωt) dt = a² (1/2 − sin(2ωT)/(4ωT)),
    and the trapezoid rule's error on the mean square is at most h²/12 · max|(a² sin²)''| =
    h²/12 · 2 a² ω² (same for cos²). The bound is tight enough to see a wrong rule (a
    rectangle rule is off by ~a² h / (2T) = 1.5e-3 a², the bound is 1.6e-6 a²)."""
    model = rotor()
    res = run(model, t_end=1.3)
    span = res.t[-1] - res.t[0]
    assert span == pytest.approx(1.3, abs=1e-14)
    row = ad.sizing_report(res, model).table.loc["spin"]
    s = np.sin(2.0 * OMEGA * span) / (4.0 * OMEGA * span)
    bound = H**2 / 12.0 * 2.0 * OMEGA**2
    ms_tau = TAU0**2 * (0.5 - s)
    ms_speed = SPEED0**2 * (0.5 + s)
    assert abs(row["rms_torque"] ** 2 - ms_tau) <= TAU0**2 * (bound + 1e-12)
    assert abs(row["rms_speed"] ** 2 - ms_speed) <= SPEED0**2 * (bound + 1e-12)
    # and the peaks of the partial run: |sin| reaches 1 at t = 0.5 s, |cos| at 0 and 1 s
    assert row["peak_torque"] == pytest.approx(TAU0, rel=SAMPLE_RTOL)
    assert row["peak_speed"] == pytest.approx(SPEED0, rel=SAMPLE_RTOL)


def test_regenerated_energy_equals_the_positive_work(two_periods):
    """A pure inertia driven sinusoidally: the net work over whole periods is 0; the rotor
    speeds up and slows down 4 times in two periods, each swing storing and returning
    ½ I (A ω)², so the regenerated energy = the positive work = 2 I A² ω². The negative lobes
    of P end on output samples (t = k/2 s), so the trapezoid error is at most
    (T/2) h²/12 · max|P''| = (T/2) h²/12 · 4 ω² P0."""
    model, res = two_periods
    row = ad.sizing_report(res, model).table.loc["spin"]
    exact = 2.0 * I_Z * AMP**2 * OMEGA**2
    bound = 2.0 * H**2 / 12.0 * 4.0 * OMEGA**2 * POWER0
    assert abs(row["energy_regenerated"] - exact) <= bound + 1e-12 * exact
    assert row["energy_regenerated"] > 0.0
    # the same from the run's own kinetic energy: four full swings of ½ I q̇²
    swing = res.kinetic_energy.max() - res.kinetic_energy.min()
    assert swing == pytest.approx(0.5 * I_Z * SPEED0**2, rel=1e-12)
    assert abs(row["energy_regenerated"] - 4.0 * swing) <= bound + 1e-12 * exact


def test_margins_and_ok():
    model = rotor(effort=2.0 * TAU0, velocity=3.0 * SPEED0, passive=True)
    tab = ad.sizing_report(run(model), model).table
    assert list(tab.index) == ["spin", "idle_spin"] and tab.index.name == "joint"
    spin = tab.loc["spin"]
    assert spin["effort_limit"] == 2.0 * TAU0 and spin["velocity_limit"] == 3.0 * SPEED0
    assert spin["torque_margin"] == pytest.approx(2.0, rel=SAMPLE_RTOL)
    assert spin["speed_margin"] == pytest.approx(3.0, rel=SAMPLE_RTOL)
    assert bool(spin["ok"])
    # the undriven joint does not move; nothing acts on it: zero applied torque (joint_torques)
    # or, from the drives alone, no torque in the result (NaN)
    idle = tab.loc["idle_spin"]
    for col in ("peak_torque", "rms_torque", "peak_power", "energy_regenerated"):
        assert unactuated(idle[col]), (col, idle[col])
    np.testing.assert_equal(idle["torque_margin"], np.inf if HAS_JOINT_TORQUES else np.nan)
    assert idle["peak_speed"] == 0.0 and idle["rms_speed"] == 0.0
    assert idle["effort_limit"] == np.inf and idle["speed_margin"] == np.inf
    assert bool(idle["ok"])
    # limits below the peaks: margins < 1 and not ok
    tight = rotor(effort=0.5 * TAU0, velocity=0.8 * SPEED0)
    row = ad.sizing_report(run(tight), tight).table.loc["spin"]
    assert row["torque_margin"] == pytest.approx(0.5, rel=SAMPLE_RTOL)
    assert row["speed_margin"] == pytest.approx(0.8, rel=SAMPLE_RTOL)
    assert not bool(row["ok"])
    only_speed = rotor(effort=2.0 * TAU0, velocity=0.8 * SPEED0)
    assert not bool(ad.sizing_report(run(only_speed), only_speed).table.loc["spin", "ok"])


def test_velocity_and_effort_violation_spans():
    """|q̇| > 0.8 A ω where |cos ωt| > 0.8: around t = 0, 1, 2, 3, 4 s (half-width
    arccos(0.8)/ω); |τ| > τ0/2 where |sin ωt| > 1/2: t in (k + 1/6, k + 5/6) s. The spans are
    resolved at the samples: t_start lies within one step after the true crossing, t_end
    within one step before it; a span that starts with the run starts at t = 0."""
    model = rotor(effort=0.5 * TAU0, velocity=0.8 * SPEED0)
    res = run(model)
    table = res.limit_violations(model)
    assert list(table.columns) == [
        "joint",
        "kind",
        "t_start",
        "t_end",
        "worst",
        "limit",
        "samples",
    ]
    assert (table["joint"] == "spin").all()
    assert np.all(np.diff(table["t_start"]) > 0)

    vel = table[table["kind"] == "velocity"].reset_index(drop=True)
    half = np.arccos(0.8) / OMEGA
    centres = np.arange(5.0)
    starts = np.maximum(centres - half, 0.0)
    ends = np.minimum(centres + half, 4.0)
    assert len(vel) == 5
    eps = 1e-12  # grid round-off
    assert np.all(vel["t_start"] >= starts - eps) and np.all(vel["t_start"] <= starts + H + eps)
    assert np.all(vel["t_end"] <= ends + eps) and np.all(vel["t_end"] >= ends - H - eps)
    assert vel["t_start"].iloc[0] == 0.0 and vel["t_end"].iloc[-1] == pytest.approx(4.0, abs=eps)
    np.testing.assert_allclose(vel["worst"], SPEED0 * np.array([1, -1, 1, -1, 1]), rtol=1e-12)
    assert np.all(vel["limit"] == 0.8 * SPEED0)
    np.testing.assert_array_equal(
        vel["samples"], np.round((vel["t_end"] - vel["t_start"]) / H).astype(int) + 1
    )

    eff = table[table["kind"] == "effort"].reset_index(drop=True)
    assert len(eff) == 4
    starts = np.arange(4.0) + 1.0 / 6.0
    ends = np.arange(4.0) + 5.0 / 6.0
    assert np.all(eff["t_start"] >= starts - eps) and np.all(eff["t_start"] <= starts + H + eps)
    assert np.all(eff["t_end"] <= ends + eps) and np.all(eff["t_end"] >= ends - H - eps)
    # τ = −τ0 sin ωt: negative around t = 0.5 and 2.5 s
    np.testing.assert_allclose(eff["worst"], TAU0 * np.array([-1, 1, -1, 1]), rtol=1e-12)
    assert np.all(eff["limit"] == 0.5 * TAU0)

    # the module function is the method; the inverse dynamics on the same times agree
    pd.testing.assert_frame_equal(ad.limit_violations(model, res), table)
    idr = ad.driven_inverse_dynamics(model, res.t)
    from_id = idr.limit_violations(model)
    pd.testing.assert_frame_equal(from_id, table, check_exact=False, rtol=1e-12)


def test_no_violation_within_the_limits():
    model = rotor(effort=1.01 * TAU0, velocity=1.01 * SPEED0)
    table = run(model).limit_violations(model)
    assert table.empty and "worst" in table.columns


def test_coupled_follower_takes_its_own_limits():
    """q_f = 2 q_l with the drive on the leader: qd columns are (follower, leader)
    (``joint_dof_names``), the follower's velocity limit is its joint's (not one of
    ``coord_velocity_limit``'s entries), and the drive torque carries both inertias:
    τ = (I + 2² I) q̈_l."""
    b = ad.ModelBuilder(gravity=(0.0, 0.0, 0.0))
    b.add_body("f", 1.0, [0.5, 0.5, I_Z], position=(0, 0, 0))
    b.add_revolute("jf", "ground", "f", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_body("l", 1.0, [0.5, 0.5, I_Z], position=(1, 0, 0))
    b.add_revolute("jl", "ground", "l", point=(1, 0, 0), axis=(0, 0, 1))
    b.add_coupling("c", "jf", "jl", 2.0)
    b.set_joint_limits("jf", -100.0, 100.0, velocity=1.5 * SPEED0)
    b.add_drive("jl", ad.profiles.sine(AMP, FREQ))
    model = b.finalize()
    assert list(model.joint_dof_names) == ["jf", "jl"] and list(model.dof_names) == ["jl"]
    res = ad.simulate(model, 2.0, output_dt=H)
    tab = ad.sizing_report(res, model).table
    assert tab.loc["jf", "velocity_limit"] == 1.5 * SPEED0
    assert tab.loc["jf", "peak_speed"] == pytest.approx(2.0 * SPEED0, rel=SAMPLE_RTOL)
    assert tab.loc["jl", "peak_torque"] == pytest.approx(5.0 * TAU0, rel=1e-12)
    assert unactuated(tab.loc["jf", "peak_torque"])  # the drive acts on the leader
    viol = res.limit_violations(model)
    assert set(viol["joint"]) == {"jf"} and len(viol) == 3  # around t = 0, 1, 2 s


def test_save_writes_table_html_and_figures(tmp_path, two_periods):
    pytest.importorskip("matplotlib")
    model = rotor(velocity=3.0 * SPEED0, passive=True)
    report = ad.sizing_report(run(model, t_end=1.0), model)
    page = report.save(tmp_path / "out")
    assert page == tmp_path / "out" / "report.html"
    back = pd.read_csv(tmp_path / "out" / "table.csv", index_col="joint")
    pd.testing.assert_frame_equal(back, report.table, check_exact=False, rtol=1e-15)
    html = page.read_text("utf-8")
    assert "<table" in html and "peak_torque" in html
    # the page embeds the figure it also writes (one self-contained file)
    png = (tmp_path / "out" / "torque_0.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    assert f'src="data:image/png;base64,{base64.b64encode(png).decode()}"' in html
    # the undriven joint has no (or a zero) torque, so no figure
    assert not (tmp_path / "out" / "torque_1.png").exists()


def test_result_from_another_model_is_refused(two_periods):
    model, _ = two_periods
    other = rotor(passive=True)
    res = run(other, t_end=0.1)
    with pytest.raises(ad.ModelError, match=r"result\.qd has shape \(101, 2\).*1 joint rate"):
        ad.sizing_report(res, model)
    with pytest.raises(ad.ModelError, match=r"limit_violations: result\.qd has shape"):
        res.limit_violations(model)
    # the same columns but another drive count
    b = ad.ModelBuilder(gravity=(0.0, 0.0, 0.0))
    b.add_body("rotor", 1.0, [0.5, 0.5, I_Z], position=(0, 0, 0))
    b.add_revolute("spin", "ground", "rotor", point=(0, 0, 0), axis=(0, 0, 1))
    undriven = b.finalize()
    with pytest.raises(ad.ModelError, match=r"drive_forces has shape \(4001, 1\).*0 drives"):
        ad.sizing_report(two_periods[1], undriven)
    # one sample spans no time
    one = ad.driven_inverse_dynamics(model, [0.5])
    with pytest.raises(ad.ModelError, match="at least two samples"):
        ad.sizing_report(one, model)


def test_functions_of_a_result_take_its_model_by_default(two_periods):
    """sizing_report, limit_violations, gear_ratio_sweep and motor_side_of_result take the model
    the result holds (result.model): the same values as with the model passed (the older call
    form, still accepted); a result without a model and no model is a ModelError naming model."""
    from types import SimpleNamespace

    from armdyn.actuators import motor_side_of_result

    model, res = two_periods
    assert res.model is model
    pd = pytest.importorskip("pandas")
    pd.testing.assert_frame_equal(ad.sizing_report(res).table, ad.sizing_report(res, model).table)
    pd.testing.assert_frame_equal(ad.limit_violations(res), ad.limit_violations(model, res))
    spec = {"spin": {"rotor_inertia": 1e-4}}
    by_default = ad.gear_ratio_sweep(res, ratios=[10.0, 40.0], actuators=spec)
    positional = ad.gear_ratio_sweep(res, [10.0, 40.0], spec)
    old_form = ad.gear_ratio_sweep(res, model, [10.0, 40.0], spec)
    pd.testing.assert_frame_equal(by_default.table, old_form.table)
    pd.testing.assert_frame_equal(positional.table, old_form.table)
    # the other results hold their model too
    idr = ad.driven_inverse_dynamics(model, res.t[:50])
    assert idr.model is model
    pd.testing.assert_frame_equal(ad.sizing_report(idr).table, ad.sizing_report(idr, model).table)
    pd.testing.assert_frame_equal(idr.limit_violations(), idr.limit_violations(model))
    plan = ad.trajectory_run(model, res.t, res.q, res.qd, res.qdd)
    assert plan.model is model
    pd.testing.assert_frame_equal(ad.sizing_report(plan).table, ad.sizing_report(plan, model).table)
    assert motor_side_of_result(res) == {}  # no actuators in this model
    # a result with no model, and none passed
    bare = SimpleNamespace(t=res.t, q=res.q, qd=res.qd, qdd=res.qdd, drive_forces=res.drive_forces)
    for call in (
        lambda: ad.sizing_report(bare),
        lambda: ad.limit_violations(bare),
        lambda: ad.gear_ratio_sweep(bare, ratios=[10.0], actuators=spec),
        lambda: motor_side_of_result(bare),
    ):
        with pytest.raises(ad.ModelError, match=r"model is required: the result holds no model"):
            call()
    with pytest.raises(ad.ModelError, match="gear_ratio_sweep: ratios is required"):
        ad.gear_ratio_sweep(res)
