"""The least-energy motion between two joint configurations in a given time: rest to rest, the
motion that minimises the motors' copper losses (or the joint torques' squares) under the joint
position, speed and torque limits and each motor's peak torque, speed and speed–torque envelope.

Parametrisation: each joint follows the quintic rest-to-rest move plus a correction, a clamped
B-spline of degree 5 in ``u = t / T`` whose value and first derivative vanish at both ends
(``end_acceleration="free"``, the default: the optimum of a quadratic torque cost starts and
ends with a step in torque, as the cubic that minimises ∫ τ² for a free inertia does) or also
its second derivative (``"zero"``: the motion starts and ends with zero acceleration, as the
quintic). The correction's free coefficients p are the unknowns. The cost is Simpson's rule over
``samples`` uniform samples; scipy's SLSQP minimises it with its exact gradient by the chain
rule, ``dτ/dp = ∂τ/∂q dq/dp + ∂τ/∂q̇ dq̇/dp + M dq̈/dp``
(:func:`armdyn.inverse_dynamics_derivatives`, :func:`armdyn.mass_matrix`), and the motor side
through the gear as :func:`armdyn.actuators.motor_side` writes it. The unknowns are scaled by
the Cholesky factor of the cost's Gauss–Newton Hessian at the quintic (SLSQP's quasi-Newton
Hessian starts as the identity, which is then about right).

The gear's efficiency switches where a joint reverses with a load (the power flow changes
direction): the cost's integrand jumps there, which the samples resolve to their spacing; the
reported costs are therefore Simpson's rule on the check grid, ``check_factor`` times finer.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from armdyn import _checks, _core
from armdyn.actuators import coulomb_smoothing
from armdyn.motion.trajectory import Trajectory
from armdyn.sizing.motor import envelope_corners, speed_limit

#: the quintic rest-to-rest blend s(u) = 10 u³ − 15 u⁴ + 6 u⁵ and its two derivatives
_QUINTIC = (
    lambda u: u**3 * (10.0 - 15.0 * u + 6.0 * u * u),
    lambda u: 30.0 * u**2 * (1.0 - u) ** 2,
    lambda u: 60.0 * u * (1.0 - u) * (1.0 - 2.0 * u),
)

#: the limit families, in the order of the constraint vector and of ``info["limit_usage"]``
LIMITS = ("position", "speed", "torque", "motor_peak_torque", "motor_envelope")

#: the largest number of samples (and of check samples) a solve takes
MAX_SAMPLES = 100_000

#: the largest samples * joints * unknowns (the entries of dτ/dp a solve holds: 8 bytes each,
#: and about ten times as many in the limits' Jacobian)
MAX_ENTRIES = 2_000_000

#: a solve takes every limit's side the motion leans to at the samples, and then the sides used
#: to at least this fraction at the instants the check adds ...
SCREEN = 0.5
#: ... and resumes with those it left out that the motion came to use, at most this many times
ROUNDS = 8


class _Diverged(Exception):
    """The solve stepped to a non-finite motion."""


class _Basis:
    """The correction's basis: the clamped quintic B-spline on [0, 1] with ``knots`` uniform
    interior knots, less the functions that would move the ends (``fixed`` at each end: 2 keep
    the end value and rate, 3 the acceleration too)."""

    def __init__(self, knots: int, fixed: int) -> None:
        from scipy.interpolate import BSpline

        inner = np.linspace(0.0, 1.0, knots + 2)[1:-1]
        t = np.concatenate([np.zeros(6), inner, np.ones(6)])
        count = len(t) - 6
        self.splines = [BSpline(t, np.eye(count), 5)]
        self.splines += [self.splines[0].derivative(k) for k in (1, 2)]
        self.columns = slice(fixed, count - fixed)
        self.size = count - 2 * fixed

    def at(self, u: np.ndarray, duration: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(B, dB/dt, d²B/dt²), each (len(u), size), at ``u = t / duration``."""
        return tuple(
            np.asarray(s(u), dtype=float)[:, self.columns] / duration**k
            for k, s in enumerate(self.splines)
        )


@dataclass
class _Drives:
    """Per dof (n,) arrays: the gear and motor values of the motor-side maths (1 and 0 on a joint
    without an actuator), ``copper`` = R / k_t² (NaN without a motor's k_t and R), the motor's
    peak torque and envelope corners (NaN: not given)."""

    actuated: np.ndarray
    ratio: np.ndarray
    efficiency: np.ndarray
    inertia: np.ndarray
    viscous: np.ndarray
    coulomb: np.ndarray
    smoothing: np.ndarray
    copper: np.ndarray
    peak_torque: np.ndarray
    stall: np.ndarray
    no_load: np.ndarray
    joint_speed: np.ndarray


def _num(value) -> float:
    return np.nan if value is None else float(value)


