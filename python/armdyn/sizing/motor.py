"""The motor-side checks of the sizing report: one actuator's motor columns along a run
(:func:`motor_values`: torque, speed, current, power and energy, the margins against the
datasheet, the temperature rises), the speed–torque envelope (:func:`motor_envelope`) and the
inertia ratio (:func:`inertia_ratios`). The motor-side values themselves (ω, T, i, P_el, the
losses) are :mod:`armdyn.actuators`'."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from armdyn import _checks, _core
from armdyn._runs import time_mean
from armdyn.actuators import gear_input_torque, rotor_torque
from armdyn.sizing.checks import margin
from armdyn.sizing.options import sizing_options
from armdyn.sizing.thermal import temperature_rises, thermal_cycle, thermal_network

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
    t0, w0 = envelope_corners(
        *(
            _num(getattr(motor, a, None))
            for a in ("torque_constant", "voltage", "resistance", "peak_torque", "no_load_speed")
        )
    )
    return float(t0[0]), float(w0[0])


def speed_limit(max_speed, no_load_speed) -> np.ndarray:
    """The speed check's allowable: the maximum speed, else the no-load speed (NaN: neither),
    elementwise."""
    max_speed, no_load_speed = np.atleast_1d(max_speed, no_load_speed)
    return np.where(np.isnan(max_speed), no_load_speed, max_speed).astype(float)


def envelope_corners(k_t, voltage, resistance, peak_torque, no_load_speed):
    """:func:`motor_envelope`'s ``(T0, ω0)`` of many motors at once (arrays of one shape, NaN =
    not given): the one place the rule is written."""
    k_t, v, r, peak, w_nl = (
        np.atleast_1d(np.asarray(x, dtype=float))
        for x in (k_t, voltage, resistance, peak_torque, no_load_speed)
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        stall = k_t * v / r
        t0 = np.where(np.isfinite(stall) & (r > 0), stall, peak)
        w0 = np.where(np.isnan(w_nl), np.where(k_t > 0, v / k_t, np.nan), w_nl)
    return t0, w0


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
    speed_lim = float(
        speed_limit(
            _num(getattr(motor, "max_speed", None)), _num(getattr(motor, "no_load_speed", None))
        )[0]
    )
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


# --- the motor side of a duty cycle, vectorised over k candidates ----------------------------

#: candidates per chunk of motor_cycle_values (bounds its memory: a few (n, chunk) arrays)
CHUNK = 1024

#: the (k,) values of motor_cycle_values besides the margins
CYCLE_VALUES = (
    "motor_rms_torque",
    "motor_peak_torque",
    "motor_peak_speed",
    "envelope_worst",
    "stall_torque",
    "winding_temperature_peak",
    "housing_temperature_peak",
    "peak_current",
    "rms_current",
    "peak_terminal_voltage",
    "peak_electrical_power",
    "energy_regenerated",
)

#: the motor's numeric datasheet fields the cycle values read (NaN where a mapping lacks one):
#: armdyn.Motor's, its one list
_MOTOR_NUMBERS: tuple[str, ...] = tuple(_core.Motor.FIELDS)


def _candidate_arrays(who: str, ratio, efficiency, rotor_inertia):
    """``(ratio, efficiency, rotor_inertia)`` as checked (k,) arrays: ratios finite and
    non-zero, efficiencies in (0, 1], rotor inertias finite and ≥ 0 (ModelError naming the
    argument and the first bad candidate)."""
    arrays = []
    for name, x in (("ratio", ratio), ("efficiency", efficiency), ("rotor_inertia", rotor_inertia)):
        a = np.atleast_1d(np.asarray(x, dtype=float))
        if a.ndim != 1:
            raise _core.ModelError(f"{who}: {name} must be a 1-D array, got shape {a.shape}")
        arrays.append(a)
    try:
        ratio, eta, j = np.broadcast_arrays(*arrays)
    except ValueError:
        raise _core.ModelError(
            f"{who}: ratio, efficiency and rotor_inertia must have one length, got "
            f"{[len(a) for a in arrays]}"
        ) from None
    for name, a, ok in (
        ("ratio", ratio, np.isfinite(ratio) & (ratio != 0.0)),
        ("efficiency", eta, (eta > 0.0) & (eta <= 1.0)),
        ("rotor_inertia", j, np.isfinite(j) & (j >= 0.0)),
    ):
        if not np.all(ok):
            i = int(np.argmin(ok))
            raise _core.ModelError(f"{who}: {name}[{i}] = {a[i]!r} is out of range")
    return ratio, eta, j


def _motors_length(who: str, motors) -> int:
    """The number of motors in the mapping (its longest 1-D field; 1 for scalars)."""
    if motors is None or not hasattr(motors, "get"):
        raise _core.ModelError(f"{who}: motors must be a mapping of field -> (k,) arrays")
    sizes = [np.size(motors.get(f)) for f in _MOTOR_NUMBERS if motors.get(f) is not None]
    return max(sizes, default=1)


def _motor_arrays(who: str, motors, k: int) -> dict[str, np.ndarray]:
    """The numeric datasheet fields of k motors as (k,) float arrays (NaN where a field is
    missing or not given); a given value must be a finite positive number (a finite number for
    the maximum winding temperature, in °C)."""
    if motors is None or not hasattr(motors, "get"):
        raise _core.ModelError(f"{who}: motors must be a mapping of field -> (k,) arrays")
    out = {}
    for name in _MOTOR_NUMBERS:
        value = motors.get(name)
        if value is None:
            out[name] = np.full(k, np.nan)
            continue
        try:
            a = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise _core.ModelError(f"{who}: motors[{name!r}] is not numeric") from None
        if a.ndim == 0:
            a = np.full(k, float(a))
        if a.shape != (k,):
            raise _core.ModelError(f"{who}: motors[{name!r}] must have shape ({k},), got {a.shape}")
        given = ~np.isnan(a)
        with np.errstate(invalid="ignore"):
            ok = np.isfinite(a) if name == "max_winding_temperature" else np.isfinite(a) & (a > 0)
        if np.any(given & ~ok):
            i = int(np.argmax(given & ~ok))
            raise _core.ModelError(
                f"{who}: motors[{name!r}][{i}] = {a[i]!r} must be a finite "
                f"{'number' if name == 'max_winding_temperature' else 'positive number'}"
            )
        out[name] = a
    return out


def _load_arrays(who: str, load):
    """(t, speed, acceleration, torque, repeat) of a :class:`armdyn.sizing.cycle.JointLoad`
    (or an object with those attributes), checked."""
    try:
        t, qd, qdd, tau = (
            np.asarray(getattr(load, a), dtype=float)
            for a in ("t", "speed", "acceleration", "torque")
        )
    except AttributeError as exc:
        raise _core.ModelError(f"{who}: load must be a JointLoad ({exc})") from None
    if t.ndim != 1 or len(t) < 2 or any(x.shape != t.shape for x in (qd, qdd, tau)):
        raise _core.ModelError(f"{who}: load's arrays must be 1-D of one length (2 at least)")
    for name, x in (("t", t), ("speed", qd), ("acceleration", qdd), ("torque", tau)):
        if not np.all(np.isfinite(x)):
            raise _core.ModelError(f"{who}: load.{name} has non-finite samples")
    if not (np.all(np.diff(t) >= 0.0) and t[-1] > t[0]):
        raise _core.ModelError(f"{who}: load.t must not decrease and span a positive time")
    repeat = _checks.integer(who, "load.repeat", getattr(load, "repeat", None), lo=1, none=True)
    return t, qd, qdd, tau, repeat


def _thermal_inputs(m: dict, sel, options):
    """The candidates' thermal network and their resistance at the ambient temperature and its
    slope per kelvin (the copper law of the options); no network without k_t and R."""
    k_t, r = m["torque_constant"][sel], m["resistance"][sel]
    net = thermal_network(
        *(
            m[f][sel]
            for f in (
                "thermal_resistance_winding",
                "thermal_resistance_housing",
                "thermal_time_constant_winding",
                "thermal_time_constant_housing",
                "thermal_resistance",
                "thermal_time_constant",
            )
        )
    )
    copper = np.isfinite(k_t) & np.isfinite(r)
    net = replace(net, valid=net.valid & copper)
    alpha = options.copper_temperature_coefficient
    r_ambient = r * (1.0 + alpha * (options.ambient_temperature - options.resistance_temperature))
    return net, np.where(copper, r_ambient, 0.0), np.where(copper, alpha * r, 0.0)


def _chunk(t, qd, qdd, tau, repeat, ratio, eta, j, m: dict, sel, options, series=False):
    """The cycle values of the candidates ``sel`` (time-major (n, kc) arrays inside); with
    ``series`` the per-sample arrays of those candidates instead."""
    n_r, eta_c, j_c = ratio[sel], eta[sel], j[sel]
    # T = J N q̈ + gear_input_torque: the gear's factor per power-flow direction (row 0 while
    # motoring, row 1 backwards), then one outer product per term
    factor = gear_input_torque(np.ones((2, 1)), np.array([[1.0], [-1.0]]), n_r, eta_c)
    motoring = tau * qd >= 0.0
    torque = np.multiply.outer(qdd, j_c * n_r)
    torque += np.multiply.outer(np.where(motoring, tau, 0.0), factor[0])
    torque += np.multiply.outer(np.where(motoring, 0.0, tau), factor[1])
    speed = np.multiply.outer(qd, n_r)
    k_t, r = m["torque_constant"][sel], m["resistance"][sel]
    t0, w0 = envelope_corners(
        k_t, m["voltage"][sel], r, m["peak_torque"][sel], m["no_load_speed"][sel]
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        current = torque / k_t
        current_sq = current * current
        net, r_ambient, r_slope = _thermal_inputs(m, sel, options)
        heated = current_sq
        if not np.all(net.valid):  # NaN without k_t; no loss where nothing is modelled
            heated = np.where(net.valid, current_sq, 0.0)
        heat = thermal_cycle(t, heated, net, r_ambient, r_slope, repeat)
        copper = np.isfinite(k_t) & np.isfinite(r)
        # the winding resistance along the cycle (at ambient where there is no thermal model)
        r_t = heat.winding * r_slope
        r_t += r_ambient
        r_t[:, ~net.valid] = r_ambient[~net.valid]
        loss = r_t * current_sq
        loss[:, ~copper] = 0.0
        power = torque * speed
        power += loss
        voltage = r_t * current
        voltage += np.multiply.outer(qd, k_t * n_r)
        voltage[:, ~copper] = np.nan
    if series:
        return {
            "t": np.asarray(t, dtype=float).copy(),
            "torque": torque[:, 0],
            "speed": speed[:, 0],
            "current": current[:, 0],
            "terminal_voltage": voltage[:, 0],
            "electrical_power": power[:, 0],
            "copper_loss": loss[:, 0],
            "winding_temperature": options.ambient_temperature + heat.winding[:, 0],
            "housing_temperature": options.ambient_temperature + heat.housing[:, 0],
        }
    weights = _trapezoid_weights(t)
    rms = np.sqrt(np.einsum("i,ij->j", weights, torque**2) / (t[-1] - t[0]))
    with np.errstate(divide="ignore", invalid="ignore"):
        envelope = _peak(torque + np.multiply.outer(qd, n_r * t0 / w0))
    peak_torque = _peak(torque)
    return {
        "motor_rms_torque": rms,
        "motor_peak_torque": peak_torque,
        "motor_peak_speed": np.abs(n_r) * np.max(np.abs(qd)),
        "envelope_worst": np.where(np.isfinite(t0) & np.isfinite(w0), envelope, np.nan),
        "stall_torque": t0,
        "winding_temperature_peak": options.ambient_temperature + heat.winding_peak,
        "housing_temperature_peak": options.ambient_temperature + heat.housing_peak,
        "peak_current": peak_torque / np.abs(k_t),
        "rms_current": rms / k_t,
        "peak_terminal_voltage": _peak(voltage),
        "peak_electrical_power": _peak(power),
        "energy_regenerated": np.einsum("i,ij->j", weights, np.maximum(-power, 0.0)),
    }


def _peak(x: np.ndarray) -> np.ndarray:
    """max |x| over axis 0 (NaN propagates)."""
    return np.maximum(np.max(x, axis=0), -np.min(x, axis=0))


def _trapezoid_weights(t: np.ndarray) -> np.ndarray:
    """w with w @ y = the trapezoid rule's ∫ y dt over the samples (armdyn._runs.trapezoid)."""
    dt = np.diff(t)
    w = np.zeros(len(t))
    w[:-1] += 0.5 * dt
    w[1:] += 0.5 * dt
    return w


