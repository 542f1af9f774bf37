r"""Drive, DC-bus and holding-brake values, vectorised over k candidates: the values and
margins of the ``"drive"`` and ``"brake"`` checks of :data:`armdyn.sizing.checks.CHECKS`, and
the bus of a set of axes (:data:`BUS_CHECKS`).

Conventions as :mod:`armdyn.sizing.gearbox`: (k,) arrays in, a dict of (k,) arrays out, margins
keyed ``"<check name>_margin"``, a parameter that is absent or NaN is not given (its checks get
a NaN margin), a negative or infinite one is a ModelError naming it and the candidate.

**Drive** (:func:`drive_values`; SEW's and Kollmorgen's drive selection): the motor's peak
current against the drive's peak current, its RMS current over the cycle against the drive's
continuous current (a drive folds its current back on an RMS/i²t basis, so it can trip where
the motor passes), and the motor's largest terminal voltage R i + k_t ω against the bus
voltage. The drive's catalog columns ``peak_current``, ``continuous_current``, ``bus_voltage``
are returned as ``drive_peak_current``, ``drive_continuous_current``, ``bus_voltage`` (the
checks' allowable columns; the motor's own ``peak_current`` is a value column).

**Holding brake** (:func:`brake_values`; SEW's brake selection): the brake's holding torque at
the joint N T_b (``brake_torque`` at the motor, through the gear; the gear's friction, which
helps holding, is left out: conservative) against the safety factor
(:class:`SizingOptions` ``brake_safety_factor``, SEW: at least 2) times the largest
|gravity torque| along the cycle.

**DC bus** (:func:`bus_values`; SEW "Basic calculation process", braking resistor; Kollmorgen
MOTIONEERING, shunt regulation). The axes share one bus: their electrical powers P_j (negative
when regenerating), given on one common time grid, add up to the bus power P = Σ_j P_j (one
axis braking feeds another one's motoring). Per sample interval the bus takes the net
trapezoid energy e = (P_i + P_{i+1}) Δt / 2: e > 0 is drawn, e < 0 returned (regenerated). The
bus capacitance C stores up to E_C = ½ C (V_max² − V_nom²) above its nominal voltage V_nom
(``bus_voltage``) before the braking chopper switches on at V_max (``max_bus_voltage``); the
supply does not take energy back. The stored energy s follows, per interval,
s ← min(s − e, E_C) when e < 0 (the overflow goes to the braking resistor) and
s ← max(s − e, 0) when e > 0 (motoring draws the stored energy first). The resistor's energy
per cycle is the overflow over one period at the periodic steady state of the repeated cycle:
the period map is s ↦ min(max(s + A, L), H) (a composition of such clamps) whose limit from
s = 0 is H when A > 0 and L otherwise, computed in closed form; it is the largest per-cycle
overflow of a cycle started at V_nom (the map is monotone in s). Without a capacitance or
V_max, E_C = 0: every regenerated joule goes to the resistor (conservative). The resistor's
mean power is its energy per period; its peak power is the largest regenerative bus power −P
at the samples of the intervals where it conducts (the chopper passes the instantaneous
power). Checked against the drive's ``braking_resistor_power`` (continuous) and
``braking_resistor_peak_power`` when given.
"""

from __future__ import annotations

import numpy as np

from armdyn.sizing import _inputs
from armdyn.sizing.checks import CHECKS_BY_NAME, Check, margin

#: the checks of the common DC bus (a set of axes, not one joint): the braking resistor's
#: mean and peak power against the drive's ratings
BUS_CHECKS: tuple[Check, ...] = (
    Check(
        "braking_resistor_power",
        "bus",
        "resistor_mean_power",
        "braking_resistor_power",
        False,
        "W",
        "braking resistor's mean power over the repeated cycle against its continuous rating",
    ),
    Check(
        "braking_resistor_peak",
        "bus",
        "resistor_peak_power",
        "braking_resistor_peak_power",
        False,
        "W",
        "braking resistor's largest power against its peak rating",
    ),
)

_NONNEG = {"nan": True, "lo": 0.0}