def _drives(model, n: int) -> _Drives:
    ones, zeros, nans = np.ones(n), np.zeros(n), np.full(n, np.nan)
    d = _Drives(
        actuated=np.zeros(n, dtype=bool),
        ratio=ones.copy(),
        efficiency=ones.copy(),
        inertia=zeros.copy(),
        viscous=zeros.copy(),
        coulomb=zeros.copy(),
        smoothing=ones.copy(),
        copper=nans.copy(),
        peak_torque=nans.copy(),
        stall=nans.copy(),
        no_load=nans.copy(),
        joint_speed=np.full(n, np.inf),
    )
    for a in getattr(model, "actuators", None) or []:
        k = int(a.dof)
        d.actuated[k] = True
        d.ratio[k], d.efficiency[k] = float(a.gear_ratio), float(a.efficiency)
        d.inertia[k], d.viscous[k] = float(a.rotor_inertia), float(a.friction_viscous)
        d.coulomb[k], d.smoothing[k] = float(a.friction_coulomb), coulomb_smoothing(a)
        m = a.motor
        if m is None:
            continue
        k_t, r = _num(m.torque_constant), _num(m.resistance)
        d.copper[k] = r / k_t**2
        d.peak_torque[k] = _num(m.peak_torque)
        t0, w0 = envelope_corners(
            k_t, _num(m.voltage), r, _num(m.peak_torque), _num(m.no_load_speed)
        )
        d.stall[k], d.no_load[k] = t0[0], w0[0]
        limit = speed_limit(_num(m.max_speed), _num(m.no_load_speed))[0]
        if np.isfinite(limit):
            d.joint_speed[k] = limit / abs(d.ratio[k])
    return d


