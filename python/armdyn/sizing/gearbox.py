r"""Gearbox, output-bearing and emergency-stop values of one joint's duty cycle, vectorised over
k candidate gearboxes (and motors): the values and margins of the ``"gearbox"`` and
``"bearing"`` checks of :data:`armdyn.sizing.checks.CHECKS`.

Every function takes a joint's load (:class:`armdyn.sizing.cycle.JointLoad` or any object with
its fields: ``t`` (n,) one period of the cycle, dwell included; ``speed``, ``torque`` (the
torque the gearbox output delivers to the link), ``gravity_torque``, ``inertia`` (n,);
``force``, ``moment`` (n, 3); ``axis`` (3,)) and per-candidate arrays (k,) or a catalog table
(a mapping or DataFrame of column -> (k,) values, SI units: rad/s, N m, N, m, h). It returns a
dict of (k,) arrays: the values (check ``value`` columns) and the margins, keyed by each check's
``margin_column`` (``"<check name>_margin"``: the check names ``gear_life`` and
``gear_average_torque`` are also value columns). A catalog column that is absent or NaN is *not
given*: the checks that need it get a NaN margin (not checked), never a guess. A negative,
infinite or non-numeric value, a zero ratio, a load with non-finite samples or fewer than two
samples is a ModelError naming the argument, the column and the candidate's index.

Integrals over the cycle use the trapezoid rule on the samples (as the sizing report does), so a
sampled cycle stands for the vendors' load segments (T_i, n_i, t_i); the averages are over one
period ``t[-1] - t[0]``, the dwell (the vendors' pause time t_p) included.

**Gearbox** (:func:`gearbox_cycle_values`). Harmonic Drive's selection procedure (CSD-2A,
HFUS-2A/-2SH engineering data, "Selection procedure" and "Life of the Wave Generator bearing";
Nabtesco's RV glossary and selection flow chart are the same with the exponent 10/3):

- average output torque, weights |n| dt, with each gearbox's life exponent p (the cubic mean
  of strain-wave gears, p = 3; Nabtesco's mean torque of RV gears, p = 10/3):
  T_av = (∫ |n| |T|^p dt / ∫ |n| dt)^(1/p). A joint that never moves has no speed weights:
  its T_av is the time-weighted mean (∫ |T|^p dt / period)^(1/p) (the torque it holds),
  and its life is infinite (no revolutions);
- average input speed n_av = |N| ∫ |n| dt / period, the vendors' Σ |n_i| t_i / Σ t_i over a
  cycle whose segments include the pause (Harmonic Drive's cycle diagrams mark t_p, "the pause
  time between cycles"). The pause is in the average because the rated life counts the hours
  of operation, pauses included: the revolutions over the life are n_av L only so. Leaving the
  pause out (as some worksheets do for the speed only while moving) gives a larger n_av and a
  shorter life; the required life (:class:`SizingOptions` ``required_life``) is counted in the
  same hours as here;
- cycles per hour 3600 / period (``gear_cycles_per_hour``): Wittenstein and Beckhoff rate the
  acceleration (repeated peak) torque for at most 1000 cycles per hour and reduce it by a
  shock factor above; that factor is not applied here (the catalog's ``repeated_peak_torque``
  should be the value for the cycle's rate);
- life L = L_N (T_N / T_av)^p (n_N / n_av) with (T_N, n_N, L_N) the catalog's
  ``rated_torque``, ``rated_input_speed``, ``rated_life`` and p = ``life_exponent`` (3 for
  strain-wave gears, 10/3 for RV; absent or NaN = 3). Harmonic Drive's L_N is an L50 life
  (L10 ≈ L50 / 5): the catalog's ``rated_life`` says which; this module does not convert;
- repeated peak torque = max |T| over the cycle (the start/stop accelerations are in the
  cycle); peak input speed = |N| max |n|;
- emergency stops over the life (:class:`SizingOptions` ``emergency_stops``) against the
  catalog's ``momentary_peak_count``. Harmonic Drive derives that count from the flexspline's
  10⁴ allowed overload cycles, N = 10⁴ / (2 n_in t / 60) for a peak of duration t [s] at n_in
  [rpm]: a catalog may store that number.

**Output bearing** (:func:`bearing_cycle_values`). The load's ``force`` F and ``moment`` M_O
are the reaction wrench on the child at the joint point O, in the child's joint frame, and
``axis`` a (normalised here) the joint axis in that frame. The bearing's reference point is
P = O + b a with b the catalog's ``bearing_offset`` [m], **positive along the joint axis a as
the model states it** (the load's ``axis``). When the axis points from the parent's side of the
joint towards the child's (the usual mounting: the output flange on the child's side), b > 0
is towards the child; a model whose axis points the other way takes b with the opposite sign
(a mount's geometry, not a catalog's: the load knows no more than the axis). Moving the
wrench to P::

    F_a = F · a                         (axial force, signed; its peak is max |F_a|)
    F_r = |F − (F · a) a|               (radial force)
    M_P = M_O + (O − P) × F = M_O − b a × F
    M   = |M_P − (M_P · a) a| = |M_O⊥ − b a × F|   (tilting moment; a × F ⊥ a)

The axial component of the moment (the transmitted joint torque) is not a bearing load. The
peaks are the maxima over the samples. The bearing's life is Harmonic Drive's cross-roller
bearing life (CSD-2UH/2UF, HFUS-2SH, FHA, CHA manuals, "Output bearing life"), when the
catalog gives ``bearing_dynamic_load_rating`` C [N] and ``bearing_pitch_diameter`` d_p [m]:

- averages with exponent B = 10/3 and weights |n| dt (n the output speed):
  F_rav = (∫ |n| F_r^B dt / ∫ |n| dt)^(1/B), and the same for F_aav and M_av. Harmonic
  Drive writes the moment of the averaged forces, M = F_rav (L_r + R) + F_aav L_a; armdyn has
  the exact moment at every sample, so it averages M the same way as the forces;
- equivalent load P_c = x (F_rav + 2 M_av / d_p) + y F_aav with (x, y) = (1, 0.45) when
  F_aav / (F_rav + 2 M_av / d_p) ≤ 1.5, else (0.67, 0.67);
- L_10 = 10⁶ / (60 n_av) · (C / (f_w P_c))^(10/3) hours, n_av the average output speed in
  rpm over the period (pause included, as above) and f_w the load factor
  (:class:`SizingOptions` ``bearing_load_factor``). A joint that never moves or a bearing
  without load has an infinite life. Harmonic Drive's separate formula for small oscillating
  motions (the 90/θ factor) is not used.

**Emergency stop** (:func:`emergency_stop_values`). The drive (the motor's peak torque) or the
brake (its holding torque) stops the joint with a constant torque T_s at the motor, opposing
the motion. Per axis, as the vendors' worksheets: the other joints are held (their coupling
and the velocity-product terms are left out), the joint's load is its own inertia
J_L = ``inertia`` (diagonal of M(q), rotor-free) and its gravity torque g = ``gravity_torque``
at the sample, the motor shaft's inertia J (``rotor_inertia``: motor rotor plus the gearbox's
input inertia) turns at N q̇. With τ the gearbox output torque on the link and c the gear's
power-flow factor (c = η when the link drives the motor, τ q̇ < 0, the back-driven branch of
:mod:`armdyn.actuators`; c = 1/η when the rotor drives the link)::

    link:  J_L q̈ = τ − g
    rotor: J N q̈ = T_m − c τ / N,      T_m = −sign(q̇) T_s
    =>     τ = N (J_L T_m + N J g) / (N² J + c J_L)

The sign of τ does not depend on c, so the branch follows from the sign of
N (J_L T_m + N J g) q̇. The stop can start at any moving sample (q̇ ≠ 0) of the cycle; the
**worst state** is the sample where |τ| is largest. For a constant stop torque the peak output
torque does not depend on the speed (the kinetic energy sets how long the stop lasts, not its
torque), so the state of the largest kinetic energy or speed is not in general the worst: the
maximum over every moving sample contains it and is never smaller. A cycle that never moves
has no stop: its momentary torque is the cycle's largest |T|. With J = J_L = 0, τ = g.

Sources (the vendors' public manuals; the formulas above are theirs, the sampled-cycle form and
the choices stated above are armdyn's):

- Harmonic Drive, "CSD-2A component sets" engineering data (1019659, 11/2014) and "HFUS-2SH"
  (1021387, 12/2018), §4.1 selection procedure: T_av, n_in,av, L50 = L_n (n_N / n_in,av)
  (T_N / T_av)³ with L_n = 35,000 h (CSD, CSF, HFUS, HFUC, SHD) or 50,000 h (CSG, SHG,
  CobaltLine), L10 ≈ L50 / 5; the momentary peak torque "should not occur during the normal
  operating cycle" and its allowed number of events.
- Harmonic Drive "CHA" (1018854) and "SHG/HFUS-2SH" manuals, output bearing: the dynamic
  equivalent load P_C = x (F_rav + 2M/d_p) + y F_aav, (x, y) = (1, 0.45) for
  F_aav / (F_rav + 2M/d_p) ≤ 1.5 else (0.67, 0.67), the averages with exponent B and weights
  |n_i| t_i, and the pause time t_p between cycles; "FHA-C" and "CSF/CSG-2UH" manuals:
  L_B-10 = 10⁶ / (60 N_av) (C / (f_w P_c))^(10/3), f_w = 1–1.2 smooth, 1.2–1.5 normal, 1.5–3
  with shocks.
- Nabtesco "RV-E / RH-E" glossary: rated service life, allowable acceleration/deceleration
  torque (the repeated peak), momentary maximum allowable torque (emergency stop or external
  shock), allowable moment and maximum thrust load; the RV life law has the exponent 10/3.
"""

