"""`armdyn size` / `armdyn select`: the payload, duty-cycle and check-option arguments and the
select command's argument checking. Bad arguments exit with code 2 and one line naming the
option and the bad value (never a traceback), before any file is read where the argument alone
decides; the check options are generated from ``armdyn.sizing.options`` (one per
``OPTION_NAMES`` field, with its docstring's sentence and its default)."""

import os
import socket

import armdyn as ad
import numpy as np
import pandas as pd
import pytest
from armdyn.__main__ import main
from armdyn.sizing import cli
from armdyn.sizing.options import OPTION_NAMES, SizingOptions

from tests.validate.test_size_cli_bad_input import URDF, assert_one_line_exit_2, good_csv

I_P, MGL, G = 0.01 + 2.0 * 0.5**2, 2.0 * 9.81 * 0.5, 9.81


def run_cli(capsys, command, *args, urdf=URDF):
    code = main([command, str(urdf), *map(str, args)])
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.fixture
def traj(tmp_path):
    return good_csv(tmp_path / "t.csv")


# ------------------------------------------------------------------------------- parsing


def test_payload_strings_parse_to_mass_and_com():
    assert cli.parse_payload("3") == (3.0, (0.0, 0.0, 0.0))
    assert cli.parse_payload(" 2.5 , 0.1,-0.2 , 5e-2") == (2.5, (0.1, -0.2, 0.05))


@pytest.mark.parametrize(
    "text, fragment",
    [
        ("", "the mass (kg) must be a finite number"),
        ("abc", "the mass (kg) must be a finite number"),
        ("nan", "the mass (kg) must be a finite number"),
        ("inf", "the mass (kg) must be a finite number"),
        ("1e400", "the mass (kg) must be a finite number"),
        ("-1", "the mass must be > 0 kg, got -1"),
        ("0", "the mass must be > 0 kg, got 0"),
        ("1,2", "expected MASS or MASS,X,Y,Z"),
        ("1,2,3", "got 3 comma-separated value(s)"),
        ("1,0,0,0,0", "got 5 comma-separated value(s)"),
        ("3,x,0,0", "the centre of mass' x (m) ('x') must be a finite number"),
        ("3,0,nan,0", "the centre of mass' y (m) ('nan') must be a finite number"),
        ("3,0,0,-inf", "the centre of mass' z (m) ('-inf') must be a finite number"),
        ("3,,0,0", "the centre of mass' x (m)"),
    ],
)
def test_bad_payload_exits_2_naming_it(capsys, traj, text, fragment):
    code, out, err = run_cli(capsys, "size", "--trajectory", traj, f"--payload={text}")
    assert_one_line_exit_2(code, err, "armdyn size: --payload", repr(text), fragment)
    assert out == ""  # refused before anything is computed


@pytest.mark.parametrize("command", ["size", "select"])
def test_payload_strings_are_checked_before_any_file(capsys, tmp_path, command):
    """A bad payload is reported even when the files are missing: the argument is checked
    first (the message names the argument, not a file)."""
    args = ["--trajectory", tmp_path / "none.csv", "--payload", "-2"]
    if command == "select":
        args += ["--catalog", tmp_path / "no_catalog"]
    code, _, err = run_cli(capsys, command, *args, urdf=tmp_path / "none.urdf")
    assert_one_line_exit_2(code, err, f"armdyn {command}: --payload '-2'")


def test_unknown_payload_frame_names_it_and_the_frames(capsys, traj):
    code, _, err = run_cli(
        capsys, "size", "--trajectory", traj, "--payload", "1", "--payload-frame", "tool0"
    )
    assert_one_line_exit_2(code, err, "--payload-frame 'tool0'", "no such frame", "['base', 'arm']")


def test_payload_frame_without_payload_is_refused(capsys, traj):
    code, _, err = run_cli(capsys, "size", "--trajectory", traj, "--payload-frame", "arm")
    assert_one_line_exit_2(code, err, "--payload-frame is given without --payload")