class _Problem:
    """The discretised problem: the motion, its torques, the motor side, the cost and the
    limits at the samples ``u`` (the objective's trapezoid weights ``w``, zero at the points the
    limit check adds), each with its derivative in the unknowns ``p`` ((n, K) flattened)."""

    def __init__(self, model, start, goal, duration, basis, drives, objective, weights, limits):
        self.model, self.start, self.goal = model, start, goal
        self.duration = np.float64(duration)  # T³ overflows to inf, not OverflowError
        self.basis, self.drives, self.objective = basis, drives, objective
        self.weights, self.limits = weights, limits
        self.n, self.k = len(start), basis.size
        self.scale = 1.0
        self.mask: dict | None = None
        self._cache: tuple[bytes, dict] | None = None
        self.set_grid(np.linspace(0.0, 1.0, 2), np.zeros(2))

    def set_grid(self, u: np.ndarray, w: np.ndarray) -> None:
        """Samples ``u`` (in t / T) and the cost's weights there: the quintic's motion and the
        basis at them (non-finite where T² or T³ underflows: :meth:`state` refuses those)."""
        self.u, self.w = u, w
        with np.errstate(all="ignore"):
            self.base = [
                f(u)[:, None] * (self.goal - self.start) / self.duration**k
                for k, f in enumerate(_QUINTIC)
            ]
            self.base[0] = self.base[0] + self.start
            self.b = self.basis.at(u, self.duration)
        self._cache = None

    def motion(self, p: np.ndarray, u: np.ndarray | None = None):
        """(q, qd, qdd), each (rows, n), on the grid (or at ``u``)."""
        c = p.reshape(self.n, self.k)
        if u is None:
            with np.errstate(all="ignore"):
                return tuple(base + b @ c.T for base, b in zip(self.base, self.b, strict=True))
        dq = self.goal - self.start
        b = self.basis.at(u, self.duration)
        return tuple(
            f(u)[:, None] * dq / self.duration**k + (self.start if k == 0 else 0.0) + bk @ c.T
            for k, (f, bk) in enumerate(zip(_QUINTIC, b, strict=True))
        )

    # --- the torques and the motor side, with their derivatives --------------------------------
    def state(self, p: np.ndarray, derivatives: bool = True) -> dict:
        """The motion, torques and motor side at the grid (cached for the last ``p``), with
        their derivatives in ``p`` when ``derivatives``."""
        key = p.tobytes()
        if self._cache is not None and self._cache[0] == key:
            if "dtau" in self._cache[1] or not derivatives:
                return self._cache[1]
        q, qd, qdd = self.motion(p)
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(qdd))):
            raise _Diverged
        t = self.u * self.duration
        s = {"q": q, "qd": qd, "qdd": qdd, "t": t}
        s["tau"] = np.asarray(_core.inverse_dynamics(self.model, q, qd, qdd, t), dtype=float)
        self._motor_side(s)
        if derivatives:
            self._derivatives(s)
        self._cache = (key, s)
        return s

    def _derivatives(self, s: dict) -> None:
        """dτ/dp and dT/dp, each (rows, n, n K)."""
        q, qd, qdd, t = s["q"], s["qd"], s["qdd"], s["t"]
        d_q, d_qd = (
            np.asarray(x, dtype=float)
            for x in _core.inverse_dynamics_derivatives(self.model, q, qd, qdd, t)
        )
        mass = np.asarray(_core.mass_matrix(self.model, q), dtype=float)
        b0, b1, b2 = self.b
        # dτ[i, j] / dp[k, m] = ∂τ/∂q[i, j, k] B[i, m] + ∂τ/∂q̇ B' + M B''
        dtau = np.einsum("ijk,im->ijkm", d_q, b0)
        dtau += np.einsum("ijk,im->ijkm", d_qd, b1)
        dtau += np.einsum("ijk,im->ijkm", mass, b2)
        s["dtau"] = dtau.reshape(len(t), self.n, -1)
        # dT = f dτ + (1 − f N) dT_rot, dT_rot = J N dq̈ + (b N + c N / v_s sech²) dq̇ (own joint)
        d, f = self.drives, s["gear_factor"]
        dT = f[:, :, None] * s["dtau"]
        th = s["tanh"]
        rot_rate = d.viscous * d.ratio + d.coulomb * d.ratio / d.smoothing * (1.0 - th * th)
        gain = 1.0 - f * d.ratio
        rows = np.arange(self.n)
        block = dT.reshape(len(t), self.n, self.n, self.k)
        block[:, rows, rows, :] += (gain * d.inertia * d.ratio)[:, :, None] * b2[:, None, :]
        block[:, rows, rows, :] += (gain * rot_rate)[:, :, None] * b1[:, None, :]
        s["dT"] = dT

    def _motor_side(self, s: dict) -> None:
        """The motor torque T = (1 − f N) T_rot + f τ (f = 1 / (N η) while the gear drives the
        load, η / N backwards; T_rot = J N q̈ + b N q̇ + c tanh(N q̇ / v_s): the formulas of
        armdyn.actuators.motor_side; T = τ on a joint without an actuator)."""
        d, qd, qdd, tau = self.drives, s["qd"], s["qdd"], s["tau"]
        n_r = d.ratio
        w = n_r * qd
        th = np.tanh(w / d.smoothing)
        t_rot = d.inertia * n_r * qdd + d.viscous * w + d.coulomb * th
        load = tau - n_r * t_rot
        # the power's direction; at a rest end (q̇ = 0) its limit from inside the move, where
        # q̇ ≈ q̈ t after the start and −q̈ (T − t) before the end
        rate = qd.copy()
        for row, sign in ((0, 1.0), (-1, -1.0)):
            at_rest = rate[row] == 0.0
            rate[row] = np.where(at_rest, sign * qdd[row], rate[row])
        f = np.where(load * rate >= 0.0, 1.0 / (n_r * d.efficiency), d.efficiency / n_r)
        f = np.where(d.actuated, f, 1.0)
        s["speed"], s["tanh"], s["gear_factor"] = w, th, f
        s["T"] = (1.0 - f * n_r) * t_rot + f * tau

    # --- the cost --------------------------------------------------------------------------------
    def cost_terms(self, s: dict) -> tuple[np.ndarray, np.ndarray]:
        """(x, c): the cost is Σ_i w_i Σ_j c_j x_ij² (x the motor or joint torques)."""
        if self.objective == "copper":
            return s["T"], self.drives.copper
        return s["tau"], self.weights

    def value(self, p: np.ndarray) -> float:
        x, c = self.cost_terms(self.state(p, derivatives=False))
        return float(self.w @ (x * x) @ c) / self.scale

    def gradient(self, p: np.ndarray) -> np.ndarray:
        s = self.state(p)
        x, c = self.cost_terms(s)
        dx = s["dT"] if self.objective == "copper" else s["dtau"]
        return np.einsum("ij,ijp->p", 2.0 * self.w[:, None] * c * x, dx) / self.scale

    # --- the limits ------------------------------------------------------------------------------
    def families(self, s: dict):
        """(name, x (rows, n), limit (n,), dx/dp (rows, n, nK), a str "q"/"qd" for a linear
        family (its Jacobian from :meth:`_linear`) or None without derivatives): |x| ≤ limit."""
        lim, d = self.limits, self.drives
        with np.errstate(invalid="ignore"):
            centre = 0.5 * (lim["upper"] + lim["lower"])
        centre = np.where(np.isfinite(centre), centre, 0.0)
        yield "position", s["q"] - centre, 0.5 * (lim["upper"] - lim["lower"]), "q"
        yield "speed", s["qd"], lim["speed"], "qd"
        yield "torque", s["tau"], lim["torque"], s.get("dtau")
        if lim["motors"]:
            yield "motor_peak_torque", s["T"], d.peak_torque, s.get("dT")
            slope = np.where(np.isfinite(d.stall / d.no_load), d.stall / d.no_load, 0.0)
            env = s["T"] + slope * s["speed"]
            denv = None
            if "dT" in s:
                denv = s["dT"] + (slope * d.ratio)[:, None] * self._linear("qd")
            limit = np.where(np.isfinite(d.no_load) & (d.no_load > 0), d.stall, np.nan)
            yield "motor_envelope", env, limit, denv

    def _linear(self, which: str) -> np.ndarray:
        """d q / dp or d q̇ / dp, (rows, n, nK): block diagonal in the joints."""
        b = self.b[0 if which == "q" else 1]
        out = np.zeros((len(self.u), self.n, self.n, self.k))
        rows = np.arange(self.n)
        out[:, rows, rows, :] = b[:, None, :]
        return out.reshape(len(self.u), self.n, -1)

    def _ratios(self, s: dict):
        """(name, x / limit (rows, n), where the limit applies (rows, n), dx/dp, limit): the
        linear families at the interior samples only (their end values are fixed)."""
        interior = np.ones(len(self.u), dtype=bool)
        interior[[0, -1]] = False
        for name, x, limit, dx in self.families(s):
            valid = np.isfinite(limit) & (limit > 0)
            rows = interior if name in ("position", "speed") else np.ones_like(interior)
            lim = np.where(valid, limit, 1.0)
            with np.errstate(invalid="ignore"):
                yield name, x / lim, rows[:, None] & valid[None, :], dx, lim

    def screen(self, p: np.ndarray, threshold: float) -> dict:
        """{limit: (rows, n, 2)} the sides (x ≤ limit, −x ≤ limit) used to at least
        ``threshold`` at ``p``: the constraints a solve takes (the others are checked after)."""
        out = {}
        for name, r, ok, _, _ in self._ratios(self.state(p, derivatives=False)):
            with np.errstate(invalid="ignore"):
                out[name] = np.stack([ok & (r >= threshold), ok & (-r >= threshold)], axis=-1)
        return out

    def constraints(self, p: np.ndarray, margin: float, jacobian: bool = False) -> np.ndarray:
        """g ≥ 0 on the sides of ``self.mask`` (None: all): (1 − margin) ∓ x / limit (the two
        sides of |x| ≤ (1 − margin) limit); its Jacobian in ``p`` with ``jacobian``."""
        s = self.state(p, derivatives=jacobian)
        out = []
        for name, r, ok, dx, lim in self._ratios(s):
            up, down = (
                (ok, ok) if self.mask is None else (m for m in np.moveaxis(self.mask[name], -1, 0))
            )
            if not (up.any() or down.any()):
                continue
            if jacobian:
                dx = self._linear(dx) if isinstance(dx, str) else dx
                js = dx / lim[None, :, None]
                out += [-js[up], js[down]]
            else:
                out += [1.0 - margin - r[up], 1.0 - margin + r[down]]
        if not out:
            return np.zeros((0, self.n * self.k)) if jacobian else np.zeros(0)
        return np.vstack(out) if jacobian else np.concatenate(out)


