"""Effort and velocity limits along a run, the sizing report (joint and motor side) and the
gear-ratio sweep.

They work on a finished run (:class:`armdyn.SimulationResult`,
:class:`armdyn.InverseDynamicsResult`, or a planned motion's :class:`TrajectoryRun` from
:func:`trajectory_run`) and the model it came from. Those results hold their model
(``result.model``), which is the default; a model passed explicitly (the older call form
``sizing_report(result, model)``) is checked against the result's columns. A result without a
model (one built by hand) and no model passed is a ModelError naming ``model``.

Conventions shared by these functions:

- Columns are the result's ``qd`` columns: ``model.joint_dof_names`` (every joint coordinate, the
  couplings' followers included; ``model.dof_names`` for a :class:`TrajectoryRun`). The effort
  and velocity limits of the independent coordinates come from ``model.coord_effort_limit`` /
  ``model.coord_velocity_limit``; a coupling's follower takes its own joint's limits
  (``model.joint_limits``). ``inf`` where there is none.
- Joint torques/forces are ``result.joint_torques`` when the result has them (every joint's
  actuation, joint side), else the efforts of the run's drives (``result.drive_forces``) summed
  per driven coordinate (``model.drive_coords``). A coordinate without either has no effort in
  the result: its torque-based values are NaN and its effort limit is not checked.
- Everything is evaluated at the output samples only: peaks are the largest sampled values, RMS
  and energies use the trapezoid rule over the samples, and a limit violation that begins and
  ends between two samples is not seen.
- Motor-side values follow :mod:`armdyn.actuators` (gear efficiency by power-flow direction,
  current, electrical power, losses).
"""

from __future__ import annotations

import html
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from armdyn import _core
from armdyn._runs import checked as _checked
from armdyn._runs import model_of as _model_of

if TYPE_CHECKING:  # pandas is imported when a table is built: `import armdyn` stays light
    import pandas as pd
    from matplotlib.figure import Figure

#: the runs the sizing functions take: a SimulationResult, an InverseDynamicsResult or a
#: TrajectoryRun (not imported here: armdyn.simulation and armdyn.dynamics import this module)
_Run = Any

_VIOLATION_COLUMNS = ["joint", "kind", "t_start", "t_end", "worst", "limit", "samples"]


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


# a position within this of its limit (relative to max(1, |limit|)) is on it: simulate's stops
# fire 1e-9 beyond theirs (detail/limit_stops.hpp)
_POSITION_TOLERANCE = 1e-8


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


def _trapezoid(y: np.ndarray, t: np.ndarray) -> np.ndarray:
    """∫ y dt over the samples, per column (trapezoid rule)."""
    dt = np.diff(t)[:, None]
    return np.sum(0.5 * (y[1:] + y[:-1]) * dt, axis=0)


@dataclass
class TrajectoryRun:
    """Joint torques along a planned motion (:func:`trajectory_run`), shaped like a run's
    result so that :func:`sizing_report` and :func:`limit_violations` take it.

    Attributes:
        t: (n,) times [s].
        q: (n, len(model.coord_names)) coordinates.
        qd, qdd: (n, len(model.dof_names)) rates and accelerations.
        joint_torques: (n, len(model.dof_names)) ``armdyn.inverse_dynamics`` at each sample.
        actuators: ``{joint: armdyn.actuators.MotorSide}`` for every actuator of the model
            (empty without actuators).
        model: the model the torques were computed with (:func:`trajectory_run` sets it; the
            default model of :func:`sizing_report`, :func:`limit_violations` and
            :func:`gear_ratio_sweep`).
    """

    t: npt.NDArray[np.float64]
    q: npt.NDArray[np.float64]
    qd: npt.NDArray[np.float64]
    qdd: npt.NDArray[np.float64]
    joint_torques: npt.NDArray[np.float64]
    actuators: dict[str, Any] = field(default_factory=dict)
    model: _core.Model | None = field(default=None, repr=False, compare=False)

    def limit_violations(self, model: _core.Model | None = None) -> pd.DataFrame:
        """See :func:`limit_violations`; ``model`` default :attr:`model`."""
        return limit_violations(_model_of(self, model, "TrajectoryRun.limit_violations"), self)


