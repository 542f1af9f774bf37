"""Motor-side values of a geared actuator along a run: speed, torque, current, electrical power,
energy, regeneration and the losses, from the joint-side motion and torque.

The actuator model (``ModelBuilder.add_actuator``): a rotor of axial inertia ``J`` turning at
``ω = N q̇`` behind a gear of ratio ``N`` and efficiency ``η``, with motor-side viscous friction
``b`` and smoothed Coulomb friction ``c tanh(ω / v_s)`` (``v_s`` the actuator's
``friction_smoothing``, default ``1e-3 |N|`` rad/s: :func:`coulomb_smoothing`).
The rotor is in the dynamics, so the joint-side torque ``τ`` of a run (``result.joint_torques``,
or the drives' efforts) already includes the reflected rotor terms
``N² J q̈ + N² b q̇ + N c tanh(N q̇ / v_s)``. Splitting it:

- ``T_rot = J ω̇ + b ω + c tanh(ω / v_s)``: the motor-side torque that spins the rotor itself
  (:func:`rotor_torque`);
- ``τ_gear = τ − N T_rot``: the load's share, the torque the gear output delivers to the link;
- the motor (air-gap) torque ``T = T_rot + τ_gear / (N η)`` while the gear transmits power from
  the motor to the load (``τ_gear q̇ ≥ 0``), else ``T = T_rot + τ_gear η / N`` (the load drives
  the gear backwards: it returns only ``η`` of its power to the motor). At ``q̇ = 0`` no power
  flows and the first branch holds: holding a load takes ``τ_gear / (N η)`` (conservative).

With a :class:`armdyn.Motor` attached: current ``i = T / k_t``, copper loss ``R i²``, electrical
power ``P_el = T ω + R i²`` (negative: the motor regenerates). Without a winding resistance the
electrical power is the motor's mechanical power ``T ω`` (``MotorSide.copper_included`` is then
False and the copper loss is zero: the electrical values are a lower bound).

Energy balance (exact per sample, hence for the trapezoid integrals to round-off)::

    P_el = P_mech + loss_copper + loss_friction + loss_gear
    P_mech = τ_gear q̇ + J ω ω̇            (work on the link + the rotor's kinetic energy rate)
    loss_friction = b ω² + c ω tanh(ω / v_s)          ≥ 0
    loss_gear = τ_gear q̇ (1/η − 1)  (motoring)  or  −τ_gear q̇ (1 − η)  (regenerating)   ≥ 0

and ``τ q̇ = P_mech + loss_friction`` (the joint-side torque's power includes the motor friction).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from armdyn import _core
from armdyn._runs import checked, model_of, trapezoid_steps

#: add_actuator's default Coulomb smoothing velocity per unit gear ratio: v_s = 1e-3 |N| rad/s
#: on the motor side, i.e. 1e-3 rad/s (or m/s) at the joint.
ROTOR_COULOMB_SMOOTHING = 1e-3


def coulomb_smoothing(actuator: _core.Actuator | Any) -> float:
    """The motor-side smoothing velocity v_s [rad/s] of an actuator's Coulomb friction
    ``c tanh(ω / v_s)``: its ``friction_smoothing`` when positive, else add_actuator's default
    ``ROTOR_COULOMB_SMOOTHING · |N|``."""
    v = getattr(actuator, "friction_smoothing", None)
    if v is not None and float(v) > 0.0:
        return float(v)
    return ROTOR_COULOMB_SMOOTHING * abs(float(actuator.gear_ratio))


def cumulative_trapezoid(y: np.ndarray, t: np.ndarray) -> np.ndarray:
    """∫_{t0}^{t_k} y dt at every sample (trapezoid rule), starting at 0."""
    y = np.asarray(y, dtype=float)
    out = np.zeros_like(y)
    out[1:] = np.cumsum(trapezoid_steps(y, t))
    return out


def rotor_torque(
    actuator: _core.Actuator | Any, qd: npt.ArrayLike, qdd: npt.ArrayLike
) -> npt.NDArray[np.float64]:
    """T_rot = J ω̇ + b ω + c tanh(ω / v_s), ω = N q̇, ω̇ = N q̈: the motor-side torque that
    spins the rotor itself (its inertia and motor-side friction; v_s:
    :func:`coulomb_smoothing`). The joint carries N T_rot of it. ``qd``, ``qdd``: the joint's
    rates and accelerations (arrays of one shape); the actuator's values are taken as they
    are (:func:`motor_side` checks them)."""
    qd, qdd = np.asarray(qd, dtype=float), np.asarray(qdd, dtype=float)
    n, j = float(actuator.gear_ratio), float(actuator.rotor_inertia)
    b, c = float(actuator.friction_viscous), float(actuator.friction_coulomb)
    return _rotor(actuator, n, j, b, c, qd, qdd)[3]


def _rotor(actuator, n: float, j: float, b: float, c: float, qd, qdd):
    """(ω, ω̇, the Coulomb term c tanh(ω / v_s), T_rot) of gear ratio ``n``, rotor inertia
    ``j``, viscous ``b`` and Coulomb ``c`` friction: the one place the rotor torque is written
    (:func:`rotor_torque`, :func:`motor_side`, and through them armdyn.sizing)."""
    w = n * qd
    wd = n * qdd
    coulomb = c * np.tanh(w / coulomb_smoothing(actuator))
    return w, wd, coulomb, j * wd + b * w + coulomb


def gear_input_torque(load_torque, qd, ratio, efficiency):
    """The motor-side torque that drives the gear: τ_gear / (N η) while the gear transmits
    power from the motor to the load (τ_gear q̇ ≥ 0), else τ_gear η / N (the load drives it
    backwards). Elementwise with numpy broadcasting (``load_torque``, ``qd`` the joint side;
    ``ratio``, ``efficiency`` of one or many gears): the one place the formula is written
    (:func:`motor_side`, :func:`armdyn.sizing.motor.motor_cycle_values`)."""
    motoring = load_torque * qd >= 0.0
    return np.where(motoring, load_torque / (ratio * efficiency), load_torque * efficiency / ratio)


@dataclass
class MotorSide:
    """Motor-side values of one actuator at the samples of a run (SI units, 1-D arrays).

    Attributes:
        joint: the joint's name.
        t: times [s].
        speed: motor speed ω = N q̇ [rad/s].
        acceleration: ω̇ = N q̈ [rad/s²].
        torque: motor (air-gap) torque T [N m] (see the module notes).
        load_torque: τ_gear, the joint-side torque the gear delivers to the link [N m].
        current: T / k_t [A], None without a torque constant.
        electrical_power: T ω + R i² [W]; T ω when the resistance (or k_t) is unknown.
        mechanical_power: τ_gear q̇ + J ω ω̇ [W] (link work + rotor kinetic energy rate).
        loss_copper, loss_friction, loss_gear: [W], each ≥ 0.
        energy: cumulative ∫ P_el dt [J] (net: regeneration subtracts).
        energy_regenerated: cumulative ∫ max(−P_el, 0) dt [J] (positive).
        copper_included: False when R or k_t is missing (P_el is then the mechanical T ω).
        notes: what could not be computed and why.
    """

    joint: str
    t: npt.NDArray[np.float64]
    speed: npt.NDArray[np.float64]
    acceleration: npt.NDArray[np.float64]
    torque: npt.NDArray[np.float64]
    load_torque: npt.NDArray[np.float64]
    current: npt.NDArray[np.float64] | None
    electrical_power: npt.NDArray[np.float64]
    mechanical_power: npt.NDArray[np.float64]
    loss_copper: npt.NDArray[np.float64]
    loss_friction: npt.NDArray[np.float64]
    loss_gear: npt.NDArray[np.float64]
    energy: npt.NDArray[np.float64]
    energy_regenerated: npt.NDArray[np.float64]
    copper_included: bool
    notes: list[str] = field(default_factory=list)

    def integral(self, name: str) -> float:
        """∫ x dt over the whole run (trapezoid rule) of one of the power arrays."""
        return float(cumulative_trapezoid(getattr(self, name), self.t)[-1])


def _get(obj, name):
    return None if obj is None else getattr(obj, name, None)


def _positive(value, what: str, joint: str, allow_zero: bool = False) -> float:
    v = float(value)
    if not np.isfinite(v) or v < 0.0 or (v == 0.0 and not allow_zero):
        raise _core.ModelError(
            f"actuator on joint {joint!r}: {what} must be a positive number, got {value!r}"
        )
    return v


def motor_side(
    actuator: _core.Actuator | Any,
    t: npt.ArrayLike,
    qd: npt.ArrayLike,
    qdd: npt.ArrayLike,
    tau: npt.ArrayLike,
    joint: str | None = None,
) -> MotorSide:
    """Motor-side values of one actuator from its joint's samples (joint side).

    Args:
        actuator: an entry of ``model.actuators`` (or any object with ``gear_ratio``,
            ``rotor_inertia``, ``efficiency``, ``friction_viscous``, ``friction_coulomb``,
            ``motor`` attributes; ``motor`` an :class:`armdyn.Motor` or None).
        t, qd, qdd: (n,) times [s], joint rates and accelerations.
        tau: (n,) joint-side torque including the reflected rotor terms (what a run reports).
        joint: name for messages (default ``actuator.joint``).

    Returns:
        :class:`MotorSide`.

    Raises:
        ModelError: arrays of different lengths, decreasing times, an efficiency outside
            (0, 1], a zero gear ratio, negative inertia/friction, non-finite samples.
    """
    name = joint if joint is not None else str(getattr(actuator, "joint", "?"))
    t = np.asarray(t, dtype=float)
    qd, qdd, tau = (np.asarray(x, dtype=float) for x in (qd, qdd, tau))
    if t.ndim != 1 or any(x.shape != t.shape for x in (qd, qdd, tau)):
        raise _core.ModelError(
            f"motor_side({name!r}): t, qd, qdd and tau must be 1-D of one length, got shapes "
            f"{t.shape}, {qd.shape}, {qdd.shape}, {tau.shape}"
        )
    if len(t) > 1 and not np.all(np.diff(t) >= 0.0):
        raise _core.ModelError(f"motor_side({name!r}): times must not decrease")
    for label, x in (("t", t), ("qd", qd), ("qdd", qdd), ("tau", tau)):
        if not np.all(np.isfinite(x)):
            raise _core.ModelError(f"motor_side({name!r}): {label} has non-finite samples")
    n_ratio = float(actuator.gear_ratio)
    if not np.isfinite(n_ratio) or n_ratio == 0.0:
        raise _core.ModelError(
            f"actuator on joint {name!r}: gear_ratio must be finite and non-zero, got "
            f"{actuator.gear_ratio!r}"
        )
    j_rot = _positive(actuator.rotor_inertia, "rotor_inertia", name, allow_zero=True)
    eta = float(actuator.efficiency)
    if not 0.0 < eta <= 1.0:
        raise _core.ModelError(
            f"actuator on joint {name!r}: efficiency must be in (0, 1], got {actuator.efficiency!r}"
        )
    b = _positive(actuator.friction_viscous, "friction_viscous", name, allow_zero=True)
    c = _positive(actuator.friction_coulomb, "friction_coulomb", name, allow_zero=True)

    w, wd, coulomb, t_rot = _rotor(actuator, n_ratio, j_rot, b, c, qd, qdd)
    tau_gear = tau - n_ratio * t_rot
    p_load = tau_gear * qd
    motoring = p_load >= 0.0
    torque = t_rot + gear_input_torque(tau_gear, qd, n_ratio, eta)
    loss_gear = np.where(motoring, p_load * (1.0 / eta - 1.0), -p_load * (1.0 - eta))
    loss_friction = b * w * w + coulomb * w
    p_mech = p_load + j_rot * w * wd

    motor = _get(actuator, "motor")
    k_t, r_w = _get(motor, "torque_constant"), _get(motor, "resistance")
    notes = []
    current = None
    if k_t is not None:
        current = torque / _positive(k_t, "motor torque_constant", name)
    elif motor is not None:
        notes.append("no torque_constant: current and copper loss unknown")
    if current is not None and r_w is not None:
        loss_copper = _positive(r_w, "motor resistance", name, allow_zero=True) * current**2
        copper = True
    else:
        loss_copper = np.zeros_like(torque)
        copper = False
        if motor is None:
            notes.append("no motor data: electrical power is the motor's mechanical power T ω")
        elif r_w is None:
            notes.append("no resistance: electrical power is the motor's mechanical power T ω")
    p_el = torque * w + loss_copper
    return MotorSide(
        joint=name,
        t=t.copy(),
        speed=w,
        acceleration=wd,
        torque=torque,
        load_torque=tau_gear,
        current=current,
        electrical_power=p_el,
        mechanical_power=p_mech,
        loss_copper=loss_copper,
        loss_friction=loss_friction,
        loss_gear=loss_gear,
        energy=cumulative_trapezoid(p_el, t),
        energy_regenerated=cumulative_trapezoid(np.maximum(-p_el, 0.0), t),
        copper_included=copper,
        notes=notes,
    )


def motor_side_of_result(
    model: _core.Model | Any, result: Any | None = None
) -> dict[str, MotorSide]:
    """Motor-side values of every actuator of ``model`` along ``result``
    (``motor_side_of_result(result)``: the model the result holds, ``result.model``).

    Args:
        model: the model the run was made with (``model.actuators``); default
            ``result.model``.
        result: a :class:`~armdyn.SimulationResult`, :class:`~armdyn.InverseDynamicsResult`
            or :class:`~armdyn.sizing.TrajectoryRun` (``t``, ``qd``, ``qdd`` and the joint
            torques, columns ``model.joint_dof_names``).

    Returns:
        ``{joint name: MotorSide}`` in ``model.actuators`` order (empty without actuators).

    Raises:
        ModelError: the result does not match the model, or an actuated joint has no torque in
            the result (an undriven joint of a drive-based result); no model passed and none
            held by the result (names ``model``).
    """
    if result is None:  # motor_side_of_result(result)
        model, result = None, model
    model = model_of(result, model, "motor_side_of_result")
    actuators = list(getattr(model, "actuators", None) or [])
    if not actuators:
        return {}
    t, names, _, tau = checked(model, result, "motor_side_of_result")
    qd = np.asarray(result.qd, dtype=float)
    qdd = np.asarray(result.qdd, dtype=float)
    out = {}
    for a in actuators:
        joint = str(a.joint)
        k = actuated_column(joint, names, tau, "motor_side_of_result")
        out[joint] = motor_side(a, t, qd[:, k], qdd[:, k], tau[:, k], joint=joint)
    return out


def actuated_column(joint: str, names: list[str], tau: np.ndarray, caller: str) -> int:
    """The result column of an actuated joint, checked to exist and to carry a torque."""
    if joint not in names:
        raise _core.ModelError(
            f"{caller}: actuated joint {joint!r} is not a column of the result ({names})"
        )
    k = names.index(joint)
    if np.any(np.isnan(tau[:, k])):
        raise _core.ModelError(
            f"{caller}: the result has no torque for actuated joint {joint!r} (no drive and no "
            "joint_torques)"
        )
    return k