def _cycle_margins(values: dict, m: dict, options) -> dict:
    """The margins of the motor checks of CHECKS, keyed by check name."""
    allowed_speed = speed_limit(m["max_speed"], m["no_load_speed"])
    ambient = options.ambient_temperature
    return {
        "continuous_torque": margin(values["motor_rms_torque"], m["continuous_torque"]),
        "peak_torque": margin(values["motor_peak_torque"], m["peak_torque"]),
        "speed": margin(values["motor_peak_speed"], allowed_speed),
        "envelope": margin(values["envelope_worst"], values["stall_torque"]),
        # rises above the ambient temperature
        "winding_temperature": margin(
            values["winding_temperature_peak"] - ambient, m["max_winding_temperature"] - ambient
        ),
    }


def motor_cycle_values(
    load, ratio, efficiency, rotor_inertia, motors, options=None, chunk: int = CHUNK
) -> dict[str, np.ndarray]:
    """The motor side of a joint's duty cycle for k candidate drivetrains at once.

    Candidate c is a gear of ratio N = ``ratio[c]`` and efficiency η = ``efficiency[c]``
    with a motor of rotor inertia J = ``rotor_inertia[c]`` (motor side, the gear's input
    inertia included if the caller adds it) and datasheet ``motors[field][c]``. At each
    sample the motor speed is ω = N q̇ and its torque T = J N q̈ +
    :func:`armdyn.actuators.gear_input_torque` (τ_gear / (N η) while the gear transmits power
    to the load, else τ_gear η / N), τ_gear the load's torque (``load.torque``): the formulas
    of :func:`armdyn.actuators.motor_side` (no motor-side friction). Then i = T / k_t, the
    copper loss R(T_w) i² and the winding and housing temperatures of
    :func:`armdyn.sizing.thermal.thermal_cycle` (``load.repeat`` periods from ambient, or the
    periodic steady state when None), the terminal voltage R(T_w) i + k_t ω and the electrical
    power T ω + R(T_w) i², with R(T_w) along the cycle's temperatures (R at the ambient
    temperature for a motor without a thermal model). Without k_t and R the current, the
    thermal and voltage values are NaN and the electrical power is T ω.

    Args:
        load: a :class:`armdyn.sizing.cycle.JointLoad` (one period of the cycle).
        ratio, efficiency, rotor_inertia: (k,) arrays (or scalars for all).
        motors: a mapping of motor field (``armdyn.sizing.MOTOR_FIELDS``) -> (k,) arrays; a
            missing field or NaN = not given.
        options: :class:`armdyn.sizing.options.SizingOptions` (default).
        chunk: candidates evaluated at once (memory: about 12 (n, chunk) float arrays, 95 MiB
            at n = 1,000 and the default chunk: ``python -m benchmarks.motor_cycle``).

    Returns:
        ``{name: (k,) array}``: :data:`CYCLE_VALUES` (peaks and RMS over one period; the
        temperatures in °C at the peak of the repeated cycle's last, or periodic, period; the
        regenerated energy per period [J]) and the margins of the motor checks of
        :data:`armdyn.sizing.checks.CHECKS` keyed by check name (NaN = not checked).
    """
    who = "motor_cycle_values"
    options = sizing_options(options)
    t, qd, qdd, tau, repeat = _load_arrays(who, load)
    ratio, eta, j = _candidate_arrays(who, ratio, efficiency, rotor_inertia)
    k = max(len(ratio), _motors_length(who, motors))
    if len(ratio) == 1 and k > 1:  # one gear for every motor
        ratio, eta, j = (np.repeat(x, k) for x in (ratio, eta, j))
    if len(ratio) != k:
        raise _core.ModelError(
            f"{who}: {len(ratio)} gears (ratio) but {k} motors (the longest field of motors)"
        )
    m = _motor_arrays(who, motors, k)
    chunk = int(_checks.integer(who, "chunk", chunk, lo=1))
    values = {name: np.empty(k) for name in CYCLE_VALUES}
    for start in range(0, k, chunk):
        sel = slice(start, min(start + chunk, k))
        for name, x in _chunk(t, qd, qdd, tau, repeat, ratio, eta, j, m, sel, options).items():
            values[name][sel] = x
    values.update(_cycle_margins(values, m, options))
    return values