def _limits(who: str, model, n: int, drives: _Drives, max_velocity, max_torque, motors: bool):
    """The limits per dof: position [lower, upper] from the model, speed (the smaller of the
    joint's and the motor's through its gear), torque; ``max_velocity``/``max_torque``
    (scalars or (n,)) replace the model's joint limits."""

    def per_joint(name, value, default):
        if value is None:
            return np.asarray(default, dtype=float).copy()
        a = _checks.array(who, name, value)
        if a.ndim == 0:
            a = np.full(n, float(a))
        if a.shape != (n,):
            raise _core.ModelError(f"{who}: {name} must be a number or shape ({n},), got {a.shape}")
        bad = np.isnan(a) | (a <= 0.0)
        if bad.any():
            k = int(np.argmax(bad))
            raise _core.ModelError(
                f"{who}: {name}[{k}] = {float(a[k]):g} (joint {model.dof_names[k]!r}) must be > 0 "
                "(inf: no limit)"
            )
        return a

    speed = per_joint("max_velocity", max_velocity, model.coord_velocity_limit)
    if motors:
        speed = np.minimum(speed, drives.joint_speed)
    return {
        "lower": np.asarray(model.coord_lower, dtype=float),
        "upper": np.asarray(model.coord_upper, dtype=float),
        "speed": speed,
        "torque": per_joint("max_torque", max_torque, model.coord_effort_limit),
        "motors": motors,
    }


def _check_model(who: str, model, objective: str) -> int:
    if not isinstance(model, _core.Model):
        raise _core.ModelError(f"{who}: model must be an armdyn.Model, got {type(model).__name__}")
    n = int(model.n_dofs)
    if int(model.n_coords) != n or n == 0:
        raise _core.ModelError(
            f"{who}: the model must have as many coordinates as rates (no floating base, no "
            f"ball joint) and at least one: it has {model.n_coords} and {n}"
        )
    if objective == "copper":
        d = _drives(model, n)
        missing = [model.dof_names[k] for k in range(n) if not np.isfinite(d.copper[k])]
        if missing:
            raise _core.ModelError(
                f"{who}: objective 'copper' needs every joint's actuator with a motor giving "
                f"torque_constant and resistance; joint {missing[0]!r} has none (add_actuator("
                "..., motor=Motor(torque_constant=..., resistance=...)) or "
                "objective='rms_torque')"
            )
    return n


def _configuration(who: str, name: str, value, model, n: int) -> np.ndarray:
    a = _checks.array(who, name, value, finite=True)
    if a.shape != (n,):
        raise _core.ModelError(f"{who}: {name} must have shape ({n},), got {a.shape}")
    lo, hi = np.asarray(model.coord_lower), np.asarray(model.coord_upper)
    bad = (a < lo) | (a > hi)
    if bad.any():
        k = int(np.argmax(bad))
        raise _core.ModelError(
            f"{who}: {name}[{k}] = {a[k]:g} is outside joint {model.dof_names[k]!r}'s position "
            f"limits [{lo[k]:g}, {hi[k]:g}]"
        )
    return a


