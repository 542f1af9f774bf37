"""The drivetrain selection (:func:`select_drivetrain`): per joint, the best motor × gearbox (×
drive) of a catalog for a duty cycle, with the actuators' masses carried by the arm.

Each joint's candidates are screened by :mod:`armdyn.sizing.drivetrain` (every check of
:data:`armdyn.sizing.checks.CHECKS`, in closed form from the cycle's load at the joint) and
ranked by the objective. The choice is **coupled**: an actuator's housing (motor + gearbox
mass) sits on the arm, by default on its joint's *parent* body at the joint's point, so it
loads the joints between it and the base but not its own joint nor the joints beyond it. The
search therefore goes from the distal joints to the proximal ones (deepest in the kinematic
tree first): when a joint is chosen, the actuators of every joint beyond it are already on the
model (``model.with_payload``), and the cycle is re-run on that model (``cycle.with_model``, the
same motion: its torques and reactions recomputed). A pass visits every joint once this way;
passes repeat until one changes no joint's choice, so that the result is a fixed point: every
joint's choice is the best for the loads that the model *carrying all the chosen actuators*
gives, and the table's values are that model's. On a serial arm with the default mounts the
first pass already reaches it and the second confirms it (``passes == 2``); a mount that puts an
actuator on its own joint's child or beyond (``mounts=``) couples joints both ways and may need
more. A joint whose load did not change between passes is not re-screened.

The fixed point is the best set overall (what an exhaustive search over every combination of
every joint's parts gives, the coupled masses included) when a heavier actuator never makes a
check of a joint nearer the base easier, the usual case; a mass that unloads a proximal joint
(a counterweight) can make a heavier distal choice better overall, which the fixed point does
not explore.

A joint with no feasible candidate takes its closest one (largest least margin), whose mass is
carried, and :attr:`DrivetrainSelection.infeasible` says which check no candidate passes and the
best margin reached on it, by which parts.
"""

from __future__ import annotations

import dataclasses
import os
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from armdyn import _checks, _core
from armdyn.sizing.checks import CHECKS, CHECKS_BY_NAME
from armdyn.sizing.drivetrain import (
    OBJECTIVES,
    CatalogParts,
    JointEvaluation,
    candidate_parts,
    catalog_parts,
    evaluate_joint,
)
from armdyn.sizing.options import sizing_options

_WHO = "select_drivetrain"

#: the value columns of the selection's table (those the checks computed)
TABLE_VALUES: tuple[str, ...] = (
    "gear_ratio",
    "motor_rms_torque",
    "motor_peak_torque",
    "motor_peak_speed",
    "winding_temperature_peak",
    "peak_current",
    "rms_current",
    "peak_electrical_power",
    "gear_average_torque",
    "gear_life",
    "gear_repeated_peak_torque",
    "gear_momentary_torque",
    "bearing_peak_moment",
    "bearing_life",
)

#: the joint types a drivetrain is selected for
_ACTUATED_TYPES = ("revolute", "prismatic")