def motor_cycle_series(
    load, ratio, efficiency, rotor_inertia, motor, options=None
) -> dict[str, np.ndarray]:
    """One candidate's per-sample values over the period that holds the peak (the periodic
    steady state, or the last of ``load.repeat`` periods): ``t``, ``torque``, ``speed`` (motor
    side), ``current``, ``terminal_voltage``, ``electrical_power``, ``copper_loss``,
    ``winding_temperature`` and ``housing_temperature`` [°C], each (n,), by the formulas of
    :func:`motor_cycle_values`. ``motor``: an :class:`armdyn.Motor`, an object with its
    fields, or a mapping field -> number."""
    who = "motor_cycle_series"
    options = sizing_options(options)
    t, qd, qdd, tau, repeat = _load_arrays(who, load)
    ratio, eta, j = _candidate_arrays(who, ratio, efficiency, rotor_inertia)
    if len(ratio) != 1:
        raise _core.ModelError(f"{who}: one candidate (scalars), got {len(ratio)}")
    if not hasattr(motor, "get"):
        motor = {f: _num(getattr(motor, f, None)) for f in _MOTOR_NUMBERS}
    m = _motor_arrays(who, {f: _num(motor.get(f)) for f in _MOTOR_NUMBERS}, 1)
    return _chunk(t, qd, qdd, tau, repeat, ratio, eta, j, m, slice(0, 1), options, series=True)
