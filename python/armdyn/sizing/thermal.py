"""The motor winding's temperature along a run or a repeated duty cycle, vectorised over k
candidate motors (:func:`thermal_cycle`), and the sizing report's first-order rise
(:func:`thermal_rise`, :func:`temperature_rises`), which is its one-node case.

**Two-node model** (winding → housing → ambient; rises θ above the ambient temperature)::

    C_w dθ_w/dt = P_cu − (θ_w − θ_h) / R_w
    C_h dθ_h/dt = (θ_w − θ_h) / R_w − θ_h / R_h,      C_w = τ_w / R_w,  C_h = τ_h / R_h

(``thermal_resistance_winding`` R_w, ``thermal_resistance_housing`` R_h,
``thermal_time_constant_winding`` τ_w, ``thermal_time_constant_housing`` τ_h). A motor that
gives only ``thermal_resistance`` R_th and ``thermal_time_constant`` τ_th has the **one-node**
model τ_th dθ_w/dt = R_th P_cu − θ_w (its housing is not modelled: NaN); a motor with neither
is not checked (NaN).

**Exact steps.** With the loss linear in time over a step of length h, x = (θ_w, θ_h),
x' = A x + b P: x(h) = e^{Ah} x(0) + h φ₁(Ah) b P(0) + h φ₂(Ah) b (P(h) − P(0)), φ₁(z) =
(e^z − 1)/z, φ₂(z) = (e^z − 1 − z)/z², evaluated in closed form for the 2×2 matrix (its
eigenvalues are real and distinct: f(A) = [f(λ₁)(A − λ₂) − f(λ₂)(A − λ₁)] / (λ₁ − λ₂), with
``expm1`` and short series near 0). Steps of zero length (a repeated time) leave the state.

**Copper resistance** R(T_w) = R_ref (1 + α (T_w − T_ref)) (α: the options'
``copper_temperature_coefficient``, T_ref their ``resistance_temperature``). The loss at each
sample is R(T_w) i² with the winding temperature at that sample, linear between samples (as
any loss is): a step's end temperature is in its own end loss, an affine equation solved in
closed form (one division), so each step stays an affine map of the state and the periodic
state below is still the exact fixed point of the period's map (no iteration). Against the
exact R(T_w(t)) i(t)² this is second order in the sample step (the trapezoid rule's error on
the resistance's rise). A step at constant current (a dwell's hold) is exact instead: R(T_w)
i² is then linear in θ_w and goes into the step's matrix (A + α R_ref i² e₁e₁ᵀ / C_w).

**Repeated cycles.** One period maps the start state affinely, x ↦ Φ x + ψ (the steps' maps
composed in order, by pairs within blocks of steps). ``repeat=None`` (forever): the periodic
steady state x* = (I − Φ)⁻¹ ψ, which exists when the spectral radius of Φ is below 1 (Φ ≥ 0
elementwise: when I − Φ is an M-matrix); otherwise the copper's resistance rise runs away and
the temperatures are ``inf``. ``repeat=N``: the start of the N-th period, (Φ, ψ)^{N−1}
applied to ambient (exponentiation by squaring). Losses are non-negative and every step's map
is ≥ 0 elementwise, so temperatures rise period after period from ambient and the last period
holds the peak. The temperatures at the samples then come from one pass from that period's
start. Each candidate is independent; the candidates are arrays of one chunk (the caller
bounds its size).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from armdyn import _checks, _core
from armdyn._runs import time_mean

#: |z| below which φ₁, φ₂ use their series (5 terms: error below 1e-17 relative)
_SERIES = 1e-3


def _phi(z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(e^z − 1, φ₁(z), φ₂(z)) elementwise (φ₁(0) = 1, φ₂(0) = 1/2)."""
    small = np.abs(z) < _SERIES
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        em = np.expm1(z)
        zs = np.where(small, 1.0, z)
        p1 = np.where(small, 1 + z * (1 / 2 + z * (1 / 6 + z * (1 / 24 + z / 120))), em / zs)
        p2 = np.where(
            small, 1 / 2 + z * (1 / 6 + z * (1 / 24 + z * (1 / 120 + z / 720))), (em - z) / zs**2
        )
    return em, p1, p2


