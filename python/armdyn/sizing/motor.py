"""The motor-side checks of the sizing report: one actuator's motor columns along a run
(:func:`motor_values`: torque, speed, current, power and energy, the margins against the
datasheet, the temperature rises), the speed–torque envelope (:func:`motor_envelope`) and the
inertia ratio (:func:`inertia_ratios`). The motor-side values themselves (ω, T, i, P_el, the
losses) are :mod:`armdyn.actuators`'."""

from __future__ import annotations

import numpy as np

from armdyn import _core
from armdyn._runs import time_mean
from armdyn.actuators import rotor_torque
from armdyn.sizing.thermal import temperature_rises

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


def motor_values(side, actuator, t: np.ndarray) -> dict:
    """The report's motor-side columns of one actuator (see :func:`sizing_report`)."""
    motor = getattr(actuator, "motor", None)
    row = _torque_speed_values(side, actuator, t)
    row.update(_margins(motor, side, row))
    if side.copper_included:
        r_th = _num(getattr(motor, "thermal_resistance", None))
        tau_th = _num(getattr(motor, "thermal_time_constant", None))
        steady, peak = temperature_rises(t, side.loss_copper, r_th, tau_th)
        row["temperature_rise_steady"], row["temperature_rise_peak"] = steady, peak
    return row


def _torque_speed_values(side, actuator, t: np.ndarray) -> dict:
    """The columns from the motor-side arrays alone: the torque's two shares (joint side),
    the motor's peak and RMS torque, speed and current, its electrical power and energies (the
    temperature columns NaN, set by :func:`motor_values`)."""
    T, w = side.torque, side.speed
    n = float(actuator.gear_ratio)
    # the joint torque's two shares: the load's (what the gear output delivers to the link) and
    # the rotor's, N T_rot (its inertia and motor-side friction reflected to the joint)
    reflected = n * rotor_torque(actuator, side.speed / n, side.acceleration / n)
    row = {
        "gear_ratio": n,
        "peak_load_torque": float(np.max(np.abs(side.load_torque))),
        "peak_rotor_torque": float(np.max(np.abs(reflected))),
        "motor_peak_torque": float(np.max(np.abs(T))),
        "motor_rms_torque": np.sqrt(time_mean(T**2, t)),
        "motor_peak_speed": float(np.max(np.abs(w))),
        "motor_rms_speed": np.sqrt(time_mean(w**2, t)),
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
        row["rms_current"] = float(np.sqrt(time_mean(side.current**2, t)))
    return row


def _margins(motor, side, row: dict) -> dict:
    """The four margin columns of :data:`MOTOR_CHECKS`: the datasheet's limit over the run's
    value (inf for a zero value, NaN without the datasheet value)."""

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
    out = {
        "continuous_torque_margin": ratio(cont, row["motor_rms_torque"]),
        "peak_torque_margin": ratio(peak, row["motor_peak_torque"]),
        "motor_speed_margin": ratio(speed_lim, row["motor_peak_speed"]),
        "envelope_margin": np.nan,
    }
    t0, w0 = motor_envelope(motor)
    if np.isfinite(t0) and np.isfinite(w0) and t0 > 0 and w0 > 0:
        worst = float(np.max(np.abs(side.torque + t0 * side.speed / w0)))
        out["envelope_margin"] = np.inf if worst == 0.0 else t0 / worst
    return out


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


def _mass_matrices(model, q: np.ndarray | None) -> np.ndarray | None:
    """:func:`_mass_matrix` along the run, or None without coordinates (``q`` None) or for a
    model that has none (not a joint-space model)."""
    if q is None:
        return None
    try:
        return _mass_matrix(model, q)
    except (_core.ModelError, _core.SolverError):
        return None


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
    m = _mass_matrices(model, q)
    if m is None:
        return out
    for k, a in enumerate(actuators):
        rotor = float(a.gear_ratio) ** 2 * float(a.rotor_inertia)
        if rotor > 0.0:
            load = m[:, a.dof, a.dof] - (rotor if k < len(own) else 0.0)
            out[str(a.joint)] = float(np.max(load) / rotor)
    return out


def _load_inertia(m: np.ndarray | None, model, joint: str, own) -> float | None:
    """The largest load inertia at ``joint`` along the run, rotor-free: max M_jj − N₀² J₀ with
    the model's own actuator ``own`` on it (None: max M_jj); None without the mass matrices
    ``m`` (:func:`_mass_matrices`) or when ``joint`` is not an independent coordinate."""
    if m is not None and own is not None:
        return np.max(m[:, own.dof, own.dof]) - own.gear_ratio**2 * own.rotor_inertia
    if m is not None:
        dofs = list(model.dof_names)
        return np.max(m[:, dofs.index(joint), dofs.index(joint)]) if joint in dofs else None
    return None
