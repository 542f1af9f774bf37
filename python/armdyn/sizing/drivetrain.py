"""The per-candidate evaluation engine of the drivetrain selection
(:func:`armdyn.select_drivetrain`, whose search is :mod:`armdyn.sizing.select`).

A **candidate** of a joint is one motor with one gearbox (with one drive when drives are
checked): every row of the catalog's ``motors`` times every row of its ``gearboxes`` (times every
row of its ``drives``). :func:`evaluate_joint` screens all of a joint's candidates against one
load (a :class:`armdyn.sizing.cycle.JointLoad`) with the vectorised functions of the checks,
in chunks of candidates so that memory stays bounded:

- the gearbox's own values (life, average torque and input speed, repeated peak, input speed)
  and its output bearing's depend on the gearbox alone: evaluated once per gearbox;
- the motor side (torques with the rotor and gearbox input inertia reflected, currents,
  voltage, the two-node thermal model), the emergency stop and the brake depend on the motor
  and the gearbox: evaluated per (motor, gearbox) pair, the rotor inertia being the motor's
  ``rotor_inertia`` plus the gearbox's ``input_inertia`` (both on the motor shaft);
- the drive's currents and voltage depend on the pair and the drive: per (pair, drive).

Every margin goes through :data:`armdyn.sizing.checks.CHECKS` and
:func:`armdyn.sizing.checks.verdict`: a candidate is ``ok`` when every checked margin is ≥ 1.

**Ranking.** The feasible candidates come first, by the objective (ascending; for ``"margin"``
by least margin, descending), ties broken by the least margin (descending; for ``"margin"`` by
the actuator mass), then by catalog order (motor, gearbox, drive rows); the infeasible ones
follow by least margin (descending: the closest first), then by the objective. The objectives:

- ``"mass"``: motor + gearbox mass [kg] (what the arm carries);
- ``"cost"``: motor + gearbox (+ drive) ``cost`` (the catalog's unit);
- ``"bus_power"``: the axis's peak electrical power [W] (``peak_electrical_power``); summed
  over the joints it is the power the DC bus must deliver when the axes' peaks coincide (an
  upper bound of the peak of the summed power, which the selection reports for the chosen set);
- ``"margin"``: the least margin (larger is better).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from armdyn import _core
from armdyn.sizing import motor as _motor_module
from armdyn.sizing.checks import CHECKS, verdict

#: the objectives of the selection, each with its label (and unit) in figures
OBJECTIVE_LABELS: dict[str, str] = {
    "mass": "mass [kg]",
    "cost": "cost",
    "bus_power": "peak electrical power [W]",
    "margin": "least margin",
}
#: the objectives of the selection
OBJECTIVES: tuple[str, ...] = tuple(OBJECTIVE_LABELS)

#: candidates × samples per chunk of the motor-side evaluation (bounds the memory of the
#: (k, n) arrays the vectorised functions build)
CHUNK_ELEMENTS = 1_000_000

#: the most candidates of one joint (motors × gearboxes × drives) a selection screens: every
#: candidate keeps its values and margins (about 60 numbers, 0.5 kB), so this bounds the memory
#: to about 0.1 GB per joint
MAX_CANDIDATES = 200_000

_WHO = "select_drivetrain"


@dataclass
class CatalogParts:
    """A catalog's parts as arrays, prepared once for every joint.

    Attributes:
        motor_names, gearbox_names, drive_names: the part names (row order of the catalog);
            ``drive_names`` is empty when drives are not checked.
        motors, gearboxes, drives: ``{column: (rows,) float array}`` of every numeric column.
        motor_mass, gearbox_mass: (rows,) [kg].
        cost_motor, cost_gearbox, cost_drive: (rows,) costs, or None when not needed.
    """

    motor_names: np.ndarray
    gearbox_names: np.ndarray
    drive_names: np.ndarray
    motors: dict[str, np.ndarray]
    gearboxes: dict[str, np.ndarray]
    drives: dict[str, np.ndarray]
    motor_mass: np.ndarray
    gearbox_mass: np.ndarray
    cost_motor: np.ndarray | None = None
    cost_gearbox: np.ndarray | None = None
    cost_drive: np.ndarray | None = None

    @property
    def with_drives(self) -> bool:
        return len(self.drive_names) > 0

    @property
    def n_candidates(self) -> int:
        d = max(len(self.drive_names), 1)
        return len(self.motor_names) * len(self.gearbox_names) * d


def _table(catalog, kind: str):
    """The catalog's DataFrame of ``kind`` (``motors``, ``gearboxes``, ``drives``) or None."""
    table = getattr(catalog, kind, None)
    if table is None:
        return None
    if not hasattr(table, "columns") or not hasattr(table, "index"):
        raise _core.ModelError(
            f"{_WHO}: catalog.{kind} must be a pandas DataFrame, got {type(table).__name__}"
        )
    return table