@dataclass(frozen=True)
class ThermalNetwork:
    """The thermal model of k candidates as x' = A x + b P (x = winding and housing rise):
    the entries of A and b₁ (b₂ = 0), each (k,). A one-node candidate has a₁₂ = a₂₁ = 0 and a
    decoupled dummy housing mode (a₂₂ = 2 a₁₁, its rise stays 0); ``two_node`` tells which,
    ``valid`` which candidates have a thermal model at all (the others carry dummy values)."""

    a11: np.ndarray
    a12: np.ndarray
    a21: np.ndarray
    a22: np.ndarray
    b1: np.ndarray
    two_node: np.ndarray
    valid: np.ndarray

    def __len__(self) -> int:
        return len(self.a11)


def _positive(x: np.ndarray) -> np.ndarray:
    with np.errstate(invalid="ignore"):
        return np.isfinite(x) & (x > 0.0)


def thermal_network(
    r_winding=np.nan,
    r_housing=np.nan,
    tau_winding=np.nan,
    tau_housing=np.nan,
    r_th=np.nan,
    tau_th=np.nan,
) -> ThermalNetwork:
    """The :class:`ThermalNetwork` of k candidates from their datasheet values (arrays of one
    shape, or scalars; NaN = not given): two-node where R_w, R_h, τ_w, τ_h are all positive,
    else one-node where R_th and τ_th are, else none (``valid`` False)."""
    rw, rh, tw, th, r1, t1 = np.broadcast_arrays(
        *(
            np.atleast_1d(np.asarray(x, dtype=float))
            for x in (r_winding, r_housing, tau_winding, tau_housing, r_th, tau_th)
        )
    )
    two = _positive(rw) & _positive(rh) & _positive(tw) & _positive(th)
    one = ~two & _positive(r1) & _positive(t1)
    with np.errstate(divide="ignore", invalid="ignore"):
        cw = np.where(two, 1.0 / tw, 0.0)
        ch = np.where(two, rh / (rw * th), 0.0)  # 1 / (R_w C_h)
        a11 = np.where(two, -cw, np.where(one, -1.0 / t1, -1.0))
        a22 = np.where(two, -ch - 1.0 / th, 2.0 * a11)
        b1 = np.where(two, rw / tw, np.where(one, r1 / t1, 0.0))
    return ThermalNetwork(a11, cw, ch, a22, b1, two, two | one)


@dataclass
class _Steps:
    """The exact step coefficients of a set of step lengths (rows) for every candidate
    (columns): the state matrix E = e^{Ah} and the loss vectors D = h (φ₁ − φ₂)(Ah) b,
    U = h φ₂(Ah) b, so that x(h) = E x(0) + D P(0) + U P(h)."""

    e11: np.ndarray
    e12: np.ndarray
    e21: np.ndarray
    e22: np.ndarray
    dw: np.ndarray
    dh: np.ndarray
    uw: np.ndarray
    uh: np.ndarray


def _steps(net: ThermalNetwork, h: np.ndarray, feedback=None) -> _Steps:
    """:class:`_Steps` for step lengths ``h`` ((m, 1) against the (k,) candidates); with
    ``feedback`` (k,) the winding row of A gains b₁ · feedback (a loss α R_ref i² θ_w at
    constant current)."""
    a11 = net.a11 if feedback is None else net.a11 + net.b1 * feedback
    a12, a21, a22 = net.a12, net.a21, net.a22
    mu = 0.5 * (a11 + a22)
    half = np.sqrt((0.5 * (a11 - a22)) ** 2 + a12 * a21)  # > 0 (see ThermalNetwork)
    l1, l2 = mu + half, mu - half
    em1, p11, p21 = _phi(l1 * h)
    em2, p12, p22 = _phi(l2 * h)
    inv = 0.5 / half
    with np.errstate(invalid="ignore", over="ignore"):
        d_em = (em1 - em2) * inv
        e11 = 1.0 + (em1 * (a11 - l2) - em2 * (a11 - l1)) * inv
        e22 = 1.0 + (em1 * (a22 - l2) - em2 * (a22 - l1)) * inv

        def first_column(f1, f2):  # f(Ah) e₁
            return (f1 * (a11 - l2) - f2 * (a11 - l1)) * inv, a21 * (f1 - f2) * inv

        g1w, g1h = first_column(p11, p12)
        g2w, g2h = first_column(p21, p22)
        hb = h * net.b1
        return _Steps(
            e11, a12 * d_em, a21 * d_em, e22, hb * (g1w - g2w), hb * (g1h - g2h), hb * g2w, hb * g2h
        )


