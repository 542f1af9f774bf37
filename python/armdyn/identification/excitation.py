"""Excitation design: periodic joint motions that make the base parameters well conditioned.

Each joint follows a finite Fourier series (Swevers, Ganseman, Tukel, De Schutter, Van Brussel,
"Optimal robot excitation and identification", IEEE T-RA 13(5), 1997):

    q_j(t) = q0_j + sum_l  a_jl / (w_f l) sin(w_f l t) - b_jl / (w_f l) cos(w_f l t),

``w_f = 2 pi / period``, ``l = 1..harmonics``: periodic, so a log can be averaged over periods,
and with closed-form ``qd`` and ``qdd`` (:func:`fourier_series`). :func:`fourier_excitation`
chooses the coefficients (and ``q0``) that minimise the condition number of the stacked base
regressor over one period, within the position, velocity, acceleration and torque limits;
:func:`random_fourier` gives random coefficients scaled into the same limits (the comparison).

Starting from rest: by default (``at_rest=True``) the coefficients satisfy
``sum_l a_jl = 0`` and ``sum_l l b_jl = 0`` for every joint, i.e. ``qd = qdd = 0`` at
``t = 0`` (and so at every whole period): the motion starts and ends at rest at
``q(0) = q0 - sum_l b_l / (w_f l)``; a controller moves there slowly, then plays the CSV
(:meth:`Excitation.to_csv`) and stops at its end without a jump in velocity or acceleration.
"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt
import scipy.optimize

from armdyn import _checks, _core
from armdyn.identification.base import (
    BaseParameters,
    base_parameters,
    one_blas_thread,
)
from armdyn.motion.trajectory import Trajectory

__all__ = ["Excitation", "fourier_excitation", "fourier_series", "random_fourier"]

#: the sampled torque constraints of the optimisation hold |tau| <= TORQUE_MARGIN * limit, so the
#: torque between the samples stays below the limit (checked on a fine grid afterwards)
TORQUE_MARGIN = 0.95
#: default acceleration limit: ACCELERATION_PER_VELOCITY * the velocity limit [1/s]
ACCELERATION_PER_VELOCITY = 5.0
#: the fine grid every result is checked on: samples per period of the highest harmonic; there
#: the torques must stay within TORQUE_CHECK of their limit (room for a peak between samples)
CHECK_PER_CYCLE = 40
TORQUE_CHECK = 0.999
MAX_HARMONICS = 50
#: the condition numbers fourier_excitation can minimise: "scaled" (each base regressor column
#: divided by its RMS over random states) or "raw" (the base regressor as it is, SI units)
CRITERIA = ("scaled", "raw")
#: the exponent k of the optimiser's smooth surrogate of log cond (:meth:`_Problem.surrogate`)
SMOOTHING = 20.0


def _single_blas_thread(fn):
    """``fn`` run under :func:`armdyn.identification.base.one_blas_thread`."""

    @functools.wraps(fn)
    def run(*args, **kwargs):
        with one_blas_thread():
            return fn(*args, **kwargs)

    return run


def fourier_series(
    t: npt.ArrayLike, q0: npt.ArrayLike, a: npt.ArrayLike, b: npt.ArrayLike, period: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions, velocities and accelerations (each (len(t), n)) of the finite Fourier series
    ``q = q0 + sum_l a_l / (w_f l) sin(w_f l t) - b_l / (w_f l) cos(w_f l t)``,
    ``qd = sum_l a_l cos(w_f l t) + b_l sin(w_f l t)``,
    ``qdd = sum_l w_f l (-a_l sin(w_f l t) + b_l cos(w_f l t))``, ``w_f = 2 pi / period``;
    ``q0`` (n,), ``a`` and ``b`` (n, harmonics)."""
    who = "fourier_series"
    t = np.atleast_1d(_checks.array(who, "t", t, finite=True))
    if t.ndim != 1:
        raise _core.ModelError(f"{who}: t must be 1-D, got shape {t.shape}")
    q0 = _checks.array(who, "q0", q0, ndim=1, finite=True)
    a = _checks.array(who, "a", a, ndim=2, finite=True)
    b = _checks.array(who, "b", b, ndim=2, finite=True)
    if a.shape != b.shape or a.shape[0] != q0.size or a.shape[1] < 1:
        raise _core.ModelError(
            f"{who}: a and b must both have shape (len(q0), harmonics) = ({q0.size}, h >= 1), "
            f"got {a.shape} and {b.shape}"
        )
    period = _checks.number(who, "period", period, lo=0.0, lo_open=True)
    return _series(t, q0, a, b, 2.0 * np.pi / period)


def _series(t, q0, a, b, wf):
    harm = wf * np.arange(1, a.shape[1] + 1)  # (H,)
    arg = np.outer(t, harm)  # (N, H)
    s, c = np.sin(arg), np.cos(arg)
    q = q0 + s @ (a / harm).T - c @ (b / harm).T
    qd = c @ a.T + s @ b.T
    qdd = -s @ (a * harm).T + c @ (b * harm).T
    return q, qd, qdd