def least_energy(
    model: _core.Model,
    start: npt.ArrayLike,
    goal: npt.ArrayLike,
    duration: float,
    *,
    objective: str = "copper",
    knots: int = 6,
    samples: int = 101,
    end_acceleration: str = "free",
    max_velocity: npt.ArrayLike | None = None,
    max_torque: npt.ArrayLike | None = None,
    motors: bool = True,
    weights: npt.ArrayLike | None = None,
    margin: float = 1e-3,
    check_factor: int = 8,
    max_iterations: int = 200,
    tol: float = 1e-8,
) -> Trajectory:
    """The least-energy rest-to-rest motion from ``start`` to ``goal`` in ``duration`` seconds.

    Minimises, over the motion (the quintic move plus a B-spline correction: see the module
    notes), Simpson's rule over ``samples`` uniform samples of

    - ``objective="copper"``: the motors' copper loss ∫ Σ R i² dt [J], i = T / k_t, T the motor
      torque of :func:`armdyn.actuators.motor_side` (the joint torque less the rotor's share
      through the gear: / (N η) while the motor drives the load, · η / N while the load drives
      it back, plus the rotor's inertia and friction torque), R the motor's resistance (at the
      datasheet's temperature): every joint needs an actuator whose motor gives
      ``torque_constant`` and ``resistance``. At the rest ends (q̇ = 0) the gear's branch is
      its limit from inside the move (motor_side takes the holding branch there: one instant);
    - ``objective="rms_torque"``: ∫ Σ w_j τ_j² dt [N² m² s] of the joint torques τ
      (``weights`` w, default 1; the result reports each joint's RMS torque).

    subject to, at every sample (the interior ones for the position and speed, whose end values
    are fixed):

    - the joint position limits (``model.coord_lower``/``coord_upper``);
    - the joint speed: ``max_velocity`` (a number or per joint; default the model's
      ``coord_velocity_limit``) and, with ``motors``, each motor's ``max_speed`` (else its
      ``no_load_speed``) through its gear;
    - the joint torque: ``max_torque`` (default ``coord_effort_limit``);
    - with ``motors`` and an actuator's motor data: the motor's ``peak_torque`` and its
      speed–torque envelope |T + T0 ω / ω0| ≤ T0 (:func:`armdyn.sizing.motor.motor_envelope`).

    Each limit is enforced at ``(1 - margin)`` of its value at the samples, on the side the
    motion leans to (|x| ≤ L as x ≤ L where x ≥ 0, −x ≤ L where x ≤ 0: the other side is
    slack). After a solve the motion is checked against the full limits on a grid
    ``check_factor`` times finer: the instants found beyond a limit join the constrained
    samples, and so do sides the new motion leans to that were left out (used to at least
    :data:`SCREEN` of their limit), and the solve resumes (at most :data:`ROUNDS` solves).
    Starting point: the quintic. The problem is not convex (gravity, the gear's two branches):
    the result is the local optimum SLSQP reaches from the quintic (``info["saving_percent"]``
    compares it with the quintic). Models with force elements need their
    derivatives (``armdyn.inverse_dynamics_derivatives`` raises ModelError where it has none).

    Args:
        model: a fixed-base model (as many coordinates as rates); gravity and its force
            elements act, drives are ignored.
        start, goal: (n,) joint positions, within the position limits.
        duration: the move's time T [s] > 0.
        objective: ``"copper"`` or ``"rms_torque"``.
        knots: interior knots of the correction's B-spline, 0 to 200 (unknowns per joint:
            ``knots + 2`` with ``end_acceleration="free"``, ``knots`` with ``"zero"``, which
            needs one at least).
        samples: samples of the cost and the limits (odd, ≥ 11: Simpson's rule).
        end_acceleration: ``"free"`` (the motion may start and end with a step in acceleration
            and torque) or ``"zero"`` (starts and ends with zero acceleration, as the quintic).
        max_velocity, max_torque: joint limits replacing the model's (> 0; inf: none).
        motors: enforce the motors' speed, peak torque and envelope limits.
        weights: (n,) positive weights of ``"rms_torque"``'s joints.
        margin: the fraction of each limit kept free at the samples, in [0, 0.49].
        check_factor: the check grid's refinement (≥ 2; ``samples * check_factor`` at most
            :data:`MAX_SAMPLES`).
        max_iterations, tol: SLSQP's iteration limit (per solve) and tolerance (on the cost
            relative to the quintic's).

    Returns:
        A :class:`Trajectory` on the ``samples`` grid from t = 0 with an exact ``evaluate``;
        ``info``: ``method`` ``"least_energy"``, ``objective``, ``value`` (the cost by Simpson's
        rule on the check grid: J for copper, N² m² s for rms_torque), ``baseline`` (the
        quintic's of the same duration, likewise), ``saving_percent`` (100 (1 − value /
        baseline)), ``per_joint`` (copper loss [J] or RMS torque [N m] per joint),
        ``baseline_per_joint``, ``limit_usage`` ({limit: {joint: the largest |x| / limit on
        the check grid, NaN where not limited}}, the limits of :data:`LIMITS`),
        ``baseline_limit_usage`` (the quintic's: above 1 where the quintic itself exceeds a
        limit), ``active_limits`` (a list of (limit, joint, t) where the usage at the samples
        reaches 1 − margin, t where it is largest), ``iterations`` (SLSQP's, all solves),
        ``converged``, ``message``, ``unknowns``, ``end_acceleration``, ``duration``. A solve
        that SLSQP stops unconverged (its iteration limit, a failed line search) with a motion
        within the limits returns it with ``converged`` False and a RuntimeWarning.

    Raises:
        ModelError: a bad argument (named), a floating-base model, a joint without motor data
            for ``"copper"``, ``start`` or ``goal`` outside the position limits.
        SolverError: no motion within the limits was found (names the limit, joint and time
            most exceeded), or the limits are exceeded between samples after refinement.
    """
    problem, options = _setup(
        model,
        start,
        goal,
        duration,
        objective=objective,
        knots=knots,
        samples=samples,
        end_acceleration=end_acceleration,
        max_velocity=max_velocity,
        max_torque=max_torque,
        motors=motors,
        weights=weights,
        margin=margin,
        check_factor=check_factor,
        max_iterations=max_iterations,
        tol=tol,
    )
    return _solve(problem, **options)