def trajectory_run(
    model: _core.Model, t: npt.ArrayLike, q: npt.ArrayLike, qd: npt.ArrayLike, qdd: npt.ArrayLike
) -> TrajectoryRun:
    """The joint torques of a tree model along a planned motion: ``armdyn.inverse_dynamics``
    (recursive Newton–Euler, gravity, force elements and, with actuators, the reflected rotor
    terms included) at every sample, as a result :func:`sizing_report` takes.

    Args:
        model: a joint-space model (``model.joint_space``).
        t: (n,) strictly increasing times [s].
        q: (n, len(model.coord_names)); qd, qdd: (n, len(model.dof_names)).

    Raises:
        ModelError: shapes that do not match the model, non-increasing times, or a model the
            joint-space inverse dynamics does not cover.
    """
    from armdyn import _checks

    t = np.atleast_1d(_checks.array("trajectory_run", "t", t, finite=True))
    q, qd, qdd = (
        np.atleast_2d(_checks.array("trajectory_run", name, x, finite=True))
        for name, x in (("q", q), ("qd", qd), ("qdd", qdd))
    )
    nq, nv = len(model.coord_names), len(model.dof_names)
    if t.ndim != 1 or q.shape != (len(t), nq) or qd.shape != (len(t), nv) or qdd.shape != qd.shape:
        raise _core.ModelError(
            f"trajectory_run: expected t (n,), q (n, {nq}) over {list(model.coord_names)}, qd and "
            f"qdd (n, {nv}); got t {t.shape}, q {q.shape}, qd {qd.shape}, qdd {qdd.shape}"
        )
    if len(t) > 1 and not np.all(np.diff(t) > 0.0):
        raise _core.ModelError("trajectory_run: times must be strictly increasing")
    from armdyn.actuators import motor_side_of_result

    tau = np.asarray(_core.inverse_dynamics(model, q, qd, qdd, t), dtype=float)
    run = TrajectoryRun(
        t=t.copy(), q=q.copy(), qd=qd.copy(), qdd=qdd.copy(), joint_torques=tau, model=model
    )
    if getattr(model, "actuators", None):
        run.actuators = motor_side_of_result(model, run)
    return run


# --- motor checks ------------------------------------------------------------------------------

#: the motor checks of the report: (check name, margin column)
MOTOR_CHECKS = (
    ("continuous_torque", "continuous_torque_margin"),
    ("peak_torque", "peak_torque_margin"),
    ("speed", "motor_speed_margin"),
    ("envelope", "envelope_margin"),
)


def _num(value) -> float:
    return np.nan if value is None else float(value)


def motor_envelope(motor) -> tuple[float, float]:
    """``(T0, ω0)`` of a motor's speed–torque line from (0, T0) to (ω0, 0): T0 the stall torque
    k_t V / R when the motor gives k_t, V and R, else its peak torque; ω0 the no-load speed, else
    V / k_t. NaN where the datasheet values are missing. An operating point (ω, T) is inside the
    envelope when |T + T0 ω / ω0| ≤ T0: under the line in the motoring quadrants (T ω ≥ 0), and
    the voltage equation's limit |R i + k_t ω| ≤ V in the regenerating ones."""
    if motor is None:
        return np.nan, np.nan
    k_t, v, r = (
        _num(getattr(motor, a, None)) for a in ("torque_constant", "voltage", "resistance")
    )
    t0 = k_t * v / r if np.isfinite(k_t * v / r) and r > 0 else _num(motor.peak_torque)
    w0 = _num(motor.no_load_speed)
    if np.isnan(w0):
        w0 = v / k_t if k_t > 0 else np.nan
    return float(t0), float(w0)


def thermal_rise(t: np.ndarray, loss: np.ndarray, r_th: float, tau_th: float) -> np.ndarray:
    """Winding temperature rise of the first-order model τ_th dΔT/dt = R_th P(t) − ΔT from
    ΔT = 0, P linear between samples (exact per step)."""
    out = np.zeros_like(loss)
    for k in range(1, len(t)):
        h = t[k] - t[k - 1]
        if h <= 0.0:  # a repeated sample (an event's time): nothing elapses
            out[k] = out[k - 1]
            continue
        a = np.exp(-h / tau_th)
        slope = (loss[k] - loss[k - 1]) / h
        p1 = r_th * (loss[k] - tau_th * slope)
        p0 = r_th * (loss[k - 1] - tau_th * slope)
        out[k] = p1 + (out[k - 1] - p0) * a
    return out


def _mean(y, t):
    return float(_trapezoid(np.asarray(y)[:, None], t)[0] / (t[-1] - t[0]))


