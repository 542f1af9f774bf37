"""Catalogs (armdyn.load_catalog, armdyn.sizing.catalog): the example catalog (shipped in the
package, labelled, self-consistent, and sized so that the UR5 with a 3 kg payload has small
parts that fail and larger ones that pass), the reading rules (every row checked, a bad cell
named by file, 1-based line and column), hostile files, merging, Catalog.motor/gearbox/drive,
the DataFrame path (equal to the CSV path), the synthetic catalog and the documented columns."""

from __future__ import annotations

import dataclasses
import math
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import armdyn as ad
import numpy as np
import pandas as pd
import pytest
from armdyn.sizing import catalog as cat
from armdyn.sizing.catalog import (
    DRIVE_COLUMNS,
    EXAMPLE_CATALOG,
    GEARBOX_COLUMNS,
    MOTOR_COLUMNS,
    Catalog,
    load_catalog,
    synthetic_catalog,
)

ROOT = Path(__file__).resolve().parents[2]
MOTORS_HEADER = "name,torque_constant,resistance,rotor_inertia,mass,continuous_torque,peak_torque"
MOTOR_ROW = "M1,0.1,0.5,1e-5,0.3,0.5,1.5"
GEARBOX_HEADER = "name,ratio,efficiency,input_inertia,mass,rated_torque,repeated_peak_torque"
GEARBOX_ROW = "G1,100,0.8,1e-6,0.5,10,30"


def write(path: Path, text: str, encoding="utf-8") -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(text.encode(encoding))
    return path


def folder(tmp_path: Path, motors: str, gearboxes: str | None = None, drives=None) -> Path:
    d = tmp_path / "cat"
    write(d / "motors.csv", motors)
    write(d / "gearboxes.csv", gearboxes or f"{GEARBOX_HEADER}\n{GEARBOX_ROW}\n")
    if drives is not None:
        write(d / "drives.csv", drives)
    return d


def raises(match: str):
    return pytest.raises(ad.ModelError, match=match)


# --- the example catalog --------------------------------------------------------------------


@pytest.fixture(scope="module")
def example():
    return load_catalog(EXAMPLE_CATALOG)


def test_the_example_catalog_is_in_the_imported_package_and_loads(example):
    """EXAMPLE_CATALOG is a folder of the imported armdyn (in CI: the installed package, built
    from the wheel's file selection) holding the three files, and it loads."""
    package = Path(ad.__file__).resolve().parent
    assert Path(ad.sizing.EXAMPLE_CATALOG) == package / "sizing" / "example_catalog"
    assert sorted(p.name for p in EXAMPLE_CATALOG.iterdir() if p.suffix == ".csv") == [
        "drives.csv",
        "gearboxes.csv",
        "motors.csv",
    ]
    assert len(example.motors) >= 8 and len(example.gearboxes) >= 20 and len(example.drives) >= 3
    assert example.paths == tuple(EXAMPLE_CATALOG / f for f in cat.FILE_NAMES.values())


def test_the_wheel_takes_the_example_catalog():
    """The wheel is python/armdyn as a whole (scikit-build-core's wheel.packages, every file
    not ignored by git): the CSV files are under it, not git-ignored, and no exclude rule of
    pyproject.toml drops them."""
    try:
        import tomllib
    except ImportError:  # Python 3.10
        import tomli as tomllib
    py = tomllib.loads((ROOT / "pyproject.toml").read_text("utf-8"))["tool"]["scikit-build"]
    assert py["wheel"]["packages"] == ["python/armdyn"]
    assert "exclude" not in py["wheel"] and "exclude" not in py.get("sdist", {})
    source = ROOT / "python" / "armdyn" / "sizing" / "example_catalog"
    files = [source / f for f in cat.FILE_NAMES.values()]
    assert all(f.is_file() for f in files)
    if (ROOT / ".git").exists():
        ignored = subprocess.run(
            ["git", "-C", str(ROOT), "check-ignore", *map(str, files)],
            capture_output=True,
            text=True,
        )
        assert ignored.returncode == 1 and ignored.stdout == "", ignored.stdout  # none ignored


def test_the_built_wheel_holds_the_example_catalog(tmp_path, example):
    """The wheel's Python part, built by scikit-build-core from this checkout (CMake skipped:
    wheel.cmake=false, the same package file selection as the full build), holds the example
    catalog, and the files installed from it load to the same tables."""
    pytest.importorskip("scikit_build_core")
    build = ["--no-deps", "--no-build-isolation", "-C", "wheel.cmake=false", "-q"]
    proc = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", str(ROOT), *build, "-w", str(tmp_path / "dist")],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    (wheel,) = (tmp_path / "dist").glob("armdyn-*.whl")
    import zipfile

    with zipfile.ZipFile(wheel) as z:
        members = [n for n in z.namelist() if n.startswith("armdyn/sizing/example_catalog/")]
        assert sorted(members) == [
            f"armdyn/sizing/example_catalog/{f}" for f in sorted(cat.FILE_NAMES.values())
        ]
        z.extractall(tmp_path / "site", members)
    installed = load_catalog(tmp_path / "site" / "armdyn" / "sizing" / "example_catalog")
    for kind in cat.KINDS:
        pd.testing.assert_frame_equal(getattr(installed, kind), getattr(example, kind))