def _columns(table) -> dict[str, np.ndarray]:
    """Every numeric column of a part table as a float array."""
    out = {}
    for col in table.columns:
        series = table[col]
        if series.dtype.kind in "fiu":
            out[str(col)] = series.to_numpy(dtype=float)
    return out


def _required(kind: str, names: np.ndarray, cols: dict, column: str, why: str) -> np.ndarray:
    """``cols[column]``, finite and ≥ 0 in every row, else a ModelError naming the part."""
    if column not in cols:
        raise _core.ModelError(f"{_WHO}: catalog {kind} has no {column!r} column ({why})")
    values = cols[column]
    bad = ~np.isfinite(values) | (values < 0)
    if np.any(bad):
        row = int(np.flatnonzero(bad)[0])
        raise _core.ModelError(
            f"{_WHO}: catalog {kind} {names[row]!r} has {column} = {float(values[row])!r} "
            f"({why}: a finite number >= 0 is needed)"
        )
    return values


def catalog_parts(catalog, drives: bool, objective: str) -> CatalogParts:
    """The catalog's parts as arrays, checked for what the selection needs: some motors and
    gearboxes, drives when ``drives``; every part's ``mass`` (the arm carries it), the motor's
    ``rotor_inertia``, the gearbox's ``ratio`` (> 0), ``efficiency`` and ``input_inertia``;
    ``cost`` of every part for the cost objective. A missing or bad one is a ModelError naming
    the part and the column."""
    motors, gearboxes = _table(catalog, "motors"), _table(catalog, "gearboxes")
    for kind, table in (("motors", motors), ("gearboxes", gearboxes)):
        if table is None or len(table) == 0:
            raise _core.ModelError(f"{_WHO}: the catalog has no {kind}")
    drive_table = _table(catalog, "drives") if drives else None
    if drives and (drive_table is None or len(drive_table) == 0):
        raise _core.ModelError(
            f"{_WHO}: drives=True but the catalog has no drives (drives.csv); pass "
            "drives=False to select without the drive checks"
        )
    names = {
        "motor": np.asarray([str(n) for n in motors.index], dtype=object),
        "gearbox": np.asarray([str(n) for n in gearboxes.index], dtype=object),
        "drive": np.asarray(
            [] if drive_table is None else [str(n) for n in drive_table.index], dtype=object
        ),
    }
    cols = {
        "motor": _columns(motors),
        "gearbox": _columns(gearboxes),
        "drive": {} if drive_table is None else _columns(drive_table),
    }
    n_candidates = len(names["motor"]) * len(names["gearbox"]) * max(len(names["drive"]), 1)
    if n_candidates > MAX_CANDIDATES:
        raise _core.ModelError(
            f"{_WHO}: {len(names['motor'])} motors x {len(names['gearbox'])} gearboxes"
            + (f" x {len(names['drive'])} drives" if len(names["drive"]) else "")
            + f" = {n_candidates} candidates per joint, more than MAX_CANDIDATES = "
            f"{MAX_CANDIDATES} (narrow the catalog, or pass drives=False)"
        )
    carried = "the arm carries it"
    parts = CatalogParts(
        names["motor"],
        names["gearbox"],
        names["drive"],
        cols["motor"],
        cols["gearbox"],
        cols["drive"],
        _required("motor", names["motor"], cols["motor"], "mass", carried),
        _required("gearbox", names["gearbox"], cols["gearbox"], "mass", carried),
    )
    _required("motor", names["motor"], cols["motor"], "rotor_inertia", "the motor side")
    _required("gearbox", names["gearbox"], cols["gearbox"], "input_inertia", "the motor side")
    _required("gearbox", names["gearbox"], cols["gearbox"], "efficiency", "the motor side")
    ratio = _required("gearbox", names["gearbox"], cols["gearbox"], "ratio", "the motor side")
    if np.any(ratio <= 0):
        row = int(np.flatnonzero(ratio <= 0)[0])
        raise _core.ModelError(
            f"{_WHO}: catalog gearbox {names['gearbox'][row]!r} has ratio = {float(ratio[row])!r} "
            "(must be > 0)"
        )
    if objective == "cost":
        why = "objective='cost'"
        parts.cost_motor = _required("motor", names["motor"], cols["motor"], "cost", why)
        parts.cost_gearbox = _required("gearbox", names["gearbox"], cols["gearbox"], "cost", why)
        if drives:
            parts.cost_drive = _required("drive", names["drive"], cols["drive"], "cost", why)
    return parts


