"""The drivetrain checks, declared once: every check a duty cycle is screened by (motor, gearbox,
output bearing, drive, brake), what it compares and the column its margin goes in.

A check compares a value of the cycle with an allowable value of a part (a catalog column or an
option of :class:`armdyn.sizing.options.SizingOptions`). Its **margin** is allowable / value for
an upper limit (the value must stay below) and value / allowable for a lower limit (a life, a
holding torque), so that a margin ≥ 1 passes in both cases; ``inf`` when the value is zero (an
upper limit) and NaN when the check cannot be made (the part's column is not given): a NaN
margin is *not checked*, neither passing nor failing, and the report says so. A drivetrain is
``ok`` when every margin that was checked is ≥ 1; its **binding check** is the check of least
margin, and ``margin`` that margin.

The functions that compute the values live with their concern (:mod:`armdyn.sizing.motor`,
:mod:`armdyn.sizing.thermal`, :mod:`armdyn.sizing.gearbox`, :mod:`armdyn.sizing.drive`); the
selection, the report and the CLI take the list from here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Check:
    """One drivetrain check.

    Attributes:
        name: the check's name (``binding_check`` values; the margin column is
            ``<name>_margin``).
        part: ``"motor"``, ``"gearbox"``, ``"bearing"``, ``"drive"`` or ``"brake"``.
        value: what the cycle gives (a column of the result tables).
        allowable: what it is compared with (a catalog column, or an option).
        lower: True for a lower limit (value ≥ allowable passes), False for an upper one.
        unit: the unit of value and allowable.
        doc: one sentence for the report and the docs.
    """

    name: str
    part: str
    value: str
    allowable: str
    lower: bool
    unit: str
    doc: str

    @property
    def margin_column(self) -> str:
        return f"{self.name}_margin"


CHECKS: tuple[Check, ...] = (
    # motor (the first four are the sizing report's MOTOR_CHECKS)
    Check(
        "continuous_torque",
        "motor",
        "motor_rms_torque",
        "continuous_torque",
        False,
        "N m",
        "RMS motor torque over the whole cycle, dwell included, against the continuous torque",
    ),
    Check(
        "peak_torque",
        "motor",
        "motor_peak_torque",
        "peak_torque",
        False,
        "N m",
        "largest motor torque against the peak torque",
    ),
    Check(
        "speed",
        "motor",
        "motor_peak_speed",
        "max_speed",
        False,
        "rad/s",
        "largest motor speed against the maximum (else the no-load) speed",
    ),
    Check(
        "envelope",
        "motor",
        "envelope_worst",
        "stall_torque",
        False,
        "N m",
        "every operating point inside the speed-torque envelope (|T + T0 w / w0| <= T0)",
    ),
    Check(
        "winding_temperature",
        "motor",
        "winding_temperature_peak",
        "max_winding_temperature",
        False,
        "degC",
        "winding temperature at the periodic steady state of the repeated cycle (two-node "
        "model); the margin compares rises above the ambient temperature",
    ),
    # gearbox
    Check(
        "gear_life",
        "gearbox",
        "gear_life",
        "required_life",
        True,
        "h",
        "rated life L = L_N (T_N / T_av)^p (n_N / n_av) against the required life",
    ),
    Check(
        "gear_average_torque",
        "gearbox",
        "gear_average_torque",
        "average_torque_limit",
        False,
        "N m",
        "mean output torque (cubic; 10/3 for RV) against the limit for average torque",
    ),
    Check(
        "gear_average_input_speed",
        "gearbox",
        "gear_average_input_speed",
        "average_input_speed_limit",
        False,
        "rad/s",
        "average input speed against the limit for average input speed",
    ),
    Check(
        "gear_repeated_peak",
        "gearbox",
        "gear_repeated_peak_torque",
        "repeated_peak_torque",
        False,
        "N m",
        "largest output torque of the cycle against the repeated peak torque",
    ),
    Check(
        "gear_momentary_peak",
        "gearbox",
        "gear_momentary_torque",
        "momentary_peak_torque",
        False,
        "N m",
        "output torque of an emergency stop from the cycle's worst state "
        "against the momentary peak torque",
    ),
    Check(
        "gear_momentary_count",
        "gearbox",
        "emergency_stops",
        "momentary_peak_count",
        False,
        "1",
        "emergency stops over the life against the allowed number of momentary peaks",
    ),
    Check(
        "gear_input_speed",
        "gearbox",
        "gear_peak_input_speed",
        "max_input_speed",
        False,
        "rad/s",
        "largest input speed against the maximum input speed",
    ),
    # output bearing, from the joint's reaction wrench moved to the bearing's reference point
    Check(
        "bearing_moment",
        "bearing",
        "bearing_peak_moment",
        "bearing_moment_allowable",
        False,
        "N m",
        "largest tilting moment against the allowable moment",
    ),
    Check(
        "bearing_axial",
        "bearing",
        "bearing_peak_axial",
        "bearing_axial_allowable",
        False,
        "N",
        "largest axial force against the allowable axial force",
    ),
    Check(
        "bearing_radial",
        "bearing",
        "bearing_peak_radial",
        "bearing_radial_allowable",
        False,
        "N",
        "largest radial force against the allowable radial force",
    ),
    Check(
        "bearing_life",
        "bearing",
        "bearing_life",
        "required_life",
        True,
        "h",
        "output bearing's rating life against the required life",
    ),
    # drive
    Check(
        "drive_peak_current",
        "drive",
        "peak_current",
        "drive_peak_current",
        False,
        "A",
        "largest motor current against the drive's peak current",
    ),
    Check(
        "drive_rms_current",
        "drive",
        "rms_current",
        "drive_continuous_current",
        False,
        "A",
        "RMS motor current over the cycle against the drive's continuous current",
    ),
    Check(
        "drive_voltage",
        "drive",
        "peak_terminal_voltage",
        "bus_voltage",
        False,
        "V",
        "largest terminal voltage R i + k_t w against the drive's bus voltage",
    ),
    # brake
    Check(
        "brake_holding",
        "brake",
        "brake_holding_torque",
        "brake_required_torque",
        True,
        "N m",
        "holding brake torque at the joint against the safety factor times the "
        "largest gravity torque along the cycle",
    ),
)

#: the checks by name
CHECKS_BY_NAME: dict[str, Check] = {c.name: c for c in CHECKS}
#: the margin columns, in CHECKS order
MARGIN_COLUMNS: tuple[str, ...] = tuple(c.margin_column for c in CHECKS)


def margin(value, allowable, lower: bool = False):
    """The margin of a check (see the module notes), elementwise: allowable / value (upper
    limit) or value / allowable (lower limit); inf where the quotient's denominator is zero and
    the numerator positive, NaN where either is NaN (not checked)."""
    value = np.asarray(value, dtype=float)
    allowable = np.asarray(allowable, dtype=float)
    num, den = (value, allowable) if lower else (allowable, value)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where(den == 0.0, np.where(num > 0.0, np.inf, np.nan), num / den)
    return np.where(np.isnan(allowable) | np.isnan(value), np.nan, out)


def verdict(margins: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(ok, binding_check, margin)`` elementwise from ``{check name: margins}`` (arrays of one
    shape): ok where every checked (non-NaN) margin is ≥ 1; the binding check is the name of the
    least checked margin ('' where nothing was checked), margin that margin (NaN there)."""
    names = list(margins)
    if not names:
        raise ValueError("verdict: no checks")
    stack = np.stack([np.asarray(margins[n], dtype=float) for n in names])
    masked = np.where(np.isnan(stack), np.inf, stack)
    idx = np.argmin(masked, axis=0)
    least = np.take_along_axis(masked, idx[None], axis=0)[0]
    checked = ~np.all(np.isnan(stack), axis=0)
    ok = np.all(np.isnan(stack) | (stack >= 1.0), axis=0)
    binding = np.where(checked, np.asarray(names, dtype=object)[idx], "")
    return ok, binding, np.where(checked, least, np.nan)
