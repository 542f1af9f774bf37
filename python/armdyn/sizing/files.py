"""The input files of the sizing commands, read and checked (a ModelError naming the file, and
the column and data row or the key): a trajectory CSV (:func:`read_trajectory`; the format is in
:mod:`armdyn.sizing.cli`'s notes) and an actuators TOML (:func:`read_actuators`). Also what
:func:`armdyn.duty_cycle` reads a motion CSV with."""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np

from armdyn import _checks, _core
from armdyn.sizing.what_if import _ACTUATOR_FIELDS, MOTOR_FIELDS, _actuator_numbers

#: the keys of a joint's table (add_actuator's keywords; its motor is a sub-table)
ACTUATOR_KEYS = tuple(k for k in _ACTUATOR_FIELDS if k != "motor")
MOTOR_KEYS = MOTOR_FIELDS  # armdyn.Motor's keywords


def _derivative(t: np.ndarray, y: np.ndarray, order: int, joint: str) -> np.ndarray:
    if len(t) < 4:
        raise _core.ModelError(
            f"trajectory: {len(t)} samples are too few for a cubic spline of {joint!r} "
            "(4 at least), or give its .qd and .qdd columns"
        )
    from scipy.interpolate import CubicSpline

    return CubicSpline(t, y)(t, order)


def read_trajectory(path, model):
    """``(t, q, qd, qdd)`` from a trajectory CSV (see the module notes), columns ordered as
    ``model.coord_names`` / ``model.dof_names``. Raises ModelError naming the file and the
    missing, unknown or bad column."""
    path = Path(path)
    rows = list(csv.reader(io.StringIO(_text(path, "trajectory"), newline="")))
    if not rows:
        raise _core.ModelError(f"{path}: empty trajectory file")
    header = [h.strip() for h in rows[0]]
    coords, dofs = list(model.coord_names), list(model.dof_names)
    if coords != dofs:
        raise _core.ModelError(
            f"{path}: the robot's coordinates {coords} differ from its rates {dofs} (a floating "
            "base): armdyn size takes fixed-base arms"
        )
    known = {"t"} | set(coords) | {f"{c}.qd" for c in coords} | {f"{c}.qdd" for c in coords}
    unknown = [h for h in header if h not in known]
    if unknown:
        raise _core.ModelError(
            f"{path}: unknown column(s) {unknown}; expected t, the joints {coords} and optional "
            "<joint>.qd / <joint>.qdd"
        )
    missing = [c for c in ["t", *coords] if c not in header]
    if missing:
        raise _core.ModelError(f"{path}: missing column(s) {missing}")
    if len(set(header)) != len(header):
        raise _core.ModelError(f"{path}: repeated column names in {header}")
    data = _numbers(path, header, [r for r in rows[1:] if r])
    col = {h: data[:, k] for k, h in enumerate(header)}
    t = col["t"]
    if not np.all(np.diff(t) > 0.0):
        raise _core.ModelError(f"{path}: column t must be strictly increasing")
    q = np.stack([col[c] for c in coords], axis=1)
    qd = np.stack(
        [col[f"{c}.qd"] if f"{c}.qd" in col else _derivative(t, col[c], 1, c) for c in coords],
        axis=1,
    )
    qdd = np.stack(
        [col[f"{c}.qdd"] if f"{c}.qdd" in col else _derivative(t, col[c], 2, c) for c in coords],
        axis=1,
    )
    with np.errstate(all="ignore"):
        limit = np.nanmax(np.abs(data), axis=0, initial=0.0)
    for values, suffix in ((qd, ".qd"), (qdd, ".qdd")):
        bad = np.argwhere(~np.isfinite(values))
        if len(bad):
            r, c = bad[0]
            raise _core.ModelError(
                f"{path}: column {coords[c] + suffix!r}, data row {r + 1}: the spline derivative "
                f"of {coords[c]!r} overflows ({values[r, c]}); the positions are too large "
                f"(largest |{coords[c]}| = {limit[header.index(coords[c])]:.3g})"
            )
    return t, q, qd, qdd


#: the largest trajectory CSV or actuators TOML read [bytes] (the URDF loader's bound)
MAX_INPUT_BYTES = _core.URDF_MAX_BYTES


def _text(path: Path, what: str) -> str:
    """The UTF-8 text of an input file, read through the URDF loader's rules (a regular file of
    at most MAX_INPUT_BYTES: never a FIFO or a device)."""
    data = _checks.regular_file(path, f"{what} file", MAX_INPUT_BYTES)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise _core.ModelError(f"{path}: not UTF-8 text (byte offset {err.start})") from None


def _numbers(path: Path, header: list[str], rows: list[list[str]]) -> np.ndarray:
    """The data rows as floats, or a ModelError naming the column and the data row (1 = the
    first after the header) of a value that is not a finite number, or a short row."""
    if len(rows) < 2:
        raise _core.ModelError(f"{path}: need at least two data rows, got {len(rows)}")
    data = np.empty((len(rows), len(header)))
    for i, row in enumerate(rows):
        if len(row) != len(header):
            raise _core.ModelError(
                f"{path}: data row {i + 1} has {len(row)} values, the header {len(header)}"
            )
        for k, text in enumerate(row):
            try:
                x = float(text)
            except ValueError:
                x = None
            if x is None or not np.isfinite(x):
                raise _core.ModelError(
                    f"{path}: column {header[k]!r}, data row {i + 1}: {text.strip()!r} is not "
                    "a finite number"
                )
            data[i, k] = x
    return data


def read_actuators(path) -> dict[str, dict]:
    """``{joint: {add_actuator keyword: value, "motor": {Motor keyword: value} or None}}`` from
    an actuators TOML file. Raises ModelError naming the file, joint and key."""
    try:
        import tomllib
    except ImportError:  # Python 3.10
        try:
            import tomli as tomllib
        except ImportError as exc:
            raise _core.ModelError(
                f"{path}: reading TOML on Python 3.10 needs tomli (pip install tomli)"
            ) from exc
    path = Path(path)
    try:
        doc = tomllib.loads(_text(path, "actuators"))
    except tomllib.TOMLDecodeError as exc:
        raise _core.ModelError(f"{path}: not valid TOML ({exc})") from exc
    out = {}
    for joint, table in doc.items():
        if not isinstance(table, dict):
            raise _core.ModelError(f"{path}: {joint!r} must be a table [{joint}]")
        spec = {k: v for k, v in table.items() if k != "motor"}
        bad = [k for k in spec if k not in ACTUATOR_KEYS]
        if bad:
            raise _core.ModelError(
                f"{path}: [{joint}] unknown key(s) {bad}; allowed {ACTUATOR_KEYS}"
            )
        for key in ("gear_ratio", "rotor_inertia"):
            if key not in spec:
                raise _core.ModelError(f"{path}: [{joint}] needs {key}")
        motor = table.get("motor")
        if motor is not None:
            if not isinstance(motor, dict):
                raise _core.ModelError(f"{path}: [{joint}.motor] must be a table")
            bad = [k for k in motor if k not in MOTOR_KEYS]
            if bad:
                raise _core.ModelError(
                    f"{path}: [{joint}.motor] unknown key(s) {bad}; allowed {MOTOR_KEYS}"
                )
            for key, value in motor.items():
                check = _checks.text if key == "name" else _checks.number
                check(f"{path}: [{joint}.motor]", key, value)
        _actuator_numbers(f"{path}: [{joint}]", spec.get)
        spec["motor"] = motor
        out[str(joint)] = spec
    return out