def test_every_example_part_says_where_its_values_come_from(example):
    for kind in cat.KINDS:
        for name, source in getattr(example, kind)["source"].items():
            assert source.startswith("illustrative") or re.search(r"datasheet|catalog", source), (
                kind,
                name,
            )


def test_the_example_catalog_has_every_column_the_checks_use(example):
    """Per gearbox the life and bearing columns, per motor the two-node thermal columns and the
    winding limit (and a brake on some), per drive currents and bus voltage: no NaN there."""
    g, m, d = example.gearboxes, example.motors, example.drives
    need = [
        "rated_torque",
        "rated_input_speed",
        "rated_life",
        "life_exponent",
        "repeated_peak_torque",
        "momentary_peak_torque",
        "momentary_peak_count",
        "max_input_speed",
        "bearing_moment_allowable",
        "bearing_axial_allowable",
        "bearing_radial_allowable",
        "bearing_offset",
        "bearing_dynamic_load_rating",
        "bearing_pitch_diameter",
    ]
    assert not g[need].isna().any().any()
    thermal = [
        f"thermal_{x}_{y}" for x in ("resistance", "time_constant") for y in ("winding", "housing")
    ]
    assert (
        not m[[*thermal, "max_winding_temperature", "voltage", "no_load_speed"]].isna().any().any()
    )
    assert 0 < m["brake_torque"].notna().sum() < len(m)
    assert not d[["continuous_current", "peak_current", "bus_voltage"]].isna().any().any()
    # several ratios per size, and a 10/3 life exponent on the RV-type rows
    sizes = g.index.str.extract(r"^SW-(\d+)-", expand=False).dropna()
    assert (sizes.value_counts() >= 3).all() and (sizes.value_counts() >= 5).sum() >= 3
    assert np.isclose(g["life_exponent"], 10 / 3, rtol=1e-6).sum() >= 1


def test_the_example_motors_are_self_consistent(example):
    """Closed forms a datasheet obeys: no-load speed V / k_t, and the continuous torque is the
    one whose copper loss (hot resistance, copper's 0.00393 /K from 25 degC) raises the
    winding to its limit through R_w + R_h at 25 degC ambient (to the CSV's rounding)."""
    m = example.motors
    assert np.allclose(m["no_load_speed"], m["voltage"] / m["torque_constant"], rtol=5e-4)
    assert (m["max_speed"] <= m["no_load_speed"]).all()
    rise = m["max_winding_temperature"] - 25.0
    hot = m["resistance"] * (1.0 + 0.00393 * rise)
    loss = hot * (m["continuous_torque"] / m["torque_constant"]) ** 2
    r_total = m["thermal_resistance_winding"] + m["thermal_resistance_housing"]
    assert np.allclose(loss * r_total, rise, rtol=0.01)


def _ur5_cycle():
    """The UR5 (example-robot-data) with a 3 kg payload 5 cm beyond tool0, on quintic
    rest-to-rest moves home -> pick -> place -> home (notebooks/sizing_ur5.ipynb's poses)."""
    from benchmarks import common

    path = common.robot_urdf("ur5")
    if path is None:
        pytest.skip("example-robot-data is not installed")
    bare = ad.load_urdf(path)
    at = (ad.frame_pose(bare, np.zeros(6), "tool0") @ [0.0, 0.0, 0.05, 1.0])[:3]
    b = ad.urdf_builder(str(path))
    b.add_body("payload", 3.0, [3.0 * 0.1**2 / 6] * 3, position=at)
    b.add_fixed("payload_mount", bare.frame("tool0")["body"], "payload")
    model = b.finalize()
    poses = [
        [0.0, -1.57, 1.57, -1.57, -1.57, 0.0],
        [0.7, -1.05, 1.85, -2.37, -1.57, 0.7],
        [-0.9, -1.05, 1.85, -2.37, -1.57, -0.9],
        [0.0, -1.57, 1.57, -1.57, -1.57, 0.0],
    ]
    ts, qs, qds, qdds, t0 = [], [], [], [], 0.0
    for a, b_, dur in zip(poses, poses[1:], (1.0, 1.2, 1.0), strict=False):
        a, b_ = np.asarray(a), np.asarray(b_)
        u = np.arange(0.0, dur, 0.01) / dur
        s = 10 * u**3 - 15 * u**4 + 6 * u**5
        sd = (30 * u**2 - 60 * u**3 + 30 * u**4) / dur
        sdd = (60 * u - 180 * u**2 + 120 * u**3) / dur**2
        ts.append(t0 + u * dur)
        qs.append(a + np.outer(s, b_ - a))
        qds.append(np.outer(sd, b_ - a))
        qdds.append(np.outer(sdd, b_ - a))
        t0 += dur
    t, q, qd, qdd = map(np.concatenate, (ts, qs, qds, qdds))
    return ad.trajectory_run(model, t, q, qd, qdd)