def drive_values(motor_values, drives) -> dict[str, np.ndarray]:
    """The drive checks for k motor x drive candidates.

    Args:
        motor_values: mapping with (k,) ``peak_current``, ``rms_current`` [A] and
            ``peak_terminal_voltage`` [V] (``motor_cycle_values``' output; NaN = unknown).
        drives: the k drives' columns ``peak_current``, ``continuous_current`` [A],
            ``bus_voltage`` [V] (mapping or DataFrame; absent or NaN = not given).

    Returns:
        dict of (k,) arrays: ``drive_peak_current``, ``drive_continuous_current``,
        ``bus_voltage`` (the drive's ratings) and ``drive_peak_current_margin``,
        ``drive_rms_current_margin``, ``drive_voltage_margin``.
    """
    who = "drive_values"
    spec = {
        "peak_current": _NONNEG,
        "rms_current": _NONNEG,
        "peak_terminal_voltage": {"nan": True, "lo": None},
    }
    motor = _inputs.columns(who, motor_values, spec, None, "motor_values")
    k = motor["peak_current"].shape[0]
    ratings = {"peak_current": _NONNEG, "continuous_current": _NONNEG, "bus_voltage": _NONNEG}
    drive = _inputs.columns(who, drives, ratings, k, "drives")
    out = {
        "drive_peak_current": drive["peak_current"],
        "drive_continuous_current": drive["continuous_current"],
        "bus_voltage": drive["bus_voltage"],
    }
    pairs = {
        "drive_peak_current": (motor["peak_current"], drive["peak_current"]),
        "drive_rms_current": (motor["rms_current"], drive["continuous_current"]),
        "drive_voltage": (np.abs(motor["peak_terminal_voltage"]), drive["bus_voltage"]),
    }
    for name, (value, allowable) in pairs.items():
        check = CHECKS_BY_NAME[name]
        out[check.margin_column] = margin(value, allowable, check.lower)
    return out


def brake_values(load, ratio, brake_torque, options=None) -> dict[str, np.ndarray]:
    """The holding-brake check for k candidates (module notes).

    Args:
        load: the joint's load (``t``, ``gravity_torque``).
        ratio: (k,) gear ratios (non-zero; the sign is ignored).
        brake_torque: (k,) the brake's holding torque at the motor [N m]; NaN = no brake data.
        options: :class:`armdyn.sizing.options.SizingOptions` (``brake_safety_factor``).

    Returns:
        dict of (k,) arrays: ``brake_holding_torque`` (N T_b), ``brake_required_torque``
        (safety factor x max |gravity torque|) [N m] and ``brake_holding_margin``.
    """
    who = "brake_values"
    opts = _inputs.options_of(options)
    t = _inputs.cycle_times(who, load)
    gravity = _inputs.series(who, load, "gravity_torque", t.shape)
    n_ratio = np.abs(
        _inputs.candidates(who, "ratio", ratio, None, nan=False, lo=None, nonzero=True)
    )
    k = n_ratio.shape[0]
    t_b = _inputs.candidates(who, "brake_torque", brake_torque, k, nan=True)
    holding = n_ratio * t_b
    required = np.full(k, float(opts.brake_safety_factor) * float(np.max(np.abs(gravity))))
    check = CHECKS_BY_NAME["brake_holding"]
    return {
        "brake_holding_torque": holding,
        "brake_required_torque": required,
        check.margin_column: margin(holding, required, check.lower),
    }


def _bus_power(who: str, t, electrical_power):
    t = _inputs.times(who, "t", t)
    try:
        p = np.asarray(electrical_power, dtype=float)
    except (TypeError, ValueError):
        raise _inputs.fail(who, "electrical_power must be numbers") from None
    if p.ndim == 2:
        p = p[None]
    if p.ndim != 3 or p.shape[2] != t.shape[0] or p.shape[1] < 1:
        raise _inputs.fail(
            who,
            f"electrical_power must have shape (axes, n) or (k, axes, n) with n = len(t) = "
            f"{t.shape[0]}, got {np.shape(electrical_power)}",
        )
    if not np.all(np.isfinite(p)):
        idx = tuple(int(i) for i in np.argwhere(~np.isfinite(p))[0])
        raise _inputs.fail(who, f"electrical_power has a non-finite value at {idx}")
    return t, p.sum(axis=1)


def _steady_start(e: np.ndarray, cap: np.ndarray) -> np.ndarray:
    """The stored energy at the start of a period at the periodic steady state (module notes):
    compose the per-interval clamps s ↦ min(max(s − e_j, 0), E_C) into
    s ↦ min(max(s + A, L), H), then H if A > 0 else L. e (k, m), cap (k,)."""
    a = np.zeros_like(cap)
    lo = np.zeros_like(cap)
    hi = cap.copy()
    for j in range(e.shape[1]):
        d = -e[:, j]
        a = a + d
        lo = np.minimum(np.maximum(lo + d, 0.0), cap)
        hi = np.minimum(np.maximum(hi + d, 0.0), cap)
    return np.where(a > 0.0, hi, lo)