@dataclass
class DrivetrainSelection:
    """Result of :func:`select_drivetrain`.

    Attributes:
        table: DataFrame indexed by joint: ``motor``, ``gearbox``, ``drive`` (None without
            drives), ``ok``, ``binding_check``, ``margin`` (the least margin), ``objective``
            (its value for the choice), ``mass`` (motor + gearbox, kg), ``cost`` (with the cost
            objective), the main values of the checks (``gear_ratio``, ``motor_rms_torque``,
            ... where the checks give them), ``candidates`` and ``feasible`` (how many were
            screened and passed), then every check's ``<check>_margin`` (NaN: not checked).
            A joint with no feasible candidate shows its closest one (``ok`` False).
        objective: the objective ranked by.
        passes: the coupled passes made (each re-runs the cycle with the actuators chosen).
        converged: True when the last pass changed no choice (False: ``max_passes`` reached or
            the choices cycle; a warning says so and ``ok`` is False).
        history: the choice after each pass, ``[{joint: (motor, gearbox, drive)}]``.
        infeasible: DataFrame, one row per (joint with no feasible candidate, failing check):
            ``joint``, ``check``, ``part`` (motor, gearbox, bearing, drive or brake),
            ``best_margin`` (the best margin any candidate reaches on it), ``motor``,
            ``gearbox``, ``drive`` (the candidate reaching it) and ``reason``; empty when every
            joint has a feasible candidate.
        bus: the DC bus of the chosen set (``armdyn.sizing.drive.bus_values``), or None
            without drives.
        model: the model carrying the chosen actuators (the one the table's values are of).
        cycle: the duty cycle on that model.
        options: the :class:`armdyn.sizing.options.SizingOptions` used.
        catalog: the catalog the parts were chosen from.
    """

    table: Any
    objective: str
    passes: int
    converged: bool
    history: list
    infeasible: Any
    bus: dict | None
    model: Any
    cycle: Any
    options: Any
    catalog: Any = field(repr=False)
    _parts: CatalogParts = field(repr=False)
    _evaluations: dict = field(repr=False)

    @property
    def ok(self) -> bool:
        """Every joint feasible, the search converged and every bus check that was made
        passed."""
        bus_ok = True
        if self.bus:
            bus_ok = all(
                not (np.isfinite(v) and v < 1.0)
                for k, v in self.bus.items()
                if k.endswith("_margin") and np.ndim(v) == 0
            )
        return bool(self.converged and bool(self.table["ok"].all()) and bus_ok)

    def save(self, directory: str | os.PathLike[str]) -> Path:
        """Write the selection's report into ``directory`` (created if missing):
        ``report.html`` (one self-contained page: the verdict first, one row per joint with its
        parts, pass or fail, binding check and margin; then the checks by part, the duty
        cycle's torques, each chosen motor's temperatures and operating points, the ranking
        and each joint's objective against its least margin), its figures and
        ``selection.csv`` (:attr:`table`). Needs matplotlib (the ``plot`` extra). Returns the
        page's path."""
        from armdyn.sizing.writer import write_selection_report

        return write_selection_report(self, directory, self.catalog)

    def candidates(self, joint: str, n: int | None = None):
        """The joint's candidates ranked, best first (the choice is rank 1): a DataFrame
        indexed by ``rank`` with the columns of :attr:`table` for each (every value the checks
        computed and every margin); ``n`` the first n only (default all)."""
        if joint not in self._evaluations:
            raise _core.ModelError(
                f"DrivetrainSelection.candidates: joint {joint!r} was not selected "
                f"(selected: {list(self._evaluations)})"
            )
        n = _checks.integer("DrivetrainSelection.candidates", "n", n, lo=1, none=True)
        ev = self._evaluations[joint]
        order = ev.order if n is None else ev.order[:n]
        return _candidate_frame(self._parts, ev, order)

    def explain(self) -> str:
        """One line per joint: its choice and verdict, and for a joint with no feasible
        candidate the checks no candidate passes (or the closest candidate's failing checks)."""
        lines = []
        for joint, row in self.table.iterrows():
            state = "ok" if row["ok"] else "NO FEASIBLE CANDIDATE"
            lines.append(
                f"{joint}: {row['motor']} + {row['gearbox']}"
                + (f" + {row['drive']}" if row["drive"] is not None else "")
                + f": {state}, binding {row['binding_check']} (margin {row['margin']:.3g})"
            )
            if len(self.infeasible):
                for _, why in self.infeasible[self.infeasible["joint"] == joint].iterrows():
                    lines.append(f"  {why['reason']}")
        if not self.converged:
            lines.append(f"not converged after {self.passes} passes")
        return "\n".join(lines)