@dataclass(frozen=True, eq=False)  # arrays: compared by identity
class Excitation:
    """A periodic excitation motion (from :func:`fourier_excitation` or :func:`random_fourier`).

    Attributes:
        period: [s]; q0: (n,) the offsets; a, b: (n, harmonics) the coefficients
            (:func:`fourier_series`).
        cond: the condition number of the stacked base regressor over one period (its columns
            scaled or not by ``info["criterion"]``, as :func:`fourier_excitation` says).
        base: the base parameters it was designed for.
        joint_names: the model's coordinate names (the CSV's columns).
        info: what the design reports: the limits, the samples, the random starts' and the
            optimised conds, iterations, the time it took.
    """

    period: float
    q0: np.ndarray
    a: np.ndarray
    b: np.ndarray
    cond: float
    base: BaseParameters
    joint_names: tuple[str, ...] = ()
    info: dict[str, Any] = field(default_factory=dict)

    @property
    def harmonics(self) -> int:
        """The number of harmonics per joint (the columns of ``a`` and ``b``)."""
        return int(self.a.shape[1])

    def evaluate(self, t: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``q, qd, qdd`` at times ``t`` (s)."""
        return fourier_series(t, self.q0, self.a, self.b, self.period)

    def _grid(self, who: str, dt, periods) -> np.ndarray:
        periods = _checks.integer(who, "periods", periods, lo=1, hi=100_000)
        if dt is None:  # 0.01 s, finer when the highest harmonic would get < 20 samples a cycle
            dt = min(0.01, self.period / (20 * self.harmonics))
        dt = _checks.number(who, "dt", dt, lo=0.0, lo_open=True)
        total = periods * self.period
        count = int(np.ceil(total / dt - 1e-9))
        if count > 10_000_000:
            raise _core.ModelError(f"{who}: dt = {dt:g} s gives {count} samples (> 1e7)")
        return np.append(dt * np.arange(count), total)

    def trajectory(self, dt: float | None = None, periods: int = 1) -> Trajectory:
        """The motion over ``periods`` whole periods from ``t = 0`` (the end included), sampled
        every ``dt`` s (default 0.01 s, finer when the highest harmonic would get fewer than 20
        samples a cycle), with the exact evaluator (:meth:`Trajectory.sample` re-grids
        exactly)."""
        t = self._grid("Excitation.trajectory", dt, periods)
        q, qd, qdd = self.evaluate(t)
        info = {"method": "fourier excitation", "period": self.period, "cond": self.cond}
        return Trajectory(
            t, q, qd, qdd, names=self.joint_names or None, info=info, evaluate=self.evaluate
        )

    def to_csv(self, path, dt: float = 0.01, periods: int = 1) -> None:
        """Write the motion for a controller: columns ``t``, one position per joint (named as
        ``model.coord_names``), then ``<joint>.qd`` and ``<joint>.qdd`` per joint; one row every
        ``dt`` s over ``periods`` periods (the end included), 17 significant digits."""
        t = self._grid("Excitation.to_csv", dt, periods)
        q, qd, qdd = self.evaluate(t)
        names = self.joint_names or tuple(f"q{i}" for i in range(q.shape[1]))
        header = ["t", *names, *(f"{n}.qd" for n in names), *(f"{n}.qdd" for n in names)]
        data = np.column_stack([t, q, qd, qdd])
        np.savetxt(path, data, delimiter=",", header=",".join(header), comments="", fmt="%.17g")


@dataclass
class _Limits:
    lower: np.ndarray  # (n,) the position limits minus the margin (-inf: none)
    upper: np.ndarray
    velocity: np.ndarray  # (n,) > 0
    acceleration: np.ndarray  # (n,) > 0
    torque: np.ndarray  # (n,) > 0, inf: none


class _Problem:
    """The design problem: the decision vector x = (q0 if free, a, b) with, when at rest, the
    first harmonic's coefficients eliminated (a_1 = -sum a_l, b_1 = -sum l b_l)."""

    def __init__(self, model, base, period, harmonics, q0, limits, samples, at_rest):
        self.model, self.base, self.limits, self.at_rest = model, base, limits, at_rest
        self.n, self.h = model.n_dofs, harmonics
        self.period, self.wf = period, 2.0 * np.pi / period
        self.harm = np.arange(1, harmonics + 1, dtype=float)
        self.fixed_q0 = q0
        self.times = period * np.arange(samples) / samples
        self.torque_times = self.times
        self.criterion = "scaled"
        self.scale = _column_scale(model, base, limits)
        self.evaluations = 0
        self._maps = {}
        # the decision variables in units of what each joint allows (a finger's centimetres and
        # a shoulder's radians alike O(1)): a coefficient by the largest first-harmonic one
        # its position room, velocity and acceleration limits allow, q0 by half its range
        lim = limits
        both = np.isfinite(lim.upper) & np.isfinite(lim.lower)
        half = np.where(both, 0.5 * (lim.upper - lim.lower), np.inf)
        amp = np.minimum(np.minimum(half * self.wf, lim.velocity), lim.acceleration / self.wf)
        free = harmonics - 1 if at_rest else harmonics
        parts = [] if q0 is not None else [np.where(both, half, 1.0)]
        self.xscale = np.concatenate([*parts, np.repeat(amp, free), np.repeat(amp, free)])

    def unpack(self, x):
        x = x * self.xscale
        k = 0
        if self.fixed_q0 is None:
            q0, k = x[: self.n], self.n
        else:
            q0 = self.fixed_q0
        free = self.h - 1 if self.at_rest else self.h
        a_free = x[k : k + self.n * free].reshape(self.n, free)
        b_free = x[k + self.n * free :].reshape(self.n, free)
        if not self.at_rest:
            return q0, a_free, b_free
        a1 = -a_free.sum(axis=1, keepdims=True)
        b1 = -(b_free * self.harm[1:]).sum(axis=1, keepdims=True)
        return q0, np.hstack([a1, a_free]), np.hstack([b1, b_free])

    def pack(self, q0, a, b):
        cut = 1 if self.at_rest else 0
        parts = [] if self.fixed_q0 is not None else [q0]
        return np.concatenate([*parts, a[:, cut:].ravel(), b[:, cut:].ravel()]) / self.xscale

    def states(self, q0, a, b, t):
        return _series(t, q0, a, b, self.wf)

    def log_cond(self, x):
        self.evaluations += 1
        return np.log(_cond(self, *self.unpack(x), self.times))

    def maps(self, t):
        """The states are affine in x: (Jq, Jqd, Jqdd), each (len(t), n, len(x)), the
        derivatives of q, qd, qdd at the times t (exact: differences of unit vectors)."""
        key = ("states", t.size, float(t[-1]) if t.size else 0.0)
        if key not in self._maps:
            dim = self.xscale.size
            zero = self.states(*self.unpack(np.zeros(dim)), t)
            cols = [np.empty((t.size, self.n, dim)) for _ in range(3)]
            for i in range(dim):
                unit = np.zeros(dim)
                unit[i] = 1.0
                for col, s, s0 in zip(cols, self.states(*self.unpack(unit), t), zero, strict=True):
                    col[:, :, i] = s - s0
            self._maps[key] = cols
        return self._maps[key]

    def coefficient_maps(self):
        """(Uq0, Ua, Ub): q0 (n, len(x)), a and b (n, h, len(x)) are linear in x."""
        if "coefficients" not in self._maps:
            dim = self.xscale.size
            q00, a0, b0 = self.unpack(np.zeros(dim))
            uq = np.zeros((self.n, dim))
            ua, ub = np.zeros((self.n, self.h, dim)), np.zeros((self.n, self.h, dim))
            for i in range(dim):
                unit = np.zeros(dim)
                unit[i] = 1.0
                q0, a, b = self.unpack(unit)
                uq[:, i], ua[:, :, i], ub[:, :, i] = q0 - q00, a - a0, b - b0
            self._maps["coefficients"] = (uq, ua, ub)
        return self._maps["coefficients"]

    def surrogate(self, x):
        """The smooth surrogate of log cond the optimiser follows and its gradient in x:
        ``(log sum s_i^k + log sum s_i^-k) / k`` over the singular values s_i of the scaled
        stacked base regressor Z (k = :data:`SMOOTHING`; it bounds log cond from above, within
        ``2 log(rank) / k``). Its differential is ``<Z M, dZ>`` with ``M = V diag(c) V^T``
        (V, the eigenvectors of Z^T Z); dZ by the chain rule through the states: Y's
        derivatives in each joint's q and qd (central differences of step 1e-6) and qdd (Y is
        linear in it: one difference), then the Fourier series' exact derivatives in x
        (:meth:`maps`)."""
        self.evaluations += 1
        q, qd, qdd = self.states(*self.unpack(x), self.times)
        z = self._z(q, qd, qdd)
        flat = z.reshape(-1, self.base.rank)
        lam, v = np.linalg.eigh(flat.T @ flat)
        lam = np.maximum(lam, 1e-300 + 1e-24 * lam[-1])
        logs = 0.5 * np.log(lam)
        k = SMOOTHING
        up, down = k * logs, -k * logs
        wu, wd = np.exp(up - up.max()), np.exp(down - down.max())
        f = (up.max() + np.log(wu.sum()) + down.max() + np.log(wd.sum())) / k
        c = (wu / wu.sum() - wd / wd.sum()) / (2.0 * lam)  # df/dlam_i
        adj = 2.0 * (z @ ((v * c) @ v.T))  # df/dZ: (S, n, p)
        grads = self._state_gradients(q, qd, qdd, z, adj)
        jac = self.maps(self.times)
        grad = sum(np.einsum("kj,kjd->d", g, m) for g, m in zip(grads, jac, strict=True))
        return f, grad

    def _z(self, q, qd, qdd):
        y = _core.joint_torque_regressor(self.model, q, qd, qdd)
        return y[..., self.base.independent] / self.scale

    def _state_gradients(self, q, qd, qdd, z, adj):
        """(gq, gqd, gqdd), each (S, n): the objective's derivative in each sample's state."""
        s, n = q.shape
        step = 1e-6
        eye = np.eye(n)
        # one batch: per joint q +- step, qd +- step, qdd + 1
        qs = np.concatenate([q + step * eye[j] * sign for j in range(n) for sign in (1, -1)])
        rows = [
            (qs, np.tile(qd, (2 * n, 1)), np.tile(qdd, (2 * n, 1))),
            (
                np.tile(q, (2 * n, 1)),
                np.concatenate([qd + step * eye[j] * sign for j in range(n) for sign in (1, -1)]),
                np.tile(qdd, (2 * n, 1)),
            ),
            (
                np.tile(q, (n, 1)),
                np.tile(qd, (n, 1)),
                np.concatenate([qdd + eye[j] for j in range(n)]),
            ),
        ]
        big = self._z(*(np.concatenate(parts) for parts in zip(*rows, strict=True)))
        zq = big[: 2 * n * s].reshape(n, 2, s, n, -1)
        zd = big[2 * n * s : 4 * n * s].reshape(n, 2, s, n, -1)
        za = big[4 * n * s :].reshape(n, s, n, -1)
        dq = (zq[:, 0] - zq[:, 1]) / (2.0 * step)
        dqd = (zd[:, 0] - zd[:, 1]) / (2.0 * step)
        dqdd = za - z
        return tuple(np.einsum("knp,jknp->kj", adj, d) for d in (dq, dqd, dqdd))

    def bounds(self, q0, a, b):
        """Analytic bounds over all t: |q - q0|, |qd|, |qdd| per joint (amplitude sums)."""
        amp = np.sqrt(a**2 + b**2 + 1e-30)
        return (
            (amp / (self.wf * self.harm)).sum(axis=1),
            amp.sum(axis=1),
            (amp * self.wf * self.harm).sum(axis=1),
        )

    def constraints(self, x):
        """>= 0 when feasible, each scaled by its limit: position (upper, lower), velocity,
        acceleration, then the sampled torques."""
        q0, a, b = self.unpack(x)
        pos, vel, acc = self.bounds(q0, a, b)
        lim = self.limits
        both = np.isfinite(lim.upper) & np.isfinite(lim.lower)
        room = np.where(both, np.maximum(lim.upper - lim.lower, 1e-9), 1.0)
        g = [
            np.where(np.isfinite(lim.upper), (lim.upper - q0 - pos) / room, 1.0),
            np.where(np.isfinite(lim.lower), (q0 - pos - lim.lower) / room, 1.0),
            1.0 - vel / lim.velocity,
            1.0 - acc / lim.acceleration,
        ]
        limited = np.isfinite(lim.torque)
        if limited.any():
            tau = _core.inverse_dynamics(self.model, *self.states(q0, a, b, self.torque_times))
            g.append(
                (1.0 - np.abs(tau[:, limited]) / (TORQUE_MARGIN * lim.torque[limited])).ravel()
            )
        return np.concatenate(g)

    def constraints_jacobian(self, x):
        """The derivative of :meth:`constraints` in x: the amplitude bounds' analytically
        (``d|c_l| = (a_l da_l + b_l db_l) / |c_l|``), the torques' by the chain rule through
        the states (:func:`armdyn.inverse_dynamics_derivatives`; the mass matrix for qdd, from
        one difference: tau is linear in qdd) and the series' exact derivatives in x."""
        q0, a, b = self.unpack(x)
        uq, ua, ub = self.coefficient_maps()
        amp = np.sqrt(a**2 + b**2 + 1e-30)
        damp = (a[:, :, None] * ua + b[:, :, None] * ub) / amp[:, :, None]  # (n, h, dim)
        lw = self.wf * self.harm
        dpos = np.einsum("jhd,h->jd", damp, 1.0 / lw)
        lim = self.limits
        both = np.isfinite(lim.upper) & np.isfinite(lim.lower)
        room = np.where(both, np.maximum(lim.upper - lim.lower, 1e-9), 1.0)[:, None]
        rows = [
            np.where(np.isfinite(lim.upper)[:, None], (-uq - dpos) / room, 0.0),
            np.where(np.isfinite(lim.lower)[:, None], (uq - dpos) / room, 0.0),
            -damp.sum(axis=1) / lim.velocity[:, None],
            -np.einsum("jhd,h->jd", damp, lw) / lim.acceleration[:, None],
        ]
        limited = np.isfinite(lim.torque)
        if limited.any():
            t = self.torque_times
            q, qd, qdd = self.states(q0, a, b, t)
            tau = _core.inverse_dynamics(self.model, q, qd, qdd)
            dq, dqd = _core.inverse_dynamics_derivatives(self.model, q, qd, qdd)
            jq, jqd, jqdd = self.maps(t)
            dtau = np.einsum("kij,kjd->kid", dq, jq) + np.einsum("kij,kjd->kid", dqd, jqd)
            for j in range(self.n):  # + M jqdd, M's column j = tau(qdd + e_j) - tau
                step = np.zeros(self.n)
                step[j] = 1.0
                col = _core.inverse_dynamics(self.model, q, qd, qdd + step) - tau
                dtau += col[:, :, None] * jqdd[:, j, None, :]
            scale = np.sign(tau[:, limited]) / (TORQUE_MARGIN * lim.torque[limited])
            rows.append((-scale[:, :, None] * dtau[:, limited, :]).reshape(-1, x.size))
        return np.vstack(rows)


def _column_scale(model, base, limits):
    """The RMS of each base regressor column over 200 random states within the limits (seed 0):
    positions uniform within the position limits minus the margin ([-pi, pi] where one is
    infinite), velocities and accelerations uniform within +-max_velocity and
    +-max_acceleration: a fixed scale per column, independent of each joint's units."""
    rng = np.random.default_rng(0)
    finite = np.isfinite(limits.lower) & np.isfinite(limits.upper)
    lo = np.where(finite, limits.lower, -np.pi)
    hi = np.where(finite, limits.upper, np.pi)
    count = 200
    q = rng.uniform(lo, hi, size=(count, lo.size))
    qd = rng.uniform(-1.0, 1.0, size=(count, lo.size)) * limits.velocity
    qdd = rng.uniform(-1.0, 1.0, size=(count, lo.size)) * limits.acceleration
    y = base.regressor(_core.joint_torque_regressor(model, q, qd, qdd))
    return np.sqrt(np.mean(y.reshape(-1, base.rank) ** 2, axis=0))


def _cond(problem, q0, a, b, t):
    y = problem.base.regressor(
        _core.joint_torque_regressor(problem.model, *problem.states(q0, a, b, t))
    )
    return scaled_cond(y.reshape(-1, problem.base.rank) / problem.scale)


def scaled_cond(y: np.ndarray) -> float:
    """The 2-norm condition number of ``y`` (rows >= columns): from the eigenvalues of
    ``y^T y`` (a small symmetric eigenproblem, cheaper than the tall matrix's SVD) while that is
    accurate (cond < 1e6: the
    squared cond keeps ~1e-4 relative), else from the SVD."""
    lam = np.linalg.eigvalsh(y.T @ y)
    if lam[0] > 1e-12 * lam[-1]:
        return float(np.sqrt(lam[-1] / lam[0]))
    s = np.linalg.svd(y, compute_uv=False)
    return float(s[0] / s[-1]) if s[-1] > 0.0 else float("inf")


def _violations(problem, q0, a, b, t):
    """The limits the motion breaks on the grid t (and the analytic position bound), as
    messages naming the joint (empty: feasible)."""
    names = problem.model.coord_names
    lim = problem.limits
    q, qd, qdd = problem.states(q0, a, b, t)
    pos = problem.bounds(q0, a, b)[0]
    out = []
    tol = 1e-9
    for j, name in enumerate(names):
        hi, lo = q0[j] + pos[j], q0[j] - pos[j]
        if hi > lim.upper[j] + tol or lo < lim.lower[j] - tol:
            out.append(
                f"position limit of joint {name!r}: the motion spans [{lo:.6g}, {hi:.6g}], "
                f"the limits minus the margin are [{lim.lower[j]:.6g}, {lim.upper[j]:.6g}] rad"
            )
        if np.abs(qd[:, j]).max() > lim.velocity[j] * (1 + tol):
            out.append(
                f"velocity limit of joint {name!r}: {np.abs(qd[:, j]).max():.6g} > "
                f"{lim.velocity[j]:.6g}"
            )
        if np.abs(qdd[:, j]).max() > lim.acceleration[j] * (1 + tol):
            out.append(
                f"acceleration limit of joint {name!r}: {np.abs(qdd[:, j]).max():.6g} > "
                f"{lim.acceleration[j]:.6g}"
            )
    if np.isfinite(lim.torque).any():
        tau = np.abs(_core.inverse_dynamics(problem.model, q, qd, qdd)).max(axis=0)
        for j in np.flatnonzero(tau > TORQUE_CHECK * lim.torque):
            out.append(
                f"torque limit of joint {names[j]!r}: {tau[j]:.6g} > {TORQUE_CHECK:g} x "
                f"{lim.torque[j]:.6g} N m"
            )
    return out


def _check_grid(problem):
    count = max(CHECK_PER_CYCLE * problem.h, 200)
    return problem.period * np.arange(count) / count


def _per_joint(who, name, value, default, n, names):
    if value is None:
        if default is None:
            return None
        value = default
    arr = _checks.array(who, name, value)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,):
        raise _core.ModelError(
            f"{who}: {name} must be a number or have shape ({n},), got {arr.shape}"
        )
    for j in range(n):
        if not arr[j] > 0.0 or np.isnan(arr[j]):
            raise _core.ModelError(
                f"{who}: {name}[{j}] (joint {names[j]!r}) must be positive (or inf: no limit), "
                f"got {arr[j]!r}"
            )
    return arr