def test_the_example_catalog_sizes_the_ur5_non_trivially(example):
    """Evaluated by armdyn.sizing_report's motor side (what-if actuators: motor rotor + gear
    input inertia, the gear's efficiency) and the gear's repeated peak torque: on each of the
    shoulder, elbow and first wrist joint, some motor x gearbox pairs pass every motor check and
    the gear's peak, and the lightest motor on the lightest gearbox does not."""
    run = _ur5_cycle()
    m, g = example.motors, example.gearboxes
    joints = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint"]
    peak_load = np.abs(run.joint_torques).max(axis=0)
    # one gearbox per joint and motor: the lightest whose repeated peak carries the load
    checks = ["continuous_torque_margin", "peak_torque_margin", "motor_speed_margin"]
    for k, joint in enumerate(joints):
        verdicts = {}
        lightest_gear = g["mass"].idxmin()
        for gear in (lightest_gear, *g.index[g["repeated_peak_torque"] >= 1.3 * peak_load[k]]):
            row = g.loc[gear]
            for motor in (m["mass"].idxmin(), *m.index):
                if (motor, gear) in verdicts:
                    continue
                spec = dict(
                    gear_ratio=row["ratio"],
                    rotor_inertia=m.loc[motor, "rotor_inertia"] + row["input_inertia"],
                    efficiency=row["efficiency"],
                    motor=example.motor(motor),
                )
                tab = ad.sizing_report(run, actuators={joint: spec}).table.loc[joint]
                ok = (
                    bool((tab[checks] >= 1.0).all()) and peak_load[k] <= row["repeated_peak_torque"]
                )
                verdicts[(motor, gear)] = ok
            if sum(verdicts.values()) >= 2:
                break
        assert sum(verdicts.values()) >= 2, joint
        assert not verdicts[(m["mass"].idxmin(), lightest_gear)], joint


# --- reading rules ----------------------------------------------------------------------------


def test_a_minimal_folder_loads_with_nan_for_blank_optionals_and_defaults(tmp_path):
    d = folder(tmp_path, f"{MOTORS_HEADER},voltage,brake_torque\n{MOTOR_ROW},48,\n")
    c = load_catalog(d)
    assert list(c.motors.index) == ["M1"] and c.motors.index.name == "name"
    assert list(c.motors.columns[: len(MOTOR_COLUMNS) - 1]) == [x.name for x in MOTOR_COLUMNS[1:]]
    assert c.motors.loc["M1", "voltage"] == 48.0
    assert math.isnan(c.motors.loc["M1", "brake_torque"])  # blank
    assert math.isnan(c.motors.loc["M1", "max_winding_temperature"])  # absent column
    assert c.gearboxes.loc["G1", "life_exponent"] == 3.0  # the declared default
    assert len(c.drives) == 0 and list(c.drives.columns) == [x.name for x in DRIVE_COLUMNS[1:]]
    assert c.motors.loc["M1", "source"] == ""


def test_unknown_columns_are_kept_numbers_as_floats_text_as_text(tmp_path):
    d = folder(
        tmp_path,
        f"{MOTORS_HEADER},frame_size,vendor\n{MOTOR_ROW},70,Acme\nM2,0.1,0.5,1e-5,0.3,0.5,1.5,,\n",
    )
    c = load_catalog(d)
    assert c.motors.columns[-2:].tolist() == ["frame_size", "vendor"]
    assert c.motors.loc["M1", "frame_size"] == 70.0 and math.isnan(c.motors.loc["M2", "frame_size"])
    assert c.motors.loc["M1", "vendor"] == "Acme" and c.motors.loc["M2", "vendor"] == ""


def test_a_misspelt_column_is_kept_with_a_warning(tmp_path):
    d = folder(tmp_path, f"{MOTORS_HEADER},max_winding_temp\n{MOTOR_ROW},155\n")
    with pytest.warns(
        UserWarning, match="'max_winding_temp' is not a motor column .*'max_winding_temperature'"
    ):
        c = load_catalog(d)
    assert c.motors.loc["M1", "max_winding_temp"] == 155.0
    assert math.isnan(c.motors.loc["M1", "max_winding_temperature"])