def _candidate_frame(parts: CatalogParts, ev: JointEvaluation, order: np.ndarray):
    """The rows of candidates ``order`` (a DataFrame indexed by rank from 1)."""
    import pandas as pd

    names = [candidate_parts(parts, ev, int(c)) for c in order]
    data: dict[str, Any] = {
        "motor": [n[0] for n in names],
        "gearbox": [n[1] for n in names],
        "drive": [n[2] for n in names],
        "ok": ev.ok[order],
        "binding_check": ev.binding_check[order],
        "margin": ev.margin[order],
        "objective": ev.objective[order],
    }
    for key in sorted(ev.values):
        data.setdefault(key, ev.values[key][order])
    for check in CHECKS:
        if check.name in ev.margins:
            data[check.margin_column] = ev.margins[check.name][order]
    return pd.DataFrame(data, index=pd.RangeIndex(1, len(order) + 1, name="rank"))


# ---------------------------------------------------------------------------------------------
# arguments


def _cycle_of(model, cycle):
    """The duty cycle on ``model``: a DutyCycle (re-run on ``model`` when it is another's) or
    any motion :func:`armdyn.duty_cycle` takes."""
    if not (hasattr(cycle, "joint_load") and hasattr(cycle, "with_model")):
        from armdyn.sizing.cycle import duty_cycle

        cycle = duty_cycle(model, cycle)
    if cycle.model is not model:
        cycle = cycle.with_model(model)
    return cycle


def _joints(model, cycle, joints) -> list[str]:
    """The joints to select for: default every revolute or prismatic joint of the cycle's
    columns; an unknown or non-actuable one is a ModelError naming it."""
    types = dict(zip(model.joint_names, model.joint_types, strict=True))
    columns = list(cycle.names)
    actuable = [j for j in columns if types.get(j) in _ACTUATED_TYPES]
    if joints is None:
        if not actuable:
            raise _core.ModelError(f"{_WHO}: the cycle has no revolute or prismatic joint")
        return actuable
    if isinstance(joints, str):
        joints = [joints]
    try:
        joints = list(joints)
    except TypeError:
        raise _core.ModelError(
            f"{_WHO}: joints must be a list of joint names, got {type(joints).__name__}"
        ) from None
    if not joints:
        raise _core.ModelError(f"{_WHO}: joints is empty (default: every actuable joint)")
    for j in joints:
        if not isinstance(j, str) or j not in actuable:
            raise _core.ModelError(
                f"{_WHO}: joints: {j!r} is not a revolute or prismatic joint of the cycle "
                f"(those: {actuable})"
            )
    if len(set(joints)) != len(joints):
        raise _core.ModelError(f"{_WHO}: joints: a joint is listed twice ({joints})")
    return joints


def _default_mount(model, joint: str):
    """``(at, com)``: the joint's point on its parent body; None on the ground (a housing
    fixed to the world loads nothing). ``with_payload`` takes a name that is also a frame's
    (a URDF link's) as that frame: the point is then given in the frame's axes from its
    origin."""
    jf = model.joint_frame(joint)
    body = str(jf["parent"])
    if body == "ground":
        return None
    point = np.asarray(jf["point_parent"], dtype=float)  # body axes, from its centre of mass
    if body in model.frame_names:
        frame = model.frame(body)
        if frame["body"] != body:
            raise _core.ModelError(
                f"{_WHO}: joint {joint!r}: its parent body {body!r} shares its name with a "
                f"frame on body {frame['body']!r}; pass mounts={{{joint!r}: (at, com)}}"
            )
        rotation = np.asarray(frame["rotation"], dtype=float)
        point = rotation.T @ (point - np.asarray(frame["point"], dtype=float))
    return body, point