@dataclass
class JointEvaluation:
    """Every candidate of one joint against one load.

    Attributes:
        joint: the joint.
        motor, gearbox, drive: (K,) row indices into the catalog's parts (drive -1 without
            drives); candidate c is motor row ``motor[c]`` with gearbox row ``gearbox[c]``.
        values: ``{value column: (K,)}``: every value the checks computed, ``gear_ratio``,
            ``mass`` (motor + gearbox) and ``cost`` (when known).
        margins: ``{check name: (K,)}`` (NaN: not checked).
        ok, binding_check, margin: the verdict of each candidate.
        objective: (K,) the objective's value.
        order: (K,) candidate indices, best first (see the module notes).
    """

    joint: str
    motor: np.ndarray
    gearbox: np.ndarray
    drive: np.ndarray
    values: dict[str, np.ndarray]
    margins: dict[str, np.ndarray]
    ok: np.ndarray
    binding_check: np.ndarray
    margin: np.ndarray
    objective: np.ndarray
    order: np.ndarray

    @property
    def best(self) -> int:
        """The best candidate (its index)."""
        return int(self.order[0])

    @property
    def n_feasible(self) -> int:
        return int(np.count_nonzero(self.ok))


def _split(out: dict) -> tuple[dict, dict]:
    """``(values, margins)`` of a check function's output: a check's margin is under its
    ``<name>_margin`` key, or under its name where that is not also its value column (the
    motor side's keys); every other numeric (k,) entry is a value."""
    margins, taken = {}, set()
    for check in CHECKS:
        for key in (check.margin_column, check.name):
            if key in out and (key != check.name or check.name != check.value):
                margins[check.name] = out[key]
                taken.add(key)
                break
    values = {}
    for key, val in out.items():
        if key not in taken and not key.endswith("_margin"):
            arr = np.asarray(val)
            if arr.dtype.kind in "fiub" and arr.ndim <= 1:
                values[key] = arr
    return values, margins


def _rows(cols: dict[str, np.ndarray], index: np.ndarray) -> dict[str, np.ndarray]:
    return {c: v[index] for c, v in cols.items()}


def _gearbox_stage(load, parts: CatalogParts, options) -> tuple[dict, dict]:
    """The gearbox's and its output bearing's values and margins, once per gearbox."""
    from armdyn.sizing import gearbox as gearbox_module

    ratio = parts.gearboxes["ratio"]
    gear = gearbox_module.gearbox_cycle_values(load, ratio, parts.gearboxes, options)
    bearing = gearbox_module.bearing_cycle_values(load, parts.gearboxes, options)
    values, margins = _split(gear)
    more_values, more_margins = _split(bearing)
    values.update(more_values)
    margins.update(more_margins)
    return values, margins