def test_default_payload_frame_is_the_last_frame():
    model = ad.load_urdf(URDF)
    assert list(model.frame_names) == ["base", "arm"]
    assert cli.payload_frame(model, None) == "arm"
    assert cli.payload_frame(model, "base") == "base"


def test_payload_adds_its_closed_form_torque(tmp_path, capsys):
    """A point mass m_p at (0, 0, -0.8) in the axes of the pendulum's link 'arm' (its origin on
    the pivot axis): tau = (I_p + m_p 0.8^2) qdd + (m g l + m_p g 0.8) sin q."""
    t = np.linspace(0.0, 2.0, 801)
    w = np.pi
    q, qd, qdd = 0.5 * np.sin(w * t), 0.5 * w * np.cos(w * t), -0.5 * w * w * np.sin(w * t)
    frame = {"t": t, "pivot": q, "pivot.qd": qd, "pivot.qdd": qdd}
    pd.DataFrame(frame).to_csv(tmp_path / "p.csv", index=False, float_format="%.17g")
    code, _, err = run_cli(
        capsys,
        "size",
        "--trajectory",
        tmp_path / "p.csv",
        "--payload",
        "1.5,0,0,-0.8",
        "--out",
        tmp_path / "rep",
    )
    assert code in (0, 1), err
    tab = pd.read_csv(tmp_path / "rep" / "table.csv", index_col="joint")
    tau = (I_P + 1.5 * 0.8**2) * qdd + (MGL + 1.5 * G * 0.8) * np.sin(q)
    assert tab.loc["pivot", "peak_torque"] == pytest.approx(np.max(np.abs(tau)), rel=1e-12)


@pytest.mark.parametrize(
    "args, fragment",
    [
        (["--cycle", "0"], "--cycle '0': expected a positive whole number of repeats or 'forever'"),
        (["--cycle", "-3"], "--cycle '-3'"),
        (["--cycle", "2.5"], "--cycle '2.5'"),
        (["--cycle", "never"], "--cycle 'never'"),
        (["--cycle", ""], "--cycle ''"),
        (["--dwell", "-1"], "--dwell '-1': the duration must be >= 0 s"),
        (["--dwell", "nan"], "--dwell 'nan': the duration (s) must be a finite number"),
        (["--dwell", "inf"], "--dwell 'inf'"),
        (["--dwell", "1s"], "--dwell '1s'"),
    ],
)
def test_bad_cycle_or_dwell_exits_2_naming_it(capsys, traj, args, fragment):
    code, _, err = run_cli(capsys, "size", "--trajectory", traj, *args)
    assert_one_line_exit_2(code, err, fragment)


def test_cycle_strings():
    assert cli.parse_repeat("forever") is None and cli.parse_repeat("FOREVER") is None
    assert cli.parse_repeat("12") == 12
    assert cli.parse_seconds("0") == 0.0 and cli.parse_seconds("2.5") == 2.5
    # a dwell alone repeats forever; nothing given: a single pass (_UNSET)
    assert cli._cycle_strings(None, "1") == (None, 1.0)
    assert cli._cycle_strings("3", None) == (3, None)
    assert cli._cycle_strings(None, None) == (cli._UNSET, None)


# --------------------------------------------------------------------------- the options


@pytest.mark.parametrize("command", ["size", "select"])
def test_every_sizing_option_is_an_argument_with_its_default(capsys, command):
    with pytest.raises(SystemExit):
        main([command, "--help"])
    text = " ".join(capsys.readouterr().out.split())
    docs = cli.option_docs()
    assert set(docs) == set(OPTION_NAMES)
    for name in OPTION_NAMES:
        flag = f"--{name.replace('_', '-')}"
        assert flag in text, flag
        assert f"Default {getattr(SizingOptions(), name):g}." in text
        assert " ".join(docs[name].split()[:4]) in text
    assert "--ambient X" in text and "--life X" in text