def _mount(model, joint: str, spec):
    """A user mount: None (not carried), ``at`` or ``(at, com)``."""
    if spec is None:
        return None
    at, com = (spec, (0.0, 0.0, 0.0)) if isinstance(spec, str) else (None, None)
    if at is None:
        try:
            at, com = spec
        except (TypeError, ValueError):
            raise _core.ModelError(
                f"{_WHO}: mounts[{joint!r}] must be None, a frame or body name, or (at, com), "
                f"got {spec!r}"
            ) from None
    places = set(model.body_names) | set(model.frame_names)
    if not isinstance(at, str) or at not in places:
        raise _core.ModelError(
            f"{_WHO}: mounts[{joint!r}]: {at!r} is not a body or frame of the model"
        )
    com = _checks.array(_WHO, f"mounts[{joint!r}] com", com, finite=True)
    if com.shape != (3,):
        raise _core.ModelError(f"{_WHO}: mounts[{joint!r}] com must be 3 numbers")
    return None if at == "ground" else (at, com)


def _mounts(model, joints: list[str], mounts) -> dict:
    """Every joint's mount (default: its point on its parent body)."""
    if mounts is None:
        mounts = {}
    if not isinstance(mounts, dict):
        raise _core.ModelError(
            f"{_WHO}: mounts must be a dict {{joint: (at, com)}}, got {type(mounts).__name__}"
        )
    unknown = [j for j in mounts if j not in joints]
    if unknown:
        raise _core.ModelError(
            f"{_WHO}: mounts: {unknown[0]!r} is not a selected joint (selected: {joints})"
        )
    return {
        j: _mount(model, j, mounts[j]) if j in mounts else _default_mount(model, j) for j in joints
    }


def _distal_first(model, joints: list[str]) -> list[str]:
    """``joints`` ordered deepest in the kinematic tree first (ties: later in the model
    first)."""
    child_joint = {}
    for j in model.joint_names:
        child_joint[str(model.joint_frame(j)["child"])] = j

    def depth(j: str) -> int:
        d, body, seen = 0, str(model.joint_frame(j)["parent"]), set()
        while body in child_joint and body not in seen:
            seen.add(body)
            d += 1
            body = str(model.joint_frame(child_joint[body])["parent"])
        return d

    position = {j: i for i, j in enumerate(model.joint_names)}
    return sorted(joints, key=lambda j: (-depth(j), -position[j]))


# ---------------------------------------------------------------------------------------------
# the coupled search


def _with_actuators(model, carried: dict, mounts: dict):
    """``model`` carrying each joint's actuator mass ``carried[joint]`` at its mount (a point
    mass)."""
    payloads = [
        {
            "at": mounts[joint][0],
            "mass": float(mass),
            "com": tuple(float(x) for x in mounts[joint][1]),
            "name": f"{joint}_actuator",
        }
        for joint, mass in carried.items()
        if mounts[joint] is not None and mass > 0.0
    ]
    if not payloads:
        return model
    if hasattr(model, "with_payloads"):
        return model.with_payloads(payloads)
    out = model
    for p in payloads:
        out = out.with_payload(p["at"], p["mass"], com=p["com"], name=p["name"])
    return out


def _same_load(a, b) -> bool:
    """Whether two joint loads are the same (every array field equal)."""
    fa = {f.name: getattr(a, f.name) for f in dataclasses.fields(a)}
    fb = {f.name: getattr(b, f.name) for f in dataclasses.fields(b)}
    for key, va in fa.items():
        vb = fb[key]
        if isinstance(va, np.ndarray) or isinstance(vb, np.ndarray):
            if not np.array_equal(np.asarray(va), np.asarray(vb)):
                return False
        elif va != vb:
            return False
    return True


