"""Effort and velocity limits along a run, and the joint-side sizing report.

Both work on a finished run (:class:`armdyn.SimulationResult` or
:class:`armdyn.InverseDynamicsResult`) and the model it came from; the results do not hold their
model, so it is passed explicitly and checked against the result's columns.

Conventions shared by both functions:

- Columns are the result's ``qd`` columns: ``model.joint_dof_names`` (every joint coordinate, the
  couplings' followers included). The effort and velocity limits of the independent coordinates
  come from ``model.coord_effort_limit`` / ``model.coord_velocity_limit``; a coupling's follower
  takes its own joint's limits (``model.joint_limits``). ``inf`` where there is none.
- Joint torques/forces are the efforts of the run's drives (``result.drive_forces``), summed per
  driven coordinate (``model.drive_coords``). A coordinate without a drive has no effort in the
  result (a passive joint, or an ``add_motor`` controller whose torque is not reported yet):
  its torque-based values are NaN and its effort limit is not checked.
- Everything is evaluated at the output samples only: peaks are the largest sampled values, RMS
  and energies use the trapezoid rule over the samples, and a limit violation that begins and
  ends between two samples is not seen.

This is the first slice of the sizing work (issue 22): joint-side values only. Motor-side
values, actuators (gear ratio, rotor inertia, efficiency), motor envelopes, gear-ratio sweeps
and a command-line tool are not part of it.
"""

from __future__ import annotations

import html
import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from armdyn import _core

if TYPE_CHECKING:  # pandas is imported when a table is built: `import armdyn` stays light
    import pandas as pd

_VIOLATION_COLUMNS = ["joint", "kind", "t_start", "t_end", "worst", "limit", "samples"]


def _column_names(model) -> list[str]:
    names = getattr(model, "joint_dof_names", None)
    return list(names if names is not None else model.dof_names)


def _limit(value: float) -> float:
    """A joint's stored effort/velocity limit as the model's properties report it: inf where
    unset (0) or unbounded (>= 1e300)."""
    return float(value) if 0.0 < value < 1e300 else np.inf