def _margin(who, value, n):
    """position_margin: one number or one per joint, each finite and >= 0."""
    arr = _checks.array(who, "position_margin", value, finite=True)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,) or np.any(arr < 0.0):
        raise _core.ModelError(
            f"{who}: position_margin must be a number >= 0 or {n} of them, got {value!r}"
        )
    return arr


def _limits(who, model, max_velocity, max_acceleration, max_torque, margin):
    n, names = model.n_dofs, list(model.coord_names)
    vel_model = np.asarray(model.coord_velocity_limit, dtype=float)
    vel = _per_joint(who, "max_velocity", max_velocity, None, n, names)
    if vel is None:
        bad = [names[j] for j in range(n) if not (np.isfinite(vel_model[j]) and vel_model[j] > 0)]
        if bad:
            raise _core.ModelError(
                f"{who}: the model has no velocity limit for joint {bad[0]!r}: give max_velocity"
            )
        vel = vel_model
    if not np.all(np.isfinite(vel)):
        j = int(np.flatnonzero(~np.isfinite(vel))[0])
        raise _core.ModelError(f"{who}: max_velocity[{j}] (joint {names[j]!r}) must be finite")
    acc = _per_joint(
        who, "max_acceleration", max_acceleration, ACCELERATION_PER_VELOCITY * vel, n, names
    )
    if not np.all(np.isfinite(acc)):
        j = int(np.flatnonzero(~np.isfinite(acc))[0])
        raise _core.ModelError(f"{who}: max_acceleration[{j}] (joint {names[j]!r}) must be finite")
    eff = np.asarray(model.coord_effort_limit, dtype=float)
    eff = np.where(np.isfinite(eff) & (eff > 0), eff, np.inf)
    tau = _per_joint(who, "max_torque", max_torque, eff, n, names)
    lower = np.asarray(model.coord_lower, dtype=float) + margin
    upper = np.asarray(model.coord_upper, dtype=float) - margin
    for j in range(n):
        if not upper[j] > lower[j]:
            raise _core.SolverError(
                f"{who}: position limits of joint {names[j]!r} minus position_margin = "
                f"{margin[j]:g} leave no room: [{lower[j]:.6g}, {upper[j]:.6g}]"
            )
    return _Limits(lower, upper, vel, acc, tau)