def motor_values(side, actuator, t: np.ndarray) -> dict:
    """The report's motor-side columns of one actuator (see :func:`sizing_report`)."""
    motor = getattr(actuator, "motor", None)
    T, w = side.torque, side.speed
    peak_t, peak_w = float(np.max(np.abs(T))), float(np.max(np.abs(w)))
    rms_t, rms_w = np.sqrt(_mean(T**2, t)), np.sqrt(_mean(w**2, t))
    n = float(actuator.gear_ratio)
    # the joint torque's two shares: the load's (what the gear output delivers to the link) and
    # the rotor's, N T_rot (its inertia and motor-side friction reflected to the joint)
    reflected = n * rotor_torque(actuator, side.speed / n, side.acceleration / n)
    row = {
        "gear_ratio": n,
        "peak_load_torque": float(np.max(np.abs(side.load_torque))),
        "peak_rotor_torque": float(np.max(np.abs(reflected))),
        "motor_peak_torque": peak_t,
        "motor_rms_torque": rms_t,
        "motor_peak_speed": peak_w,
        "motor_rms_speed": rms_w,
        "peak_current": np.nan,
        "rms_current": np.nan,
        "peak_electrical_power": float(np.max(np.abs(side.electrical_power))),
        "electrical_energy": float(side.energy[-1]),
        "motor_energy_regenerated": float(side.energy_regenerated[-1]),
        "temperature_rise_steady": np.nan,
        "temperature_rise_peak": np.nan,
    }
    if side.current is not None:
        row["peak_current"] = float(np.max(np.abs(side.current)))
        row["rms_current"] = float(np.sqrt(_mean(side.current**2, t)))

    def ratio(limit, value):
        if np.isnan(limit):
            return np.nan
        return np.inf if value == 0.0 else limit / value

    cont, peak = (
        _num(getattr(motor, "continuous_torque", None)),
        _num(getattr(motor, "peak_torque", None)),
    )
    speed_lim = _num(getattr(motor, "max_speed", None))
    if np.isnan(speed_lim):
        speed_lim = _num(getattr(motor, "no_load_speed", None))
    row["continuous_torque_margin"] = ratio(cont, rms_t)
    row["peak_torque_margin"] = ratio(peak, peak_t)
    row["motor_speed_margin"] = ratio(speed_lim, peak_w)
    t0, w0 = motor_envelope(motor)
    if np.isfinite(t0) and np.isfinite(w0) and t0 > 0 and w0 > 0:
        worst = float(np.max(np.abs(T + t0 * w / w0)))
        row["envelope_margin"] = np.inf if worst == 0.0 else t0 / worst
    else:
        row["envelope_margin"] = np.nan
    r_th = _num(getattr(motor, "thermal_resistance", None))
    if side.copper_included and np.isfinite(r_th):
        row["temperature_rise_steady"] = r_th * _mean(side.loss_copper, t)
        tau_th = _num(getattr(motor, "thermal_time_constant", None))
        if np.isfinite(tau_th) and tau_th > 0:
            row["temperature_rise_peak"] = float(
                np.max(thermal_rise(t, side.loss_copper, r_th, tau_th))
            )
    return row


def _independent_q(model, result) -> np.ndarray | None:
    """The run's coordinates over ``model.coord_names`` (None when the result has no q)."""
    q = getattr(result, "q", None)
    if q is None:
        return None
    q = np.asarray(q, dtype=float)
    coords = list(model.coord_names)
    if q.shape[1] == len(coords):
        return q
    full = list(model.joint_coord_names)
    if q.shape[1] == len(full) and all(c in full for c in coords):
        return q[:, [full.index(c) for c in coords]]
    return None


def _mass_matrix(model, q: np.ndarray) -> np.ndarray:
    """(n, nv, nv) ``armdyn.mass_matrix`` at each row of ``q``."""
    return np.asarray(_core.mass_matrix(model, q), dtype=float)


def inertia_ratios(model, result, extra=()) -> dict[str, float]:
    """Per actuated joint, the largest ratio along the run of the load inertia reflected to the
    motor to the rotor inertia: ``(M_jj(q) − N² J) / (N² J)``, ``M_jj`` the joint's diagonal of
    ``armdyn.mass_matrix`` (which includes the rotor's N² J); for the ``extra`` (what-if)
    actuators, which are not in the model, ``M_jj / (N² J)``. NaN when the mass matrix is not
    available (not a joint-space model, no coordinates in the result) or J = 0."""
    own = list(getattr(model, "actuators", None) or [])
    actuators = own + list(extra)
    out = {str(a.joint): np.nan for a in actuators}
    q = _independent_q(model, result)
    if not actuators or q is None:
        return out
    try:
        m = _mass_matrix(model, q)
    except (_core.ModelError, _core.SolverError):
        return out
    for k, a in enumerate(actuators):
        rotor = float(a.gear_ratio) ** 2 * float(a.rotor_inertia)
        if rotor > 0.0:
            load = m[:, a.dof, a.dof] - (rotor if k < len(own) else 0.0)
            out[str(a.joint)] = float(np.max(load) / rotor)
    return out


