"""`armdyn size` on bad input: exit code 2 (as its docs say: ``armdyn.size``, ``armdyn --help``)
and one line naming the file, column, row or key, never a traceback; its CSV and TOML are read
through the URDF loader's rules (a regular file of bounded size: never a FIFO or a device)."""

import os
import subprocess
import sys
from pathlib import Path

import armdyn
import numpy as np
import pandas as pd
import pytest
from armdyn.__main__ import main

ROOT = Path(__file__).resolve().parents[2]
URDF = ROOT / "tests" / "data" / "urdf" / "sizing_pendulum.urdf"


def good_csv(path, n=41):
    t = np.linspace(0.0, 2.0, n)
    q = 0.3 * np.sin(np.pi * t)
    pd.DataFrame({"t": t, "pivot": q}).to_csv(path, index=False, float_format="%.17g")
    return path


def run_cli(capsys, *args):
    code = main(["size", str(URDF), *map(str, args)])
    out = capsys.readouterr()
    return code, out.out, out.err


def assert_one_line_exit_2(code, err, *fragments):
    assert code == 2, err
    assert "Traceback" not in err
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1, err
    for f in fragments:
        assert f in lines[0], lines[0]


@pytest.mark.parametrize(
    "toml, fragments",
    [
        ('gear_ratio = "ten"\nrotor_inertia = 1e-5', ["gear_ratio", "'ten'", "finite number"]),
        ("gear_ratio = 0\nrotor_inertia = 1e-5", ["gear_ratio", "nonzero"]),
        ("gear_ratio = 10\nrotor_inertia = -1.0", ["rotor_inertia", ">= 0"]),
        ("gear_ratio = 10\nrotor_inertia = 1e-5\nefficiency = 1.5", ["efficiency", "(0, 1]"]),
        ("gear_ratio = 10\nrotor_inertia = nan", ["rotor_inertia", "nan"]),
        ("gear_ratio = 1\nrotor_inertia = 0\n[pivot.motor]\npeak_torque = [1]", ["peak_torque"]),
    ],
)
def test_bad_actuator_values_exit_2_naming_the_key(tmp_path, capsys, toml, fragments):
    csv = good_csv(tmp_path / "t.csv")
    (tmp_path / "a.toml").write_text("[pivot]\n" + toml + "\n")
    code, _, err = run_cli(capsys, "--trajectory", csv, "--actuators", tmp_path / "a.toml")
    assert_one_line_exit_2(code, err, "[pivot", *fragments)


def test_huge_positions_are_refused_naming_column_and_row(tmp_path, capsys):
    """1e300 rad: the spline's second derivative overflows; the CLI names the column and row
    instead of reporting 'all joints ok'."""
    t = np.linspace(0.0, 2.0, 41)
    q = 1e300 * np.sin(np.pi * t)
    pd.DataFrame({"t": t, "pivot": q}).to_csv(tmp_path / "big.csv", index=False)
    code, out, err = run_cli(capsys, "--trajectory", tmp_path / "big.csv")
    assert "all joints ok" not in out
    assert_one_line_exit_2(code, err, "pivot", "row")


def test_huge_positions_with_given_rates_are_refused(tmp_path, capsys):
    """Rates given, positions 1e300: the inverse dynamics overflow (q̇² terms are fine, but
    the CSV's finite values reach the solver): refused with exit 2 or flagged, never 'ok'."""
    t = np.linspace(0.0, 2.0, 41)
    q = np.full_like(t, 1e300)
    qd = np.full_like(t, 1e200)
    qdd = np.zeros_like(t)
    frame = {"t": t, "pivot": q, "pivot.qd": qd, "pivot.qdd": qdd}
    pd.DataFrame(frame).to_csv(tmp_path / "big.csv", index=False)
    code, out, err = run_cli(capsys, "--trajectory", tmp_path / "big.csv")
    assert "all joints ok" not in out
    assert code in (1, 2), err
    assert "Traceback" not in err


