"""``armdyn size ROBOT.urdf --trajectory FILE.csv [--actuators FILE.toml] [--payload ...]
[--cycle ...] [--dwell ...] [--out DIR]``: the sizing report of a planned motion from the
command line (also importable as ``armdyn.size``, its former module).

Trajectory CSV: a header row, then one row per sample. Columns: ``t`` (strictly increasing, s),
one column per joint coordinate of the URDF (``model.coord_names``: positions, rad or m), and
optionally ``<joint>.qd`` and ``<joint>.qdd`` (rates and accelerations). Joints without them
are differentiated by a not-a-knot cubic spline through the positions (scipy's
``CubicSpline``).

Actuators TOML (optional): one table per joint with ``gear_ratio`` and ``rotor_inertia``
(kg m², motor side) and optionally ``efficiency``, ``friction_viscous`` (N m s/rad) and
``friction_coulomb`` (N m), motor side, and a ``motor`` sub-table of :class:`armdyn.Motor`
keywords (SI, motor side). They are evaluated on the URDF's rotor-free dynamics by the closed
form of :func:`armdyn.sizing_report`'s ``actuators=`` (what the model with
``add_actuator(..., gyroscopic=False)`` gives along the same motion)::

    [shoulder_pan_joint]
    gear_ratio = 100.0
    rotor_inertia = 3.3e-5        # kg m^2
    efficiency = 0.9
    [shoulder_pan_joint.motor]
    torque_constant = 0.07        # N m / A
    continuous_torque = 0.6       # N m
    peak_torque = 2.0

The command prints the report's table and, with ``--out``, writes the report there
(``report.html``, ``table.csv``, figures), and a line for each joint whose positions leave its
URDF ``<limit>`` (such a joint is not ok either). Exit code: 0 when every joint is ``ok``, 1
when some joint is not, 2 for bad input (one line names the file, column and data row, or key).

Options: ``--payload MASS[,X,Y,Z]`` welds a point mass [kg] to the robot (its centre of mass
[m] in the axes of ``--payload-frame NAME``, default the model's last frame
``model.frame_names[-1]``, from the frame's origin; :func:`add_payload`). ``--dwell SECONDS``
and ``--cycle N|forever`` make the motion a duty cycle (``armdyn.duty_cycle``; a dwell alone
repeats forever, ``--cycle`` alone has no dwell): the report is of one period
(:func:`cycle_motion`: the dwell holds the last pose with its holding torques, so peaks and RMS
values are those of the periodic cycle), plus the winding temperature check of the repeated
cycle (:func:`winding_temperature_check`). Of the check options (one per
:class:`~armdyn.sizing.options.SizingOptions` field, generated from the dataclass:
:func:`add_option_arguments`) ``armdyn size`` uses the thermal ones (:data:`SIZE_OPTIONS`,
with a duty cycle) and refuses the others, whose checks it does not make (exit code 2, saying
so; ``armdyn select`` takes them). Every option string is checked before a file is read; a
build without ``Model.with_payload`` or ``armdyn.duty_cycle`` refuses the options that need
them (exit code 2, naming what is missing) rather than ignoring them.

``--sweep MIN:MAX:N`` (with ``--actuators`` and ``--out``, :func:`parse_sweep`): the report
adds the gear-ratio sweep of the TOML's joints (:func:`armdyn.gear_ratio_sweep`).

``armdyn select ROBOT.urdf --trajectory FILE.csv --catalog PATH [--objective
mass|cost|bus_power|margin] [the options above] [--out DIR]`` (:func:`select_run`): the
drivetrain selection (``armdyn.select_drivetrain``) on the catalog(s) (``armdyn.load_catalog``;
a path must be a folder or a regular file) and the duty cycle; prints the selection's table,
writes its page with ``--out``; exit code 0 when every joint has a drivetrain that passes, 1
when not, 2 for bad input.

Both files are read as the URDF loader reads its own: a regular file (never a FIFO or a
device such as ``/dev/zero``) of at most ``MAX_INPUT_BYTES`` (64 MiB), UTF-8. Every value must
be a finite number, and so must the spline derivatives and the joint torques of the motion
(a trajectory that overflows them is bad input, named by column and data row).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from armdyn import _checks, _core
from armdyn.sizing.files import (  # noqa: F401  (read_trajectory, MAX_INPUT_BYTES: their old home)
    ACTUATOR_KEYS,
    MAX_INPUT_BYTES,
    MOTOR_KEYS,
    read_actuators,
    read_trajectory,
)


def run(
    urdf,
    trajectory,
    actuators=None,
    out=None,
    echo=print,
    *,
    payload=None,
    payload_frame=None,
    cycle=None,
    dwell=None,
    options=None,
    sweep=None,
) -> int:
    """The ``armdyn size`` command: returns the exit code (0 all ok, 1 some joint not ok).

    ``payload``, ``payload_frame``, ``cycle``, ``dwell`` are the options' strings
    (:func:`parse_payload`, :func:`parse_repeat`, :func:`parse_seconds`) and ``options``
    ``{SizingOptions field: string}`` (:func:`sizing_options_from_strings`); every one is
    checked before a file is read."""
    import pandas as pd

    from armdyn.sizing.limits import limit_violations
    from armdyn.sizing.report import sizing_report

    mass_com = parse_payload(payload) if payload is not None else None
    repeat, dwell_s = _cycle_strings(cycle, dwell)  # checked before any file is read
    overrides = sizing_options_from_strings(options or {})
    ratios = parse_sweep(sweep) if sweep is not None else None
    if ratios is not None and not actuators:
        raise _core.ModelError("--sweep needs --actuators (the motors and rotors it sweeps)")
    if ratios is not None and out is None:
        raise _core.ModelError("--sweep needs --out (the sweep is a section of the report)")
    spec = read_actuators(actuators) if actuators else None
    model = load_robot(urdf, mass_com, payload_frame)
    run_ = planned_motion(model, trajectory)
    _size_needs(overrides, cycle, dwell)
    duty = None
    if repeat is not _UNSET:
        from armdyn.sizing.cycle import duty_cycle

        duty = duty_cycle(model, run_, dwell=dwell_s or 0.0, repeat=repeat)
        run_ = cycle_motion(duty, model)
    report = sizing_report(run_, model, actuators=spec)
    if duty is not None:
        winding_temperature_check(report, duty, spec or {}, overrides)
    if out is not None:
        from armdyn.sizing.selection import gear_ratio_sweep

        swept = gear_ratio_sweep(run_, model, ratios, spec) if ratios is not None else None
        report.save(out, sweep=swept)
    with pd.option_context("display.max_columns", None, "display.width", 200):
        echo(report.table.to_string(float_format=lambda v: f"{v:.4g}"))
    bad = [str(j) for j, ok in report.table["ok"].items() if not ok]
    # positions beyond the joints' limits (the table's "ok" covers speed and torque)
    for row in limit_violations(model, run_).itertuples():
        if row.kind == "position":
            echo(
                f"{row.joint}: position {row.worst:.6g} beyond its limit {row.limit:.6g} "
                f"(t = {row.t_start:.6g} to {row.t_end:.6g} s)"
            )
            if row.joint not in bad:
                bad.append(str(row.joint))
    if out is not None:
        echo(f"report written to {Path(out).resolve() / 'report.html'}")
    echo("all joints ok" if not bad else f"not ok: {', '.join(bad)}")
    return 0 if not bad else 1


def load_robot(urdf, mass_com=None, frame=None):
    """The URDF's model, with the payload ``mass_com`` (:func:`parse_payload`) welded at
    ``frame`` (default the model's last frame, :func:`payload_frame`) when given."""
    from armdyn.urdf import load_urdf

    model = load_urdf(urdf)
    if mass_com is None:
        if frame is not None:
            raise _core.ModelError("--payload-frame is given without --payload")
        return model
    return add_payload(model, mass_com, payload_frame(model, frame))


def planned_motion(model, trajectory):
    """The :class:`~armdyn.TrajectoryRun` of the trajectory CSV on ``model``; an overflow of
    the inverse dynamics names the CSV's column and data row."""
    from armdyn.sizing.trajectory import trajectory_run

    t, q, qd, qdd = read_trajectory(trajectory, model)
    try:
        return trajectory_run(model, t, q, qd, qdd)
    except _core.SolverError as exc:
        raise _core.ModelError(f"{trajectory}: {_culprit(str(exc), model)}") from None


def cycle_motion(duty, model):
    """One period of the duty cycle ``duty`` (``armdyn.duty_cycle``) as a run the sizing report
    takes: its samples (the motion's, then the dwell's at its start and end, holding the last
    pose) with its torques (the dwell's: the holding torques). The report's peaks, RMS values
    and energies are then those of the periodic cycle, the dwell included (the same for any
    repeat count); its ``temperature_rise_*`` columns are of one period from the start, the
    repeated cycle's winding temperature is :func:`winding_temperature_check`'s."""
    from types import SimpleNamespace

    return SimpleNamespace(
        t=duty.t, q=duty.q, qd=duty.qd, qdd=duty.qdd, joint_torques=duty.torque, model=model
    )


#: the check options ``armdyn size`` uses (the winding temperature's); the others set checks
#: it does not make (gearbox life, emergency stops, bearing, brake)
SIZE_OPTIONS = ("ambient_temperature", "copper_temperature_coefficient", "resistance_temperature")


def winding_temperature_check(report, duty, spec: dict, overrides: dict) -> None:
    """Add the winding temperature check of the repeated cycle to ``report.table`` (in place):
    per actuated joint with a motor, ``winding_temperature_peak`` [°C] (the two-node model, or
    the one-node one with ``thermal_resistance`` / ``thermal_time_constant``, over
    ``duty.repeat`` periods from the ambient temperature or at the periodic steady state:
    :func:`armdyn.sizing.motor.motor_cycle_values` on ``duty.joint_load(joint)``, the gear's
    ratio, efficiency and the rotor inertia of the actuator; motor-side friction is not in
    that model), ``max_winding_temperature`` and ``winding_temperature_margin`` (rises above
    the ambient temperature; NaN: not checked, the datasheet values missing). A made check
    that fails makes the joint not ``ok``. The temperatures over the period of the peak
    (:func:`armdyn.sizing.motor.motor_cycle_series`) go to ``report.thermal``."""
    from armdyn.sizing.motor import motor_cycle_series, motor_cycle_values
    from armdyn.sizing.options import sizing_options

    options = sizing_options(**overrides)
    table = report.table
    peak, allowed, margin = (np.full(len(table), np.nan) for _ in range(3))
    for k, joint in enumerate(table.index):
        motor = report.envelopes.get(joint)
        if joint not in report.motors or motor is None:
            continue
        a = spec.get(joint, {})
        fields = {
            f: np.array([np.nan if getattr(motor, f, None) is None else getattr(motor, f)])
            for f in MOTOR_KEYS
            if f != "name"
        }
        load = duty.joint_load(joint)
        gear = (
            np.array([float(table.loc[joint, "gear_ratio"])]),
            np.array([float(a.get("efficiency", 1.0))]),
            np.array([float(a.get("rotor_inertia", 0.0))]),
        )
        values = motor_cycle_values(load, *gear, fields, options)
        if np.isfinite(values["winding_temperature_peak"][0]):
            series = motor_cycle_series(load, *gear, motor, options)
            report.thermal[str(joint)] = tuple(
                series[c] for c in ("t", "winding_temperature", "housing_temperature")
            )
        peak[k] = values["winding_temperature_peak"][0]
        allowed[k] = fields["max_winding_temperature"][0]
        margin[k] = values["winding_temperature"][0]
    table["winding_temperature_peak"] = peak
    table["max_winding_temperature"] = allowed
    table["winding_temperature_margin"] = margin
    table["ok"] = table["ok"].to_numpy(dtype=bool) & ~(margin < 1.0)


def _size_needs(overrides, cycle, dwell) -> None:
    """``armdyn size``'s options: those of checks it does not make are refused (never
    ignored), and the thermal ones need a duty cycle (``--cycle`` or ``--dwell``)."""
    other = [f"--{k.replace('_', '-')}" for k in overrides if k not in SIZE_OPTIONS]
    if other:
        raise _core.ModelError(
            f"{', '.join(other)}: armdyn size does not make the checks these set (gearbox life, "
            "emergency stops, output bearing, brake: armdyn select makes them)"
        )
    if overrides and cycle is None and dwell is None:
        given = ", ".join(f"--{k.replace('_', '-')}" for k in overrides)
        raise _core.ModelError(
            f"{given}: the winding temperature is checked on a duty cycle: give --cycle or --dwell"
        )


def _culprit(message: str, model) -> str:
    """The inverse dynamics' overflow message with its row and input entry (``row 3: ... the
    largest input is qd[0]``) named as the CSV's data row and column."""
    import re

    m = re.search(r"row (\d+): .*the largest input is (q|qd|qdd)\[(\d+)\] = (\S+)", message)
    if not m:
        return message
    row, arg, k, value = int(m[1]), m[2], int(m[3]), m[4]
    column = model.coord_names[k] + ("" if arg == "q" else f".{arg}")
    return (
        f"column {column!r}, data row {row + 1}: {value} overflows the inverse dynamics "
        "(the joint torques are not finite); the trajectory's values are too large"
    )


# --------------------------------------------------------------------- option strings

#: ``--cycle`` not given (a single pass; ``None`` is ``forever``)
_UNSET = object()


def _number(option: str, text: str, what: str, whole: str | None = None) -> float:
    """``float(text)``, finite, or a ModelError ``<option> '<whole>': <what> must be a finite
    number`` (``whole``: the option's whole value, default ``text``)."""
    try:
        x = float(text)
    except (TypeError, ValueError):
        x = None
    if x is None or not np.isfinite(x):
        shown = text if whole is None else whole
        part = "" if whole is None else f" ({text!r})"
        raise _core.ModelError(f"{option} {shown!r}: {what}{part} must be a finite number")
    return x


def parse_payload(text: str) -> tuple[float, tuple[float, float, float]]:
    """``(mass, com)`` of ``--payload MASS[,X,Y,Z]``: the mass [kg] (finite, > 0) and its
    centre of mass [m] in the payload frame's axes, from its origin (default the origin).
    ModelError naming the option and the bad field otherwise."""
    fields = str(text).split(",")
    if len(fields) not in (1, 4):
        raise _core.ModelError(
            f"--payload {text!r}: expected MASS or MASS,X,Y,Z (kg, then the centre of mass in m), "
            f"got {len(fields)} comma-separated value(s)"
        )
    whole = None if len(fields) == 1 else str(text)
    mass = _number("--payload", fields[0].strip(), "the mass (kg)", whole)
    if not mass > 0.0:
        raise _core.ModelError(f"--payload {text!r}: the mass must be > 0 kg, got {mass:g}")
    if len(fields) == 1:
        return mass, (0.0, 0.0, 0.0)
    x, y, z = (
        _number("--payload", f.strip(), f"the centre of mass' {axis} (m)", whole)
        for axis, f in zip("xyz", fields[1:], strict=True)
    )
    return mass, (x, y, z)


def payload_frame(model, name: str | None) -> str:
    """The frame the payload is welded at: ``name``, which must be one of
    ``model.frame_names``, or by default the model's last frame (``model.frame_names[-1]``:
    the URDF's last link, e.g. a UR5's ``tool0``)."""
    frames = list(model.frame_names)
    if name is None:
        if not frames:
            raise _core.ModelError("--payload: the robot has no frame to weld the payload to")
        return frames[-1]
    if name not in frames:
        raise _core.ModelError(
            f"--payload-frame {name!r}: the robot has no such frame; its frames: {frames}"
        )
    return name


def add_payload(model, mass_com: tuple[float, tuple[float, float, float]], frame: str):
    """``model.with_payload(frame, mass, com=com)`` (a point mass; the one place the commands
    call it)."""
    mass, com = mass_com
    return model.with_payload(frame, mass, com=com)


#: the most gear ratios ``--sweep`` evaluates
MAX_SWEEP = 10_000


def parse_sweep(text: str) -> np.ndarray:
    """``--sweep MIN:MAX:N``: N gear ratios spaced geometrically from MIN to MAX (0 < MIN <=
    MAX finite, 1 <= N <= :data:`MAX_SWEEP`)."""
    fields = str(text).split(":")
    if len(fields) != 3:
        raise _core.ModelError(f"--sweep {text!r}: expected MIN:MAX:N (e.g. 20:200:19)")
    lo = _number("--sweep", fields[0].strip(), "MIN", str(text))
    hi = _number("--sweep", fields[1].strip(), "MAX", str(text))
    n = fields[2].strip()
    if not (0.0 < lo <= hi):
        raise _core.ModelError(f"--sweep {text!r}: need 0 < MIN <= MAX")
    if not n.isdigit() or not 1 <= int(n) <= MAX_SWEEP:
        raise _core.ModelError(f"--sweep {text!r}: N must be a whole number from 1 to {MAX_SWEEP}")
    return np.geomspace(lo, hi, int(n))


def parse_repeat(text: str) -> int | None:
    """``--cycle N|forever``: a positive repeat count, or None for ``forever``."""
    t = str(text).strip()
    if t.lower() == "forever":
        return None
    if not t.isdigit() or int(t) < 1:
        raise _core.ModelError(
            f"--cycle {text!r}: expected a positive whole number of repeats or 'forever'"
        )
    return int(t)


def parse_seconds(text: str, option: str = "--dwell") -> float:
    """A duration [s] of an option: finite and >= 0."""
    x = _number(option, str(text).strip(), "the duration (s)")
    if x < 0.0:
        raise _core.ModelError(f"{option} {text!r}: the duration must be >= 0 s")
    return x


def _cycle_strings(cycle, dwell):
    """``(repeat, dwell)`` of ``--cycle``/``--dwell``: ``_UNSET`` / None where not given; a
    dwell alone repeats forever."""
    repeat = parse_repeat(cycle) if cycle is not None else _UNSET
    dwell_s = parse_seconds(dwell) if dwell is not None else None
    if dwell_s is not None and repeat is _UNSET:
        repeat = None
    return repeat, dwell_s


#: short spellings of some options (besides --<field-name-with-dashes>)
OPTION_ALIASES = {"ambient_temperature": "--ambient", "required_life": "--life"}


def option_docs() -> dict[str, str]:
    """``{field: its sentence}`` from :class:`~armdyn.sizing.options.SizingOptions`'
    docstring (the one place the options are described)."""
    import re

    from armdyn.sizing.options import OPTION_NAMES, SizingOptions

    doc = (SizingOptions.__doc__ or "").split("Attributes:", 1)[-1]
    out, name = {}, None
    for line in doc.splitlines():
        m = re.match(r"\s{4,8}(\w+): (.*)", line)
        if m and m.group(1) in OPTION_NAMES:
            name = m.group(1)
            out[name] = m.group(2).strip()
        elif name and line.strip():
            out[name] += " " + line.strip()
    return out


def add_option_arguments(parser) -> None:
    """One ``--<field>`` option per :class:`~armdyn.sizing.options.SizingOptions` field
    (``OPTION_NAMES``, its docstring and default; plus :data:`OPTION_ALIASES`)."""
    from armdyn.sizing.options import OPTION_NAMES, SizingOptions

    group = parser.add_argument_group("check options (armdyn.sizing.SizingOptions)")
    docs, defaults = option_docs(), SizingOptions()
    for name in OPTION_NAMES:
        flags = [f"--{name.replace('_', '-')}"]
        if name in OPTION_ALIASES:
            flags.append(OPTION_ALIASES[name])
        default = getattr(defaults, name)
        text = docs.get(name, name).replace("%", "%%")
        group.add_argument(*flags, dest=name, metavar="X", help=f"{text} Default {default:g}.")


def option_strings(args) -> dict[str, str]:
    """``{field: string}`` of the options given on the command line."""
    from armdyn.sizing.options import OPTION_NAMES

    return {n: getattr(args, n) for n in OPTION_NAMES if getattr(args, n, None) is not None}


def sizing_options_from_strings(strings: dict[str, str]) -> dict[str, float]:
    """The option overrides as numbers, checked by :class:`SizingOptions` (a bad value is a
    ModelError naming the option)."""
    from armdyn.sizing.options import sizing_options

    values = {}
    for name, text in strings.items():
        values[name] = _number(f"--{name.replace('_', '-')}", str(text).strip(), "the value")
    try:
        sizing_options(**values)
    except _core.ModelError as exc:
        raise _core.ModelError(f"{_option_flag(str(exc))}{exc}") from None
    return values


def _option_flag(message: str) -> str:
    from armdyn.sizing.options import OPTION_NAMES

    for name in OPTION_NAMES:
        if name in message:
            return f"--{name.replace('_', '-')}: "
    return ""


def _command(name: str, call) -> int:
    """``call()``'s exit code; bad input (a ModelError, UrdfError, SolverError or OSError) one
    line on stderr naming the command, exit code 2."""
    try:
        return call()
    except (_core.ModelError, _core.UrdfError, _core.SolverError, OSError) as exc:
        print(f"armdyn {name}: {exc}", file=sys.stderr)
        return 2


def main(args) -> int:
    return _command(
        "size",
        lambda: run(
            args.urdf,
            args.trajectory,
            args.actuators,
            args.out,
            payload=args.payload,
            payload_frame=args.payload_frame,
            cycle=args.cycle,
            dwell=args.dwell,
            options=option_strings(args),
            sweep=args.sweep,
        ),
    )


# --------------------------------------------------------------------------- armdyn select


def catalog_paths(paths) -> list[Path]:
    """The ``--catalog`` paths: each an existing folder or regular file (never a FIFO or a
    device: a ModelError naming it; a missing one: FileNotFoundError naming it)."""
    import os
    import stat

    out = []
    for p in paths:
        st = os.stat(p)  # FileNotFoundError / PermissionError name the path
        if not (stat.S_ISDIR(st.st_mode) or stat.S_ISREG(st.st_mode)):
            raise _core.ModelError(
                f"--catalog {str(p)!r} is {_checks._file_kind(st.st_mode)}, not a folder or a "
                "regular file"
            )
        out.append(Path(p))
    return out


def select_run(
    urdf,
    trajectory,
    catalogs,
    objective="mass",
    out=None,
    echo=print,
    *,
    payload=None,
    payload_frame=None,
    cycle=None,
    dwell=None,
    options=None,
) -> int:
    """The ``armdyn select`` command: returns the exit code (0: every joint has a drivetrain
    that passes, 1: some joint has none). Every option string is checked before a file is
    read."""
    from armdyn.sizing.catalog import load_catalog
    from armdyn.sizing.cycle import duty_cycle
    from armdyn.sizing.drivetrain import OBJECTIVES
    from armdyn.sizing.select import select_drivetrain

    if objective not in OBJECTIVES:
        raise _core.ModelError(f"--objective {objective!r}: expected one of {list(OBJECTIVES)}")
    mass_com = parse_payload(payload) if payload is not None else None
    repeat, dwell_s = _cycle_strings(cycle, dwell)
    overrides = sizing_options_from_strings(options or {})
    paths = catalog_paths(catalogs)
    model = load_robot(urdf, mass_com, payload_frame)
    run_ = planned_motion(model, trajectory)
    duty = duty_cycle(
        model, run_, dwell=dwell_s or 0.0, repeat=None if repeat is _UNSET else repeat
    )
    catalog = load_catalog(*paths)
    selection = select_drivetrain(model, duty, catalog, objective=objective, **overrides)
    return _print_selection(selection, out, echo, catalog)


def _print_selection(selection, out, echo, catalog=None) -> int:
    import pandas as pd

    table = selection.table
    with pd.option_context("display.max_columns", None, "display.width", 200):
        echo(table.to_string(float_format=lambda v: f"{v:.4g}"))
    if out is not None:
        from armdyn.sizing.writer import write_selection_report

        page = write_selection_report(selection, out, catalog)
        echo(f"report written to {page.resolve()}")
    bad = [str(j) for j, ok in table["ok"].items() if not ok]
    echo("every joint has a drivetrain that passes" if not bad else f"not ok: {', '.join(bad)}")
    return 0 if not bad else 1


def select_main(args) -> int:
    return _command(
        "select",
        lambda: select_run(
            args.urdf,
            args.trajectory,
            args.catalog,
            args.objective,
            args.out,
            payload=args.payload,
            payload_frame=args.payload_frame,
            cycle=args.cycle,
            dwell=args.dwell,
            options=option_strings(args),
        ),
    )