def test_option_arguments_reach_the_options(tmp_path):
    import argparse

    parser = argparse.ArgumentParser()
    cli.add_option_arguments(parser)
    args = parser.parse_args(["--ambient", "25", "--life", "30000", "--emergency-stops", "10"])
    strings = cli.option_strings(args)
    assert strings == {
        "ambient_temperature": "25",
        "required_life": "30000",
        "emergency_stops": "10",
    }
    values = cli.sizing_options_from_strings(strings)
    assert values == {
        "ambient_temperature": 25.0,
        "required_life": 30000.0,
        "emergency_stops": 10.0,
    }


@pytest.mark.parametrize(
    "args, fragment",
    [
        (["--ambient", "nan"], "--ambient-temperature 'nan': the value must be a finite number"),
        (["--ambient", "-300"], "--ambient-temperature: SizingOptions: ambient_temperature"),
        (["--life", "-5"], "--required-life: SizingOptions: required_life"),
        (["--required-life", "0"], "--required-life: SizingOptions: required_life"),
        (["--emergency-stops", "-1"], "--emergency-stops: SizingOptions: emergency_stops"),
        (["--brake-safety-factor", "inf"], "--brake-safety-factor 'inf'"),
        (["--bearing-load-factor", "x"], "--bearing-load-factor 'x'"),
    ],
)
def test_bad_option_values_exit_2_naming_the_option(capsys, traj, args, fragment):
    code, _, err = run_cli(capsys, "size", "--trajectory", traj, *args)
    assert_one_line_exit_2(code, err, fragment)


def test_size_refuses_what_it_does_not_check(capsys, traj):
    """Never ignored: the options of checks armdyn size does not make (gearbox life, emergency
    stops, bearing, brake) are refused, and the thermal ones need a duty cycle."""
    code, _, err = run_cli(capsys, "size", "--trajectory", traj, "--cycle", "3", "--life", "9")
    assert_one_line_exit_2(code, err, "--required-life: armdyn size does not make the checks")
    code, _, err = run_cli(capsys, "size", "--trajectory", traj, "--ambient", "25")
    assert_one_line_exit_2(code, err, "--ambient-temperature: the winding temperature is checked")


def test_dwell_counts_the_holding_torque(tmp_path, capsys):
    """The pendulum swung from 0 to A = 0.6 rad in 1 s (ending at rest), then held 2 s: the
    report's RMS torque is sqrt((int_0^1 tau^2 dt + 2 (m g l sin A)^2) / 3) with tau = I_p qdd
    + m g l sin q (the trapezoid rule over the motion's samples), its peak the larger of the
    motion's and the holding torque."""
    a, t = 0.6, np.linspace(0.0, 1.0, 401)
    q = a * (1 - np.cos(np.pi * t)) / 2
    qd, qdd = a * np.pi / 2 * np.sin(np.pi * t), a * np.pi**2 / 2 * np.cos(np.pi * t)
    qd[-1] = 0.0  # at rest (sin(pi) is 1.2e-16)
    frame = {"t": t, "pivot": q, "pivot.qd": qd, "pivot.qdd": qdd}
    pd.DataFrame(frame).to_csv(tmp_path / "m.csv", index=False, float_format="%.17g")
    out = tmp_path / "rep"
    code, _, err = run_cli(
        capsys, "size", "--trajectory", tmp_path / "m.csv", "--dwell", "2", "--out", out
    )
    assert code == 0, err
    tab = pd.read_csv(out / "table.csv", index_col="joint")
    tau = I_P * qdd + MGL * np.sin(q)
    hold = MGL * np.sin(a)
    rms = np.sqrt((np.trapezoid(tau**2, t) + 2.0 * hold**2) / 3.0)
    assert tab.loc["pivot", "rms_torque"] == pytest.approx(rms, rel=1e-12)
    assert tab.loc["pivot", "peak_torque"] == pytest.approx(
        max(np.max(np.abs(tau)), hold), rel=1e-12
    )
    # without the dwell the RMS is the motion's alone (the dwell is what changed it)
    assert tab.loc["pivot", "rms_torque"] != pytest.approx(
        np.sqrt(np.trapezoid(tau**2, t)), rel=1e-3
    )