@dataclass
class _Search:
    """The state of the coupled search."""

    model: Any
    cycle: Any
    order: list[str]
    parts: CatalogParts
    mounts: dict
    options: Any
    objective: str
    choice: dict = field(default_factory=dict)
    carried: dict = field(default_factory=dict)
    loads: dict = field(default_factory=dict)
    evaluations: dict = field(default_factory=dict)
    current: tuple = ()
    current_model: Any = None
    current_cycle: Any = None

    def cycle_now(self):
        """The cycle on the model carrying the actuators chosen so far (re-run only when a
        carried mass changed)."""
        key = tuple(
            sorted((j, float(m)) for j, m in self.carried.items() if self.mounts[j] is not None)
        )
        if self.current_cycle is None or key != self.current:
            self.current_model = _with_actuators(self.model, self.carried, self.mounts)
            self.current_cycle = (
                self.cycle
                if self.current_model is self.model
                else self.cycle.with_model(self.current_model)
            )
            self.current = key
        return self.current_cycle

    def visit(self, joint: str) -> bool:
        """Screen ``joint`` on the current model; whether its choice changed."""
        load = self.cycle_now().joint_load(joint)
        if joint not in self.loads or not _same_load(self.loads[joint], load):
            self.evaluations[joint] = evaluate_joint(
                joint, load, self.parts, self.options, self.objective
            )
            self.loads[joint] = load
        ev = self.evaluations[joint]
        best = ev.best
        changed = self.choice.get(joint) != best
        self.choice[joint] = best
        self.carried[joint] = float(ev.values["mass"][best])
        return changed

    def state(self) -> dict:
        return {
            j: candidate_parts(self.parts, self.evaluations[j], c) for j, c in self.choice.items()
        }


def _run_passes(search: _Search, max_passes: int) -> tuple[int, bool, list]:
    """Passes distal to proximal until one changes nothing: ``(passes, converged, history)``."""
    history: list = []
    seen: list = []
    for p in range(1, max_passes + 1):
        changed = [j for j in search.order if search.visit(j)]
        history.append(search.state())
        if not changed:
            return p, True, history
        key = tuple(search.choice[j] for j in search.order)
        if key in seen:
            warnings.warn(
                f"{_WHO}: the choices cycle between passes (joints {changed} keep changing); "
                "the selection is not converged",
                stacklevel=3,
            )
            return p, False, history
        seen.append(key)
    warnings.warn(
        f"{_WHO}: not converged after max_passes={max_passes} (joints {changed} still changed)",
        stacklevel=3,
    )
    return max_passes, False, history


# ---------------------------------------------------------------------------------------------
# the result


def _table(search: _Search, joints: list[str]):
    """The selection's table, indexed by joint, in ``joints`` order."""
    import pandas as pd

    rows = []
    for joint in joints:
        ev = search.evaluations[joint]
        c = search.choice[joint]
        motor, gearbox, drive = candidate_parts(search.parts, ev, c)
        row: dict[str, Any] = {
            "motor": motor,
            "gearbox": gearbox,
            "drive": drive,
            "ok": bool(ev.ok[c]),
            "binding_check": str(ev.binding_check[c]),
            "margin": float(ev.margin[c]),
            "objective": float(ev.objective[c]),
            "mass": float(ev.values["mass"][c]),
        }
        if "cost" in ev.values:
            row["cost"] = float(ev.values["cost"][c])
        for key in TABLE_VALUES:
            if key in ev.values:
                row[key] = float(ev.values[key][c])
        row["candidates"] = len(ev.ok)
        row["feasible"] = ev.n_feasible
        for check in CHECKS:
            if check.name in ev.margins:
                row[check.margin_column] = float(ev.margins[check.name][c])
        rows.append(row)
    return pd.DataFrame(rows, index=pd.Index(joints, name="joint"))