def _setup(who, model, period, harmonics, q0, limits, base, samples, at_rest, criterion):
    """Check the model and arguments; the design problem."""
    if not isinstance(model, _core.Model):
        raise _core.ModelError(f"{who}: model must be an armdyn.Model, got {type(model).__name__}")
    if model.n_dofs == 0:
        raise _core.ModelError(f"{who}: the model has no joint to excite")
    if model.n_free or model.n_coords != model.n_dofs:
        raise _core.ModelError(
            f"{who}: a floating base (or a quaternion coordinate) cannot follow a joint-space "
            "Fourier excitation: identification logs are for fixed-base models"
        )
    period = _checks.number(who, "period", period, lo=0.0, lo_open=True)
    at_rest = _checks.flag(who, "at_rest", at_rest)
    harmonics = _checks.integer(
        who, "harmonics", harmonics, lo=2 if at_rest else 1, hi=MAX_HARMONICS
    )
    samples = _checks.integer(who, "samples", samples, lo=1, hi=100_000)
    margin = _margin(who, limits.pop("position_margin"), model.n_dofs)
    lim = _limits(who, model, **limits, margin=margin)
    if base is None:
        base = base_parameters(model)
    elif not isinstance(base, BaseParameters) or base.param_names != list(
        _core.dynamic_parameter_names(model)
    ):
        raise _core.ModelError(f"{who}: base must be the BaseParameters of this model")
    if samples * model.n_dofs < base.rank or samples < 2 * harmonics + 1:
        raise _core.ModelError(
            f"{who}: samples = {samples} too few: need samples * n_dofs >= {base.rank} base "
            f"parameters and samples > 2 * harmonics = {2 * harmonics}"
        )
    if q0 is not None:
        q0 = _checks.array(who, "q0", q0, ndim=1, finite=True)
        if q0.shape != (model.n_dofs,):
            raise _core.ModelError(f"{who}: q0 must have shape ({model.n_dofs},), got {q0.shape}")
        for j, name in enumerate(model.coord_names):
            if not lim.lower[j] < q0[j] < lim.upper[j]:
                raise _core.SolverError(
                    f"{who}: q0[{j}] = {q0[j]:.6g} is outside joint {name!r}'s position limits "
                    f"minus the margin [{lim.lower[j]:.6g}, {lim.upper[j]:.6g}]"
                )
    problem = _Problem(model, base, period, harmonics, q0, lim, samples, at_rest)
    problem.who = who
    problem.criterion = _checks.choice(who, "criterion", criterion, CRITERIA)
    if problem.criterion == "raw":
        problem.scale = np.ones(base.rank)
    return problem


