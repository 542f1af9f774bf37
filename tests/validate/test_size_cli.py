"""`armdyn size` end to end on a one-joint pendulum URDF (tests/data/urdf/sizing_pendulum.urdf):
the actuator torque of a motion is tau = I_p q̈ + m g l sin q with I_p = 0.01 + 2 · 0.5²,
m g l = 2 · 9.81 · 0.5, against a 30 N m effort and 4 rad/s velocity limit."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parents[2]
URDF = ROOT / "tests" / "data" / "urdf" / "sizing_pendulum.urdf"
I_P, MGL = 0.01 + 2.0 * 0.5**2, 2.0 * 9.81 * 0.5


def swing(amp, freq, n=801, t_end=2.0):
    t = np.linspace(0.0, t_end, n)
    w = 2 * np.pi * freq
    return t, amp * np.sin(w * t), amp * w * np.cos(w * t), -amp * w * w * np.sin(w * t)


def write_csv(path, t, q, qd=None, qdd=None):
    cols = {"t": t, "pivot": q}
    if qd is not None:
        cols["pivot.qd"], cols["pivot.qdd"] = qd, qdd
    pd.DataFrame(cols).to_csv(path, index=False, float_format="%.17g")


def size(*args):
    return subprocess.run(
        [sys.executable, "-m", "armdyn", "size", str(URDF), *map(str, args)],
        capture_output=True,
        text=True,
        timeout=300,
    )


def test_size_reports_the_closed_form_and_exits_0_when_ok(tmp_path):
    t, q, qd, qdd = swing(0.5, 0.5)
    write_csv(tmp_path / "traj.csv", t, q, qd, qdd)
    proc = size("--trajectory", tmp_path / "traj.csv", "--out", tmp_path / "rep")
    assert proc.returncode == 0, proc.stderr
    assert "all joints ok" in proc.stdout and "pivot" in proc.stdout
    tab = pd.read_csv(tmp_path / "rep" / "table.csv", index_col="joint")
    tau = I_P * qdd + MGL * np.sin(q)
    assert tab.loc["pivot", "peak_torque"] == pytest.approx(np.max(np.abs(tau)), rel=1e-12)
    rms = np.sqrt(np.trapezoid(tau**2, t) / t[-1])
    assert tab.loc["pivot", "rms_torque"] == pytest.approx(rms, rel=1e-12)
    assert (tmp_path / "rep" / "report.html").is_file()


def test_size_exits_1_when_a_limit_is_exceeded(tmp_path):
    # 1.2 rad at 1 Hz: peak speed 7.5 rad/s > 4 rad/s
    t, q, qd, qdd = swing(1.2, 1.0)
    write_csv(tmp_path / "fast.csv", t, q, qd, qdd)
    proc = size("--trajectory", tmp_path / "fast.csv")
    assert proc.returncode == 1, proc.stderr
    assert "not ok: pivot" in proc.stdout


def test_spline_derivatives_when_the_columns_are_missing(tmp_path):
    """Positions only: a not-a-knot cubic spline on 801 samples differentiates the sine with
    errors O(h³) in q̇ and O(h²) in q̈: the peak torque within 1e-5 relative."""
    pytest.importorskip("scipy")
    t, q, qd, qdd = swing(0.5, 0.5)
    write_csv(tmp_path / "pos.csv", t, q)
    proc = size("--trajectory", tmp_path / "pos.csv", "--out", tmp_path / "rep")
    assert proc.returncode == 0, proc.stderr
    tab = pd.read_csv(tmp_path / "rep" / "table.csv", index_col="joint")
    tau = I_P * qdd + MGL * np.sin(q)
    assert tab.loc["pivot", "peak_torque"] == pytest.approx(np.max(np.abs(tau)), rel=1e-5)
    assert tab.loc["pivot", "peak_speed"] == pytest.approx(np.max(np.abs(qd)), rel=1e-7)


def test_bad_trajectory_files_are_named(tmp_path):
    t, q, qd, qdd = swing(0.5, 0.5, n=11)
    pd.DataFrame({"t": t, "elbow": q}).to_csv(tmp_path / "a.csv", index=False)
    proc = size("--trajectory", tmp_path / "a.csv")
    assert proc.returncode == 2 and "unknown column(s) ['elbow']" in proc.stderr
    pd.DataFrame({"t": t[::-1], "pivot": q}).to_csv(tmp_path / "b.csv", index=False)
    proc = size("--trajectory", tmp_path / "b.csv")
    assert proc.returncode == 2 and "strictly increasing" in proc.stderr
    (tmp_path / "c.toml").write_text("[pivot]\ngear_ratio = 10.0\n")
    write_csv(tmp_path / "ok.csv", t, q, qd, qdd)
    proc = size("--trajectory", tmp_path / "ok.csv", "--actuators", tmp_path / "c.toml")
    assert proc.returncode == 2 and "[pivot] needs rotor_inertia" in proc.stderr


def test_read_actuators(tmp_path):
    from armdyn.size import read_actuators

    (tmp_path / "a.toml").write_text(
        "[pivot]\ngear_ratio = 50.0\nrotor_inertia = 2e-5\nefficiency = 0.9\n"
        "[pivot.motor]\ntorque_constant = 0.07\npeak_torque = 1.5\n"
    )
    spec = read_actuators(tmp_path / "a.toml")
    assert spec == {
        "pivot": {
            "gear_ratio": 50.0,
            "rotor_inertia": 2e-5,
            "efficiency": 0.9,
            "motor": {"torque_constant": 0.07, "peak_torque": 1.5},
        }
    }
    (tmp_path / "b.toml").write_text("[pivot]\ngear_ratio = 5\nrotor_inertia = 1\nratio = 3\n")
    from armdyn import ModelError

    with pytest.raises(ModelError, match=r"\[pivot\] unknown key\(s\) \['ratio'\]"):
        read_actuators(tmp_path / "b.toml")


def test_size_with_actuators(tmp_path):
    """With an actuators file: the motor-side torque of a geared pendulum,
    T = J N q̈ + τ_L / (N η) while the gear drives the load, else J N q̈ + τ_L η / N; the
    joint side then carries the reflected rotor, τ = τ_L + N² J q̈."""
    n, j, eta = 40.0, 3e-5, 0.9
    t, q, qd, qdd = swing(0.5, 0.5)
    write_csv(tmp_path / "traj.csv", t, q, qd, qdd)
    (tmp_path / "act.toml").write_text(
        f"[pivot]\ngear_ratio = {n}\nrotor_inertia = {j}\nefficiency = {eta}\n"
        "[pivot.motor]\ncontinuous_torque = 1e-6\n"
    )
    proc = size(
        "--trajectory",
        tmp_path / "traj.csv",
        "--actuators",
        tmp_path / "act.toml",
        "--out",
        tmp_path / "rep",
    )
    assert proc.returncode == 1, proc.stderr  # a 1 µN m continuous rating cannot hold it
    tab = pd.read_csv(tmp_path / "rep" / "table.csv", index_col="joint")
    tau_l = I_P * qdd + MGL * np.sin(q)
    motor_t = j * n * qdd + np.where(tau_l * qd >= 0, tau_l / (n * eta), tau_l * eta / n)
    assert tab.loc["pivot", "motor_peak_torque"] == pytest.approx(np.max(np.abs(motor_t)), rel=1e-9)