# ---------------------------------------------------------------------------- armdyn select


def select(capsys, traj, *args, catalog=None, urdf=URDF):
    extra = [] if catalog is None else ["--catalog", catalog]
    return run_cli(capsys, "select", "--trajectory", traj, *extra, *args, urdf=urdf)


def test_select_needs_a_catalog(capsys, traj):
    with pytest.raises(SystemExit) as stop:
        select(capsys, traj)
    assert stop.value.code == 2
    assert "--catalog" in capsys.readouterr().err


def test_select_unknown_objective(capsys, traj, tmp_path):
    code, _, err = select(capsys, traj, "--objective", "speed", catalog=tmp_path)
    assert_one_line_exit_2(
        code, err, "--objective 'speed'", "['mass', 'cost', 'bus_power', 'margin']"
    )


def test_select_missing_catalog(capsys, traj, tmp_path):
    code, _, err = select(capsys, traj, catalog=tmp_path / "nowhere")
    assert_one_line_exit_2(code, err, "armdyn select:", "nowhere")


def test_select_catalog_special_files(capsys, traj, tmp_path):
    code, _, err = select(capsys, traj, catalog="/dev/zero")
    assert_one_line_exit_2(code, err, "--catalog '/dev/zero' is a character device")
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    code, _, err = select(capsys, traj, catalog=fifo)
    assert_one_line_exit_2(code, err, "is a FIFO (named pipe), not a folder or a regular file")
    sock_path = tmp_path / "s.sock"
    with socket.socket(socket.AF_UNIX) as s:
        s.bind(str(sock_path))
        code, _, err = select(capsys, traj, catalog=sock_path)
    assert_one_line_exit_2(code, err, "is a socket")


def test_select_missing_or_special_robot_and_trajectory(capsys, traj, tmp_path):
    code, _, err = select(capsys, traj, catalog=tmp_path, urdf=tmp_path / "none.urdf")
    assert code == 2 and "none.urdf" in err and "Traceback" not in err
    code, _, err = select(capsys, tmp_path / "none.csv", catalog=tmp_path)
    assert_one_line_exit_2(code, err, "none.csv")
    code, _, err = select(capsys, "/dev/zero", catalog=tmp_path)
    assert_one_line_exit_2(code, err, "/dev/zero", "not a regular file")
    code, _, err = select(capsys, tmp_path, catalog=tmp_path)
    assert_one_line_exit_2(code, err, "is a directory")


def test_select_bad_payload_cycle_and_options(capsys, traj, tmp_path):
    for args, fragment in [
        (["--payload", "1,2"], "--payload '1,2'"),
        (["--cycle", "0"], "--cycle '0'"),
        (["--dwell", "-2"], "--dwell '-2'"),
        (["--life", "nan"], "--required-life 'nan'"),
        (["--payload", "1", "--payload-frame", "tool9"], "--payload-frame 'tool9'"),
    ]:
        code, _, err = select(capsys, traj, *args, catalog=tmp_path)
        assert_one_line_exit_2(code, err, "armdyn select: " + fragment)