def _setup(model, start, goal, duration, **kw) -> tuple[_Problem, dict]:
    """least_energy's checked arguments: the problem (on a two-sample grid) and the solve's
    options."""
    who = "least_energy"
    objective, knots, samples = kw["objective"], kw["knots"], kw["samples"]
    end_acceleration, motors, weights = kw["end_acceleration"], kw["motors"], kw["weights"]
    margin, check_factor = kw["margin"], kw["check_factor"]
    max_iterations, tol = kw["max_iterations"], kw["tol"]
    objective = _checks.choice(who, "objective", objective, ("copper", "rms_torque"))
    n = _check_model(who, model, objective)
    start = _configuration(who, "start", start, model, n)
    goal = _configuration(who, "goal", goal, model, n)
    duration = _checks.number(who, "duration", duration, lo=0.0, lo_open=True)
    knots = _checks.integer(who, "knots", knots, lo=0, hi=200)
    samples = _checks.integer(who, "samples", samples, lo=11, hi=MAX_SAMPLES)
    if samples % 2 == 0:
        raise _core.ModelError(f"{who}: samples must be odd (Simpson's rule), got {samples}")
    end = _checks.choice(who, "end_acceleration", end_acceleration, ("free", "zero"))
    motors = _checks.flag(who, "motors", motors)
    margin = _checks.number(who, "margin", margin, lo=0.0, hi=0.49)
    check_factor = _checks.integer(who, "check_factor", check_factor, lo=2, hi=100)
    if samples * check_factor > MAX_SAMPLES:
        raise _core.ModelError(
            f"{who}: samples * check_factor = {samples * check_factor} exceeds {MAX_SAMPLES}"
        )
    max_iterations = _checks.integer(who, "max_iterations", max_iterations, lo=1, hi=100_000)
    tol = _checks.number(who, "tol", tol, lo=0.0, lo_open=True, hi=1.0)
    if end == "zero" and knots == 0:
        raise _core.ModelError(f"{who}: knots must be >= 1 with end_acceleration='zero'")
    unknowns = n * (knots + (2 if end == "free" else 0))
    if samples * n * unknowns > MAX_ENTRIES:
        raise _core.ModelError(
            f"{who}: samples * joints * unknowns = {samples} * {n} * {unknowns} exceeds "
            f"{MAX_ENTRIES:.0e} (the torque derivatives held per iteration): fewer samples or "
            "knots"
        )
    w = _weights(who, weights, n, model)
    drives = _drives(model, n)
    limits = _limits(who, model, n, drives, kw["max_velocity"], kw["max_torque"], motors)
    basis = _Basis(knots, 2 if end == "free" else 3)
    problem = _Problem(model, start, goal, duration, basis, drives, objective, w, limits)
    options = dict(
        samples=samples,
        margin=margin,
        check_factor=check_factor,
        max_iterations=max_iterations,
        tol=tol,
        end=end,
    )
    return problem, options


def _weights(who: str, weights, n: int, model) -> np.ndarray:
    if weights is None:
        return np.ones(n)
    a = _checks.array(who, "weights", weights, finite=True)
    if a.shape != (n,):
        raise _core.ModelError(f"{who}: weights must have shape ({n},), got {a.shape}")
    if np.any(a <= 0.0):
        k = int(np.argmax(a <= 0.0))
        raise _core.ModelError(
            f"{who}: weights[{k}] = {a[k]:g} (joint {model.dof_names[k]!r}) must be > 0"
        )
    return a


def _simpson(u: np.ndarray, duration: float) -> np.ndarray:
    """w with w @ y = composite Simpson's rule ∫ y dt over an odd number of uniform samples."""
    h = (u[1] - u[0]) * duration
    w = np.full(len(u), 2.0)
    w[1::2] = 4.0
    w[[0, -1]] = 1.0
    return w * h / 3.0


def _usage(problem: _Problem, p: np.ndarray, u: np.ndarray | None = None) -> dict:
    """{limit: (rows, n) |x| / limit (NaN where not limited)} on the problem's grid, or on
    ``u`` (the problem's grid restored after)."""
    saved = (problem.u, problem.w)
    if u is not None:
        problem.set_grid(u, np.zeros(len(u)))
    out = {}
    try:
        for name, x, limit, _ in problem.families(problem.state(p, derivatives=False)):
            limited = np.isfinite(limit) & (limit > 0)
            with np.errstate(divide="ignore", invalid="ignore"):
                out[name] = np.where(limited, np.abs(x) / np.where(limited, limit, 1.0), np.nan)
    finally:
        if u is not None:
            problem.set_grid(*saved)
    return out