from __future__ import annotations

import numpy as np

from armdyn.sizing import _inputs
from armdyn.sizing.checks import CHECKS_BY_NAME, margin

#: the output bearing's life exponent (roller bearings) and the averaging exponent B
BEARING_EXPONENT = 10.0 / 3.0

#: candidates x samples per block of the emergency-stop arrays (bounded memory for any k)
_BLOCK = 1 << 18

_RATING = {"nan": True, "lo": 0.0, "lo_open": True}
_ALLOWABLE = {"nan": True, "lo": 0.0}

#: the gearbox catalog columns gearbox_cycle_values reads, with their checks
GEAR_COLUMNS = {
    "rated_torque": _RATING,
    "rated_input_speed": _RATING,
    "rated_life": _RATING,
    "life_exponent": {**_RATING, "default": 3.0},
    "average_torque_limit": _ALLOWABLE,
    "average_input_speed_limit": _ALLOWABLE,
    "repeated_peak_torque": _ALLOWABLE,
    "momentary_peak_count": _ALLOWABLE,
    "max_input_speed": _ALLOWABLE,
}

#: the gearbox catalog columns bearing_cycle_values reads
BEARING_COLUMNS = {
    "bearing_offset": {"nan": True, "lo": None},
    "bearing_moment_allowable": _ALLOWABLE,
    "bearing_axial_allowable": _ALLOWABLE,
    "bearing_radial_allowable": _ALLOWABLE,
    "bearing_dynamic_load_rating": _RATING,
    "bearing_pitch_diameter": _RATING,
}