@pytest.mark.parametrize("text", ["inf", "nan", "1e400", "one"])
def test_non_finite_values_are_named_by_column_and_row(tmp_path, capsys, text):
    good_csv(tmp_path / "t.csv")
    lines = (tmp_path / "t.csv").read_text().splitlines()
    t3 = lines[3].split(",")[0]
    lines[3] = f"{t3},{text}"
    (tmp_path / "t.csv").write_text("\n".join(lines) + "\n")
    code, _, err = run_cli(capsys, "--trajectory", tmp_path / "t.csv")
    assert_one_line_exit_2(code, err, "column 'pivot'", "data row 3", repr(text))


def test_a_directory_is_refused(tmp_path, capsys):
    code, _, err = run_cli(capsys, "--trajectory", tmp_path)
    assert_one_line_exit_2(code, err, "a directory, not a regular file")


def test_a_large_file_is_refused_before_it_is_read(tmp_path, capsys, monkeypatch):
    import armdyn.sizing.files

    csv = good_csv(tmp_path / "t.csv")
    monkeypatch.setattr(armdyn.sizing.files, "MAX_INPUT_BYTES", 100)
    code, _, err = run_cli(capsys, "--trajectory", csv)
    size = csv.stat().st_size
    assert_one_line_exit_2(code, err, f"is {size} bytes, more than the limit of 100 bytes")


def _cli(*args):
    return subprocess.run(
        [sys.executable, "-m", "armdyn", "size", str(URDF), *map(str, args)],
        capture_output=True,
        text=True,
        timeout=120,
        # the armdyn this test imported (installed, or a source tree on PYTHONPATH)
        env={**os.environ, "PYTHONPATH": str(Path(armdyn.__file__).resolve().parents[1])},
    )


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_devices_and_fifos_are_refused_without_reading(tmp_path):
    """/dev/zero as the CSV or the TOML, and a FIFO without a writer: refused at once by the
    stat before the open (a subprocess with a timeout: the old code read /dev/zero until memory
    ran out and blocked on the FIFO)."""
    csv = good_csv(tmp_path / "t.csv")
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    for args, kind in (
        (("--trajectory", "/dev/zero"), "a character device"),
        (("--trajectory", csv, "--actuators", "/dev/zero"), "a character device"),
        (("--trajectory", fifo), "a FIFO (named pipe)"),
        (("--trajectory", csv, "--actuators", fifo), "a FIFO (named pipe)"),
    ):
        proc = _cli(*args)
        assert proc.returncode == 2, proc.stderr
        assert kind in proc.stderr and "Traceback" not in proc.stderr


def test_reproduce_to_an_unwritable_folder_exits_2(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    code = main(["reproduce", "--out", str(blocker / "report"), "--no-plots", "--no-geared"])
    err = capsys.readouterr().err
    assert_one_line_exit_2(code, err, "armdyn reproduce: cannot write the report", "report")


def test_positions_beyond_the_urdf_limits_are_not_ok(tmp_path, capsys):
    """The issue's case: positions of 1e300 rad (rates and accelerations given, zero: the
    torques are finite) were reported as 'all joints ok'. The pivot's URDF limit is ±3 rad."""
    t = np.linspace(0.0, 2.0, 41)
    frame = {"t": t, "pivot": np.full_like(t, 1e300), "pivot.qd": 0.0 * t, "pivot.qdd": 0.0 * t}
    pd.DataFrame(frame).to_csv(tmp_path / "far.csv", index=False)
    code, out, err = run_cli(capsys, "--trajectory", tmp_path / "far.csv")
    assert code == 1, err
    assert "pivot: position 1e+300 beyond its limit 3 (t = 0 to 2 s)" in out
    assert out.rstrip().endswith("not ok: pivot")
    # just inside the limit: ok
    frame["pivot"] = np.full_like(t, 2.9)
    pd.DataFrame(frame).to_csv(tmp_path / "near.csv", index=False)
    code, out, err = run_cli(capsys, "--trajectory", tmp_path / "near.csv")
    assert code == 0, err
    assert "beyond its limit" not in out and out.rstrip().endswith("all joints ok")