def _pair_stage(load, parts: CatalogParts, mi: np.ndarray, gi: np.ndarray, options):
    """The motor side, the emergency stop and the brake of the (motor, gearbox) pairs
    ``(mi, gi)``: ``(values, margins)``, each ``{name: (k,)}``."""
    from armdyn.sizing import drive as drive_module
    from armdyn.sizing import gearbox as gearbox_module

    gb = parts.gearboxes
    ratio, eff = gb["ratio"][gi], gb["efficiency"][gi]
    rotor = parts.motors["rotor_inertia"][mi] + gb["input_inertia"][gi]
    motors = _rows(parts.motors, mi)
    out = _motor_module.motor_cycle_values(load, ratio, eff, rotor, motors, options)
    values, margins = _split(out)
    brake_torque = motors.get("brake_torque", np.full(len(mi), np.nan))
    # the emergency stop: the harder of the drive's (the motor's peak torque) and the brake's
    stop = np.fmax(motors.get("peak_torque", np.full(len(mi), np.nan)), brake_torque)
    estop = gearbox_module.emergency_stop_values(
        load, ratio, eff, rotor, stop, _rows(gb, gi), options
    )
    brake = drive_module.brake_values(load, ratio, brake_torque, options)
    for extra in (estop, brake):
        v, m = _split(extra)
        values.update(v)
        margins.update(m)
    values["rotor_inertia_total"] = rotor
    return values, margins


def _drive_stage(values: dict, parts: CatalogParts, di: np.ndarray) -> tuple[dict, dict]:
    """The drive checks of pairs whose motor values are ``values`` (already tiled to the
    drives ``di``). A motor value that is +inf (a thermal runaway's current and voltage) fails
    its drive check (margin 0 where the drive gives the rating); the drive functions take
    finite values only, so it goes to them as NaN."""
    from armdyn.sizing import drive as drive_module

    checks = [c for c in CHECKS if c.part == "drive"]
    infinite = {c.value: np.isposinf(values[c.value]) for c in checks if c.value in values}
    clean = dict(values)
    for key, mask in infinite.items():
        clean[key] = np.where(mask, np.nan, values[key])
    out = drive_module.drive_values(clean, _rows(parts.drives, di))
    out_values, margins = _split(out)
    for check in checks:
        mask = infinite.get(check.value)
        if mask is not None and check.name in margins and np.any(mask):
            rating = np.asarray(out.get(check.allowable, np.full(len(mask), np.nan)), float)
            failed = np.where(np.isnan(rating), np.nan, 0.0)
            margins[check.name] = np.where(mask, failed, margins[check.name])
    return out_values, margins