def trapezoid(f: np.ndarray, t: np.ndarray) -> np.ndarray:
    """∫ f dt over the samples (last axis), the trapezoid rule."""
    return np.sum(0.5 * (f[..., 1:] + f[..., :-1]) * np.diff(t), axis=-1)


def weighted_mean(x: np.ndarray, w: np.ndarray, t: np.ndarray, p: float) -> float:
    """(∫ w |x|^p dt / ∫ w dt)^(1/p); time weights when ∫ w dt = 0. Computed on |x| / max |x|
    (no overflow of |x|^p for any finite x)."""
    scale = float(np.max(np.abs(x)))
    if scale == 0.0:
        return 0.0
    y = (np.abs(x) / scale) ** p
    den = float(trapezoid(w, t))
    if den > 0.0:
        return scale * float(trapezoid(w * y, t) / den) ** (1.0 / p)
    return scale * float(trapezoid(y, t) / (t[-1] - t[0])) ** (1.0 / p)


def _margins(out: dict, values: dict[str, tuple]) -> dict:
    for name, (value, allowable) in values.items():
        check = CHECKS_BY_NAME[name]
        out[check.margin_column] = margin(value, allowable, check.lower)
    return out


def margins_by_check(values: dict) -> dict[str, np.ndarray]:
    """``{check name: margin}`` from a dict of this module's or :mod:`armdyn.sizing.drive`'s
    values (their ``"<name>_margin"`` keys; the values keep that key because two checks,
    ``gear_life`` and ``gear_average_torque``, share their name with their value column), in
    the form :func:`armdyn.sizing.checks.verdict` takes."""
    from armdyn.sizing.drive import BUS_CHECKS

    checks = (*CHECKS_BY_NAME.values(), *BUS_CHECKS)
    return {c.name: values[c.margin_column] for c in checks if c.margin_column in values}