MOTOR_FIELDS = (
    "torque_constant",
    "resistance",
    "voltage",
    "no_load_speed",
    "continuous_torque",
    "peak_torque",
    "max_speed",
    "thermal_resistance",
    "thermal_time_constant",
    "name",
)


def make_motor(**datasheet):
    """An :class:`armdyn.Motor` from datasheet keywords (SI, motor side: ``torque_constant``
    N m/A, ``resistance`` ohm, ``voltage`` V, ``no_load_speed`` rad/s, ``continuous_torque`` and
    ``peak_torque`` N m, ``max_speed`` rad/s, ``thermal_resistance`` K/W,
    ``thermal_time_constant`` s, ``name``); an unknown key is a ModelError naming it."""
    unknown = sorted(set(datasheet) - set(MOTOR_FIELDS))
    if unknown:
        raise _core.ModelError(f"motor: unknown datasheet key(s) {unknown}; known {MOTOR_FIELDS}")
    return _core.Motor(**datasheet)


_ACTUATOR_FIELDS = (
    "gear_ratio",
    "rotor_inertia",
    "efficiency",
    "friction_viscous",
    "friction_coulomb",
    "friction_smoothing",
    "motor",
    "gyroscopic",
)


def rotor_torque(actuator, qd, qdd) -> np.ndarray:
    """T_rot = J N q̈ + b N q̇ + c tanh(N q̇ / v_s): the motor-side torque spinning the rotor
    (v_s: :func:`armdyn.actuators.coulomb_smoothing`)."""
    from armdyn.actuators import coulomb_smoothing

    n = float(actuator.gear_ratio)
    w = n * np.asarray(qd, dtype=float)
    return (
        float(actuator.rotor_inertia) * n * np.asarray(qdd, dtype=float)
        + float(actuator.friction_viscous) * w
        + float(actuator.friction_coulomb) * np.tanh(w / coulomb_smoothing(actuator))
    )


def what_if_actuators(model, names, actuators) -> list:
    """Stand-in actuators (the attributes of ``model.actuators`` entries) from
    ``{joint: spec}``: ``gear_ratio`` and ``rotor_inertia`` required, ``efficiency`` (1),
    ``friction_viscous``, ``friction_coulomb`` (0), ``friction_smoothing`` (None: 1e-3 |N|)
    and ``motor`` (an :class:`armdyn.Motor`, a dict of its keywords, or None) optional; a dict
    or an object with those attributes."""
    from types import SimpleNamespace

    own = {str(a.joint) for a in (getattr(model, "actuators", None) or [])}
    dofs = list(model.dof_names)
    out = []
    for joint, spec in actuators.items():
        joint = str(joint)
        if joint in own:
            raise _core.ModelError(
                f"actuators: joint {joint!r} already has an actuator in the model; size it with "
                "the model's own, or sweep it with gear_ratio_sweep"
            )
        if joint not in names or joint not in dofs:
            raise _core.ModelError(f"actuators: {joint!r} is not a joint coordinate ({dofs})")

        def get(key, default=None, spec=spec):
            if isinstance(spec, dict):
                return spec.get(key, default)
            return getattr(spec, key, default)

        unknown = sorted(set(spec) - set(_ACTUATOR_FIELDS)) if isinstance(spec, dict) else []
        if unknown:
            raise _core.ModelError(f"actuators: [{joint}] unknown key(s) {unknown}")
        for key in ("gear_ratio", "rotor_inertia"):
            if get(key) is None:
                raise _core.ModelError(f"actuators: [{joint}] needs {key}")
        if get("gyroscopic", False):
            raise _core.ModelError(
                f"actuators: [{joint}] gyroscopic rotors need the actuator in the model "
                "(ModelBuilder.add_actuator); the what-if evaluation is the gear-reduced model"
            )
        motor = get("motor")
        if isinstance(motor, dict):
            motor = make_motor(**motor)
        out.append(
            SimpleNamespace(
                joint=joint,
                rotor_joint=None,
                dof=dofs.index(joint),
                **_actuator_numbers(f"actuators: [{joint}]", get),
                motor=motor,
                gyroscopic=False,
            )
        )
    return out


def _actuator_numbers(who: str, get) -> dict:
    """The numeric actuator keys of a what-if spec, checked by the rules of
    ``ModelBuilder.add_actuator`` (a ModelError naming the key and what it allows)."""
    from armdyn import _checks

    gear_ratio = _checks.number(who, "gear_ratio", get("gear_ratio"))
    if gear_ratio == 0.0:
        raise _core.ModelError(f"{who}: gear_ratio must be a finite nonzero number, got 0")
    return dict(
        gear_ratio=gear_ratio,
        rotor_inertia=_checks.number(who, "rotor_inertia", get("rotor_inertia"), lo=0.0),
        efficiency=_checks.number(
            who, "efficiency", get("efficiency", 1.0), lo=0.0, lo_open=True, hi=1.0
        ),
        friction_viscous=_checks.number(
            who, "friction_viscous", get("friction_viscous", 0.0), lo=0.0
        ),
        friction_coulomb=_checks.number(
            who, "friction_coulomb", get("friction_coulomb", 0.0), lo=0.0
        ),
        friction_smoothing=_checks.number(
            who, "friction_smoothing", get("friction_smoothing"), none=True
        ),
    )