@dataclass
class _Cycle:
    """One period's steps as affine maps of the rises (w, h) ↦ (m11 w + m12 h + f1,
    m21 w + m22 h + f2), each entry (n − 1, k): what the period map and the pass over the
    samples use."""

    m11: np.ndarray
    m12: np.ndarray
    m21: np.ndarray
    m22: np.ndarray
    f1: np.ndarray
    f2: np.ndarray
    period: tuple | None = None  # the period's map (the same six entries, each (k,))


#: steps per block when the step maps are built and composed (their arrays stay in cache)
_BLOCK = 16


def _cycle(t, current_sq, net, r_ambient, r_slope, period: bool = True) -> _Cycle:
    """The step maps of one period (and with ``period`` the period's map, composed block by
    block while each block's maps are in cache). A step of length h > 0: x(h) = E x(0) +
    D P(0) + U P(h) with P = R(T_w) i² at its two ends (R = R_a + s θ_w; the end's own θ_w
    solved for: one division); a step at constant current with the resistance's rise in E
    (exact); a step of zero length: the identity."""
    h = np.diff(np.asarray(t, dtype=float))
    k = len(net)
    s = np.broadcast_to(np.asarray(r_slope, dtype=float), (k,))
    ra = np.broadcast_to(np.asarray(r_ambient, dtype=float), (k,))
    hu, which = _step_lengths(h)
    tab = _steps(net, hu[:, None])
    # the loss vectors scaled by the resistance's slope (s·) and its value at ambient (ra·)
    scaled = tuple(f * x for f in (s, ra) for x in (tab.dw, tab.uw, tab.dh, tab.uh))
    idx, exact = _exact_steps(h, current_sq, net, s, ra)
    zero = ~(h > 0.0)
    c = _Cycle(*(np.empty((len(h), k)) for _ in range(6)))
    rows = (c.m11, c.m12, c.m21, c.m22, c.f1, c.f2)
    for lo in range(0, len(h), _BLOCK):
        b = slice(lo, min(lo + _BLOCK, len(h)))
        _block_maps(c, b, tab, scaled, which[b], current_sq[lo : b.stop + 1])
        here = (idx >= lo) & (idx < b.stop)
        if np.any(here):
            for x, value in zip(rows, exact, strict=True):
                x[idx[here]] = value[here]
        if np.any(zero[b]):
            for x, value in zip(rows, (1.0, 0.0, 0.0, 1.0, 0.0, 0.0), strict=True):
                x[b][zero[b]] = value
        if period:
            block = _compose_block(tuple(x[b] for x in rows))
            c.period = block if c.period is None else _compose(block, c.period)
    return c


def _exact_steps(h, current_sq, net, s, ra):
    """The steps at constant current (with a resistance that rises: else the block maps are
    exact already) and their exact maps (m11, m12, m21, m22, f1, f2), each (steps, k)."""
    idx = np.zeros(0, dtype=int)
    if np.any(s != 0.0):
        q0, q1 = current_sq[:-1], current_sq[1:]
        same = np.all(q1 == q0, axis=1) & (h > 0.0) & np.any(q0 > 0.0, axis=1)
        idx = np.flatnonzero(same)
    if not len(idx):
        return idx, ()
    q = current_sq[idx]
    x = _steps(net, h[idx, None], feedback=s * q)
    f1, f2 = ra * (x.dw + x.uw) * q, ra * (x.dh + x.uh) * q
    return idx, (x.e11, x.e12, x.e21, x.e22, f1, f2)


def _compose_block(maps):
    """The map of a block of consecutive steps (rows of ``maps``), composed by pairs."""
    while len(maps[0]) > 1:
        n = len(maps[0])
        even = n - n % 2
        pairs = _compose(tuple(x[1:even:2] for x in maps), tuple(x[0:even:2] for x in maps))
        if n % 2:
            pairs = tuple(np.concatenate([p, x[-1:]]) for p, x in zip(pairs, maps, strict=True))
        maps = pairs
    return tuple(x[0] for x in maps)


#: step lengths this close (relative) share their coefficients: a round-off difference (a grid
#: of equal steps differs by a few ulps from step to step)
_SAME_STEP = 1e-13