def _centre(problem):
    if problem.fixed_q0 is not None:
        return problem.fixed_q0
    lo, hi = problem.limits.lower, problem.limits.upper
    # mid-range; 0 without limits; 1 (rad or m) inside a one-sided limit (or 0 when inside)
    both = np.isfinite(lo) & np.isfinite(hi)
    mid = 0.5 * (np.where(both, lo, 0.0) + np.where(both, hi, 0.0))
    mid = np.maximum(mid, np.where(np.isfinite(lo) & ~both, lo + 1.0, -np.inf))
    mid = np.minimum(mid, np.where(np.isfinite(hi) & ~both, hi - 1.0, np.inf))
    return np.clip(mid, lo + 1e-9, hi - 1e-9)


def _random_start(problem, rng, fill=0.9, per_joint=True):
    """Random coefficients scaled per joint into the analytic position, velocity and
    acceleration bounds (``fill`` of the room), then shrunk together until the torques hold on
    the check grid. SolverError when even the motion shrunk to rest at q0 breaks a torque limit."""
    n, h = problem.n, problem.h
    q0 = _centre(problem)
    a, b = rng.normal(size=(n, h)), rng.normal(size=(n, h))
    if problem.at_rest:
        a[:, 0] = -a[:, 1:].sum(axis=1)
        b[:, 0] = -(b[:, 1:] * problem.harm[1:]).sum(axis=1)
    pos, vel, acc = problem.bounds(q0, a, b)
    lim = problem.limits
    room = np.minimum(lim.upper - q0, q0 - lim.lower)
    factor = fill * np.min(
        np.vstack([room / pos, lim.velocity / vel, lim.acceleration / acc]), axis=0
    )
    if not per_joint:
        factor[:] = factor.min()
    a, b = a * factor[:, None], b * factor[:, None]
    grid = _check_grid(problem)
    for _ in range(60):
        if not _violations(problem, q0, a, b, grid):
            return q0, a, b
        a, b = 0.8 * a, 0.8 * b
    rest = _violations(problem, q0, 0.0 * a, 0.0 * b, grid)
    if rest:
        raise _core.SolverError(
            f"{problem.who}: no motion within the limits: even at rest at q0 = "
            f"{np.array2string(q0, precision=4)} the {rest[0]}"
        )
    last = _violations(problem, q0, a, b, grid)
    raise _core.SolverError(
        f"{problem.who}: no random motion within the limits found ({last[0] if last else ''})"
    )


