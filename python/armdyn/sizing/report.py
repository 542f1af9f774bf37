"""The sizing report of a run (:func:`sizing_report`, :class:`SizingReport`): the joint-side
table (peak and RMS torque and speed, power, regenerated energy, margins against the joint
limits) and, for actuated joints, the motor-side columns and checks (:mod:`armdyn.sizing.motor`),
with what-if actuators added in closed form (:mod:`armdyn.sizing.what_if`)."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from armdyn import _core
from armdyn._runs import checked as _checked
from armdyn._runs import model_of as _model_of
from armdyn._runs import trapezoid
from armdyn.actuators import actuated_column, motor_side, rotor_torque
from armdyn.sizing.limits import _column_limits
from armdyn.sizing.motor import MOTOR_CHECKS, inertia_ratios, motor_envelope, motor_values
from armdyn.sizing.what_if import what_if_actuators

if TYPE_CHECKING:  # pandas is imported when a table is built: `import armdyn` stays light
    import pandas as pd
    from matplotlib.figure import Figure

#: the runs the sizing functions take (see armdyn.sizing.limits)
_Run = Any


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
        thermal: ``{joint: (t, winding, housing)}`` temperatures [°C] over one period of a
            repeated duty cycle (filled by ``armdyn size --cycle/--dwell``:
            :func:`armdyn.sizing.cli.winding_temperature_check`), drawn by :meth:`save`.
    """

    table: pd.DataFrame
    t: npt.NDArray[np.float64]
    torque: npt.NDArray[np.float64]
    speed: npt.NDArray[np.float64]
    motors: dict[str, Any] = field(default_factory=dict)
    envelopes: dict[str, Any] = field(default_factory=dict)
    thermal: dict[str, Any] = field(default_factory=dict)

    def save(self, directory: str | os.PathLike[str], sweep: Any = None) -> Path:
        """Write ``table.csv``, ``report.html`` and the figures ``torque_<k>.png`` /
        ``motor_<k>.png`` into ``directory`` (created if missing). The page opens with the
        verdict (overall, then per joint: motor, gear ratio, pass/fail, the binding check and
        its margin), then the checks by part, the torque and thermal histories, each motor's
        operating points on its speed–torque plane, the gear-ratio sweep ``sweep`` (a
        :class:`GearRatioSweep`, when given) and the whole table; every figure is embedded,
        so the page is one self-contained file (:mod:`armdyn.sizing.writer`). Needs
        matplotlib (the ``plot`` extra). Returns the HTML page's path."""
        from armdyn.sizing.writer import write_report

        return write_report(self, directory, sweep=sweep)

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
    model, t, names, qd, tau = _checked_arguments(result, model, out)
    extra, qdd = _add_what_if(model, result, names, qd, tau, actuators)
    table, ok = _joint_side(model, t, names, qd, tau)
    all_actuators = list(getattr(model, "actuators", None) or []) + extra
    motors, envelopes, unchecked, rotor_joints = {}, {}, [""] * len(names), set()
    if all_actuators:
        motors, envelopes, unchecked = _motor_side(
            model, result, extra, t, names, (qd, qdd, tau), table, ok
        )
        rotor_joints = {str(getattr(a, "rotor_joint", "")) for a in all_actuators}
    table["ok"] = ok
    if all_actuators:
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


def _checked_arguments(result, model, out):
    """``(model, t, names, qd, tau)``: the model (default the result's), ``out`` checked, and
    the run's columns checked against the model, two samples at least over a positive span."""
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
    return model, t, names, qd, tau


def _add_what_if(model, result, names, qd, tau, actuators):
    """``(extra, qdd)``: the what-if actuators' stand-ins, their rotors' share N T_rot added to
    their joints' torques in ``tau`` (in place), and the run's accelerations (None when no
    actuator needs them)."""
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
    return extra, qdd


def _joint_side(model, t, names, qd, tau):
    """``(table, ok)``: the joint-side columns per result column, and whether its peak torque
    and speed are within the joint's limits (a column without a torque: its speed only)."""
    import pandas as pd

    span = t[-1] - t[0]
    effort_limit, velocity_limit = _column_limits(model, names)
    power = tau * qd
    with np.errstate(invalid="ignore", divide="ignore"):
        peak_torque = np.max(np.abs(tau), axis=0)
        peak_speed = np.max(np.abs(qd), axis=0)
        table = pd.DataFrame(
            {
                "peak_torque": peak_torque,
                "rms_torque": np.sqrt(trapezoid(tau**2, t) / span),
                "peak_speed": peak_speed,
                "rms_speed": np.sqrt(trapezoid(qd**2, t) / span),
                "peak_power": np.max(np.abs(power), axis=0),
                "energy_regenerated": -trapezoid(np.minimum(power, 0.0), t),
                "effort_limit": effort_limit,
                "velocity_limit": velocity_limit,
                "torque_margin": np.where(peak_torque == 0.0, np.inf, effort_limit / peak_torque),
                "speed_margin": np.where(peak_speed == 0.0, np.inf, velocity_limit / peak_speed),
            },
            index=pd.Index(names, name="joint"),
        )
        torque_ok = np.isnan(peak_torque) | (peak_torque <= effort_limit)
    table["torque_margin"] = table["torque_margin"].where(~np.isnan(peak_torque), np.nan)
    return table, torque_ok & (peak_speed <= velocity_limit)


def _motor_side(model, result, extra, t, names, samples, table, ok):
    """``(motors, envelopes, unchecked)`` of every actuator (the model's, then the what-if
    ones): each one's :class:`~armdyn.actuators.MotorSide`, motor and unmade checks; its
    motor-side columns are added to ``table`` (NaN on the other joints) and its checks to
    ``ok`` (in place)."""
    qd, qdd, tau = samples
    actuators = list(getattr(model, "actuators", None) or []) + extra
    ratios = inertia_ratios(model, result, extra)
    motors, envelopes, rows, unchecked = {}, {}, {}, [""] * len(names)
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
    for col in next(iter(rows.values())):
        table[col] = [rows[n][col] if n in rows else np.nan for n in names]
    return motors, envelopes, unchecked