@dataclass
class SizingReport:
    """Sizing values of a run (see :func:`sizing_report`).

    Attributes:
        table: DataFrame indexed by joint (coordinate) name.
        t: (n,) output times [s].
        torque: (n, n_columns) joint-side torque/force per coordinate (NaN where none).
        speed: (n, n_columns) joint rates ``result.qd``.
        motors: ``{joint: armdyn.actuators.MotorSide}`` for every actuated joint.
        envelopes: ``{joint: motor}`` (the :class:`armdyn.Motor`, or None) per actuated joint.
    """

    table: pd.DataFrame
    t: npt.NDArray[np.float64]
    torque: npt.NDArray[np.float64]
    speed: npt.NDArray[np.float64]
    motors: dict[str, Any] = field(default_factory=dict)
    envelopes: dict[str, Any] = field(default_factory=dict)

    def save(self, directory: str | os.PathLike[str]) -> Path:
        """Write ``table.csv``, ``report.html`` (the table, one torque-against-time figure per
        joint with a non-zero torque, and each motor's operating points on its speed–torque
        plane) and the figures ``torque_<k>.png`` / ``motor_<k>.png`` into ``directory`` (created if
        missing). Needs matplotlib (the ``plot`` extra). Returns the HTML page's path."""
        # bare Figures (Agg canvas): no pyplot state, the user's backend is left alone
        from armdyn.plotting import sizing_envelope_figure, sizing_torque_figure

        out = Path(os.fspath(directory))
        out.mkdir(parents=True, exist_ok=True)
        self.table.to_csv(out / "table.csv")
        figures = []
        for k, name in enumerate(self.table.index):
            tau = self.torque[:, k]
            if np.all(np.isnan(tau) | (tau == 0.0)):  # no actuation on this joint
                continue
            fig = sizing_torque_figure(self, name)
            png = f"torque_{k}.png"
            fig.savefig(out / png, dpi=100)
            items = [(png, f"torque of {name}")]
            if name in self.motors:
                png_m = f"motor_{k}.png"
                sizing_envelope_figure(self, name).savefig(out / png_m, dpi=100)
                items.append((png_m, f"speed-torque plane of the motor of {name}"))
            figures.append((name, items))
        parts = [
            "<!DOCTYPE html>",
            '<html><head><meta charset="utf-8"><title>armdyn sizing report</title></head><body>',
            "<h1>Sizing report</h1>",
            self.table.to_html(float_format=lambda v: f"{v:.6g}"),
        ]
        for name, items in figures:
            label = html.escape(str(name))
            parts.append(f"<h2>{label}</h2>")
            for png, alt in items:
                parts.append(f'<img src="{png}" alt="{html.escape(alt)}">')
        parts.append("</body></html>")
        page = out / "report.html"
        page.write_text("\n".join(parts), encoding="utf-8")
        return page

    def envelope_figure(self, joint: str) -> Figure:
        """A bare matplotlib Figure: the operating points (ω, T) of ``joint``'s motor over its
        continuous torque (±, dotted), peak torque (±, dashed), speed limit and speed–torque
        envelope (:func:`motor_envelope`), where the datasheet gives them
        (:func:`armdyn.plotting.sizing_envelope_figure`; ``plot(joint, kind="motor")``)."""
        from armdyn.plotting import sizing_envelope_figure

        return sizing_envelope_figure(self, joint)

    def _motor_envelope(self, joint) -> tuple[float, float]:
        """(T0, ω0) of ``joint``'s motor (:func:`motor_envelope`), for its figure."""
        return motor_envelope(self.envelopes.get(joint))

    def plot(self, joint=None, kind: str = "torque", ax=None, path=None):
        """The report's figures (:mod:`armdyn.plotting`; matplotlib imported here).

        Args:
            joint: a joint (coordinate) of :attr:`table`'s index; None: one panel per joint
                with a non-zero torque (``"torque"``) or with a motor (``"motor"``).
            kind: ``"torque"``: the joint torque/force against time [s] with its effort limit
                (the figures of :meth:`save`); ``"motor"``: the motor's operating points on
                its speed–torque plane (:meth:`envelope_figure`).
            ax: a matplotlib Axes to draw into (a sequence of them for several joints);
                default: a new :class:`matplotlib.figure.Figure`.
            path: save the figure there (dpi 110) when given.

        Returns:
            The Figure, or with ``ax`` the Axes drawn into.

        Raises:
            ValueError: an unknown kind. ModelError: an unknown joint (naming it and listing
            the report's), a joint without torque, or without a motor for ``"motor"``.
        """
        from armdyn.plotting import sizing_figure

        return sizing_figure(self, joint, kind=kind, ax=ax, path=path)