def _step_lengths(h: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct step lengths (those within ``_SAME_STEP`` of the group's first taken as
    equal) and each step's index into them."""
    hu, which = np.unique(h, return_inverse=True)
    new_group = np.ones(len(hu), dtype=bool)
    start = 0
    for i in range(1, len(hu)):
        if hu[i] - hu[start] <= _SAME_STEP * hu[i]:
            new_group[i] = False
        else:
            start = i
    group = np.cumsum(new_group) - 1
    return hu[new_group], group[which]


def _block_maps(c: _Cycle, b: slice, tab: _Steps, scaled, which, q) -> None:
    """The maps of the steps ``b`` (rows of ``c``) from their coefficients ``tab[which]``,
    ``scaled[·][which]`` (s D_w, s U_w, s D_h, s U_h, R_a D_w, R_a U_w, R_a D_h, R_a U_h) and
    the current squared ``q`` at their samples (one more row than steps):
    w₁ = (E₁₁ w₀ + E₁₂ h₀ + (R_a + s w₀) D_w i₀² + R_a U_w i₁²) / (1 − s U_w i₁²) and
    h₁ = E₂₁ w₀ + E₂₂ h₀ + (R_a + s w₀) D_h i₀² + (R_a + s w₁) U_h i₁²."""
    q0, q1 = q[:-1], q[1:]
    if np.all(which == which[0]):  # one step length: its coefficients' row, broadcast
        which = which[:1]
    sdw, suw, sdh, suh, rdw, ruw, rdh, ruh = (x[which] for x in scaled)
    m11, m12, m21, m22, f1, f2 = (x[b] for x in (c.m11, c.m12, c.m21, c.m22, c.f1, c.f2))
    inv = np.multiply(suw, q1)
    np.subtract(1.0, inv, out=inv)
    np.maximum(inv, 0.0, out=inv)  # 0 (inf below): the step itself runs away
    np.divide(1.0, inv, out=inv)
    np.multiply(sdw, q0, out=m11)
    m11 += tab.e11[which]
    m11 *= inv
    np.multiply(tab.e12[which], inv, out=m12)
    tmp = np.multiply(ruw, q1)
    np.multiply(rdw, q0, out=f1)
    f1 += tmp
    f1 *= inv
    sb = np.multiply(suh, q1)
    np.multiply(sdh, q0, out=m21)
    m21 += tab.e21[which]
    np.multiply(sb, m11, out=tmp)
    m21 += tmp
    np.multiply(sb, m12, out=m22)
    m22 += tab.e22[which]
    np.multiply(rdh, q0, out=f2)
    np.multiply(ruh, q1, out=tmp)
    f2 += tmp
    np.multiply(sb, f1, out=tmp)
    f2 += tmp


def _sweep(c: _Cycle, w0: np.ndarray, h0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The winding and housing rises (n, k) at every sample from (w0, h0) at the first."""
    n, k = len(c.m11) + 1, len(w0)
    ws, hs = np.empty((n, k)), np.empty((n, k))
    ws[0], hs[0] = w0, h0
    tmp = np.empty(k)
    for i in range(n - 1):
        w, x, wn, xn = ws[i], hs[i], ws[i + 1], hs[i + 1]
        np.multiply(c.m11[i], w, out=wn)
        np.multiply(c.m12[i], x, out=tmp)
        wn += tmp
        wn += c.f1[i]
        np.multiply(c.m21[i], w, out=xn)
        np.multiply(c.m22[i], x, out=tmp)
        xn += tmp
        xn += c.f2[i]
    return ws, hs


def _compose(a, b):
    """The affine map a∘b (b first) of maps (m11, m12, m21, m22, f1, f2)."""
    a11, a12, a21, a22, aw, ah = a
    b11, b12, b21, b22, bw, bh = b
    return (
        a11 * b11 + a12 * b21,
        a11 * b12 + a12 * b22,
        a21 * b11 + a22 * b21,
        a21 * b12 + a22 * b22,
        a11 * bw + a12 * bh + aw,
        a21 * bw + a22 * bh + ah,
    )


def _start_state(c: _Cycle, repeat: int | None):
    """The rises at the start of the period that holds the peak: the periodic state
    (``repeat`` None; inf where it does not exist) or the start of the last of ``repeat``
    periods from ambient."""
    k = c.m11.shape[1]
    if repeat == 1:
        return np.zeros(k), np.zeros(k)
    period = c.period
    if repeat is None:
        p11, p12, p21, p22, pw, ph = period
        det = (1.0 - p11) * (1.0 - p22) - p12 * p21
        stable = (p11 < 1.0) & (p22 < 1.0) & (det > 0.0)
        w = ((1.0 - p22) * pw + p12 * ph) / det
        h = (p21 * pw + (1.0 - p11) * ph) / det
        return np.where(stable, w, np.inf), np.where(stable, h, np.inf)
    one, zero = np.ones(k), np.zeros(k)
    result, base, m = (one, zero, zero, one, zero, zero), period, repeat - 1
    while m:  # exponentiation by squaring of the affine map
        if m & 1:
            result = _compose(base, result)
        m >>= 1
        if m:
            base = _compose(base, base)
    return result[4], result[5]


@dataclass
class ThermalCycle:
    """The result of :func:`thermal_cycle` (rises above the ambient temperature [K]):
    ``winding_peak``, ``housing_peak`` (k,) the largest rises over the period that holds the
    peak (NaN where the candidate has no thermal model, housing NaN for one-node candidates,
    inf for a thermal runaway); ``winding`` and ``housing`` (n, k): the rises at every sample
    of that period."""

    winding_peak: np.ndarray
    housing_peak: np.ndarray
    winding: np.ndarray
    housing: np.ndarray


def thermal_cycle(
    t, current_sq, net: ThermalNetwork, r_ambient, r_slope=0.0, repeat: int | None = None
) -> ThermalCycle:
    """Winding and housing temperature rises of k candidates over a repeated period (see the
    module notes).

    Args:
        t: (n,) the period's sample times (non-decreasing; t[-1] − t[0] the period).
        current_sq: (n, k) the square of each candidate's current at the samples (or any
            quantity whose product with the resistance is the loss).
        net: the candidates' :class:`ThermalNetwork`.
        r_ambient: (k,) the winding resistance at the ambient temperature [Ω].
        r_slope: (k,) dR/dT_w = α R_ref [Ω/K] (0: a constant resistance).
        repeat: None (the periodic steady state) or the number of periods from ambient.

    How: the step maps (n − 1, k) are built vectorised, the period map composes them by
    pairs, then one pass over the samples from the start state. Memory: about 10 (n, k)
    arrays besides the input (the caller chunks the candidates).
    """
    repeat = _checks.integer("thermal_cycle", "repeat", repeat, lo=1, none=True)
    t = np.asarray(t, dtype=float)
    current_sq = np.asarray(current_sq, dtype=float)
    if t.ndim != 1 or len(t) < 2 or current_sq.shape != (len(t), len(net)):
        raise _core.ModelError(
            f"thermal_cycle: t must be (n,), n >= 2, and current_sq (n, {len(net)}); got "
            f"{t.shape} and {current_sq.shape}"
        )
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        c = _cycle(t, current_sq, net, r_ambient, r_slope, period=repeat != 1)
        winding, housing = _sweep(c, *_start_state(c, repeat))
        wmax, hmax = np.max(winding, axis=0), np.max(housing, axis=0)
    bad = ~(np.isfinite(wmax) & np.isfinite(hmax))
    no_w, no_h = ~net.valid, ~(net.valid & net.two_node)
    for x, none in ((winding, no_w), (housing, no_h)):
        x[:, bad] = np.inf
        x[:, none] = np.nan
    return ThermalCycle(_masked(wmax, bad, no_w), _masked(hmax, bad, no_h), winding, housing)


def _masked(x: np.ndarray, runaway: np.ndarray, none: np.ndarray) -> np.ndarray:
    """``x`` with its candidates ``runaway`` set to inf and ``none`` to NaN."""
    return np.where(none, np.nan, np.where(runaway, np.inf, x))


def thermal_rise(t: np.ndarray, loss: np.ndarray, r_th: float, tau_th: float) -> np.ndarray:
    """Winding temperature rise of the first-order model τ_th dΔT/dt = R_th P(t) − ΔT from
    ΔT = 0, P linear between samples (exact per step): :func:`thermal_cycle`'s one-node model
    over one period from ambient."""
    loss = np.asarray(loss, dtype=float)
    if len(loss) < 2:  # nothing elapses
        return np.zeros_like(loss)
    net = thermal_network(r_th=r_th, tau_th=tau_th)
    return thermal_cycle(t, loss[:, None], net, np.ones(1), repeat=1).winding[:, 0]


def temperature_rises(
    t: np.ndarray, loss: np.ndarray, r_th: float, tau_th: float
) -> tuple[float, float]:
    """``(steady, peak)`` temperature rise [K] of a copper loss ``loss`` [W] along a run:
    steady = R_th · mean loss, peak = the largest rise of :func:`thermal_rise` from ΔT(0) = 0.
    NaN where the datasheet value is missing (R_th for both, a positive τ_th for the peak)."""
    steady, peak = np.nan, np.nan
    if np.isfinite(r_th):
        steady = r_th * time_mean(loss, t)
        if np.isfinite(tau_th) and tau_th > 0:
            peak = float(np.max(thermal_rise(t, loss, r_th, tau_th)))
    return steady, peak