def gearbox_cycle_values(load, ratio, gearboxes, options=None) -> dict[str, np.ndarray]:
    """The gearbox's cycle values and margins for k candidates (see the module notes).

    Args:
        load: the joint's load (a JointLoad: ``t``, ``speed``, ``torque``).
        ratio: (k,) gear ratios (input speed / output speed; the sign is ignored; non-zero).
        gearboxes: the k gearboxes' catalog columns (mapping or DataFrame), those of
            :data:`GEAR_COLUMNS` used (absent or NaN = not given).
        options: :class:`armdyn.sizing.options.SizingOptions` (default: the defaults).

    Returns:
        dict of (k,) arrays: ``gear_average_torque`` [N m], ``gear_average_output_speed``,
        ``gear_average_input_speed``, ``gear_peak_input_speed`` [rad/s], ``gear_life`` [h],
        ``gear_repeated_peak_torque`` [N m], ``gear_cycles_per_hour``, ``emergency_stops`` and
        the margins
        ``gear_life_margin``, ``gear_average_torque_margin``,
        ``gear_average_input_speed_margin``, ``gear_repeated_peak_margin``,
        ``gear_momentary_count_margin``, ``gear_input_speed_margin``.
    """
    who = "gearbox_cycle_values"
    opts = _inputs.options_of(options)
    t = _inputs.cycle_times(who, load)
    speed = _inputs.series(who, load, "speed", t.shape)
    torque = _inputs.series(who, load, "torque", t.shape)
    n_ratio = np.abs(
        _inputs.candidates(who, "ratio", ratio, None, nan=False, lo=None, nonzero=True)
    )
    k = n_ratio.shape[0]
    cols = _inputs.columns(who, gearboxes, GEAR_COLUMNS, k, "gearboxes")
    p = np.where(np.isnan(cols["life_exponent"]), 3.0, cols["life_exponent"])

    period = t[-1] - t[0]
    w = np.abs(speed)
    # the mean torque of each gearbox's own life law (3 strain-wave, 10/3 RV: Nabtesco's T_m)
    t_av = np.empty(k)
    for exponent in np.unique(p):
        t_av[p == exponent] = weighted_mean(torque, w, t, float(exponent))
    out_speed = float(trapezoid(w, t)) / period
    n_av = n_ratio * out_speed
    # in logarithms: no overflow to inf * 0; T_av = 0 or n_av = 0 (no wear) gives inf
    with np.errstate(divide="ignore", over="ignore"):
        log_life = np.log(cols["rated_life"]) + p * (np.log(cols["rated_torque"]) - np.log(t_av))
        life = np.exp(log_life + np.log(cols["rated_input_speed"]) - np.log(n_av))

    out = {
        "gear_average_torque": t_av,
        "gear_average_output_speed": np.full(k, out_speed),
        "gear_average_input_speed": n_av,
        "gear_peak_input_speed": n_ratio * float(np.max(w)),
        "gear_life": life,
        "gear_repeated_peak_torque": np.full(k, float(np.max(np.abs(torque)))),
        "gear_cycles_per_hour": np.full(k, 3600.0 / period),
        "emergency_stops": np.full(k, float(opts.emergency_stops)),
    }
    return _margins(
        out,
        {
            "gear_life": (life, np.full(k, float(opts.required_life))),
            "gear_average_torque": (out["gear_average_torque"], cols["average_torque_limit"]),
            "gear_average_input_speed": (n_av, cols["average_input_speed_limit"]),
            "gear_repeated_peak": (
                out["gear_repeated_peak_torque"],
                cols["repeated_peak_torque"],
            ),
            "gear_momentary_count": (out["emergency_stops"], cols["momentary_peak_count"]),
            "gear_input_speed": (out["gear_peak_input_speed"], cols["max_input_speed"]),
        },
    )