def _explain_joint(parts: CatalogParts, ev: JointEvaluation) -> list[dict]:
    """Why a joint has no feasible candidate: each check no candidate passes, with the best
    margin reached on it and by which candidate; when every check is passed by some candidate
    but none passes all, the closest candidate's failing checks."""
    rows = []
    for name, m in ev.margins.items():
        if np.all(np.isnan(m)):
            continue
        c = int(np.nanargmax(m))
        if m[c] < 1.0:
            motor, gearbox, drive = candidate_parts(parts, ev, c)
            part = CHECKS_BY_NAME[name].part
            rows.append(
                {
                    "joint": ev.joint,
                    "check": name,
                    "part": part,
                    "best_margin": float(m[c]),
                    "motor": motor,
                    "gearbox": gearbox,
                    "drive": drive,
                    "reason": f"no candidate passes {name} ({part}): best margin "
                    f"{m[c]:.3g}, by motor {motor} with gearbox {gearbox}"
                    + (f" and drive {drive}" if drive is not None else ""),
                }
            )
    if rows:
        return sorted(rows, key=lambda r: r["best_margin"])
    c = ev.best
    motor, gearbox, drive = candidate_parts(parts, ev, c)
    for name, m in ev.margins.items():
        if m[c] < 1.0:
            rows.append(
                {
                    "joint": ev.joint,
                    "check": name,
                    "part": CHECKS_BY_NAME[name].part,
                    "best_margin": float(m[c]),
                    "motor": motor,
                    "gearbox": gearbox,
                    "drive": drive,
                    "reason": f"every check is passed by some candidate but none passes all; "
                    f"the closest, motor {motor} with gearbox {gearbox}, fails {name} "
                    f"(margin {m[c]:.3g})",
                }
            )
    return sorted(rows, key=lambda r: r["best_margin"])


def _infeasible(search: _Search, joints: list[str]):
    import pandas as pd

    rows = []
    for joint in joints:
        ev = search.evaluations[joint]
        if not ev.ok[search.choice[joint]]:
            rows.extend(_explain_joint(search.parts, ev))
    columns = ["joint", "check", "part", "best_margin", "motor", "gearbox", "drive", "reason"]
    return pd.DataFrame(rows, columns=columns)


def _bus_parameters(drives: dict[str, np.ndarray]) -> dict[str, float]:
    """The common DC bus of the chosen drives (one per axis), in the catalog's column names:
    the capacitances and the braking resistors' continuous and peak powers add up (those given;
    NaN when none is); the nominal voltage is the largest of the drives' and the chopper's
    voltage the smallest (the capacitors absorb the least energy); NaN when that is below the
    nominal one (drives of different bus voltages: no common capacitor window)."""
    out = {}
    for key, reduce in (
        ("bus_voltage", np.max),
        ("max_bus_voltage", np.min),
        ("bus_capacitance", np.sum),
        ("braking_resistor_power", np.sum),
        ("braking_resistor_peak_power", np.sum),
    ):
        if key in drives:
            given = drives[key][~np.isnan(drives[key])]
            out[key] = float(reduce(given)) if len(given) else np.nan
    if out.get("max_bus_voltage", np.nan) < out.get("bus_voltage", np.nan):
        out["max_bus_voltage"] = np.nan
    return out


def _bus(search: _Search, joints: list[str]) -> dict | None:
    """The DC bus of the chosen set: every axis's electrical power over the cycle
    (``motor_cycle_series``) summed by ``armdyn.sizing.drive.bus_values`` with the chosen
    drives' common bus (:func:`_bus_parameters`); None without drives."""
    if not search.parts.with_drives:
        return None
    from armdyn.sizing import drive as drive_module
    from armdyn.sizing import motor as motor_module

    parts = search.parts
    power, drive_rows = [], []
    for joint in joints:
        ev, c = search.evaluations[joint], search.choice[joint]
        mi, gi, di = int(ev.motor[c]), int(ev.gearbox[c]), int(ev.drive[c])
        gb = {k: float(v[gi]) for k, v in parts.gearboxes.items()}
        motor = {k: float(v[mi]) for k, v in parts.motors.items()}
        rotor = motor["rotor_inertia"] + gb["input_inertia"]
        series = motor_module.motor_cycle_series(
            search.loads[joint], gb["ratio"], gb["efficiency"], rotor, motor, search.options
        )
        power.append(np.asarray(series["electrical_power"], dtype=float))
        drive_rows.append(di)
    bus = _bus_parameters({k: v[np.asarray(drive_rows)] for k, v in parts.drives.items()})
    load = search.loads[joints[0]]
    out = drive_module.bus_values(load.t, np.stack(power), load.period, bus)
    return {k: float(np.asarray(v).reshape(-1)[0]) for k, v in out.items()}