def test_select_wiring_with_stand_ins(capsys, traj, tmp_path, monkeypatch):
    """The command's calls, with stand-ins of parts 3, 4 and 6 (their contracts in the issue's
    spec): the catalog paths, the cycle's dwell and repeat, the objective and the options reach
    them; the table is printed, the page written, the exit code is 1 when a joint fails."""
    from test_report_page import FakeSelection

    calls = {}

    def duty_cycle(model, motion, dwell=0.0, repeat=None):
        calls["cycle"] = (list(model.dof_names), len(motion.t), dwell, repeat)
        return "the cycle"

    def load_catalog(*paths):
        calls["catalog"] = paths
        return "the catalog"

    def select_drivetrain(model, cycle, catalog, objective="mass", **overrides):
        calls["select"] = (cycle, catalog, objective, overrides)
        sel = FakeSelection()
        sel.cycle = None  # the stand-in cycle has no joint loads to draw
        return sel

    import armdyn.sizing.catalog
    import armdyn.sizing.cycle
    import armdyn.sizing.select

    for module, fn in [
        (armdyn.sizing.cycle, duty_cycle),
        (armdyn.sizing.catalog, load_catalog),
        (armdyn.sizing.select, select_drivetrain),
    ]:
        monkeypatch.setattr(module, fn.__name__, fn)
    (tmp_path / "more.csv").write_text("name\n")
    args = ["--catalog", tmp_path / "more.csv", "--objective", "cost", "--cycle", "50"]
    args += ["--dwell", "0.5", "--life", "3e4", "--ambient", "25", "--out", tmp_path / "out"]
    code, out, err = select(capsys, traj, *args, catalog=tmp_path)
    assert code == 1, err
    assert calls["cycle"] == (["pivot"], 41, 0.5, 50)
    assert calls["catalog"] == (tmp_path, tmp_path / "more.csv")
    assert calls["select"] == (
        "the cycle",
        "the catalog",
        "cost",
        {"required_life": 30000.0, "ambient_temperature": 25.0},
    )
    assert "G100" in out and "not ok: j2" in out
    assert (tmp_path / "out" / "report.html").is_file()
    # forever: no --cycle
    code, out, err = select(capsys, traj, "--dwell", "1", catalog=tmp_path)
    assert calls["cycle"][2:] == (1.0, None)


def test_size_checks_the_winding_temperature_of_the_repeated_cycle(tmp_path, capsys):
    """A motor with a one-node thermal model whose time constant (1e6 s) is far longer than the
    3 s period: at the periodic steady state (--cycle forever) the winding's temperature is the
    ambient one (--ambient 25) plus R_th times the period's mean copper loss R i², i = T / k_t
    (R constant: --copper-temperature-coefficient 0), within the ripple (period / tau_th);
    its margin compares the rises; a smaller allowed temperature fails the joint."""
    a, t = 0.6, np.linspace(0.0, 1.0, 401)
    q = a * (1 - np.cos(np.pi * t)) / 2
    qd, qdd = a * np.pi / 2 * np.sin(np.pi * t), a * np.pi**2 / 2 * np.cos(np.pi * t)
    qd[-1] = 0.0
    frame = {"t": t, "pivot": q, "pivot.qd": qd, "pivot.qdd": qdd}
    pd.DataFrame(frame).to_csv(tmp_path / "m.csv", index=False, float_format="%.17g")
    k_t, r, r_th = 0.05, 0.8, 3.0

    def size_with(max_temp, out):
        (tmp_path / "a.toml").write_text(
            "[pivot]\ngear_ratio = 50.0\nrotor_inertia = 2e-5\nefficiency = 0.9\n"
            f"[pivot.motor]\ntorque_constant = {k_t}\nresistance = {r}\n"
            f"thermal_resistance = {r_th}\nthermal_time_constant = 1e6\n"
            f"max_winding_temperature = {max_temp}\nvoltage = 48.0\nno_load_speed = 900.0\n"
            "continuous_torque = 10.0\npeak_torque = 20.0\nmax_speed = 900.0\n"
        )
        args = ["--trajectory", tmp_path / "m.csv", "--actuators", tmp_path / "a.toml"]
        args += ["--dwell", "2", "--cycle", "forever", "--ambient", "25"]
        args += ["--copper-temperature-coefficient", "0", "--out", tmp_path / out]
        code, _, err = run_cli(capsys, "size", *args)
        assert code in (0, 1), err
        return code, pd.read_csv(tmp_path / out / "table.csv", index_col="joint").loc["pivot"]

    code, row = size_with(120.0, "hot")
    # the report's motor torque over the period (the dwell in it): its RMS, motor_rms_torque
    mean_sq = row["motor_rms_torque"] ** 2
    expected = 25.0 + r_th * r * mean_sq / k_t**2
    assert row["winding_temperature_peak"] == pytest.approx(expected, rel=1e-5)
    rise = expected - 25.0
    assert row["winding_temperature_margin"] == pytest.approx((120.0 - 25.0) / rise, rel=1e-5)
    assert code == 0 and bool(row["ok"])
    code, row = size_with(25.0 + 0.5 * rise, "cold")  # allows half the rise: fails
    assert row["winding_temperature_margin"] == pytest.approx(0.5, rel=1e-5)
    assert code == 1 and not bool(row["ok"])
    html = (tmp_path / "cold" / "report.html").read_text("utf-8")
    assert 'data-status="fail"' in html and "winding_temperature" in html
    assert "winding and housing temperature over one period of the repeated cycle" in html
    # the drawn temperatures: the series whose peak the check is of
    model = ad.load_urdf(URDF)
    spec = cli.read_actuators(tmp_path / "a.toml")
    duty = ad.duty_cycle(model, cli.planned_motion(model, tmp_path / "m.csv"), dwell=2.0)
    report = ad.sizing_report(cli.cycle_motion(duty, model), model, actuators=spec)
    cli.winding_temperature_check(report, duty, spec, {"ambient_temperature": 25.0})
    t_s, winding, housing = report.thermal["pivot"]
    assert np.max(winding) == report.table.loc["pivot", "winding_temperature_peak"]
    assert t_s[-1] - t_s[0] == pytest.approx(3.0) and np.isnan(housing).all()  # one node


