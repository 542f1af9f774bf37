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

One module per concern (every name below is also importable from ``armdyn.sizing``):

- :mod:`armdyn.sizing.limits`: :func:`limit_violations` and each column's effort and velocity
  limit;
- :mod:`armdyn.sizing.trajectory`: :func:`trajectory_run`, :class:`TrajectoryRun`;
- :mod:`armdyn.sizing.cycle`: duty cycles (:func:`duty_cycle`, :class:`DutyCycle`) and a
  joint's load along one (:class:`JointLoad`);
- :mod:`armdyn.sizing.motor`: the motor-side columns and checks (:func:`motor_values`,
  :func:`motor_envelope`, :func:`inertia_ratios`, ``MOTOR_CHECKS``) and a duty cycle's motor
  side for many candidates at once (:func:`~armdyn.sizing.motor.motor_cycle_values`,
  :func:`~armdyn.sizing.motor.motor_cycle_series`);
- :mod:`armdyn.sizing.thermal`: the winding's temperature rise (:func:`thermal_rise`) and the
  two-node model over repeated cycles (:func:`~armdyn.sizing.thermal.thermal_cycle`);
- :mod:`armdyn.sizing.what_if`: what-if actuators from specs (:func:`what_if_actuators`) and
  motors from datasheet keywords (:func:`make_motor`, ``MOTOR_FIELDS``);
- :mod:`armdyn.sizing.selection`: the gear-ratio sweep (:func:`gear_ratio_sweep`,
  :class:`GearRatioSweep`);
- :mod:`armdyn.sizing.drivetrain` / :mod:`armdyn.sizing.select`: the drivetrain selection from
  a catalog (:func:`select_drivetrain`, :class:`DrivetrainSelection`);
- :mod:`armdyn.sizing.report`: :func:`sizing_report`, :class:`SizingReport`;
- :mod:`armdyn.sizing.writer`: the report's files (``table.csv``, figures, ``report.html``) and
  the page's models of a report and of a selection;
- :mod:`armdyn.sizing.html`: the verdict-first page, rendered from an explicit model;
- :mod:`armdyn.sizing.cli`: the ``armdyn size`` and ``armdyn select`` commands (trajectory CSV,
  actuators TOML, payload, duty cycle and check options).
- :mod:`armdyn.sizing.catalog`: catalogs of motors, gearboxes and drives (:func:`load_catalog`,
  :class:`Catalog`, the example ``EXAMPLE_CATALOG``, the declared columns).

The rotor's torque T_rot (:func:`rotor_torque`) is :mod:`armdyn.actuators`'.
"""

from armdyn.actuators import rotor_torque
from armdyn.sizing.catalog import (
    DRIVE_COLUMNS,
    EXAMPLE_CATALOG,
    GEARBOX_COLUMNS,
    MOTOR_COLUMNS,
    Catalog,
    Drive,
    Gearbox,
    load_catalog,
)
from armdyn.sizing.cycle import DutyCycle, JointLoad, duty_cycle
from armdyn.sizing.limits import limit_violations
from armdyn.sizing.motor import MOTOR_CHECKS, inertia_ratios, motor_envelope, motor_values
from armdyn.sizing.report import SizingReport, sizing_report
from armdyn.sizing.select import DrivetrainSelection, select_drivetrain
from armdyn.sizing.selection import GearRatioSweep, gear_ratio_sweep
from armdyn.sizing.thermal import thermal_rise
from armdyn.sizing.trajectory import TrajectoryRun, trajectory_run
from armdyn.sizing.what_if import MOTOR_FIELDS, make_motor, what_if_actuators

__all__ = [
    "DRIVE_COLUMNS",
    "EXAMPLE_CATALOG",
    "GEARBOX_COLUMNS",
    "MOTOR_CHECKS",
    "MOTOR_COLUMNS",
    "MOTOR_FIELDS",
    "Catalog",
    "Drive",
    "DrivetrainSelection",
    "DutyCycle",
    "GearRatioSweep",
    "Gearbox",
    "JointLoad",
    "SizingReport",
    "TrajectoryRun",
    "duty_cycle",
    "gear_ratio_sweep",
    "inertia_ratios",
    "limit_violations",
    "load_catalog",
    "make_motor",
    "motor_envelope",
    "motor_values",
    "rotor_torque",
    "select_drivetrain",
    "sizing_report",
    "thermal_rise",
    "trajectory_run",
    "what_if_actuators",
]