def test_bom_crlf_and_blank_rows_read_as_plain_csv(tmp_path):
    text = f"{MOTORS_HEADER}\n\n{MOTOR_ROW}\n,,,,,,\nM2,0.2,0.4,2e-5,0.5,1,3\n"
    plain = load_catalog(folder(tmp_path / "a", text))
    odd = tmp_path / "b" / "cat"
    write(odd / "motors.csv", "\ufeff" + text.replace("\n", "\r\n"))
    write(odd / "gearboxes.csv", f"{GEARBOX_HEADER}\r\n{GEARBOX_ROW}\r\n")
    other = load_catalog(odd)
    pd.testing.assert_frame_equal(plain.motors, other.motors)
    assert other.origin("motors", "M2") == f"{odd / 'motors.csv'}:5"  # blank lines counted
    write(odd / "motors.csv", text.replace("\n", "\r"))  # old Mac line ends
    other = load_catalog(odd)
    pd.testing.assert_frame_equal(plain.motors, other.motors)
    assert other.origin("motors", "M2") == f"{odd / 'motors.csv'}:5"
    (odd / "motors.csv").write_bytes(text.replace("\n", "\r").encode() + b"M3,\xff\r")
    with raises(re.escape(f"{odd / 'motors.csv'}:6: not UTF-8 text (byte b'\\xff'")):
        load_catalog(odd)


@pytest.mark.parametrize(
    "cell, why",
    [
        ("nan", "'nan' is not a finite number"),
        ("NaN", "'NaN' is not a finite number"),
        ("inf", "'inf' is not a finite number"),
        ("-Infinity", "'-Infinity' is not a finite number"),
        ("1e400", "'1e400' overflows a float"),
        ("0x10", "'0x10' is not a finite number"),
        ("1_000", "'1_000' is not a finite number"),
        ("abc", "'abc' is not a finite number"),
        ("-0.3", r"-0.3 must be > 0 \[kg\]"),
        ("0", r"0.0 must be > 0 \[kg\]"),
        ("1e-400", r"0.0 must be > 0 \[kg\]"),  # underflows to zero
        ("", r"a value is required \(kg, > 0\)"),
    ],
)
def test_a_bad_cell_is_named_by_file_line_and_column(tmp_path, cell, why):
    # line 1 header, 2 a good row, 3 blank, 4 the bad row
    d = folder(tmp_path, f"{MOTORS_HEADER}\n{MOTOR_ROW}\n\nM2,0.1,0.5,1e-5,{cell},0.5,1.5\n")
    with raises(re.escape(f"{d / 'motors.csv'}:4: column 'mass': ") + why):
        load_catalog(d)


@pytest.mark.parametrize(
    "column, value, why",
    [
        ("efficiency", "1.2", r"1.2 must be in \(0, 1\]"),
        ("efficiency", "0", r"0.0 must be in \(0, 1\]"),
        ("input_inertia", "-1e-6", r"-1e-06 must be >= 0"),
        ("life_exponent", "0", r"0.0 must be in \(0, 20\]"),
        ("ratio", "-100", r"-100.0 must be > 0"),
    ],
)
def test_bounds_of_gearbox_columns(tmp_path, column, value, why):
    header = f"{GEARBOX_HEADER},life_exponent"
    row = dict(zip(header.split(","), [*GEARBOX_ROW.split(","), "3"], strict=True))
    row[column] = value
    gears = f"{header}\n{','.join(row.values())}\n"
    d = folder(tmp_path, f"{MOTORS_HEADER}\n{MOTOR_ROW}\n", gears)
    with raises(re.escape(f"{d / 'gearboxes.csv'}:2: column '{column}': ") + why):
        load_catalog(d)


def test_a_negative_bearing_offset_is_allowed(tmp_path):
    gears = f"{GEARBOX_HEADER},bearing_moment_allowable,bearing_offset\n{GEARBOX_ROW},50,-0.012\n"
    c = load_catalog(folder(tmp_path, f"{MOTORS_HEADER}\n{MOTOR_ROW}\n", gears))
    assert c.gearbox("G1").bearing_offset == -0.012


@pytest.mark.parametrize(
    "kind, header, row, match",
    [
        (
            "motors",
            f"{MOTORS_HEADER},thermal_resistance_winding,thermal_resistance_housing",
            f"{MOTOR_ROW},1.0,2.0",
            r":2: column\(s\) \['thermal_time_constant_winding', "
            r"'thermal_time_constant_housing'\]: "
            r"\['thermal_resistance_winding', .*\] are given together or not at all",
        ),
        (
            "motors",
            MOTORS_HEADER,
            "M1,0.1,0.5,1e-5,0.3,2.0,1.5",
            r":2: column 'peak_torque': 1.5 is less than continuous_torque 2.0",
        ),
        (
            "gearboxes",
            f"{GEARBOX_HEADER},rated_life",
            f"{GEARBOX_ROW},7000",
            r":2: column\(s\) \['rated_input_speed'\]",
        ),
        (
            "gearboxes",
            f"{GEARBOX_HEADER},bearing_moment_allowable",
            f"{GEARBOX_ROW},50",
            r":2: column 'bearing_offset': bearing_moment_allowable needs it",
        ),
        (
            "gearboxes",
            f"{GEARBOX_HEADER},momentary_peak_torque",
            f"{GEARBOX_ROW},20",
            r":2: column 'momentary_peak_torque': 20.0 is less than repeated_peak_torque 30.0",
        ),
        (
            "drives",
            "name,continuous_current,peak_current,bus_voltage,max_bus_voltage",
            "D1,10,30,48,40",
            r":2: column 'max_bus_voltage': 40.0 is less than bus_voltage 48.0",
        ),
    ],
)
def test_columns_that_go_together_and_ordered_columns(tmp_path, kind, header, row, match):
    d = folder(tmp_path, f"{MOTORS_HEADER}\n{MOTOR_ROW}\n")
    write(d / f"{kind}.csv", f"{header}\n{row}\n")
    with raises(re.escape(str(d / f"{kind}.csv")) + match):
        load_catalog(d)