def _feasible(problem, x, grid):
    """(q0, a, b) of x, its oscillation about q0 shrunk by the first of 1, 0.999, ..., 0.5
    that meets every limit on the check grid (SLSQP's iterates meet the constraints only at
    convergence, and then to its tolerance), or None."""
    q0, a, b = problem.unpack(x)
    for shrink in (1.0, 0.999, 0.99, 0.97, 0.94, 0.9, 0.85, 0.8, 0.7, 0.6, 0.5):
        if not _violations(problem, q0, shrink * a, shrink * b, grid):
            return q0, shrink * a, shrink * b
    return None


def _optimise(problem, start, maxiter):
    """SLSQP from a feasible start, keeping the best iterate that meets the constraints; the
    torque samples of the check grid that break the limit are added to the sampled
    constraints (at most 3 rounds). Returns ((q0, a, b) feasible on the check grid or None,
    iterations)."""
    grid = _check_grid(problem)
    x = problem.pack(*start)
    iterations = 0
    for _ in range(3):
        kept = {"x": x, "f": problem.log_cond(x)}

        def keep(xk, kept=kept):
            if np.min(problem.constraints(xk)) >= 0.0:
                f = problem.log_cond(xk)
                if f < kept["f"]:
                    kept.update(x=np.array(xk), f=f)

        res = scipy.optimize.minimize(
            problem.surrogate,
            x,
            jac=True,
            method="SLSQP",
            constraints=[
                {
                    "type": "ineq",
                    "fun": problem.constraints,
                    "jac": problem.constraints_jacobian,
                }
            ],
            options={"maxiter": maxiter, "ftol": 1e-9},
            callback=keep,
        )
        iterations += int(res.nit)
        found = [
            r for r in (_feasible(problem, res.x, grid), _feasible(problem, kept["x"], grid)) if r
        ]
        if found:
            return min(found, key=lambda r: _cond(problem, *r, problem.times)), iterations
        q0, a, b = problem.unpack(res.x)
        tau = np.abs(_core.inverse_dynamics(problem.model, *problem.states(q0, a, b, grid)))
        worst = grid[np.any(tau > TORQUE_MARGIN * problem.limits.torque, axis=1)]
        if worst.size == 0:
            return None, iterations
        problem.torque_times = np.union1d(problem.torque_times, worst)
        x = kept["x"]
    return None, iterations