def test_select_end_to_end_equals_the_python_api(tmp_path, capsys):
    """`armdyn select` on the UR5 (example-robot-data) with the example catalog, a 3 kg payload
    at the last frame (tool0) and a 1 s dwell: the same choice as the Python calls it stands
    for, the page's verdict rows the selection's."""
    from armdyn.sizing import EXAMPLE_CATALOG

    from benchmarks import common

    urdf = common.robot_urdf("ur5")
    assert urdf is not None, "example-robot-data is part of the test extra"
    model = ad.load_urdf(urdf)
    t = np.linspace(0.0, 2.0, 201)
    w = np.pi / 2
    s, sd, sdd = 0.5 - 0.5 * np.cos(w * t), 0.5 * w * np.sin(w * t), 0.5 * w * w * np.cos(w * t)
    sd[-1] = 0.0
    q0 = np.array([0.0, -1.2, 1.0, -0.5, 0.4, 0.0])
    dq = np.array([1.2, 0.6, -0.6, -0.7, 0.6, 0.8])
    cols = {"t": t}
    for k, name in enumerate(model.coord_names):
        cols[name], cols[f"{name}.qd"], cols[f"{name}.qdd"] = (
            q0[k] + s * dq[k],
            sd * dq[k],
            sdd * dq[k],
        )
    pd.DataFrame(cols).to_csv(tmp_path / "ur5.csv", index=False, float_format="%.17g")
    args = ["--trajectory", tmp_path / "ur5.csv", "--catalog", EXAMPLE_CATALOG]
    args += ["--payload", "3", "--dwell", "1", "--out", tmp_path / "out"]
    code, out, err = run_cli(capsys, "select", *args, urdf=urdf)
    assert code in (0, 1), err
    assert "shoulder_lift_joint" in out and "report written to" in out
    loaded = model.with_payload("tool0", 3.0)
    run = cli.planned_motion(loaded, tmp_path / "ur5.csv")
    sel = ad.select_drivetrain(
        loaded, ad.duty_cycle(loaded, run, dwell=1.0), ad.load_catalog(EXAMPLE_CATALOG)
    )
    got = pd.read_csv(tmp_path / "out" / "selection.csv", index_col="joint")
    for col in ("motor", "gearbox", "ok", "binding_check"):
        assert list(got[col]) == list(sel.table[col]), col
    np.testing.assert_allclose(got["margin"], sel.table["margin"], rtol=1e-12)
    html = (tmp_path / "out" / "report.html").read_text("utf-8")
    for joint, row in sel.table.iterrows():
        status = "pass" if row["ok"] and row["margin"] >= 1 else "fail"
        assert f'data-joint="{joint}" data-status="{status}"' in html
    assert code == (0 if sel.table["ok"].all() else 1)
    # the chosen motors drawn over the cycle: the series the selection's values are of
    from armdyn.sizing.writer import selection_series

    for joint, (_, ratio, series) in selection_series(
        sel, ad.load_catalog(EXAMPLE_CATALOG)
    ).items():
        row = sel.table.loc[joint]
        assert ratio == row["gear_ratio"]
        peak = np.max(series["winding_temperature"])
        assert peak == pytest.approx(row["winding_temperature_peak"], rel=1e-9), joint
        assert np.max(np.abs(series["torque"])) == pytest.approx(row["motor_peak_torque"], rel=1e-9)
    assert "Thermal histories" in html and html.count("speed-torque plane of the motor of") >= 6