def test_missing_required_columns_are_named(tmp_path):
    d = folder(tmp_path, "name,torque_constant,mass\nM1,0.1,0.3\n")
    with raises(
        r"motors.csv: missing required column\(s\) \['resistance', 'rotor_inertia', "
        r"'continuous_torque', 'peak_torque'\] of motors"
    ):
        load_catalog(d)


def test_duplicate_names_within_a_file_and_across_paths(tmp_path):
    d = folder(
        tmp_path, f"{MOTORS_HEADER}\n{MOTOR_ROW}\nM2,0.1,0.5,1e-5,0.3,0.5,1.5\n{MOTOR_ROW}\n"
    )
    with raises(
        re.escape(
            f"{d / 'motors.csv'}:4: column 'name': motor 'M1' is already at {d / 'motors.csv'}:2"
        )
    ):
        load_catalog(d)
    a = write(tmp_path / "a_motors.csv", f"{MOTORS_HEADER}\n{MOTOR_ROW}\n")
    b = write(
        tmp_path / "b" / "motors.csv",
        f"{MOTORS_HEADER}\nM0,0.1,0.5,1e-5,0.3,0.5,1.5\n {MOTOR_ROW}\n",
    )
    with raises(re.escape(f"{b}:3: column 'name': motor 'M1' is already at {a}:2")):
        load_catalog(a, b)
    # the same name in two kinds is two parts
    gears = write(
        tmp_path / "gearboxes.csv", f"{GEARBOX_HEADER}\n{GEARBOX_ROW.replace('G1', 'M1')}\n"
    )
    c = load_catalog(a, gears)
    assert c.motor("M1").name == "M1" and c.gearbox("M1").ratio == 100.0


def test_merged_paths(tmp_path):
    d = folder(tmp_path, f"{MOTORS_HEADER},vendor\n{MOTOR_ROW},Acme\n")
    more = write(
        tmp_path / "extra_motors.csv", f"{MOTORS_HEADER},voltage\nM9,0.2,0.4,2e-5,0.5,1,3,24\n"
    )
    drives = write(
        tmp_path / "drives.csv", "name,continuous_current,peak_current,bus_voltage\nD1,5,15,48\n"
    )
    c = load_catalog(d, str(more), drives)
    assert list(c.motors.index) == ["M1", "M9"]
    assert c.motors.loc["M9", "voltage"] == 24.0 and math.isnan(c.motors.loc["M1", "voltage"])
    assert c.motors.loc["M1", "vendor"] == "Acme" and c.motors.loc["M9", "vendor"] == ""
    got = dataclasses.asdict(c.drive("D1"))
    assert got["continuous_current"] == 5.0 and got["peak_current"] == 15.0
    assert all(math.isnan(got[x.name]) for x in DRIVE_COLUMNS[4:-1])
    assert c.paths == (d / "motors.csv", d / "gearboxes.csv", more, drives)


def test_a_file_kind_from_its_name_or_its_header(tmp_path):
    odd = write(tmp_path / "parts_2024.csv", f"{GEARBOX_HEADER}\n{GEARBOX_ROW}\n")
    assert list(load_catalog(odd).gearboxes.index) == ["G1"]
    named = write(
        tmp_path / "acme-drives.csv", "name,continuous_current,peak_current,bus_voltage\nD,1,2,48\n"
    )
    assert list(load_catalog(named).drives.index) == ["D"]
    unknown = write(tmp_path / "parts.csv", "name,mass\nX,1\n")
    with raises(r"parts.csv: which kind of part\? .*motors: missing \['torque_constant'"):
        load_catalog(unknown)
    # a motors.csv whose header is a gearbox's: the name decides, and the columns are missing
    wrong = write(tmp_path / "w" / "motors.csv", f"{GEARBOX_HEADER}\n{GEARBOX_ROW}\n")
    with raises(r"motors.csv: missing required column\(s\) \['torque_constant'"):
        load_catalog(wrong)


def test_catalog_folders(tmp_path):
    d = tmp_path / "only_motors"
    write(d / "motors.csv", f"{MOTORS_HEADER}\n{MOTOR_ROW}\n")
    with raises(r"has no gearboxes.csv \(a catalog folder holds"):
        load_catalog(d)
    d = folder(tmp_path, f"{MOTORS_HEADER}\n{MOTOR_ROW}\n")
    write(d / "drive.csv", "name\n")
    with raises(r"unrecognised CSV file\(s\) \['drive.csv'\]"):
        load_catalog(d)