def _excitation(problem, q0, a, b, info):
    return Excitation(
        period=problem.period,
        q0=np.array(q0, dtype=float),
        a=np.array(a, dtype=float),
        b=np.array(b, dtype=float),
        cond=_cond(problem, q0, a, b, problem.times),
        base=problem.base,
        joint_names=tuple(problem.model.coord_names),
        info=info,
    )


def _info(problem, samples):
    lim = problem.limits
    return {
        "samples": samples,
        "harmonics": problem.h,
        "at_rest": problem.at_rest,
        "limits": {
            "lower": lim.lower.copy(),
            "upper": lim.upper.copy(),
            "velocity": lim.velocity.copy(),
            "acceleration": lim.acceleration.copy(),
            "torque": lim.torque.copy(),
        },
        "criterion": problem.criterion,
        "cond_scaling": (
            "columns divided by their RMS over 200 random states within the limits"
            if problem.criterion == "scaled"
            else "none (the base regressor in SI units)"
        ),
    }


@_single_blas_thread
def fourier_excitation(
    model: _core.Model,
    *,
    period: float = 10.0,
    harmonics: int = 5,
    q0: npt.ArrayLike | None = None,
    max_velocity: npt.ArrayLike | None = None,
    max_acceleration: npt.ArrayLike | None = None,
    max_torque: npt.ArrayLike | None = None,
    position_margin: npt.ArrayLike = 0.05,
    base: BaseParameters | None = None,
    seed: int = 0,
    samples: int = 100,
    maxiter: int = 100,
    starts: int = 3,
    at_rest: bool = True,
    criterion: str = "scaled",
) -> Excitation:
    """The periodic excitation (finite Fourier series per joint, :func:`fourier_series`) that
    minimises the condition number of the stacked base regressor, within the limits.

    The condition number (``criterion``) is that of ``Y_b`` stacked over ``samples`` equally
    spaced times of one period, with ``"scaled"`` (the default) each column divided by a fixed
    scale: its RMS over 200 random states within the limits (seed 0: positions uniform within
    the position limits minus the margin, velocities and accelerations uniform within
    +-``max_velocity`` and +-``max_acceleration``). ``"raw"``: ``cond(Y_b)`` as it is, in SI
    units, the figure the literature reports (Swevers et al. 1997; Gautier and Khalil; Presse
    and Gautier); it depends on the units (a mass column in N/kg against an inertia column in
    1/s^2: metres to millimetres changes it).
    Scaling by the nominal parameters fails where they are zero (a URDF has no friction or
    offsets), and scaling each column by the motion's own norm (equilibration) measures only
    the columns' collinearity, not how strongly the motion excites each: a fixed scale per
    column from what the limits allow keeps the criterion independent of each joint's units (a
    finger's m/s and a shoulder's rad/s) and still rewards exciting every column.

    SLSQP (scipy) minimises a smooth upper bound of ``log cond``,
    ``(log sum s_i^k + log sum s_i^-k) / k`` over the singular values (k =
    :data:`SMOOTHING`, 20: within ``2 log(rank) / k`` of it; log cond itself is not
    differentiable where the smallest singular values meet, and the optimum gathers them), with
    its gradient by the chain rule: the eigenvectors of ``Y_b^T Y_b``, the regressor's
    derivatives in each joint's q, qd (central differences) and qdd (exact), the series' exact
    derivatives in the coefficients; the constraints' Jacobian analytically (the torques' by
    :func:`armdyn.inverse_dynamics_derivatives`). From ``starts`` feasible random starts
    (:func:`random_fourier` with per-joint scaling, seeds ``seed``, ``seed + 1``, ...), the
    lowest condition number kept; the variables are scaled per joint by what its limits allow,
    so a gripper's centimetres and a shoulder's radians weigh alike. The constraints:
    ``|q - q0| <= sum_l |c_l| / (w_f l)``, ``|qd| <= sum_l |c_l|`` and
    ``|qdd| <= sum_l w_f l |c_l|`` (``|c_l| = sqrt(a_l^2 + b_l^2)``; conservative bounds for all
    t) within the position limits minus ``position_margin``, ``max_velocity`` and
    ``max_acceleration``; the inverse-dynamics torques at the samples within
    :data:`TORQUE_MARGIN` (0.95) of ``max_torque``. Every result is checked on a grid of
    :data:`CHECK_PER_CYCLE` (40) samples per cycle of the highest harmonic (at least 200), the
    torques within :data:`TORQUE_CHECK` (0.999) of their limits there; an optimum that breaks a
    torque limit there gets those times as constraints and is solved again. An SLSQP result
    (or the best iterate that met the constraints) that misses a limit has its oscillation about
    ``q0`` shrunk by the first factor of 1, 0.999, ..., 0.5 that meets them all; if no start
    gives a feasible result better than the best start, that start is returned
    (``info["optimised"]`` False).

    Args:
        model: a fixed-base model (no quaternion coordinates).
        period: [s] of the fundamental; harmonics: per joint (2..50 with ``at_rest``, else 1..50).
        q0: (n,) fixed offsets; None: optimised too (starting mid-range).
        max_velocity: [rad/s or m/s] per joint or one number; default model.coord_velocity_limit.
        max_acceleration: default :data:`ACCELERATION_PER_VELOCITY` (5 / s) x max_velocity.
        max_torque: default model.coord_effort_limit (0 or inf: no torque limit).
        position_margin: [rad or m] kept from each position limit: one number or one per joint
            (a gripper finger's few centimetres need a smaller one).
        base: the model's BaseParameters (default base_parameters(model)).
        seed: the first random start's seed; samples: times per period in the condition number
            and the torque constraints; maxiter: SLSQP iterations per start; starts: how many.
        at_rest: start (and end every period) at rest: qd = qdd = 0 at t = 0.
        criterion: ``"scaled"`` or ``"raw"`` (above).

    Raises:
        ModelError: a bad argument, a floating base, a model without joints.
        SolverError: limits no motion can meet (naming the limit and the joint).

    Runtime and result with the robots' own limits, period 10 s, the defaults (5 harmonics, 100
    samples, 3 starts of 100 SLSQP iterations; ``python -m
    benchmarks.identification_excitation --seeds 20``,
    benchmarks/results/identification_excitation.json; CPU time on the shared 2-core machine):
    the UR5, 23 s CPU, cond 9.3 against 25-117 (median 39) for 20 random motions scaled per
    joint: 2.7x below the best draw, 4.1x below the median; the Panda, 44 s CPU, cond 49.7
    against 680-3504 (median 1236): 13.7x and 24.9x. The UR5's random motions are already well
    conditioned (docs/identification.md, "Excitation", says why the 10x cannot hold there).
    """
    who = "fourier_excitation"
    limits = {
        "max_velocity": max_velocity,
        "max_acceleration": max_acceleration,
        "max_torque": max_torque,
        "position_margin": position_margin,
    }
    problem = _setup(who, model, period, harmonics, q0, limits, base, samples, at_rest, criterion)
    seed = _checks.integer(who, "seed", seed, lo=0, hi=2**63 - 1)
    maxiter = _checks.integer(who, "maxiter", maxiter, lo=1, hi=100_000)
    starts = _checks.integer(who, "starts", starts, lo=1, hi=1000)
    t0 = time.perf_counter()
    best, best_cond, start_conds, iterations = None, np.inf, [], 0
    fallback = None
    for k in range(starts):
        start = _random_start(problem, np.random.default_rng(seed + k))
        cond0 = _cond(problem, *start, problem.times)
        start_conds.append(cond0)
        if fallback is None or cond0 < fallback[1]:
            fallback = (start, cond0)
        result, nit = _optimise(problem, start, maxiter)
        iterations += nit
        if result is not None:
            c = _cond(problem, *result, problem.times)
            if c < best_cond:
                best, best_cond = result, c
    optimised = best is not None and best_cond <= fallback[1]
    chosen = best if optimised else fallback[0]
    info = _info(problem, samples) | {
        "optimised": optimised,
        "start_conds": start_conds,
        "iterations": iterations,
        "evaluations": problem.evaluations,
        "seconds": time.perf_counter() - t0,
        "method": "SLSQP",
    }
    return _excitation(problem, *chosen, info)