def select_drivetrain(
    model,
    cycle,
    catalog,
    objective: str = "mass",
    joints=None,
    mounts=None,
    drives: bool = True,
    options=None,
    max_passes: int = 10,
    **option_overrides,
) -> DrivetrainSelection:
    """Per joint, the best motor × gearbox (× drive) of ``catalog`` for the duty cycle
    ``cycle``, each actuator's mass carried by the arm (see :mod:`armdyn.sizing.select`).

    Args:
        model: the arm (an :class:`armdyn.Model`, without the actuators' housings).
        cycle: a :class:`armdyn.sizing.cycle.DutyCycle` (re-run on ``model`` when it is
            another model's) or a motion :func:`armdyn.duty_cycle` takes.
        catalog: an :class:`armdyn.sizing.catalog.Catalog` (``motors``, ``gearboxes`` and,
            with ``drives``, ``drives`` DataFrames indexed by part name).
        objective: ``"mass"`` (motor + gearbox mass), ``"cost"`` (motor + gearbox + drive
            ``cost``), ``"bus_power"`` (the axis's peak electrical power) or ``"margin"`` (the
            largest least margin). See :mod:`armdyn.sizing.drivetrain`.
        joints: the joints to select for (default: every revolute or prismatic joint of the
            cycle).
        mounts: ``{joint: (at, com)}``: where a joint's actuator mass sits, ``at`` a body or a
            frame of the model and ``com`` the point in its axes from its origin (a body: its
            centre of mass); ``{joint: at}`` for com (0, 0, 0); ``{joint: None}`` for an
            actuator the arm does not carry. Default: the joint's point on its parent body
            (none for a joint on the ground). The mass is a point mass.
        drives: True: every candidate also takes each of the catalog's drives (the drive and
            bus checks); False: no drive.
        options: :class:`armdyn.sizing.options.SizingOptions`; ``option_overrides`` replace
            its fields (``required_life=30000``, ...).
        max_passes: the coupled passes allowed (≥ 1).

    Returns:
        A :class:`DrivetrainSelection`.

    Raises:
        ModelError: an unknown objective, joint, mount or option; a catalog without motors or
            gearboxes, without drives with ``drives=True``, or a part without a value the
            selection needs (mass, rotor inertia, ratio, efficiency, input inertia; cost for
            the cost objective), naming it; more than
            :data:`armdyn.sizing.drivetrain.MAX_CANDIDATES` candidates per joint.

    Warns:
        UserWarning: when the passes do not converge (the result's ``converged`` is False).
    """
    objective = _checks.choice(_WHO, "objective", objective, OBJECTIVES)
    drives = _checks.flag(_WHO, "drives", drives)
    allowed = _checks.integer(_WHO, "max_passes", max_passes, lo=1, hi=1000)
    assert allowed is not None  # not none=True
    options = sizing_options(options, **option_overrides)
    if not isinstance(model, _core.Model):
        raise _core.ModelError(f"{_WHO}: model must be an armdyn.Model, got {type(model).__name__}")
    parts = catalog_parts(catalog, drives, objective)
    cycle = _cycle_of(model, cycle)
    joints = _joints(model, cycle, joints)
    mounts = _mounts(model, joints, mounts)
    search = _Search(model, cycle, _distal_first(model, joints), parts, mounts, options, objective)
    passes, converged, history = _run_passes(search, allowed)
    return DrivetrainSelection(
        table=_table(search, joints),
        objective=objective,
        passes=passes,
        converged=converged,
        history=history,
        infeasible=_infeasible(search, joints),
        bus=_bus(search, joints),
        model=search.current_model,
        cycle=search.cycle_now(),
        options=options,
        catalog=catalog,
        _parts=parts,
        _evaluations={j: search.evaluations[j] for j in joints},
    )