@pytest.mark.parametrize(
    "text, fragment",
    [
        ("20:200", "expected MIN:MAX:N"),
        ("0:200:5", "need 0 < MIN <= MAX"),
        ("300:200:5", "need 0 < MIN <= MAX"),
        ("nan:200:5", "MIN ('nan') must be a finite number"),
        ("20:inf:5", "MAX ('inf') must be a finite number"),
        ("20:200:0", "N must be a whole number from 1 to 10000"),
        ("20:200:1e9", "N must be a whole number"),
        ("20:200:100000", "N must be a whole number from 1 to 10000"),
    ],
)
def test_bad_sweep_exits_2(capsys, traj, tmp_path, text, fragment):
    args = ["--trajectory", traj, "--actuators", tmp_path / "a.toml", "--out", tmp_path]
    code, _, err = run_cli(capsys, "size", *args, f"--sweep={text}")
    assert_one_line_exit_2(code, err, f"--sweep {text!r}", fragment)


def test_sweep_needs_actuators_and_out(capsys, traj, tmp_path):
    code, _, err = run_cli(capsys, "size", "--trajectory", traj, "--sweep", "10:100:5")
    assert_one_line_exit_2(code, err, "--sweep needs --actuators")
    (tmp_path / "a.toml").write_text("[pivot]\ngear_ratio = 50.0\nrotor_inertia = 2e-5\n")
    args = ["--trajectory", traj, "--actuators", tmp_path / "a.toml", "--sweep", "10:100:5"]
    code, _, err = run_cli(capsys, "size", *args)
    assert_one_line_exit_2(code, err, "--sweep needs --out")


def test_sweep_in_the_report_is_gear_ratio_sweep(capsys, traj, tmp_path):
    toml = "[pivot]\ngear_ratio = 50.0\nrotor_inertia = 2e-5\n[pivot.motor]\n"
    toml += "torque_constant = 0.05\ncontinuous_torque = 0.2\npeak_torque = 1.0\n"
    (tmp_path / "a.toml").write_text(toml)
    args = ["--trajectory", traj, "--actuators", tmp_path / "a.toml", "--out", tmp_path / "o"]
    code, _, err = run_cli(capsys, "size", *args, "--sweep", "10:300:13")
    assert code in (0, 1), err
    html = (tmp_path / "o" / "report.html").read_text("utf-8")
    model = ad.load_urdf(URDF)
    run = cli.planned_motion(model, traj)
    sweep = ad.gear_ratio_sweep(
        run, model, np.geomspace(10, 300, 13), cli.read_actuators(tmp_path / "a.toml")
    )
    best = sweep.summary.loc["pivot", "best_ratio"]
    assert "RMS motor torque against the gear ratio per joint" in html
    assert f"<td>{best:.4g}</td>" in html  # the summary table's best ratio
    assert (tmp_path / "o" / "sweep.png").read_bytes()[:4] == b"\x89PNG"
