"""Where a run leaves its joints' position, velocity and effort limits (:func:`limit_violations`),
and each result column's effort and velocity limit (read by the sizing report and the gear-ratio
sweep too)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from armdyn import _core
from armdyn._runs import checked as _checked
from armdyn._runs import model_of as _model_of

if TYPE_CHECKING:  # pandas is imported when a table is built: `import armdyn` stays light
    import pandas as pd

#: the runs the sizing functions take: a SimulationResult, an InverseDynamicsResult or a
#: TrajectoryRun (not imported here: armdyn.simulation and armdyn.dynamics import this package)
_Run = Any

_VIOLATION_COLUMNS = ["joint", "kind", "t_start", "t_end", "worst", "limit", "samples"]

# a position within this of its limit (relative to max(1, |limit|)) is on it: simulate's stops
# fire 1e-9 beyond theirs (detail/limit_stops.hpp)
_POSITION_TOLERANCE = 1e-8


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


def _spans(mask: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) index of each maximal run of True in ``mask``."""
    m = np.concatenate([[False], mask, [False]]).astype(np.int8)
    d = np.diff(m)
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1, strict=True))


def limit_violations(model: _core.Model | _Run, result: _Run | None = None) -> pd.DataFrame:
    """Where a run exceeds its joints' position, velocity and effort limits.

    ``limit_violations(result)`` takes the model the result holds (``result.model``);
    ``limit_violations(model, result)`` checks the run against the model given.

    Args:
        model: the model the run was made with (default ``result.model``); or, called with one
            argument, the result.
        result: a :class:`~armdyn.SimulationResult`, :class:`~armdyn.InverseDynamicsResult` or
            :class:`TrajectoryRun`.

    Returns:
        A DataFrame with one row per violation span, sorted by ``t_start``: ``joint`` (the
        coordinate's name, a column of ``result.qd``), ``kind`` (``"position"``: ``q`` below its
        lower or above its upper limit, by more than 1e-8 max(1, |limit|), ``limit`` then the
        bound crossed; ``"velocity"``: ``|qd| > limit``; ``"effort"``: ``|drive torque/force| >
        limit``), ``t_start`` and ``t_end`` (the first and
        last output sample beyond the limit), ``worst`` (the sampled value of largest magnitude in
        the span, signed), ``limit`` and ``samples`` (how many output samples the span covers).
        Empty (with these columns) when the run stays within its limits.

    A span is a maximal run of consecutive output samples beyond the limit: spans are resolved
    at the output samples only (a true crossing lies up to one output step before ``t_start``
    and after ``t_end``; an excursion between two samples is not seen). Efforts are checked on
    driven coordinates only (see the module notes).

    Raises:
        ModelError: the result's columns do not match the model (names the mismatch); no model
            passed and none held by the result (names ``model``).
    """
    import pandas as pd

    if result is None:  # limit_violations(result)
        model, result = None, model
    model = _model_of(result, model, "limit_violations")
    t, names, qd, tau = _checked(model, result, "limit_violations")
    effort_limit, velocity_limit = _column_limits(model, names)
    rows = _position_rows(model, result, t)
    for kind, values, limits in (("velocity", qd, velocity_limit), ("effort", tau, effort_limit)):
        rows += _magnitude_rows(kind, names, values, limits, t)
    table = pd.DataFrame(rows, columns=_VIOLATION_COLUMNS)
    return table.sort_values(["t_start", "joint", "kind"], kind="stable", ignore_index=True)


def _magnitude_rows(kind: str, names, values, limits, t) -> list[tuple]:
    """Violation rows of ``|values| > limits`` per column (velocity or effort; a column with
    no finite limit is not checked)."""
    rows = []
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
    return rows


def _position_rows(model, result, t) -> list[tuple]:
    """Violation rows of the positions ``result.q`` against the joints' position limits
    (``model.joint_limits``): below the lower or above the upper limit by more than
    _POSITION_TOLERANCE (a driven motion, an inverse-dynamics plan, a run with limits="ignore")."""
    q = np.asarray(getattr(result, "q", np.zeros((len(t), 0))), dtype=float)
    for cols in (list(model.joint_coord_names), list(model.coord_names)):
        if q.ndim == 2 and q.shape[1] == len(cols):
            break
    else:
        return []
    joints = set(model.joint_names)
    rows = []
    for k, name in enumerate(cols):
        if name not in joints:
            continue
        lim = model.joint_limits(name)
        for bound, sign in ((lim["lower"], -1.0), (lim["upper"], 1.0)):
            if not np.isfinite(bound) or abs(bound) >= 1e299:
                continue
            x = q[:, k]
            tol = _POSITION_TOLERANCE * max(1.0, abs(bound))
            for i0, i1 in _spans(sign * (x - bound) > tol):
                seg = x[i0 : i1 + 1]
                worst = seg[np.argmax(sign * seg)]
                rows.append(
                    (name, "position", t[i0], t[i1], float(worst), float(bound), i1 - i0 + 1)
                )
    return rows