def test_bad_paths(tmp_path):
    with pytest.raises(FileNotFoundError, match="nowhere"):
        load_catalog(tmp_path / "nowhere")
    with raises(r"load_catalog: path 2 must be a str or a path, got int"):
        load_catalog(EXAMPLE_CATALOG, 3)
    with raises(r"load_catalog: path 1 must be a str or a path, got bytes"):
        load_catalog(b"x")
    with raises(r"path 1 must be a str path without NUL characters, got 'a\\x00b'"):
        load_catalog("a\x00b")


# --- hostile files ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "text, match",
    [
        ("", r"motors.csv: empty catalog file \(no header row\)"),
        ("\n\n  \n", r"motors.csv: empty catalog file"),
        (f"{MOTORS_HEADER}\n", r"motors.csv: no parts \(a header row and no data rows\)"),
        (
            f"{MOTORS_HEADER}\n{MOTOR_ROW}\nM2,0.1,0.5,1e-",
            r"motors.csv:3: the row has 4 cells, the header 7",
        ),
        (f"{MOTORS_HEADER}\n{MOTOR_ROW},9\n", r"motors.csv:2: the row has 8 cells, the header 7"),
        (f'{MOTORS_HEADER}\n"M1,0.1,0.5,1e-5,0.3,0.5,1.5\n', r"motors.csv:2: malformed CSV"),
        (
            f"{MOTORS_HEADER}\nM\x001,0.1,0.5,1e-5,0.3,0.5,1.5\n",
            rf"motors.csv:2: a NUL byte \(offset {len(MOTORS_HEADER) + 2}\)",
        ),
        (f"{MOTORS_HEADER},\n{MOTOR_ROW},\n", r"motors.csv:1: header cell 8 is empty"),
        (
            f"{MOTORS_HEADER}\n{MOTOR_ROW}\n{'M' * 200_000},0.1,0.5,1e-5,0.3,0.5,1.5\n",
            r"motors.csv:3: malformed CSV \(field larger than field limit",
        ),
        (f"{MOTORS_HEADER},mass\n{MOTOR_ROW},1\n", r"motors.csv:1: column 'mass' appears twice"),
        (
            f"{MOTORS_HEADER}\n\x01M,0.1,0.5,1e-5,0.3,0.5,1.5\n",
            r"motors.csv:2: column 'name': '\\x01M' has control",
        ),
    ],
)
def test_malformed_and_truncated_files(tmp_path, text, match):
    d = folder(tmp_path, text)
    with raises(match):
        load_catalog(d)


def test_line_numbers_count_quoted_line_breaks(tmp_path):
    text = f'{MOTORS_HEADER},source\n{MOTOR_ROW},"two\nlines"\nM2,0.1,0.5,1e-5,0.3,0.5,-1,x\n'
    d = folder(tmp_path, text)
    with raises(re.escape(f"{d / 'motors.csv'}:4: column 'peak_torque'")):
        load_catalog(d)


def test_non_utf8_text_is_named_by_line(tmp_path):
    d = folder(tmp_path, f"{MOTORS_HEADER}\n{MOTOR_ROW}\n")
    text = f"{MOTORS_HEADER},source\n{MOTOR_ROW},ok\nM2,0.1,0.5,1e-5,0.3,0.5,1.5,Müller\n"
    write(d / "motors.csv", text, "latin-1")
    with raises(re.escape(f"{d / 'motors.csv'}:3: not UTF-8 text (byte b'\\xfc'")):
        load_catalog(d)
    # UTF-16 (a spreadsheet's "Unicode text") is not UTF-8 either
    write(d / "motors.csv", f"{MOTORS_HEADER}\n{MOTOR_ROW}\n", "utf-16")
    with raises(r"motors.csv:1: a NUL byte \(offset 3\): not UTF-8 text \(a binary or UTF-16"):
        load_catalog(d)


def test_a_file_over_the_size_limit_is_refused_before_it_is_read(tmp_path):
    """A sparse file one byte over MAX_CATALOG_BYTES (64 MiB): refused by its size."""
    assert cat.MAX_CATALOG_BYTES == 64 * 2**20
    d = folder(tmp_path, f"{MOTORS_HEADER}\n{MOTOR_ROW}\n")
    with open(d / "motors.csv", "r+b") as f:
        f.truncate(cat.MAX_CATALOG_BYTES + 1)
    with raises(
        f"is {cat.MAX_CATALOG_BYTES + 1} bytes, more than the limit of "
        f"{cat.MAX_CATALOG_BYTES} bytes"
    ):
        load_catalog(d)