def _column_limits(model, names: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """(effort, velocity) limit of each result column."""
    indep = list(model.dof_names)
    effort_i = np.asarray(model.coord_effort_limit, dtype=float)
    velocity_i = np.asarray(model.coord_velocity_limit, dtype=float)
    joints = set(model.joint_names)
    effort = np.full(len(names), np.inf)
    velocity = np.full(len(names), np.inf)
    for k, name in enumerate(names):
        if name in indep:
            i = indep.index(name)
            effort[k], velocity[k] = effort_i[i], velocity_i[i]
        elif name in joints:  # a coupling's follower: its own joint's limits
            lim = model.joint_limits(name)
            effort[k], velocity[k] = _limit(lim["effort"]), _limit(lim["velocity"])
    return effort, velocity


def _checked(model, result, caller: str):
    """(t, column names, qd, efforts per column (NaN where undriven)) after checking that the
    result belongs to the model."""
    names = _column_names(model)
    t = np.asarray(result.t, dtype=float)
    qd = np.asarray(result.qd, dtype=float)
    forces = np.asarray(result.drive_forces, dtype=float)
    if t.ndim != 1:
        raise _core.ModelError(f"{caller}: result.t must be one-dimensional, got shape {t.shape}")
    if qd.ndim != 2 or qd.shape != (len(t), len(names)):
        raise _core.ModelError(
            f"{caller}: result.qd has shape {qd.shape} but the model has {len(names)} joint "
            f"rate columns ({names}) and the result {len(t)} samples: the result is not from "
            "this model"
        )
    n_drives = len(model.drive_names)
    if forces.ndim != 2 or forces.shape != (len(t), n_drives):
        raise _core.ModelError(
            f"{caller}: result.drive_forces has shape {forces.shape} but the model has "
            f"{n_drives} drives ({list(model.drive_names)}) and the result {len(t)} samples: the "
            "result is not from this model"
        )
    tau = np.full(qd.shape, np.nan)
    for d, col in enumerate(model.drive_coords):
        if not 0 <= col < len(names):
            raise _core.ModelError(
                f"{caller}: drive {model.drive_names[d]!r} acts on column {col}, outside the "
                f"{len(names)} joint rate columns"
            )
        tau[:, col] = np.where(np.isnan(tau[:, col]), 0.0, tau[:, col]) + forces[:, d]
    return t, names, qd, tau


def _spans(mask: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) index of each maximal run of True in ``mask``."""
    m = np.concatenate([[False], mask, [False]]).astype(np.int8)
    d = np.diff(m)
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1, strict=True))


def limit_violations(model, result) -> pd.DataFrame:
    """Where a run exceeds its joints' velocity and effort limits.

    Args:
        model: the model the run was made with.
        result: a :class:`~armdyn.SimulationResult` or :class:`~armdyn.InverseDynamicsResult`.

    Returns:
        A DataFrame with one row per violation span, sorted by ``t_start``: ``joint`` (the
        coordinate's name, a column of ``result.qd``), ``kind`` (``"velocity"``: ``|qd| > limit``;
        ``"effort"``: ``|drive torque/force| > limit``), ``t_start`` and ``t_end`` (the first and
        last output sample beyond the limit), ``worst`` (the sampled value of largest magnitude in
        the span, signed), ``limit`` and ``samples`` (how many output samples the span covers).
        Empty (with these columns) when the run stays within its limits.

    A span is a maximal run of consecutive output samples beyond the limit: spans are resolved
    at the output samples only (a true crossing lies up to one output step before ``t_start``
    and after ``t_end``; an excursion between two samples is not seen). Efforts are checked on
    driven coordinates only (see the module notes).

    Raises:
        ModelError: the result's columns do not match the model (names the mismatch).
    """
    import pandas as pd

    t, names, qd, tau = _checked(model, result, "limit_violations")
    effort_limit, velocity_limit = _column_limits(model, names)
    rows = []
    for kind, values, limits in (("velocity", qd, velocity_limit), ("effort", tau, effort_limit)):
        for k, name in enumerate(names):
            if not np.isfinite(limits[k]):
                continue
            x = values[:, k]
            with np.errstate(invalid="ignore"):
                beyond = np.abs(x) > limits[k]
            for i0, i1 in _spans(beyond):
                seg = x[i0 : i1 + 1]
                worst = seg[np.argmax(np.abs(seg))]
                rows.append((name, kind, t[i0], t[i1], float(worst), float(limits[k]), i1 - i0 + 1))
    table = pd.DataFrame(rows, columns=_VIOLATION_COLUMNS)
    return table.sort_values(["t_start", "joint", "kind"], kind="stable", ignore_index=True)


def _trapezoid(y: np.ndarray, t: np.ndarray) -> np.ndarray:
    """∫ y dt over the samples, per column (trapezoid rule)."""
    dt = np.diff(t)[:, None]
    return np.sum(0.5 * (y[1:] + y[:-1]) * dt, axis=0)


@dataclass
class SizingReport:
    """Joint-side sizing values of a run (see :func:`sizing_report`).

    Attributes:
        table: DataFrame indexed by joint (coordinate) name.
        t: (n,) output times [s].
        torque: (n, n_columns) drive torque/force per coordinate (NaN where undriven).
        speed: (n, n_columns) joint rates ``result.qd``.
    """

    table: pd.DataFrame
    t: np.ndarray
    torque: np.ndarray
    speed: np.ndarray

    def save(self, directory) -> Path:
        """Write ``table.csv``, ``report.html`` (the table and one torque-against-time figure per
        driven joint) and the figures ``torque_<k>.png`` into ``directory`` (created if missing).
        Needs matplotlib (the ``plot`` extra). Returns the HTML page's path."""
        # a bare Figure (Agg canvas): no pyplot state, the user's backend is left alone
        from matplotlib.figure import Figure

        out = Path(os.fspath(directory))
        out.mkdir(parents=True, exist_ok=True)
        self.table.to_csv(out / "table.csv")
        figures = []
        for k, name in enumerate(self.table.index):
            tau = self.torque[:, k]
            if np.all(np.isnan(tau)):
                continue
            fig = Figure(figsize=(6.0, 3.0))
            ax = fig.subplots()
            ax.plot(self.t, tau, lw=1.0, label="drive torque/force")
            limit = self.table["effort_limit"].iloc[k]
            if np.isfinite(limit):
                ax.axhline(limit, color="r", ls="--", lw=0.8, label="effort limit")
                ax.axhline(-limit, color="r", ls="--", lw=0.8)
            ax.set_xlabel("t [s]")
            ax.set_ylabel("torque [N m] or force [N]")
            ax.set_title(str(name))
            ax.legend(loc="best", fontsize="small")
            fig.tight_layout()
            png = f"torque_{k}.png"
            fig.savefig(out / png, dpi=100)
            figures.append((name, png))
        parts = [
            "<!DOCTYPE html>",
            '<html><head><meta charset="utf-8"><title>armdyn sizing report</title></head><body>',
            "<h1>Sizing report (joint side)</h1>",
            self.table.to_html(float_format=lambda v: f"{v:.6g}"),
        ]
        for name, png in figures:
            label = html.escape(str(name))
            parts.append(f'<h2>{label}</h2><img src="{png}" alt="torque of {label}">')
        parts.append("</body></html>")
        page = out / "report.html"
        page.write_text("\n".join(parts), encoding="utf-8")
        return page


def sizing_report(result, model) -> SizingReport:
    """Peak and RMS torque and speed, power, regenerated energy and limit margins per joint.

    Args:
        result: a :class:`~armdyn.SimulationResult` or :class:`~armdyn.InverseDynamicsResult`
            with at least two output samples spanning a positive time.
        model: the model the run was made with.

    Returns:
        A :class:`SizingReport` whose ``.table`` is indexed by joint (coordinate) name, the
        columns of ``result.qd``, with (joint side, SI units):

        - ``peak_torque`` = max |τ|, ``rms_torque`` = √(1/T ∫ τ² dt),
        - ``peak_speed`` = max |q̇|, ``rms_speed`` = √(1/T ∫ q̇² dt),
        - ``peak_power`` = max |τ q̇|,
        - ``energy_regenerated`` = −∫ min(τ q̇, 0) dt (the work the load does on the actuator,
          reported positive),
        - ``effort_limit``, ``velocity_limit`` (inf where none),
        - ``torque_margin`` = effort_limit / peak_torque, ``speed_margin`` =
          velocity_limit / peak_speed (inf for a zero peak),
        - ``ok``: no checked value beyond its limit (peak ≤ limit, the same test as
          :func:`limit_violations`).

        Integrals use the trapezoid rule over the output samples, T = t[-1] − t[0]; peaks are
        the largest sampled values. τ is the run's drive torque/force (``result.drive_forces``,
        summed per driven coordinate); a coordinate without a drive has NaN in every torque
        column (``peak_torque``, ``rms_torque``, ``peak_power``, ``energy_regenerated``,
        ``torque_margin``) and ``ok`` then checks its speed only.

    Motor-side values (gear ratio, rotor inertia, current, motor envelopes), gear-ratio sweeps
    and a CLI are not part of this first slice.

    Raises:
        ModelError: the result's columns do not match the model, or fewer than two samples /
            a zero time span.
    """
    import pandas as pd

    t, names, qd, tau = _checked(model, result, "sizing_report")
    if len(t) < 2 or not (t[-1] > t[0]):
        raise _core.ModelError(
            f"sizing_report: the result needs at least two samples over a positive time span, "
            f"got {len(t)} sample(s) over [{t[0] if len(t) else 'n/a'}, "
            f"{t[-1] if len(t) else 'n/a'}]"
        )
    span = t[-1] - t[0]
    effort_limit, velocity_limit = _column_limits(model, names)
    power = tau * qd
    with np.errstate(invalid="ignore", divide="ignore"):
        peak_torque = np.max(np.abs(tau), axis=0)
        peak_speed = np.max(np.abs(qd), axis=0)
        table = pd.DataFrame(
            {
                "peak_torque": peak_torque,
                "rms_torque": np.sqrt(_trapezoid(tau**2, t) / span),
                "peak_speed": peak_speed,
                "rms_speed": np.sqrt(_trapezoid(qd**2, t) / span),
                "peak_power": np.max(np.abs(power), axis=0),
                "energy_regenerated": -_trapezoid(np.minimum(power, 0.0), t),
                "effort_limit": effort_limit,
                "velocity_limit": velocity_limit,
                "torque_margin": np.where(peak_torque == 0.0, np.inf, effort_limit / peak_torque),
                "speed_margin": np.where(peak_speed == 0.0, np.inf, velocity_limit / peak_speed),
            },
            index=pd.Index(names, name="joint"),
        )
        torque_ok = np.isnan(peak_torque) | (peak_torque <= effort_limit)
    table["torque_margin"] = table["torque_margin"].where(~np.isnan(peak_torque), np.nan)
    table["ok"] = torque_ok & (peak_speed <= velocity_limit)
    return SizingReport(table=table, t=t.copy(), torque=tau, speed=qd.copy())