def _worst(usage: dict) -> np.ndarray:
    """(rows,) the largest usage over the limits and joints at each sample (0: none)."""
    stacked = np.stack([np.nan_to_num(r, nan=0.0) for r in usage.values()])
    return stacked.max(axis=(0, 2))


def _exceeded(problem: _Problem, p: np.ndarray, fine: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """The check grid's instants (not yet constrained) where a limit is exceeded."""
    worst = _worst(_usage(problem, p, fine))
    return np.setdiff1d(fine[worst > 1.0], grid)


def _solve(
    problem: _Problem, *, samples, margin, check_factor, max_iterations, tol, end
) -> Trajectory:
    """SLSQP from the quintic with every limit's side the motion leans to at the samples (the
    quintic is no guide to which limits bind); after each solve the check grid's instants over
    a limit join the samples (with the sides used to at least :data:`SCREEN` there), and so do
    the sides the motion now uses that much, and the solve resumes while a side left out is
    exceeded (at most :data:`ROUNDS` solves)."""
    u = np.linspace(0.0, 1.0, samples)
    w = _simpson(u, problem.duration)
    problem.set_grid(u, w)
    p = np.zeros(problem.n * problem.k)
    try:
        with np.errstate(all="ignore"):
            baseline = problem.value(p)
    except _Diverged:
        baseline = np.inf
    if not np.isfinite(baseline):
        raise _core.ModelError(
            f"least_energy: the quintic move's cost is not finite (duration = "
            f"{problem.duration:g} s too short for the distance, or coordinates too large)"
        )
    problem.scale = baseline if baseline > 0.0 else 1.0
    # unknowns z = Lᵀ p, L L' the cost's Gauss–Newton Hessian at the quintic: SLSQP's
    # quasi-Newton Hessian starts as the identity, which is then about right
    back = _preconditioner(problem, p)
    iterations = 0
    fine = np.linspace(0.0, 1.0, (samples - 1) * check_factor + 1)
    grid, mask = u, problem.screen(p, 0.0)
    for _ in range(ROUNDS):
        problem.mask = mask
        p, result = _slsqp(problem, back, p, margin, max_iterations, tol)
        iterations += int(result.nit)
        if result.status not in (0, 9) and _worst(_usage(problem, p)).max() > 1.0:
            break
        left_out = _left_out(problem, p, mask, margin)
        used = problem.screen(p, SCREEN)
        mask = {k: mask[k] | used[k] for k in mask}
        over = _exceeded(problem, p, fine, grid)
        if over.size == 0 and not left_out:
            break
        if over.size:
            grid = np.union1d(grid, over)
            rows = np.searchsorted(grid, problem.u)
            problem.set_grid(grid, _embed(u, w, grid))
            used = problem.screen(p, SCREEN)
            for k in mask:
                old, mask[k] = mask[k], used[k]
                mask[k][rows] |= old
    problem.mask = None
    problem.set_grid(u, w)
    return _result(problem, p, result, iterations, fine, margin, end)


def _slsqp(problem: _Problem, back: np.ndarray, p: np.ndarray, margin, max_iterations, tol):
    """One SLSQP solve from ``p`` in the scaled unknowns z = back⁻¹ p on the problem's grid and
    mask: (p, scipy's result)."""
    constraint = {
        "type": "ineq",
        "fun": lambda z: problem.constraints(back @ z, margin),
        "jac": lambda z: problem.constraints(back @ z, margin, jacobian=True) @ back,
    }
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        result = _minimize(
            lambda z: problem.value(back @ z),
            np.linalg.solve(back, p),
            jac=lambda z: back.T @ problem.gradient(back @ z),
            method="SLSQP",
            constraints=[constraint],
            options={"maxiter": max_iterations, "ftol": tol},
        )
    return back @ np.asarray(result.x, dtype=float), result


def _preconditioner(problem: _Problem, p: np.ndarray) -> np.ndarray:
    """L⁻ᵀ, L L' = the Gauss–Newton Hessian 2 Σ w c (dx/dp)ᵀ (dx/dp) of the scaled cost at
    ``p`` (x the motor or joint torques), with a ridge of 1e-9 of its largest diagonal entry."""
    s = problem.state(p)
    _, c = problem.cost_terms(s)
    dx = s["dT"] if problem.objective == "copper" else s["dtau"]
    weighted = dx * np.sqrt(2.0 * problem.w[:, None, None] * c[None, :, None] / problem.scale)
    flat = weighted.reshape(-1, dx.shape[-1])
    hessian = flat.T @ flat
    hessian += np.eye(len(p)) * 1e-9 * max(float(np.max(np.diag(hessian))), 1e-300)
    lower = np.linalg.cholesky(hessian)
    return np.linalg.inv(lower).T


def _minimize(*args, **kw):
    """scipy's minimize, a step to a non-finite motion a SolverError."""
    from scipy.optimize import minimize

    try:
        return minimize(*args, **kw)
    except _Diverged:
        raise _core.SolverError(
            "least_energy: the solve diverged (a step to a non-finite motion); try more "
            "samples, fewer knots or a longer duration"
        ) from None


def _left_out(problem: _Problem, p: np.ndarray, mask: dict, margin: float) -> bool:
    """Whether a side the solve left out is used beyond 1 − margin at ``p``."""
    over = problem.screen(p, 1.0 - margin + 1e-9)
    return any(np.any(over[k] & ~mask[k]) for k in mask)


def _embed(u: np.ndarray, w: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """The weights ``w`` of the samples ``u`` on ``grid`` (which holds them), 0 elsewhere."""
    out = np.zeros(len(grid))
    out[np.searchsorted(grid, u)] = w
    return out


def _per_joint(problem: _Problem, p: np.ndarray, u: np.ndarray) -> tuple[float, np.ndarray]:
    """(the cost, each joint's copper loss [J] or RMS torque [N m]) by Simpson's rule on the
    samples ``u`` (the check grid: the gear's efficiency switches where a joint reverses, a
    jump of the integrand that a finer grid resolves better; the problem's grid restored)."""
    saved = (problem.u, problem.w)
    problem.set_grid(u, _simpson(u, problem.duration))
    try:
        x, c = problem.cost_terms(problem.state(p, derivatives=False))
        squares = (problem.w @ (x * x)) * c
    finally:
        problem.set_grid(*saved)
    if problem.objective == "copper":
        return float(np.sum(squares)), squares
    return float(np.sum(squares)), np.sqrt(squares / c / problem.duration)


def _active(problem: _Problem, p: np.ndarray, margin: float) -> list:
    """(limit, joint, t) where a limit's usage at the samples reaches 1 − margin (to 1e-6)."""
    names, out = list(problem.model.dof_names), []
    for name, r in _usage(problem, p).items():
        for j in range(problem.n):
            col = r[:, j]
            if np.isfinite(col).any() and np.nanmax(col) >= 1.0 - margin - 1e-6:
                i = int(np.nanargmax(col))
                out.append((name, names[j], float(problem.u[i] * problem.duration)))
    return out


def _largest(usage: dict) -> dict:
    """{limit: (n,) the largest usage over the samples, NaN where not limited}."""
    out = {}
    for k, r in usage.items():
        seen = np.isfinite(r).any(axis=0)
        out[k] = np.where(seen, np.nanmax(np.where(np.isnan(r), -np.inf, r), 0), np.nan)
    return out


def _result(problem, p, result, iterations, fine, margin, end):
    names = list(problem.model.dof_names)
    value, per_joint = _per_joint(problem, p, fine)
    baseline, baseline_per_joint = _per_joint(problem, np.zeros_like(p), fine)
    check = _usage(problem, p, fine)
    limit_usage = _largest(check)
    baseline_usage = _largest(_usage(problem, np.zeros_like(p), fine))
    _refuse(result, p, limit_usage, check, fine, problem, names)
    s = problem.state(p, derivatives=False)
    coefficients = p.copy()

    def evaluate(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        u = np.clip(np.asarray(t, dtype=float) / problem.duration, 0.0, 1.0)
        return problem.motion(coefficients, u)

    info = {
        "method": "least_energy",
        "objective": problem.objective,
        "value": value,
        "baseline": baseline,
        "saving_percent": 100.0 * (1.0 - value / baseline) if baseline > 0.0 else 0.0,
        "per_joint": dict(zip(names, per_joint.tolist(), strict=True)),
        "baseline_per_joint": dict(zip(names, baseline_per_joint.tolist(), strict=True)),
        "limit_usage": {
            k: dict(zip(names, v.tolist(), strict=True)) for k, v in limit_usage.items()
        },
        "baseline_limit_usage": {
            k: dict(zip(names, v.tolist(), strict=True)) for k, v in baseline_usage.items()
        },
        "active_limits": _active(problem, p, margin),
        "iterations": iterations,
        "converged": bool(result.status == 0),
        "message": str(result.message),
        "unknowns": int(p.size),
        "end_acceleration": end,
        "duration": float(problem.duration),
    }
    if result.status != 0:
        warnings.warn(
            f"least_energy: SLSQP stopped unconverged ({result.message}, {iterations} "
            "iterations); the motion respects the limits but may not be the least-energy one",
            RuntimeWarning,
            stacklevel=3,
        )
    t = problem.u * problem.duration
    return Trajectory(t, s["q"], s["qd"], s["qdd"], names=names, info=info, evaluate=evaluate)


def _refuse(result, p, limit_usage, check, fine, problem, names) -> None:
    """SolverError when a limit is exceeded on the check grid (naming the limit most exceeded,
    its joint and the time)."""
    worst_name, worst_j, worst = None, 0, 0.0
    for k, v in limit_usage.items():
        if np.isfinite(v).any() and np.nanmax(v) > worst:
            worst_name, worst_j, worst = k, int(np.nanargmax(v)), float(np.nanmax(v))
    if worst <= 1.0:
        return
    i = int(np.nanargmax(check[worst_name][:, worst_j]))
    raise _core.SolverError(
        f"least_energy: no motion within the limits found in {problem.duration:g} s (SLSQP: "
        f"{result.message}); the most exceeded limit is {worst_name} of joint "
        f"{names[worst_j]!r} at t = {fine[i] * problem.duration:.4g} s ({worst:.4g} x the limit)"
    )