def test_a_directory_where_a_file_is_expected(tmp_path):
    d = folder(tmp_path, f"{MOTORS_HEADER}\n{MOTOR_ROW}\n")
    (d / "drives.csv").mkdir()
    with raises(r"catalog file '.*drives.csv' is a directory, not a regular file"):
        load_catalog(d)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_fifos_and_devices_are_refused_without_reading(tmp_path):
    """/dev/zero and a FIFO without a writer, as a file and as a folder's motors.csv: refused by
    the stat before the open (run in a subprocess with a timeout: a read would never end)."""
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    d = folder(tmp_path, f"{MOTORS_HEADER}\n{MOTOR_ROW}\n")
    (d / "motors.csv").unlink()
    (d / "motors.csv").symlink_to("/dev/zero")
    script = textwrap.dedent(
        f"""
        import armdyn as ad
        for path in ({str(fifo)!r}, "/dev/zero", {str(d)!r}):
            try:
                ad.load_catalog(path)
            except ad.ModelError as err:
                print(err)
        """
    )
    proc = subprocess.run(
        [sys.executable, "-c", script],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "PYTHONPATH": str(Path(ad.__file__).resolve().parents[1])},
    )
    lines = proc.stdout.splitlines()
    assert len(lines) == 3, proc.stdout + proc.stderr
    assert "is a FIFO (named pipe), not a regular file" in lines[0]
    assert "'/dev/zero' is a character device" in lines[1]
    assert "motors.csv' is a character device" in lines[2]


# --- parts ----------------------------------------------------------------------------------------


def test_motor_carries_every_motor_field_of_its_row(example):
    """Catalog.motor builds an armdyn.Motor from the row's MOTOR_FIELDS (every one of which is
    a catalog column, so new Motor fields are picked up): each equal to the row, None where
    the row has NaN."""
    fields = [f for f in ad.sizing.MOTOR_FIELDS if f != "name"]
    columns = {c.name for c in MOTOR_COLUMNS}
    assert set(fields) <= columns, set(fields) - columns
    for name in ("FL-70x18", "FL-85x23-B"):
        motor, row = example.motor(name), example.motors.loc[name]
        assert isinstance(motor, ad.Motor) and motor.name == name
        for f in fields:
            want = row[f]
            got = getattr(motor, f)
            assert (got is None) if math.isnan(want) else got == want, (name, f, got, want)
    with raises(r"catalog: no motor named 'nope' \(the motors: \['FL-25x08'"):
        example.motor("nope")


def test_motor_goes_through_motor_from_row_when_there_is_one(example, monkeypatch):
    """With armdyn.Motor.from_row (issue 33's motor part), Catalog.motor hands it the row: a
    pandas Series named after the part, holding every column of the row."""
    seen = []

    def from_row(row):
        seen.append(row)
        return "from_row"

    monkeypatch.setattr(ad.Motor, "from_row", staticmethod(from_row), raising=False)
    assert example.motor("FL-85x23-B") == "from_row"
    (row,) = seen
    assert row.name == "FL-85x23-B" and row["brake_torque"] == 2.5
    assert list(row.index) == list(example.motors.columns)


def test_gearbox_and_drive_are_frozen_dataclasses_of_the_declared_columns(example):
    g = example.gearbox("SW-25-100")
    assert [f.name for f in dataclasses.fields(g)] == [c.name for c in GEARBOX_COLUMNS] + ["extra"]
    assert g.ratio == 100.0 and g.rated_torque == example.gearboxes.loc["SW-25-100", "rated_torque"]
    with pytest.raises(dataclasses.FrozenInstanceError):
        g.ratio = 50.0
    d = example.drive("DR-48-10")
    assert [f.name for f in dataclasses.fields(d)] == [c.name for c in DRIVE_COLUMNS] + ["extra"]
    assert "bearing_offset: output bearing" in type(g).__doc__
    with raises(r"no gearbox named 'FL-70x18'"):
        example.gearbox("FL-70x18")


def test_extra_columns_reach_the_dataclass(tmp_path):
    gears = f"{GEARBOX_HEADER},vendor,backlash\n{GEARBOX_ROW},Acme,0.5\n"
    c = load_catalog(folder(tmp_path, f"{MOTORS_HEADER}\n{MOTOR_ROW}\n", gears))
    g = c.gearbox("G1")
    assert dict(g.extra) == {"vendor": "Acme", "backlash": 0.5}
    assert isinstance(hash(g), int)  # hashable, extra left out


def test_catalogs_and_parts_pickle(example):
    import pickle

    back = pickle.loads(pickle.dumps(example))
    for kind in cat.KINDS:
        pd.testing.assert_frame_equal(getattr(back, kind), getattr(example, kind))
    assert back.origin("motors", "FL-70x18") == example.origin("motors", "FL-70x18")
    g = example.gearbox("SW-25-100")
    assert repr(pickle.loads(pickle.dumps(g))) == repr(g)  # (NaN fields: == is False)


# --- frames and the synthetic catalog -----------------------------------------------------------