def _chunks(n_pairs: int, n_samples: int):
    """Slices of the pair range, each at most CHUNK_ELEMENTS / n_samples pairs."""
    size = max(1, CHUNK_ELEMENTS // max(n_samples, 1))
    for start in range(0, n_pairs, size):
        yield slice(start, min(start + size, n_pairs))


def _append(store: dict, new: dict) -> None:
    for key, val in new.items():
        store.setdefault(key, []).append(np.asarray(val, dtype=float))


def _chunk_stage(load, parts: CatalogParts, options, sl: slice, gear: tuple[dict, dict]):
    """The candidates of the (motor, gearbox) pairs ``sl`` (pair p = motor p // g with gearbox
    p % g), each with every drive (pair-major, drive-minor): ``(values, margins, rows)``."""
    g, d = len(parts.gearbox_names), len(parts.drive_names)
    pair = np.arange(sl.start, sl.stop)
    mi, gi = pair // g, pair % g
    pv, pm = _pair_stage(load, parts, mi, gi, options)
    pv.update({k: v[gi] for k, v in gear[0].items()})
    pm.update({k: v[gi] for k, v in gear[1].items()})
    di = np.full(len(pair), -1)
    if d:
        mi, gi, di = np.repeat(mi, d), np.repeat(gi, d), np.tile(np.arange(d), len(pair))
        pv = {k: np.repeat(v, d) for k, v in pv.items()}
        pm = {k: np.repeat(v, d) for k, v in pm.items()}
        dv, dm = _drive_stage(pv, parts, di)
        pv.update(dv)
        pm.update(dm)
    return pv, pm, np.stack([mi, gi, di])


def _screen(load, parts: CatalogParts, options) -> tuple[dict, dict, np.ndarray]:
    """Every candidate's values and margins (the chunks joined) and the candidate ->
    (motor, gearbox, drive) rows."""
    pairs = len(parts.motor_names) * len(parts.gearbox_names)
    gear = _gearbox_stage(load, parts, options)
    n_samples = len(np.atleast_1d(load.t))
    values: dict = {}
    margins: dict = {}
    rows = []
    for sl in _chunks(pairs, n_samples):
        pv, pm, r = _chunk_stage(load, parts, options, sl, gear)
        _append(values, pv)
        _append(margins, pm)
        rows.append(r)
    join = {k: np.concatenate(v) for k, v in values.items()}
    return join, {k: np.concatenate(v) for k, v in margins.items()}, np.concatenate(rows, 1)


def _objective_values(objective: str, values: dict, margin: np.ndarray) -> np.ndarray:
    """The objective's value of every candidate (see the module notes)."""
    if objective == "mass":
        return values["mass"]
    if objective == "cost":
        return values["cost"]
    if objective == "bus_power":
        if "peak_electrical_power" not in values:
            raise _core.ModelError(f"{_WHO}: the motor side gives no peak_electrical_power")
        return values["peak_electrical_power"]
    return margin


def rank(ok: np.ndarray, margin: np.ndarray, objective: str, objective_values, mass):
    """Candidate indices, best first (see the module notes)."""
    idx = np.arange(len(ok))
    least = np.where(np.isnan(margin), -np.inf, margin)
    if objective == "margin":
        primary, second = -least, mass
    else:
        primary, second = objective_values, -least
    feasible, infeasible = idx[ok], idx[~ok]
    first = feasible[np.lexsort((feasible, second[feasible], primary[feasible]))]
    rest = infeasible[np.lexsort((infeasible, objective_values[infeasible], -least[infeasible]))]
    return np.concatenate([first, rest])


def evaluate_joint(joint: str, load, parts: CatalogParts, options, objective: str):
    """Every candidate of ``joint`` against ``load``: a :class:`JointEvaluation`."""
    values, margins, rows = _screen(load, parts, options)
    mi, gi, di = rows
    values["gear_ratio"] = parts.gearboxes["ratio"][gi]
    values["mass"] = parts.motor_mass[mi] + parts.gearbox_mass[gi]
    if parts.cost_motor is not None and parts.cost_gearbox is not None:
        cost = parts.cost_motor[mi] + parts.cost_gearbox[gi]
        if parts.cost_drive is not None:
            cost = cost + parts.cost_drive[di]
        values["cost"] = cost
    checked = {c.name: margins[c.name] for c in CHECKS if c.name in margins}
    if not checked:
        raise _core.ModelError(f"{_WHO}: no check gave a margin for joint {joint!r}")
    ok, binding, least = verdict(checked)
    obj = np.asarray(_objective_values(objective, values, least), dtype=float)
    order = rank(ok, least, objective, obj, values["mass"])
    return JointEvaluation(joint, mi, gi, di, values, checked, ok, binding, least, obj, order)


def candidate_parts(parts: CatalogParts, ev: JointEvaluation, c: int) -> tuple[str, str, Any]:
    """``(motor, gearbox, drive)`` names of candidate ``c`` (drive None without drives)."""
    drive = parts.drive_names[ev.drive[c]] if ev.drive[c] >= 0 else None
    return parts.motor_names[ev.motor[c]], parts.gearbox_names[ev.gearbox[c]], drive