def bearing_wrench(force, moment, axis, offset: float):
    """The bearing's loads at every sample for one offset b (module notes): (F_a signed, F_r,
    M) each (n,), from the reaction ``force``/``moment`` (n, 3) at the joint point, the unit
    ``axis`` (3,), in one frame."""
    f_a = force @ axis
    f_r = np.linalg.norm(force - f_a[:, None] * axis, axis=1)
    m_perp = moment - (moment @ axis)[:, None] * axis
    m_ref = m_perp - offset * np.cross(axis, force)
    return f_a, f_r, np.linalg.norm(m_ref, axis=1)


def _bearing_life(f_rav, f_aav, m_av, out_speed, rating, pitch, load_factor):
    """Harmonic Drive's cross-roller bearing L10 [h] (module notes), elementwise."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        radial = f_rav + 2.0 * m_av / pitch
        ratio = np.where(radial > 0.0, f_aav / radial, np.where(f_aav > 0.0, np.inf, 0.0))
        x = np.where(ratio <= 1.5, 1.0, 0.67)
        y = np.where(ratio <= 1.5, 0.45, 0.67)
        p_c = x * radial + y * f_aav
        # in logarithms (no inf * 0); P_c = 0 or no motion gives inf
        log_revs = np.log(out_speed * 3600.0 / (2.0 * np.pi))  # revolutions per hour
        log_ratio = np.log(rating) - np.log(load_factor * p_c)
        life = np.exp(np.log(1e6) - log_revs + BEARING_EXPONENT * log_ratio)
    given = ~np.isnan(rating + pitch + m_av)
    return np.where(given, life, np.nan)


_BEARING_VALUES = (
    "bearing_peak_moment",
    "bearing_peak_axial",
    "bearing_peak_radial",
    "bearing_average_moment",
    "bearing_average_axial",
    "bearing_average_radial",
    "bearing_life",
)


def _bearing_loads(t, w, force, moment, axis, offset) -> dict[str, np.ndarray]:
    """The peaks and the 10/3 means (weights w = |n|) of the bearing's loads, per candidate
    offset (NaN offset: the moment is not given); each distinct offset is computed once."""
    k = offset.shape[0]
    f_a, f_r, _ = bearing_wrench(force, moment, axis, 0.0)
    peak_m, avg_m = np.full(k, np.nan), np.full(k, np.nan)
    for b in np.unique(offset[~np.isnan(offset)]):
        m = bearing_wrench(force, moment, axis, float(b))[2]
        at = offset == b
        peak_m[at] = float(np.max(m))
        avg_m[at] = weighted_mean(m, w, t, BEARING_EXPONENT)
    return {
        "bearing_peak_moment": peak_m,
        "bearing_peak_axial": np.full(k, float(np.max(np.abs(f_a)))),
        "bearing_peak_radial": np.full(k, float(np.max(f_r))),
        "bearing_average_moment": avg_m,
        "bearing_average_axial": np.full(k, weighted_mean(f_a, w, t, BEARING_EXPONENT)),
        "bearing_average_radial": np.full(k, weighted_mean(f_r, w, t, BEARING_EXPONENT)),
    }


def bearing_cycle_values(load, gearboxes, options=None) -> dict[str, np.ndarray]:
    """The output bearing's cycle values and margins for k candidate gearboxes (module notes).

    Args:
        load: the joint's load (``t``, ``speed``, ``force``, ``moment``, ``axis``); ``force``
            or ``moment`` None (a cycle without reactions): every value and margin is NaN
            (not checked).
        gearboxes: the k gearboxes' catalog columns, those of :data:`BEARING_COLUMNS` used
            (a NaN ``bearing_offset`` leaves the moment and the life not given).
        options: :class:`armdyn.sizing.options.SizingOptions` (``bearing_load_factor``,
            ``required_life``).

    Returns:
        dict of (k,) arrays: ``bearing_peak_moment`` [N m], ``bearing_peak_axial``,
        ``bearing_peak_radial`` [N], ``bearing_average_moment``, ``bearing_average_axial``,
        ``bearing_average_radial`` (the 10/3 means), ``bearing_life`` [h] and the margins
        ``bearing_moment_margin``, ``bearing_axial_margin``, ``bearing_radial_margin``,
        ``bearing_life_margin``.
    """
    who = "bearing_cycle_values"
    opts = _inputs.options_of(options)
    t = _inputs.cycle_times(who, load)
    n = t.shape[0]
    speed = _inputs.series(who, load, "speed", (n,))
    axis = _inputs.unit_axis(who, load)
    cols = _inputs.columns(who, gearboxes, BEARING_COLUMNS, None, "gearboxes")
    offset = cols["bearing_offset"]
    k = offset.shape[0]
    for name in ("force", "moment"):
        if not hasattr(load, name):
            raise _inputs.fail(who, f"load has no field {name!r}")
    if load.force is None or load.moment is None:
        # the cycle has no reaction wrench (a build without it): nothing is checked
        out = {name: np.full(k, np.nan) for name in _BEARING_VALUES}
    else:
        force = _inputs.series(who, load, "force", (n, 3))
        moment = _inputs.series(who, load, "moment", (n, 3))
        out = _bearing_loads(t, np.abs(speed), force, moment, axis, offset)
        out["bearing_life"] = _bearing_life(
            out["bearing_average_radial"],
            out["bearing_average_axial"],
            out["bearing_average_moment"],
            float(trapezoid(np.abs(speed), t)) / (t[-1] - t[0]),
            cols["bearing_dynamic_load_rating"],
            cols["bearing_pitch_diameter"],
            float(opts.bearing_load_factor),
        )
    peak_m = out["bearing_peak_moment"]
    life = out["bearing_life"]
    return _margins(
        out,
        {
            "bearing_moment": (peak_m, cols["bearing_moment_allowable"]),
            "bearing_axial": (out["bearing_peak_axial"], cols["bearing_axial_allowable"]),
            "bearing_radial": (out["bearing_peak_radial"], cols["bearing_radial_allowable"]),
            "bearing_life": (life, np.full(k, float(opts.required_life))),
        },
    )


def _stop_block(n_ratio, eta, j_rotor, stop_torque, j_load, gravity, sign):
    """The gearbox output torque τ of a stop (module notes) for a block of candidates (b,)
    (finite parameters) at the moving samples (m,) (σ = sign(q̇) ≠ 0): a (b, m) array, built
    in place (a few passes over one buffer)."""
    b_k = n_ratio * n_ratio * j_rotor  # N² J
    num = np.multiply.outer(-n_ratio * stop_torque, sign * j_load)  # N T_m J_L
    num += np.multiply.outer(b_k, gravity)  # + N² J g
    back = num * sign < 0.0  # τ q̇ < 0: the link back-drives the gear, c = η
    den = np.multiply.outer(1.0 / eta, j_load)
    np.multiply(den, (eta * eta)[:, None], out=den, where=back)
    den += b_k[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        tau = np.divide(num, den, out=num)
    if not np.all(b_k > 0.0) and not np.all(j_load > 0.0):
        # no inertia at all (J = J_L = 0): the load sees its gravity torque alone
        np.copyto(tau, np.broadcast_to(gravity, tau.shape), where=den == 0.0)
    return tau


def _worst_stops(n_ratio, eta, j_rot, t_s, j_load, gravity, sign):
    """The largest |τ| over the moving samples and its sample, per candidate; NaN (sample 0)
    where a parameter is not given. Candidates in blocks of at most _BLOCK elements."""
    k, m = n_ratio.shape[0], j_load.shape[0]
    peak, worst = np.full(k, np.nan), np.zeros(k, dtype=np.intp)
    given = np.flatnonzero(~np.isnan(j_rot + t_s))
    step = max(1, _BLOCK // m)
    for lo in range(0, given.size, step):
        c = given[lo : lo + step]
        mag = np.abs(_stop_block(n_ratio[c], eta[c], j_rot[c], t_s[c], j_load, gravity, sign))
        worst[c] = np.argmax(mag, axis=1)
        peak[c] = np.take_along_axis(mag, worst[c, None], axis=1)[:, 0]
    return peak, worst


def emergency_stop_values(
    load, ratio, efficiency, rotor_inertia, stop_torque, gearboxes=None, options=None
) -> dict[str, np.ndarray]:
    """The gearbox's momentary peak torque of an emergency stop from the cycle's worst state,
    for k candidates (module notes), and its margin.

    Args:
        load: the joint's load (``t``, ``speed``, ``torque``, ``gravity_torque``,
            ``inertia``).
        ratio: (k,) gear ratios (non-zero; signed: ω_motor = N q̇).
        efficiency: (k,) gear efficiencies in (0, 1].
        rotor_inertia: (k,) inertia on the motor shaft [kg m²] (motor rotor + gearbox input
            inertia); NaN = not given (the torque and margin are NaN).
        stop_torque: (k,) the stopping torque at the motor [N m] ≥ 0: the motor's peak torque
            (the drive stops) or the brake's torque (the brake stops); pass the larger, or
            their sum when both act together. NaN = not given.
        gearboxes: the k gearboxes' columns; ``momentary_peak_torque`` is used.
        options: unused (kept for the common signature).

    Returns:
        dict of (k,) arrays: ``gear_momentary_torque`` [N m], ``emergency_stop_time`` [s] (the
        cycle time of the worst state; NaN when the cycle never moves or the torque is not
        given) and ``gear_momentary_peak_margin``.
    """
    who = "emergency_stop_values"
    _inputs.options_of(options)
    t = _inputs.cycle_times(who, load)
    fields = ("speed", "torque", "gravity_torque", "inertia")
    speed, torque, gravity, j_load = (_inputs.series(who, load, f, t.shape) for f in fields)
    if np.any(j_load < 0.0):
        raise _inputs.fail(who, f"load.inertia[{int(np.flatnonzero(j_load < 0.0)[0])}] is < 0")
    n_ratio = _inputs.candidates(who, "ratio", ratio, None, nan=False, lo=None, nonzero=True)
    k = n_ratio.shape[0]
    eta = _inputs.candidates(who, "efficiency", efficiency, k, nan=False, lo=0.0, lo_open=True)
    if np.any(eta > 1.0):
        i = int(np.flatnonzero(eta > 1.0)[0])
        raise _inputs.fail(who, f"efficiency[{i}] must be in (0, 1], got {eta[i]!r}")
    j_rot = _inputs.candidates(who, "rotor_inertia", rotor_inertia, k, nan=True)
    t_s = _inputs.candidates(who, "stop_torque", stop_torque, k, nan=True)
    cols = _inputs.columns(who, gearboxes, {"momentary_peak_torque": _ALLOWABLE}, k, "gearboxes")

    moving = speed != 0.0
    if np.any(moving):
        sign = np.sign(speed[moving])
        peak, worst = _worst_stops(n_ratio, eta, j_rot, t_s, j_load[moving], gravity[moving], sign)
        when = np.where(np.isnan(peak), np.nan, t[moving][worst])
    else:
        peak = np.where(np.isnan(j_rot + t_s), np.nan, float(np.max(np.abs(torque))))
        when = np.full(k, np.nan)
    out = {"gear_momentary_torque": peak, "emergency_stop_time": when}
    return _margins(out, {"gear_momentary_peak": (peak, cols["momentary_peak_torque"])})