def test_frames_and_csv_give_the_same_catalog(tmp_path):
    """A catalog written to CSV and read back equals the one checked from its DataFrames."""
    a = synthetic_catalog(30, 25, 3, seed=7)
    d = tmp_path / "syn"
    d.mkdir()
    for kind in cat.KINDS:
        getattr(a, kind).to_csv(d / f"{kind}.csv", float_format="%.17g")
    b = load_catalog(d)
    for kind in cat.KINDS:
        pd.testing.assert_frame_equal(getattr(a, kind), getattr(b, kind))


def test_from_frames_blank_cells_none_nan_and_na():
    motors = {
        "name": ["A", "B", "C"],
        "torque_constant": [0.1, 0.1, 0.1],
        "resistance": [0.5, 0.5, 0.5],
        "rotor_inertia": [1e-5, 1e-5, 1e-5],
        "mass": [0.3, 0.3, 0.3],
        "continuous_torque": [0.5, 0.5, 0.5],
        "peak_torque": [1.5, 1.5, 1.5],
        "voltage": pd.array([48, None, pd.NA], dtype=object),
        "brake_torque": np.array([np.float32("nan"), 1.0, np.nan], dtype=object),
        "ratio_pinned": [1, 2, 3],  # undeclared: kept
    }
    c = Catalog(motors)
    assert c.motors.loc["A", "voltage"] == 48.0
    assert c.motors[["voltage", "brake_torque"]].isna().sum().tolist() == [2, 2]
    assert c.motors["ratio_pinned"].tolist() == [1, 2, 3]
    assert c.origin("motors", "B") == "motors table, row 2, part 'B'"


def test_from_frames_checks_every_value():
    good = synthetic_catalog(3, 3, 1, seed=0)
    motors = good.motors.copy()
    motors.loc["SM-00001", "peak_torque"] = -2.0
    with raises(r"motors table, row 2, part 'SM-00001': column 'peak_torque': -2.0 must be > 0"):
        Catalog.from_frames(motors, good.gearboxes)
    motors = good.motors.copy()
    motors["mass"] = motors["mass"].astype(object)
    motors.loc["SM-00002", "mass"] = "heavy"
    with raises(r"part 'SM-00002': column 'mass': 'heavy' is not a number"):
        Catalog.from_frames(motors, good.gearboxes)
    with raises(r"gearboxes lacks required column\(s\) \['ratio'\]"):
        Catalog.from_frames(good.motors, good.gearboxes.drop(columns="ratio"))
    with raises(r"needs a 'name' column or an index of part names"):
        Catalog.from_frames(good.motors.reset_index(drop=True))
    with raises(r"gearboxes must be a DataFrame, a mapping of columns or None, got int"):
        Catalog.from_frames(good.motors, 5)
    with raises(r"Catalog.from_frames: motors is not a table of columns"):
        Catalog({"name": "A", "mass": 1.0})
    twice = pd.concat([good.motors, good.motors[["mass"]]], axis=1)
    with raises(r"motors has column\(s\) \['mass'\] twice"):
        Catalog(twice)
    motors = good.motors.reset_index()
    motors.loc[1, "name"] = np.nan
    with raises(r"motors table, row 2, part '': column 'name': empty part name"):
        Catalog(motors)
    motors = good.motors.astype({"mass": complex})
    with raises(r"part 'SM-00000': column 'mass': .*j\) is not a number"):
        Catalog(motors)


def test_the_synthetic_catalog():
    a = synthetic_catalog(100, 100, 4, seed=3)
    assert (len(a.motors), len(a.gearboxes), len(a.drives)) == (100, 100, 4)
    pd.testing.assert_frame_equal(a.gearboxes, synthetic_catalog(100, 100, 4, seed=3).gearboxes)
    assert not a.motors["mass"].equals(synthetic_catalog(100, 100, 4, seed=4).motors["mass"])
    assert set(a.gearboxes["ratio"]) == {50.0, 80.0, 100.0, 120.0, 160.0}
    assert (a.motors["source"] == "synthetic").all()
    # spans the example catalog's parts (so that a UR5 screening finds fits and misfits)
    ex = load_catalog(EXAMPLE_CATALOG)
    assert a.motors["continuous_torque"].min() < ex.motors["continuous_torque"].min() * 1.5
    assert a.gearboxes["repeated_peak_torque"].max() > 150.0
    with raises(r"synthetic_catalog: n_motors must be an integer in \[1, 1000000\]"):
        synthetic_catalog(0, 10)


# --- docs ------------------------------------------------------------------------------------


def test_the_docs_give_the_declared_columns():
    """docs/api.md's "Catalogs" tables are column_table(kind), verbatim."""
    api = (ROOT / "docs" / "api.md").read_text("utf-8")
    for kind in cat.KINDS:
        assert cat.column_table(kind) in api, kind
    assert f"{cat.MAX_CATALOG_BYTES >> 20} MiB" in api
