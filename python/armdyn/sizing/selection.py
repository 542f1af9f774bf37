"""Choosing a joint's drivetrain from one run: the gear-ratio sweep (:func:`gear_ratio_sweep`),
every ratio of a grid evaluated in closed form from the load's share of the joint torque, with
the report's motor-side checks at each."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from armdyn import _checks, _core
from armdyn._runs import checked as _checked
from armdyn._runs import model_of as _model_of
from armdyn.actuators import motor_side, rotor_torque
from armdyn.sizing.limits import _column_limits
from armdyn.sizing.motor import (
    MOTOR_CHECKS,
    _independent_q,
    _load_inertia,
    _mass_matrices,
    motor_values,
)
from armdyn.sizing.what_if import _swept_actuator

if TYPE_CHECKING:
    import pandas as pd

#: the runs the sizing functions take (see armdyn.sizing.limits)
_Run = Any


@dataclass
class GearRatioSweep:
    """Result of :func:`gear_ratio_sweep`.

    Attributes:
        table: DataFrame indexed by (joint, gear_ratio): the motor-side columns of
            :func:`sizing_report` at each ratio, ``peak_torque`` (joint side, with the rotor)
            and ``ok``.
        summary: DataFrame indexed by joint: ``best_ratio`` (the swept ratio of least
            ``motor_rms_torque``), ``best_rms_torque``, ``best_ok``, ``ok_ratio_min`` /
            ``ok_ratio_max`` (the smallest and largest swept ratio where every check passes;
            NaN when none does) and ``ok_contiguous`` (every swept ratio between them passes).
    """

    table: pd.DataFrame
    summary: pd.DataFrame


@dataclass
class _SweptRun:
    """The checked run the sweep evaluates: times, columns, rates, accelerations, joint
    torques, the columns' limits, the model's own actuators by joint and the mass matrices
    along the run (None without them)."""

    model: Any
    t: np.ndarray
    names: list[str]
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    effort_limit: np.ndarray
    velocity_limit: np.ndarray
    existing: dict[str, Any]
    mass: np.ndarray | None


def gear_ratio_sweep(
    result: _Run,
    model: _core.Model | None = None,
    ratios: npt.ArrayLike | dict[str, npt.ArrayLike] | None = None,
    actuators: dict[str, Any] | None = None,
) -> GearRatioSweep:
    """Per joint, the gear ratio that minimises the RMS motor torque along a run and the range
    of ratios for which every check of :func:`sizing_report` passes.

    Args:
        result: a run of ``model`` (any result :func:`sizing_report` takes).
        model: the model of the run; default the one the result holds (``result.model``).
            ``gear_ratio_sweep(result, ratios[, actuators])`` (no model between) takes the
            result's.
        ratios: the gear ratios to try (1-D, non-zero), or ``{joint: ratios}`` (required).
        actuators: ``{joint: spec}`` with ``rotor_inertia`` and optionally ``efficiency``,
            ``friction_viscous``, ``friction_coulomb``, ``motor`` (a dict or an object with
            those attributes; ``gear_ratio`` is ignored). A joint the model already actuates
            takes the missing values from its actuator. Default: every actuated joint of the
            model with its own actuator's values.

    How: the load's share of the joint torque, τ_load = τ − N₀ T_rot(N₀) (N₀ the model's own
    actuator on that joint, none: τ_load = τ), does not depend on the ratio. In the
    gear-reduced joint-space model an actuator adds N² J to its joint's diagonal of the mass
    matrix and its friction to that joint only, so at ratio N the joint torque is exactly
    τ(N) = τ_load + N (J N q̈ + b N q̇ + c tanh(N q̇ / v_s)) and the other joints' torques do not
    change: one run evaluates every ratio. This holds for ``gyroscopic=False`` actuators; with
    the rotor's gyroscopic terms (the Cartesian path) it is an approximation.

    Raises:
        ModelError: a joint that is not a column of the result, without a torque, or without a
            rotor inertia; a zero ratio; no ratios; no model passed and none held by the result.
    """
    import pandas as pd

    model, ratios, actuators = _call_form(model, ratios, actuators)
    model = _model_of(result, model, "gear_ratio_sweep")
    run, actuators = _checked_run(result, model, actuators)
    rows, index = [], []
    for joint, spec in actuators.items():
        for n, row in _joint_rows(run, joint, spec, ratios):
            rows.append(row)
            index.append((joint, n))
    table = pd.DataFrame(
        rows, index=pd.MultiIndex.from_tuples(index, names=["joint", "gear_ratio"])
    )
    table = table.drop(columns=["gear_ratio"])
    return GearRatioSweep(table=table, summary=_summary(table, list(actuators)))


def _call_form(model, ratios, actuators):
    """``(model, ratios, actuators)`` of either call form: ``(result, model, ratios[,
    actuators])`` or ``(result, ratios[, actuators])`` (the model then the result's)."""
    if model is not None and not hasattr(model, "dof_names"):
        # gear_ratio_sweep(result, ratios[, actuators]): the model is the result's
        if actuators is not None:
            raise _core.ModelError(
                f"gear_ratio_sweep: model must be an armdyn.Model, got {type(model).__name__}"
            )
        model, ratios, actuators = None, model, ratios
    if ratios is None:
        raise _core.ModelError("gear_ratio_sweep: ratios is required (the gear ratios to try)")
    return model, ratios, actuators


def _checked_run(result, model, actuators) -> tuple[_SweptRun, dict]:
    """The run's columns checked against the model, with what every ratio reuses, and the
    joints to sweep (default: the model's actuated joints)."""
    t, names, qd, tau = _checked(model, result, "gear_ratio_sweep")
    if len(t) < 2 or not (t[-1] > t[0]):
        raise _core.ModelError(
            "gear_ratio_sweep: the result needs two samples over a positive span"
        )
    qdd = np.asarray(result.qdd, dtype=float)
    existing = {str(a.joint): a for a in (getattr(model, "actuators", None) or [])}
    if actuators is None:
        actuators = {j: None for j in existing}
    if not actuators:
        raise _core.ModelError("gear_ratio_sweep: no joint to sweep (pass actuators={joint: spec})")
    effort_limit, velocity_limit = _column_limits(model, names)
    mass = _mass_matrices(model, _independent_q(model, result))
    run = _SweptRun(model, t, names, qd, qdd, tau, effort_limit, velocity_limit, existing, mass)
    return run, actuators


def _joint_rows(run: _SweptRun, joint: str, spec, ratios) -> list[tuple[float, dict]]:
    """``(ratio, row)`` of one joint at each of its ratios: the load's share of its torque and
    its load inertia (both rotor-free), then each ratio's stand-in actuator checked."""
    if joint not in run.names:
        raise _core.ModelError(f"gear_ratio_sweep: joint {joint!r} is not a column ({run.names})")
    k = run.names.index(joint)
    qd, qdd, tau = run.qd[:, k], run.qdd[:, k], run.tau[:, k]
    if np.any(np.isnan(tau)):
        raise _core.ModelError(f"gear_ratio_sweep: the result has no torque for {joint!r}")
    act = _swept_actuator(joint, spec, run.existing.get(joint))
    own = run.existing.get(joint)
    tau_load = tau
    if own is not None:
        tau_load = motor_side(own, run.t, qd, qdd, tau, joint=joint).load_torque
    m_load = _load_inertia(run.mass, run.model, joint, own)
    grid = ratios.get(joint) if isinstance(ratios, dict) else ratios
    name = f"ratios[{joint!r}]" if isinstance(ratios, dict) else "ratios"
    out = []
    for n in np.atleast_1d(_checks.array("gear_ratio_sweep", name, grid, finite=True)):
        act.gear_ratio = float(n)
        out.append((float(n), _ratio_row(run, k, act, tau_load, m_load)))
    return out


def _ratio_row(run: _SweptRun, k: int, act, tau_load: np.ndarray, m_load) -> dict:
    """The row of column ``k`` with the stand-in actuator ``act`` at its current ratio N: the
    joint torque τ_load + N T_rot, the motor-side columns, the inertia ratio, ``peak_torque``
    and ``ok``."""
    n = act.gear_ratio
    qd, qdd = run.qd[:, k], run.qdd[:, k]
    tau_n = tau_load + n * rotor_torque(act, qd, qdd)
    side = motor_side(act, run.t, qd, qdd, tau_n, joint=act.joint)
    row = motor_values(side, act, run.t)
    rotor_j = n * n * float(act.rotor_inertia)
    row["inertia_ratio"] = m_load / rotor_j if m_load is not None and rotor_j > 0 else np.nan
    peak = float(np.max(np.abs(tau_n)))
    row["peak_torque"] = peak
    ok = peak <= run.effort_limit[k] and np.max(np.abs(qd)) <= run.velocity_limit[k]
    ok = ok and act.motor is not None
    row["ok"] = bool(ok and all(row[col] >= 1.0 for _, col in MOTOR_CHECKS))
    return row


def _summary(table: pd.DataFrame, joints: list[str]) -> pd.DataFrame:
    """Per joint: the ratio of least RMS motor torque and the range of ratios that pass."""
    import pandas as pd

    summary = []
    for joint in joints:
        sub = table.loc[joint]
        best = sub["motor_rms_torque"].idxmin()
        passing = sub.index[sub["ok"].to_numpy()]
        lo, hi = (passing.min(), passing.max()) if len(passing) else (np.nan, np.nan)
        between = sub[(sub.index >= lo) & (sub.index <= hi)] if len(passing) else sub.iloc[:0]
        summary.append(
            {
                "best_ratio": best,
                "best_rms_torque": sub.loc[best, "motor_rms_torque"],
                "best_ok": bool(sub.loc[best, "ok"]),
                "ok_ratio_min": lo,
                "ok_ratio_max": hi,
                "ok_contiguous": bool(len(passing)) and bool(between["ok"].all()),
            }
        )
    return pd.DataFrame(summary, index=pd.Index(joints, name="joint"))