def sizing_report(
    result: _Run,
    model: _core.Model | None = None,
    out: str | os.PathLike[str] | None = None,
    actuators: dict[str, Any] | None = None,
) -> SizingReport:
    """Peak and RMS torque and speed, power, energy, limit margins and, for actuated joints, the
    motor-side values and checks.

    Args:
        result: a :class:`~armdyn.SimulationResult`, :class:`~armdyn.InverseDynamicsResult` or
            :class:`TrajectoryRun` (:func:`trajectory_run`) with at least two output samples
            spanning a positive time.
        model: the model the run was made with; default the one the result holds
            (``result.model``). A model passed is checked against the result's columns.
        out: a directory: the report is also saved there (:meth:`SizingReport.save`).
        actuators: what-if actuators ``{joint: spec}`` on joints the model does not actuate
            (:func:`what_if_actuators`: ``gear_ratio``, ``rotor_inertia``, optional
            ``efficiency``, ``friction_viscous``, ``friction_coulomb``, ``motor``). The run is
            then taken as the rotor-free load and each such joint's torque becomes
            τ + N T_rot (:func:`rotor_torque`): exactly what the model with
            ``add_actuator(joint, ...)`` (``gyroscopic=False``) gives along the same motion
            (see :func:`gear_ratio_sweep`), without rebuilding it.

    Returns:
        A :class:`SizingReport` whose ``.table`` is indexed by joint (coordinate) name, the
        columns of ``result.qd`` (rotor joints of actuators left out), with (joint side, SI):

        - ``peak_torque`` = max |τ|, ``rms_torque`` = √(1/T ∫ τ² dt), τ the joint torque: on
          an actuated joint (``model.actuators`` or ``actuators=``) it includes the rotor's
          reflected share N T_rot, which ``peak_rotor_torque`` reports on its own,
        - ``peak_speed`` = max |q̇|, ``rms_speed`` = √(1/T ∫ q̇² dt),
        - ``peak_power`` = max |τ q̇|,
        - ``energy_regenerated`` = −∫ min(τ q̇, 0) dt (the work the load does on the actuator,
          reported positive),
        - ``effort_limit``, ``velocity_limit`` (inf where none),
        - ``torque_margin`` = effort_limit / peak_torque, ``speed_margin`` =
          velocity_limit / peak_speed (inf for a zero peak),

        and where an actuator is attached (NaN elsewhere; motor side, see
        :mod:`armdyn.actuators`):

        - ``peak_load_torque`` = max |τ − N T_rot| (joint side: the load's share, what the gear
          delivers to the link) and ``peak_rotor_torque`` = max |N T_rot| (joint side: the
          rotor's inertia N² J q̈ and motor friction, :func:`rotor_torque`); on these joints
          ``peak_torque`` (and every other torque column above) is of the whole joint torque
          τ, the rotor's share included,
        - ``gear_ratio``, ``motor_peak_torque``, ``motor_rms_torque``, ``motor_peak_speed``,
          ``motor_rms_speed``, ``peak_current``, ``rms_current`` (NaN without k_t),
        - ``continuous_torque_margin`` = continuous_torque / motor_rms_torque,
          ``peak_torque_margin`` = peak_torque / motor_peak_torque, ``motor_speed_margin`` =
          (max_speed, else no_load_speed) / motor_peak_speed, ``envelope_margin`` =
          T0 / max |T + T0 ω / ω0| (≥ 1: every operating point inside the speed–torque
          envelope, :func:`motor_envelope`); NaN where the datasheet value is missing,
        - ``inertia_ratio``: max over the run of (M_jj − N² J) / (N² J) (:func:`inertia_ratios`),
        - ``peak_electrical_power`` = max |P_el|, ``electrical_energy`` = ∫ P_el dt (net),
          ``motor_energy_regenerated`` = ∫ max(−P_el, 0) dt,
        - ``temperature_rise_steady`` = R_th · mean copper loss (R · I_rms²) [K],
          ``temperature_rise_peak``: the largest rise along the run of the first-order model
          τ_th dΔT/dt = R_th R i² − ΔT from ΔT(0) = 0 (reported, not checked),

        (these columns only when the model has actuators) and ``ok``: every check passes:
        peak ≤ effort and velocity limit (the same test as :func:`limit_violations`) and, on
        actuated joints, every motor margin ≥ 1. A motor check that cannot be made (no motor,
        a missing datasheet value) is not a pass: ``ok`` is then False and ``unchecked`` (a
        column of models with actuators) names the checks (``""`` when all were made).

        Integrals use the trapezoid rule over the output samples, T = t[-1] − t[0]; peaks are
        the largest sampled values. τ is ``result.joint_torques`` when the result has it, else
        the drives' efforts summed per driven coordinate; a coordinate without either has NaN
        in every torque column and ``ok`` then checks its speed only (with ``joint_torques``
        an unactuated joint has a zero torque).

    Raises:
        ModelError: the result's columns do not match the model, or fewer than two samples /
            a zero time span; no model passed and none held by the result (names ``model``).
    """
    import pandas as pd

    from armdyn.actuators import actuated_column, motor_side

    model = _model_of(result, model, "sizing_report")
    if out is not None and not isinstance(out, (str, os.PathLike)):
        raise _core.ModelError(
            f"sizing_report: out must be a folder path (str or os.PathLike) or None, got "
            f"{type(out).__name__}"
        )
    t, names, qd, tau = _checked(model, result, "sizing_report")
    if len(t) < 2 or not (t[-1] > t[0]):
        raise _core.ModelError(
            f"sizing_report: the result needs at least two samples over a positive time span, "
            f"got {len(t)} sample(s) over [{t[0] if len(t) else 'n/a'}, "
            f"{t[-1] if len(t) else 'n/a'}]"
        )
    span = t[-1] - t[0]
    extra = what_if_actuators(model, names, actuators) if actuators else []
    qdd = (
        np.asarray(result.qdd, dtype=float) if extra or getattr(model, "actuators", None) else None
    )
    for a in extra:
        k = names.index(a.joint)
        if np.any(np.isnan(tau[:, k])):
            raise _core.ModelError(
                f"sizing_report: the result has no torque for joint {a.joint!r} (no drive and no "
                "joint_torques)"
            )
        tau[:, k] = tau[:, k] + a.gear_ratio * rotor_torque(a, qd[:, k], qdd[:, k])
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
    ok = torque_ok & (peak_speed <= velocity_limit)
    unchecked = [""] * len(names)

    actuators = list(getattr(model, "actuators", None) or []) + extra
    motors, envelopes = {}, {}
    if actuators:
        ratios = inertia_ratios(model, result, extra)
        rows = {}
        for a in actuators:
            joint = str(a.joint)
            k = actuated_column(joint, names, tau, "sizing_report")
            side = motor_side(a, t, qd[:, k], qdd[:, k], tau[:, k], joint=joint)
            motors[joint], envelopes[joint] = side, getattr(a, "motor", None)
            row = motor_values(side, a, t)
            row["inertia_ratio"] = ratios[joint]
            rows[joint] = row
            missing = [c for c, col in MOTOR_CHECKS if not row[col] >= 0.0]
            if getattr(a, "motor", None) is None:
                missing = ["motor"]
            unchecked[k] = ",".join(missing)
            ok[k] = ok[k] and not missing and all(row[col] >= 1.0 for _, col in MOTOR_CHECKS)
        columns = list(next(iter(rows.values())).keys())
        for col in columns:
            table[col] = [rows[n][col] if n in rows else np.nan for n in names]
        rotor_joints = {str(getattr(a, "rotor_joint", "")) for a in actuators}
    else:
        rotor_joints = set()
    table["ok"] = ok
    if actuators:
        table["unchecked"] = unchecked
    keep = [n not in rotor_joints for n in names]
    report = SizingReport(
        table=table[keep],
        t=t.copy(),
        torque=tau[:, keep],
        speed=qd[:, keep].copy(),
        motors=motors,
        envelopes=envelopes,
    )
    if out is not None:
        report.save(out)
    return report