@_single_blas_thread
def random_fourier(
    model: _core.Model,
    *,
    period: float = 10.0,
    harmonics: int = 5,
    q0: npt.ArrayLike | None = None,
    max_velocity: npt.ArrayLike | None = None,
    max_acceleration: npt.ArrayLike | None = None,
    max_torque: npt.ArrayLike | None = None,
    position_margin: npt.ArrayLike = 0.05,
    base: BaseParameters | None = None,
    seed: int = 0,
    samples: int = 100,
    at_rest: bool = True,
    scaling: str = "joint",
    criterion: str = "scaled",
) -> Excitation:
    """A random Fourier excitation within the same limits as :func:`fourier_excitation` (the
    comparison, and its starting points): standard normal coefficients (with ``at_rest``, the
    first harmonic's set so that the motion starts at rest), scaled to 90 % of the room the
    analytic position, velocity and acceleration bounds allow, then all shrunk by 0.8 until the
    torques hold on the check grid; ``q0`` mid-range unless given. ``scaling="joint"`` scales
    each joint's coefficients to its own limits (the stronger baseline, and the optimiser's
    starts); ``"common"`` scales all by one factor, until the first limit binds (the other
    joints then move less). ``cond`` as :func:`fourier_excitation` computes it (by
    ``criterion``). Same arguments and errors (``scaling`` or ``criterion`` neither:
    ModelError)."""
    who = "random_fourier"
    limits = {
        "max_velocity": max_velocity,
        "max_acceleration": max_acceleration,
        "max_torque": max_torque,
        "position_margin": position_margin,
    }
    problem = _setup(who, model, period, harmonics, q0, limits, base, samples, at_rest, criterion)
    seed = _checks.integer(who, "seed", seed, lo=0, hi=2**63 - 1)
    scaling = _checks.choice(who, "scaling", scaling, ("joint", "common"))
    start = _random_start(problem, np.random.default_rng(seed), per_joint=scaling == "joint")
    info = _info(problem, samples) | {"method": f"random ({scaling} scaling)"}
    return _excitation(problem, *start, info)