def _resistor(e: np.ndarray, p: np.ndarray, cap: np.ndarray):
    """One period from the steady start: the overflow energy per period and the largest
    regenerative power at the samples of the overflowing intervals. e (k, m), p (k, m + 1)."""
    s = _steady_start(e, cap)
    energy = np.zeros_like(cap)
    peak = np.zeros_like(cap)
    for j in range(e.shape[1]):
        s = s - e[:, j]
        over = np.maximum(s - cap, 0.0)
        s = np.clip(s, 0.0, cap)
        energy = energy + over
        regen = np.maximum(np.maximum(-p[:, j], -p[:, j + 1]), 0.0)
        peak = np.where(over > 0.0, np.maximum(peak, regen), peak)
    return energy, peak


def bus_values(t, electrical_power, period=None, drives=None) -> dict[str, np.ndarray]:
    """The DC bus of a set of axes, for k candidate sets (module notes).

    Args:
        t: (n,) the common time grid of one period [s] (non-decreasing, n >= 2).
        electrical_power: (axes, n) the axes' electrical power [W] (negative: regenerating),
            or (k, axes, n) for k candidate sets.
        period: the cycle's period [s] (default ``t[-1] - t[0]``; the means are per period;
            a period longer than the grid counts no power outside it).
        drives: the bus parameters, scalars or (k,) (one set of axes against k drives, or k sets
            against one or k drives): ``bus_voltage`` (V_nom), ``max_bus_voltage``
            (V_max) [V], ``bus_capacitance`` [F], ``braking_resistor_power``,
            ``braking_resistor_peak_power`` [W] (absent or NaN = not given).

    Returns:
        dict of (k,) arrays: ``bus_peak_power`` (largest drawn), ``bus_peak_regenerative_power``
        (largest returned, ≥ 0), ``bus_mean_power`` [W], ``bus_energy_regenerated`` (per
        period, Σ max(−e, 0)), ``bus_capacitor_energy`` (E_C), ``resistor_energy`` [J per
        period], ``resistor_mean_power``, ``resistor_peak_power`` [W] and the margins
        ``braking_resistor_power_margin``, ``braking_resistor_peak_margin``.
    """
    who = "bus_values"
    t, p = _bus_power(who, t, electrical_power)
    k = p.shape[0]
    span = t[-1] - t[0]
    period = (
        span
        if period is None
        else _inputs.candidates(who, "period", period, 1, nan=False, lo=0.0, lo_open=True)[0]
    )
    if period < span * (1.0 - 1e-12):
        raise _inputs.fail(who, f"period ({period!r}) is shorter than the time grid ({span!r})")
    spec = {
        "bus_voltage": _NONNEG,
        "max_bus_voltage": _NONNEG,
        "bus_capacitance": _NONNEG,
        "braking_resistor_power": _NONNEG,
        "braking_resistor_peak_power": _NONNEG,
    }
    if k == 1 and drives is not None:  # one set of axes against k drives' bus parameters
        sizes = [np.size(drives[c]) for c in spec if c in drives and np.ndim(drives[c]) == 1]
        k = max(sizes, default=1)
        p = np.broadcast_to(p, (k, p.shape[1]))
    bus = _inputs.columns(who, drives, spec, k, "drives")
    v_nom, v_max = bus["bus_voltage"], bus["max_bus_voltage"]
    if np.any(v_max < v_nom):
        i = int(np.flatnonzero(v_max < v_nom)[0])
        raise _inputs.fail(who, f"drives['max_bus_voltage'][{i}] is below drives['bus_voltage']")
    cap = 0.5 * bus["bus_capacitance"] * (v_max**2 - v_nom**2)
    cap = np.where(np.isnan(cap), 0.0, cap)

    e = 0.5 * (p[:, 1:] + p[:, :-1]) * np.diff(t)
    energy, peak = _resistor(e, p, cap)
    out = {
        "bus_peak_power": np.max(p, axis=1),
        "bus_peak_regenerative_power": np.maximum(np.max(-p, axis=1), 0.0),
        "bus_mean_power": np.sum(e, axis=1) / period,
        "bus_energy_regenerated": np.sum(np.maximum(-e, 0.0), axis=1),
        "bus_capacitor_energy": cap,
        "resistor_energy": energy,
        "resistor_mean_power": energy / period,
        "resistor_peak_power": peak,
    }
    for check in BUS_CHECKS:
        out[check.margin_column] = margin(out[check.value], bus[check.allowable], check.lower)
    return out