# --- gear-ratio sweep --------------------------------------------------------------------------

_SPEC_FIELDS = (
    "rotor_inertia",
    "efficiency",
    "friction_viscous",
    "friction_coulomb",
    "friction_smoothing",
    "motor",
)
_SPEC_DEFAULTS = {
    "efficiency": 1.0,
    "friction_viscous": 0.0,
    "friction_coulomb": 0.0,
    "motor": None,
}


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


def _spec(joint: str, spec, existing):
    from types import SimpleNamespace

    if isinstance(spec, dict):
        unknown = sorted(set(spec) - set(_ACTUATOR_FIELDS))
        if unknown:
            raise _core.ModelError(f"gear_ratio_sweep: [{joint}] unknown key(s) {unknown}")
        if spec.get("gyroscopic", False):
            raise _core.ModelError(
                f"gear_ratio_sweep: [{joint}] the closed-form sweep is the gear-reduced model "
                "(gyroscopic=False)"
            )
    values = {}
    for name in _SPEC_FIELDS:
        if isinstance(spec, dict):
            value = spec.get(name, getattr(existing, name, _SPEC_DEFAULTS.get(name)))
        elif spec is not None:
            value = getattr(spec, name, getattr(existing, name, _SPEC_DEFAULTS.get(name)))
        else:
            value = getattr(existing, name, _SPEC_DEFAULTS.get(name))
        if (
            name == "friction_smoothing"
            and value is not None
            and existing is not None
            and not (isinstance(spec, dict) and name in spec)
            and abs(value - 1e-3 * abs(existing.gear_ratio)) <= 1e-15 * abs(value)
        ):
            value = None  # add_actuator's default 1e-3 |N0|: at ratio N it is 1e-3 |N|
        if value is None and name == "rotor_inertia":
            raise _core.ModelError(f"gear_ratio_sweep: joint {joint!r} needs a rotor_inertia")
        if name == "motor" and isinstance(value, dict):
            value = make_motor(**value)
        values[name] = value
    return SimpleNamespace(joint=joint, gear_ratio=1.0, **values)


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

    from armdyn.actuators import motor_side

    if model is not None and not hasattr(model, "dof_names"):
        # gear_ratio_sweep(result, ratios[, actuators]): the model is the result's
        if actuators is not None:
            raise _core.ModelError(
                f"gear_ratio_sweep: model must be an armdyn.Model, got {type(model).__name__}"
            )
        model, ratios, actuators = None, model, ratios
    if ratios is None:
        raise _core.ModelError("gear_ratio_sweep: ratios is required (the gear ratios to try)")
    model = _model_of(result, model, "gear_ratio_sweep")
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
    m_diag = None
    q = _independent_q(model, result)
    if q is not None:
        try:
            m_diag = _mass_matrix(model, q)
        except (_core.ModelError, _core.SolverError):
            m_diag = None
    rows, index = [], []
    for joint, spec in actuators.items():
        if joint not in names:
            raise _core.ModelError(f"gear_ratio_sweep: joint {joint!r} is not a column ({names})")
        k = names.index(joint)
        if np.any(np.isnan(tau[:, k])):
            raise _core.ModelError(f"gear_ratio_sweep: the result has no torque for {joint!r}")
        act = _spec(joint, spec, existing.get(joint))
        tau_load, m_load = tau[:, k], None
        own = existing.get(joint)
        if own is not None:
            tau_load = motor_side(own, t, qd[:, k], qdd[:, k], tau[:, k], joint=joint).load_torque
        if m_diag is not None and own is not None:
            m_load = np.max(m_diag[:, own.dof, own.dof]) - own.gear_ratio**2 * own.rotor_inertia
        elif m_diag is not None:
            dofs = list(model.dof_names)
            m_load = (
                np.max(m_diag[:, dofs.index(joint), dofs.index(joint)]) if joint in dofs else None
            )
        grid = ratios.get(joint) if isinstance(ratios, dict) else ratios
        from armdyn import _checks

        name = f"ratios[{joint!r}]" if isinstance(ratios, dict) else "ratios"
        for n in np.atleast_1d(_checks.array("gear_ratio_sweep", name, grid, finite=True)):
            act.gear_ratio = float(n)
            tau_n = tau_load + n * rotor_torque(act, qd[:, k], qdd[:, k])
            side = motor_side(act, t, qd[:, k], qdd[:, k], tau_n, joint=joint)
            row = motor_values(side, act, t)
            rotor_j = n * n * float(act.rotor_inertia)
            row["inertia_ratio"] = (
                m_load / rotor_j if m_load is not None and rotor_j > 0 else np.nan
            )
            peak = float(np.max(np.abs(tau_n)))
            row["peak_torque"] = peak
            ok = peak <= effort_limit[k] and np.max(np.abs(qd[:, k])) <= velocity_limit[k]
            ok = ok and act.motor is not None
            row["ok"] = bool(ok and all(row[col] >= 1.0 for _, col in MOTOR_CHECKS))
            rows.append(row)
            index.append((joint, float(n)))
    table = pd.DataFrame(
        rows, index=pd.MultiIndex.from_tuples(index, names=["joint", "gear_ratio"])
    )
    table = table.drop(columns=["gear_ratio"])
    summary = []
    for joint in actuators:
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
    return GearRatioSweep(
        table=table, summary=pd.DataFrame(summary, index=pd.Index(list(actuators), name="joint"))
    )
