"""The time-optimal timing of a geometric path (:func:`time_optimal`) and the shortest repeated
cycle within the motors' thermal limits (:func:`shortest_cycle`).

**Formulation** (TOPP-RA: Pham & Pham, IEEE T-RO 2018). Along a :class:`~armdyn.motion.Path`
``q(s)``, s in [0, 1], a timing ``s(t)`` gives ``q̇ = q' ṡ`` and ``q̈ = q' s̈ + q'' ṡ²``; with
``x = ṡ²`` and ``u = s̈`` on a grid ``s_0 = 0 < … < s_N = 1`` (u constant on each interval, so
``x_{i+1} = x_i + 2 Δ_i u_i``), every limit is a constraint on ``(u_i, x_i)`` at the grid
points (collocation):

- joint speed ``|q'_j| ṡ ≤ v_j``: a bound on x;
- joint acceleration ``|q'_j u + q''_j x| ≤ α_j``;
- joint torque ``τ = a(s) u + b(s) x + d(s) √x + c(s)`` within ``±τ_max``, from
  ``armdyn.inverse_dynamics`` (batched over the grid): ``c = ID(q, 0, 0)`` (gravity, springs
  and the other force elements, evaluated at t = 0), ``a = ID(q, 0, q') − c``, and at ``u = 0``,
  ``ṡ = k`` (``q̇ = k q'``, ``q̈ = k² q''``) the rest ``r_k = ID(q, k q', k² q'') − c`` less the
  actuators' friction is ``b k² + d k``: the Coriolis and centrifugal terms are quadratic in
  q̇, and the dampers (joint spring-dampers' and URDF ``<dynamics damping>``, viscous joint
  friction, point-to-point dampers: forces linear in q̇ at fixed q) linear, so ``b = r_2/2 −
  r_1`` and ``d = 2 r_1 − r_2/2`` (d = 0 without dampers). A third speed checks it (``r_3 = 9 b +
  3 d`` to 1e-9 of the torques' scale): other velocity-dependent forces (a joint's Coulomb
  friction, gear contact) are refused;
- with actuators carrying an :class:`armdyn.Motor` (``motors=True``): each motor's speed
  ``|N q̇| ≤`` its maximum (else no-load) speed, its peak torque ``|T| ≤ T_peak`` and its
  speed–torque envelope ``|T + T0 ω/ω0| ≤ T0`` (:func:`armdyn.sizing.motor.motor_envelope`), with
  the motor torque of :mod:`armdyn.actuators`: ``T = J N q̈ + b N q̇ + c tanh(N q̇ / v_s) +
  τ_gear/(N η)`` while the gear drives the load (``τ_gear q̇ ≥ 0``), ``τ_gear η / N`` when the load
  drives it, ``τ_gear = τ − N T_rot`` (the link's share, exactly ``a u + b x + c`` without the
  rotor).

**What is exact and what is conservative.** Joint speed and acceleration limits are exact at
the grid points, and so are the joint torque limits without speed terms. The others are not
linear in (u, x): the speed terms (the dampers' ``d ṡ``, the actuators' viscous ``b ω``, the
envelope's ``T0 ω/ω0``) go as ``ṡ = √x``, the gear's efficiency switches branch with the sign of
the power, the Coulomb term is a tanh. They are replaced by linear constraints that imply them
(conservative): a term ``D √x`` by its tangent at a reference x where it tightens the constraint
(D > 0: √x is concave, the tangent lies above), and where it relaxes it (D < 0: a damper
helping to brake, ``D √x`` convex) by the secants of its piecewise-linear interpolant on the
stage's speed bound [0, X] (X = 1e20 where nothing else bounds x), at nodes dense around the
reference x (1 ± 1e-3, 1 ± 1e-2, ...; one row per secant: the interpolant of a convex function
lies above it and is the largest of its pieces); the efficiency's two branches by both linear
pieces on the side where their maximum (minimum) is the true value and by the regenerating
piece alone on the other (exact wherever that branch holds), and at the path's ends, at rest,
by the motoring piece on both sides (holding takes ``τ_gear/(N η)`` whatever its sign); the
Coulomb term by its saturated value ``±c`` on the side where it hurts and 0 on the other (0 at
the ends: at rest it is exactly 0). The first reference x is, per stage, where the tightening
terms take half the slack at rest (at most the stage's bound; if that solve finds no timing, it
is retried from references 100× lower, up to three times). The references are then moved to
the new solution and the problem solved again (``envelope_iterations``, until the duration
stops falling by more than 1e-9 relative): every iterate satisfies the true constraints at the
grid points (each linear row is exact at its reference, so the previous solution stays
feasible), the fastest is returned, and at convergence the speed terms are exact where they
bind (a tangent touches √x at its own point, a secant's nodes hold it): a damped inertia at its
torque limit meets it to 1e-6 at every sample but the switch's (tests/motion/test_timing.py).
Joint-torque rows get the same treatment for the dampers and the actuators' friction (inverse
dynamics includes both); with an actuator the dampers' torque is part of the gear's load.

**Why toppra.** The ``toppra`` package (0.6) computes the controllable sets: the backward pass
of TOPP-RA, 2N two-variable LPs by its Cython Seidel solver, the bulk of the solve; it is
maintained, peer-reviewed, and measured faster than a general convex solver on the same
discretisation (``python -m benchmarks.timing``: on the UR5 path of the benchmark, 1000
intervals, the whole call takes about a tenth of cvxpy/Clarabel's CPU time, durations equal to
1e-6). Its forward pass is not used: it lowers each x by 1e-8 (absolute; 0.01 % below
x = 1e-4) to stay inside the sets, so its u are not those of its x (a torque error of 5e-10 of
the limit on that path, relatively larger on slow paths whose x is small); the forward pass here
takes the largest u within the stage's constraints and the next controllable set and sets
``x_{i+1} = x_i + 2 Δ u_i`` exactly (closed forms to round-off). Its Seidel solver also caps x
at 1e8: the problem is handed to it in scaled units of x (and u), each row divided by its
largest coefficient.

**The output.** The trajectory's samples are the grid points: ``ṡ_i = √x_i`` and ``s̈_i = u_i``
(the acceleration over the next interval; at the last point 0: the arrival at rest, where the
hold begins, checked against every limit; ``info["qdd_arrival"]`` is the last interval's q̈
there), so the limits hold at every sample as above; between samples they hold to the
discretisation error (refine ``grid``). ``evaluate(t)`` is exact between samples
(``s = s_i + ṡ_i τ + u_i τ²/2``). Duration: ``Σ 2 Δ_i / (ṡ_i + ṡ_{i+1})``. The motion starts and
ends at rest.
"""

from __future__ import annotations

import logging
import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from armdyn import _checks, _core
from armdyn.motion.trajectory import Path, Trajectory

#: grid intervals when ``grid`` is None
DEFAULT_GRID = 1000
#: the most grid intervals (memory: a few (grid, rows) arrays)
MAX_GRID = 100_000
#: an upper bound on x = ṡ² where nothing else bounds it (reached: ModelError)
_X_CAP = 1e20
#: toppra's Seidel solver bounds x at 1e8: its problem is x / scale, scale found by re-solving
_TOPPRA_X = 1e8
#: the most tangent updates of the speed terms (dampers, envelope, viscous friction)
MAX_ITERATIONS = 30
#: stop updating the tangents when the duration changes less than this (relative)
_ITERATION_TOL = 1e-9


# --- arguments --------------------------------------------------------------------------------


def _grid(who: str, grid) -> np.ndarray:
    if grid is None:
        grid = DEFAULT_GRID
    if isinstance(grid, (int, np.integer)) and not isinstance(grid, (bool, np.bool_)):
        n = _checks.integer(who, "grid", grid, lo=2, hi=MAX_GRID)
        return np.linspace(0.0, 1.0, n + 1)
    s = np.asarray(_checks.array(who, "grid", grid, ndim=1, finite=True), dtype=float)
    if len(s) < 3 or len(s) > MAX_GRID + 1 or s[0] != 0.0 or s[-1] != 1.0:
        raise _core.ModelError(
            f"{who}: grid must be an integer (intervals, 2 to {MAX_GRID}) or path parameters "
            f"from 0 to 1 (3 to {MAX_GRID + 1} values), got {len(s)} values from "
            f"{s[0] if len(s) else None} to {s[-1] if len(s) else None}"
        )
    if not np.all(np.diff(s) > 0.0):
        i = int(np.argmin(np.diff(s) > 0.0))
        raise _core.ModelError(f"{who}: grid must be strictly increasing (grid[{i + 1}])")
    return s


def _per_joint(who: str, name: str, value, default, names: list[str]) -> np.ndarray:
    """A positive limit per joint (a scalar for all; inf: no limit); ``default`` when None."""
    n = len(names)
    if value is None:
        v = np.asarray(default, dtype=float) if default is not None else np.full(n, np.inf)
        v = np.where(np.isfinite(v) & (v > 0.0), v, np.inf)  # the model's 0/NaN: no limit
        return np.broadcast_to(v, (n,)).copy()
    v = np.asarray(_checks.array(who, name, value), dtype=float)
    if v.ndim == 0:
        v = np.full(n, float(v))
    if v.shape != (n,):
        raise _core.ModelError(
            f"{who}: {name} must be a number or one per joint ({n}: {names}), got shape {v.shape}"
        )
    bad = np.isnan(v) | ~(v > 0.0)
    if np.any(bad):
        k = int(np.argmax(bad))
        raise _core.ModelError(
            f"{who}: {name}[{k}] (joint {names[k]!r}) must be a positive number (inf: no "
            f"limit), got {v[k]!r}"
        )
    return v


def _model_path(who: str, model, path) -> list[str]:
    if not isinstance(path, Path):
        raise _core.ModelError(
            f"{who}: path must be an armdyn.motion.Path, got {type(path).__name__}"
        )
    coords, dofs = list(model.coord_names), list(model.dof_names)
    if coords != dofs:
        raise _core.ModelError(
            f"{who}: the model must have fixed-base joint coordinates (one rate each); its "
            f"coordinates {coords} differ from its rates {dofs}"
        )
    if path.n_joints != len(coords):
        raise _core.ModelError(
            f"{who}: the path has {path.n_joints} joints, the model {len(coords)} ({coords})"
        )
    if path.names is not None and list(path.names) != coords:
        raise _core.ModelError(
            f"{who}: the path's joints {list(path.names)} are not the model's {coords} (in order)"
        )
    return dofs


# --- the path's coefficients ------------------------------------------------------------------


@dataclass
class _Along:
    """The path and its dynamics on the grid (rows: grid points)."""

    s: np.ndarray
    q: np.ndarray
    d1: np.ndarray
    d2: np.ndarray
    a: np.ndarray  # τ = a u + b x + c + (visc + damp) √x + Coulomb (the actuators' friction)
    b: np.ndarray
    c: np.ndarray
    visc: np.ndarray  # the actuators' viscous friction (joint side)
    damp: np.ndarray  # the other forces linear in the rates (dampers): τ gets damp · ṡ
    coulomb: np.ndarray  # the saturated Coulomb term at each joint (signed)


def _actuators(model) -> list:
    return list(getattr(model, "actuators", None) or [])


def _friction(model, d1: np.ndarray, speed: float) -> np.ndarray:
    """The actuators' reflected friction N² b q̇ + N c tanh(N q̇ / v_s) at q̇ = q' · speed."""
    from armdyn.actuators import coulomb_smoothing

    out = np.zeros_like(d1)
    for act in _actuators(model):
        k, n = int(act.dof), float(act.gear_ratio)
        w = n * d1[:, k] * speed
        out[:, k] += n * (
            float(act.friction_viscous) * w
            + float(act.friction_coulomb) * np.tanh(w / coulomb_smoothing(act))
        )
    return out


def _along(who: str, model, path: Path, s: np.ndarray) -> _Along:
    q, d1, d2 = (np.asarray(x, dtype=float) for x in path.evaluate(s))
    for name, x in (("q", q), ("dq/ds", d1), ("d2q/ds2", d2)):
        _checks.finite_entries(who, f"the path's {name}", x)
    if not np.any(d1 != 0.0):
        raise _core.ModelError(f"{who}: the path does not move (dq/ds is zero everywhere)")
    zero = np.zeros_like(d1)
    rows = len(s)
    speeds = (1.0, 2.0, 3.0)
    try:
        tau = np.asarray(
            _core.inverse_dynamics(
                model,
                np.concatenate([q] * (2 + len(speeds))),
                np.concatenate([zero, zero] + [k * d1 for k in speeds]),
                np.concatenate([zero, d1] + [k * k * d2 for k in speeds]),
            ),
            dtype=float,
        )
    except _core.SolverError as err:  # overflow: name the path point, not the batch's row
        found = re.match(r"row (\d+): ", str(err))
        where = f" at s = {s[int(found.group(1)) % rows]:.6g}" if found else ""
        raise _core.ModelError(
            f"{who}: the inverse dynamics along the path overflows{where} (the path's "
            f"derivatives are too large): {str(err).split(': ', 1)[-1]}"
        ) from None
    c = tau[:rows]
    a = tau[rows : 2 * rows] - c
    # at s̈ = 0 and ṡ = k: τ − c − (the actuators' friction) = b k² + d k (module notes)
    r1, r2, r3 = (
        tau[(2 + i) * rows : (3 + i) * rows] - c - _friction(model, d1, k)
        for i, k in enumerate(speeds)
    )
    b = 0.5 * r2 - r1
    damp = 2.0 * r1 - 0.5 * r2
    # round-off of the differences (no damper at that joint, or not moving): exactly 0
    raw = np.abs(tau[2 * rows : 3 * rows]) + np.abs(tau[3 * rows : 4 * rows]) + np.abs(c)
    damp = np.where(np.abs(damp) <= 1e-12 * raw, 0.0, damp)
    scale = np.max(np.abs(tau)) + 1e-300
    off = np.abs(r3 - 9.0 * b - 3.0 * damp)
    if np.max(off) > 1e-9 * scale:
        i, j = np.unravel_index(int(np.argmax(off)), off.shape)
        raise _core.ModelError(
            f"{who}: the model has velocity-dependent forces that are neither linear in the "
            "rates (dampers) nor the actuators' friction (e.g. Coulomb friction of a joint, "
            f"gear contact; at s = {s[i]:.6g}, joint {list(model.dof_names)[j]!r}): the joint "
            "torques are not a(s) s̈ + b(s) ṡ² + d(s) ṡ + c(s), which the timing needs"
        )
    visc = np.zeros_like(d1)
    coulomb = np.zeros_like(d1)
    for act in _actuators(model):
        k, n = int(act.dof), float(act.gear_ratio)
        visc[:, k] += n * n * float(act.friction_viscous) * d1[:, k]
        coulomb[:, k] += abs(n) * float(act.friction_coulomb) * np.sign(d1[:, k])
    coulomb[[0, -1]] = 0.0  # at rest at both ends: tanh(0) = 0
    return _Along(s, q, d1, d2, a, b, c, visc, damp, coulomb)


# --- the constraint rows ----------------------------------------------------------------------


@dataclass
class _Rows:
    """Rows ``A u + B x + C + D √x ≤ 0`` per grid point (columns: rows), each a side of a
    limited quantity: ``label`` (what), ``limit`` (its bound), ``side`` (+1 upper, -1 lower)."""

    stages: int
    cols: list = field(default_factory=list)

    def add(self, label: str, limit: float, side: int, a, b, c, d=0.0, active=None) -> None:
        """The row ``side · (a u + b x + c + d √x) ≤ limit`` at the grid points ``active``."""
        n = self.stages
        a, b, c, d = (np.broadcast_to(np.asarray(x, dtype=float), (n,)) for x in (a, b, c, d))
        row = [side * a, side * b, side * c - limit, side * d]
        if active is not None:
            off = ~np.asarray(active, dtype=bool)
            row = [np.where(off, 0.0, x) for x in row]
            row[2] = np.where(off, -1.0, row[2])
        self.cols.append((label, float(limit), side, *row))

    def pair(self, label: str, limit: float, a, b, c, d=0.0, extra=0.0) -> None:
        """Both sides of ``|a u + b x + c + d √x + e| ≤ limit``, e within [min(0, extra),
        max(0, extra)] (each side takes its worst)."""
        if not np.isfinite(limit):
            return
        extra = np.asarray(extra, dtype=float)
        self.add(label, limit, 1, a, b, c + np.maximum(extra, 0.0), d)
        self.add(label, limit, -1, a, b, c + np.minimum(extra, 0.0), d)

    def arrays(self):
        if not self.cols:
            return tuple(np.zeros((self.stages, 0)) for _ in range(4))
        return tuple(np.stack([c[k] for c in self.cols], axis=1) for k in (3, 4, 5, 6))


@dataclass
class _Problem:
    along: _Along
    rows: _Rows
    xmax: np.ndarray  # the bound on x per grid point
    xmax_label: list  # what sets it


def _speed_bound(p: _Problem, speed: np.ndarray, limit: float, label: str) -> None:
    """x ≤ (limit / |speed|)² where ``speed`` (per grid point) is the rate at ṡ = 1."""
    if not np.isfinite(limit):
        return
    with np.errstate(divide="ignore"):
        bound = np.where(speed != 0.0, (limit / np.abs(speed)) ** 2, np.inf)
    tighter = bound < p.xmax
    p.xmax = np.where(tighter, bound, p.xmax)
    for i in np.flatnonzero(tighter):
        p.xmax_label[i] = label


def _motor_rows(p: _Problem, act) -> None:
    """The motor's speed, peak torque and envelope constraints of one actuator (module notes)."""
    from armdyn.sizing.motor import motor_envelope, speed_limit

    motor = act.motor
    al, k = p.along, int(act.dof)
    name = str(act.joint)
    n, eta, j = float(act.gear_ratio), float(act.efficiency), float(act.rotor_inertia)
    d1, d2 = al.d1[:, k], al.d2[:, k]
    w_max = float(
        speed_limit(
            np.nan if motor.max_speed is None else motor.max_speed,
            np.nan if motor.no_load_speed is None else motor.no_load_speed,
        )[0]
    )
    _speed_bound(p, n * d1, w_max if np.isfinite(w_max) else np.inf, f"motor speed {name!r}")
    # the gear's load torque τ_gear = g_u u + g_x x + g_c (the rotor's N² J taken off)
    g_u, g_x, g_c = al.a[:, k] - n * n * j * d1, al.b[:, k] - n * n * j * d2, al.c[:, k]
    g_d = al.damp[:, k]  # and the dampers' g_d √x
    sigma = np.sign(d1)
    convex, zero = sigma * n > 0.0, sigma == 0.0
    concave = ~convex & ~zero
    # at rest (q̇ = 0: the path's ends, where ṡ = 0) the motoring branch holds whatever the
    # torque's sign (holding takes τ_gear / (N η)): its piece on both sides there
    rest = zero.copy()
    rest[[0, -1]] = True
    visc = float(act.friction_viscous) * n * d1
    coul = float(act.friction_coulomb) * np.sign(n * d1)
    coul[[0, -1]] = 0.0  # at rest at both ends
    t0, w0 = motor_envelope(motor)
    limits = []
    if motor.peak_torque is not None:
        limits.append((f"motor peak torque {name!r}", float(motor.peak_torque), 0.0))
    if np.isfinite(t0) and np.isfinite(w0) and t0 > 0.0 and w0 > 0.0:
        limits.append((f"motor envelope {name!r}", float(t0), t0 / w0 * n * d1))
    for label, limit, env in limits:
        for piece, up, lo in (
            (1.0 / (n * eta), convex | rest, concave | rest),
            (eta / n, ~zero, ~zero),
        ):
            a = j * n * d1 + piece * g_u
            b = j * n * d2 + piece * g_x
            c = piece * g_c
            d = visc + env + piece * g_d
            p.rows.add(label, limit, 1, a, b, c + np.maximum(coul, 0.0), d, active=up)
            p.rows.add(label, limit, -1, a, b, c + np.minimum(coul, 0.0), d, active=lo)


def _problem(model, along: _Along, names, v_max, a_max, tau_max, motors: bool) -> _Problem:
    stages = len(along.s)
    p = _Problem(along, _Rows(stages), np.full(stages, _X_CAP), ["nothing"] * stages)
    for k, name in enumerate(names):
        _speed_bound(p, along.d1[:, k], v_max[k], f"velocity {name!r}")
        p.rows.pair(f"acceleration {name!r}", a_max[k], along.d1[:, k], along.d2[:, k], 0.0)
        p.rows.pair(
            f"torque {name!r}",
            tau_max[k],
            along.a[:, k],
            along.b[:, k],
            along.c[:, k],
            along.visc[:, k] + along.damp[:, k],
            along.coulomb[:, k],
        )
    if motors:
        for act in _actuators(model):
            if getattr(act, "motor", None) is not None:
                _motor_rows(p, act)
    return p


#: where the secants of the √x terms with D < 0 meet √x, as multiples of the reference x: dense
#: around it (1 ± 1e-3: the interpolant is within 1.3e-7 √x of √x there), then the stage's
#: bound on x (module notes)
_SECANT_NODES = (0.0, 0.5, 0.9, 0.99, 0.999, 1.0, 1.001, 1.01, 1.1, 1.5, 2.0, 4.0)


def _secants(x_ref: np.ndarray, xmax: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per stage, the lines ``k x + m`` (K columns) of √x's piecewise-linear interpolant at the
    nodes ``x_ref · _SECANT_NODES`` below the stage's bound X, and X: for D < 0 the interpolant
    of D √x (convex) lies above it on [0, X] and is the largest of its lines, so the rows
    ``A u + B x + C + D (k x + m) ≤ 0``, one per line, imply the true one, exactly at the
    nodes. Where nodes coincide (clipped at X) the stage's first line is repeated."""
    xs = x_ref[:, None] * np.asarray(_SECANT_NODES)[None, :]
    xs = np.concatenate([np.minimum(xs, xmax[:, None]), xmax[:, None]], axis=1)
    x0, x1 = xs[:, :-1], xs[:, 1:]
    gap = x1 > x0 * (1.0 + 1e-12)
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.where(gap, 1.0 / (np.sqrt(x1) + np.sqrt(x0)), np.nan)
    m = np.sqrt(x0) - k * x0
    # a node repeated (clipped at X): use a real line of the stage instead (the first one)
    first = np.argmax(gap, axis=1)
    rows = np.arange(len(x_ref))
    k = np.where(gap, k, k[rows, first][:, None])
    m = np.where(gap, m, m[rows, first][:, None])
    return np.nan_to_num(k), np.nan_to_num(m)  # X = 0: x = 0 there, the term vanishes


def _linearised(p: _Problem, x_ref: np.ndarray):
    """(A, B, C, cols) with the √x terms replaced by linear bounds (module notes): the tangent
    at ``x_ref`` where D > 0; where D < 0 the secants of :func:`_secants` on [0, X] (X the
    stage's bound on x), one row each: rows of the same constraint, ``cols`` names the
    constraint (its column of ``p.rows``) of each row."""
    a, b, c, d = p.rows.arrays()
    d[[0, -1]] = 0.0  # x = 0 at both ends: the √x terms vanish there exactly
    cols = np.arange(a.shape[1])
    if not np.any(d):
        return a, b, c, cols
    b, c = b.copy(), c.copy()
    xr = np.maximum(x_ref, 1e-6 * max(float(np.max(x_ref)), 1e-300))
    up = d > 0.0
    b += np.where(up, d / (2.0 * np.sqrt(xr[:, None])), 0.0)
    c += np.where(up, d * np.sqrt(xr[:, None]) / 2.0, 0.0)
    down = d < 0.0
    if not np.any(down):
        return a, b, c, cols
    k, m = _secants(np.minimum(xr, p.xmax), p.xmax)
    neg = np.flatnonzero(np.any(down, axis=0))
    out_a, out_b, out_c, out_cols = [a], [b], [c], [cols]
    dn = np.where(down[:, neg], d[:, neg], 0.0)
    b_neg, c_neg = b[:, neg], c[:, neg]  # copies (fancy indexing)
    for line in range(k.shape[1]):
        bb = b_neg + dn * k[:, line, None]
        cc = c_neg + dn * m[:, line, None]
        if line == 0:  # the first line replaces the term in the row itself
            b[:, neg], c[:, neg] = bb, cc
            continue
        out_a.append(a[:, neg])
        out_b.append(bb)
        out_c.append(cc)
        out_cols.append(neg)
    return (
        np.concatenate(out_a, axis=1),
        np.concatenate(out_b, axis=1),
        np.concatenate(out_c, axis=1),
        np.concatenate(out_cols),
    )


# --- the solve --------------------------------------------------------------------------------


def _controllable(s: np.ndarray, a, b, c, xmax: np.ndarray) -> np.ndarray:
    """toppra's controllable sets K (N+1, 2) of x for rows a u + b x + c ≤ 0, 0 ≤ x ≤ xmax,
    ending at rest (NaN from the stage on where none is)."""
    import toppra.algorithm as algo
    from toppra.constraint import DiscretizationType, LinearConstraint

    m = a.shape[1]

    class _Stagewise(LinearConstraint):
        def __init__(self):
            super().__init__()
            self.identical = True
            self.set_discretization_type(DiscretizationType.Collocation)

        def compute_constraint_params(self, path, gridpoints, *args, **kwargs):
            xbound = np.stack([np.zeros(len(xmax)), xmax], axis=1)
            if m == 0:
                return None, None, None, None, None, None, xbound
            return a, b, c, np.eye(m), np.zeros(m), None, xbound

    class _Interval:
        path_interval = np.array([0.0, 1.0])
        dof = 1

    log = logging.getLogger("toppra")
    level = log.level
    log.setLevel(logging.ERROR)  # its warnings of an empty set: this module reports them
    try:
        solver = algo.TOPPRA([_Stagewise()], _Interval(), gridpoints=s, solver_wrapper="seidel")
        return np.asarray(solver.compute_controllable_sets(0.0, 0.0), dtype=float)
    finally:
        log.setLevel(level)


def _scaled_controllable(s: np.ndarray, a, b, c, xmax: np.ndarray) -> np.ndarray:
    """:func:`_controllable` in units of x that keep toppra's sets between 1e-2 and its cap
    (``_TOPPRA_X``): with x = scale · x̃ (and u = scale · ũ) the rows are (a scale) ũ +
    (b scale) x̃ + c ≤ 0."""
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.abs(c) / np.abs(a)  # the accelerations the rows allow, a first guess of x
    ratio = ratio[np.isfinite(ratio) & (ratio > 0.0)]
    scale = float(np.clip(np.median(ratio), 1e-12, 1e12)) if len(ratio) else 1.0
    for _ in range(6):
        sa, sb = a * scale, b * scale
        norm = np.maximum(np.maximum(np.abs(sa), np.abs(sb)), np.abs(c))
        norm = np.where(norm > 0.0, norm, 1.0)  # each row divided by its largest coefficient
        k = _controllable(s, sa / norm, sb / norm, c / norm, np.minimum(xmax / scale, _TOPPRA_X))
        top = float(np.max(k[:, 1])) if not np.isnan(k).any() else np.nan
        if top >= 0.5 * _TOPPRA_X and scale * top < _X_CAP:
            scale *= 1e6
        elif 0.0 < top < 1e-2:
            scale *= top
        else:
            break
    return k * scale


def _u_range(a: np.ndarray, r: np.ndarray) -> tuple[float, float]:
    """The interval of u with a u + r ≤ 0 for every row (empty: lo > hi)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        q = -r / a
    hi = float(np.min(q[a > 0.0], initial=np.inf))
    lo = float(np.max(q[a < 0.0], initial=-np.inf))
    if np.any((a == 0.0) & (r > 0.0)):
        return np.inf, -np.inf
    return lo, hi


def _forward(s, a, b, c, k_sets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The greedy forward pass: from rest, at each stage the largest u within the stage's rows
    and the next controllable set; x_{i+1} = x_i + 2 Δ u_i exactly, x_N = 0."""
    n = len(s) - 1
    delta = np.diff(s)
    x, u = np.zeros(n + 1), np.zeros(n + 1)
    for i in range(n):
        hi = _u_range(a[i], b[i] * x[i] + c[i])[1]
        u_next = (k_sets[i + 1, 1] - x[i]) / (2.0 * delta[i])
        u[i] = min(hi, u_next) if i < n - 1 else -x[i] / (2.0 * delta[i])
        x[i + 1] = max(x[i] + 2.0 * delta[i] * u[i], 0.0)
    x[n] = 0.0  # u[n] = 0: at rest after the end (the hold)
    return x, u


def _violation(a, b, c, x, u) -> np.ndarray:
    """Each row's value a u + b x + c at the samples (> 0: violated)."""
    return a * u[:, None] + b * x[:, None] + c


def _fail(who: str, p: _Problem, i: int, why: str):
    """SolverError naming the grid point and what cannot be met there at rest: the failing
    point ``i`` or the next one, whichever exceeds a limit at rest the more (the backward pass
    fails one point before the end pose it cannot hold)."""
    al = p.along
    c = p.rows.arrays()[2]
    limits = np.array([max(col[1], 1e-300) for col in p.rows.cols])
    worst, excess = None, 0.0
    for k in range(i, min(i + 2, len(al.s))):
        if c.shape[1]:
            r = int(np.argmax(c[k] / limits))
            if c[k, r] / limits[r] > excess:
                worst, excess, i = r, c[k, r] / limits[r], k
    where = f"at s = {al.s[i]:.6g} (grid point {i}, q = {np.array2string(al.q[i], precision=4)})"
    if worst is not None:
        label, limit, side = p.rows.cols[worst][:3]
        value = side * (c[i, worst] + limit)
        return _core.SolverError(
            f"{who}: no feasible timing: {where} the {label} at rest is {value:.6g}, beyond "
            f"its limit ±{limit:.6g} ({why})"
        )
    return _core.SolverError(f"{who}: no feasible timing {where}: {why}")


def _solve(who: str, p: _Problem, x_ref: np.ndarray):
    s = p.along.s
    a, b, c, _ = lin = _linearised(p, x_ref)
    k_sets = _scaled_controllable(s, a, b, c, p.xmax)
    bad = np.flatnonzero(np.isnan(k_sets).any(axis=1))
    if len(bad):
        raise _fail(who, p, int(bad[-1]), "the limits admit no path speed from there to the end")
    if k_sets[0, 0] > 1e-9 * k_sets[0, 1]:  # above round-off
        raise _fail(who, p, 0, "the path cannot start from rest within the limits")
    hold = p.rows.arrays()[2][-1]  # the last sample: at rest, s̈ = 0 (the hold)
    if np.any(hold > 1e-12 * np.array([col[1] for col in p.rows.cols])):
        raise _fail(who, p, len(s) - 1, "the end pose cannot be held at rest within the limits")
    x, u = _forward(s, a, b, c, k_sets)
    if np.max(x) >= 0.5 * _X_CAP:
        i = int(np.argmax(x))
        raise _core.ModelError(
            f"{who}: nothing limits the path speed at s = {s[i]:.6g}: give max_velocity, "
            "max_acceleration or max_torque (or a model with limits) for the joints that move"
        )
    return x, u, lin


def _first_reference(p: _Problem) -> np.ndarray:
    """The first tangent points: per stage, the x where the √x terms of the rows that tighten
    (D > 0) take half the slack at rest (D √x = −C/2: the tangent there leaves 3/4 of it),
    at most the stage's bound on x (1 where neither applies)."""
    _, _, c, d = p.rows.arrays()
    with np.errstate(divide="ignore", invalid="ignore"):
        half = np.where((d > 0.0) & (c < 0.0), (c / (2.0 * d)) ** 2, np.inf)
    x0 = np.minimum(np.min(half, axis=1, initial=np.inf), p.xmax)
    return np.where(x0 < _X_CAP, x0, 1.0)


#: the first solve is retried from tangent points this much lower when it finds no timing
_RETRY_FACTOR, _RETRIES = 1e-2, 3


def _first_solve(who: str, p: _Problem, x_ref: np.ndarray):
    """The first solve; a tangent point above what a stage allows makes its linear rows
    infeasible where the true ones are not: retried from lower points before failing."""
    for attempt in range(_RETRIES + 1):
        try:
            return _solve(who, p, x_ref)
        except _core.SolverError:
            if attempt == _RETRIES or not np.any(p.rows.arrays()[3] > 0.0):
                raise
            x_ref = x_ref * _RETRY_FACTOR
    raise AssertionError("unreachable")  # pragma: no cover


def _iterate(who: str, p: _Problem):
    """The solve, with the tangents (secants) of the √x terms moved to each solution until the
    duration settles (module notes); every iterate is feasible."""
    _, _, _, d = p.rows.arrays()
    x_ref = _first_reference(p)
    best, duration, iterations = None, np.inf, 0
    while iterations < (MAX_ITERATIONS if np.any(d) else 1):
        iterations += 1
        x, u, lin = _solve(who, p, x_ref) if best is not None else _first_solve(who, p, x_ref)
        t = _times(who, p.along.s, x)
        if best is not None and t[-1] >= duration * (1.0 - _ITERATION_TOL):
            if t[-1] < duration:
                best, duration = (x, u, lin, t), t[-1]
            break
        best, duration = (x, u, lin, t), t[-1]
        x_ref = x
    return (*best, iterations)


def _times(who: str, s: np.ndarray, x: np.ndarray) -> np.ndarray:
    sd = np.sqrt(x)
    speed = sd[1:] + sd[:-1]
    if np.any(speed <= 0.0):
        i = int(np.argmax(speed <= 0.0))
        raise _core.SolverError(
            f"{who}: no feasible timing: the path speed is zero from s = {s[i]:.6g} to "
            f"{s[i + 1]:.6g} (the limits allow no motion there)"
        )
    return np.concatenate([[0.0], np.cumsum(2.0 * np.diff(s) / speed)])


def _active(p: _Problem, lin, x, u) -> list[str]:
    """Per sample, the constraint that binds (least slack within 1e-6 of its limit), the bound
    on x, or '' (the speed is set by a constraint further on)."""
    a, b, c, cols = lin
    out = [""] * len(x)
    if a.shape[1]:
        limits = np.array([max(p.rows.cols[k][1], 1e-300) for k in cols])
        ratio = _violation(a, b, c, x, u) / limits
        worst = np.argmax(ratio, axis=1)
        for i in np.flatnonzero(ratio[np.arange(len(x)), worst] >= -1e-6):
            label, _, side = p.rows.cols[cols[worst[i]]][:3]
            out[i] = f"{label} {'upper' if side > 0 else 'lower'}"
    at_bound = (x >= p.xmax * (1.0 - 1e-9)) & (x > 0.0)
    for i in np.flatnonzero(at_bound):
        if not out[i]:
            out[i] = p.xmax_label[i]
    return out


def time_optimal(
    model: Any,
    path: Path,
    *,
    max_velocity=None,
    max_acceleration=None,
    max_torque=None,
    motors: bool = True,
    grid: int | np.ndarray | None = None,
) -> Trajectory:
    """The fastest timing of ``path`` from rest to rest within the limits (module notes).

    Args:
        model: a fixed-base joint-space model (``model.coord_names`` the path's columns).
        path: the geometric :class:`~armdyn.motion.Path`.
        max_velocity: joint speed limits [rad/s or m/s], a number or one per joint (inf: none);
            default ``model.coord_velocity_limit``.
        max_acceleration: joint acceleration limits, likewise; default none.
        max_torque: joint torque (force) limits, likewise; default ``model.coord_effort_limit``.
        motors: True to respect each actuator's motor (``model.actuators`` with a
            :class:`armdyn.Motor`): speed, peak torque, speed–torque envelope through the gear.
        grid: the path parameters of the discretisation (0 … 1, strictly increasing), or a
            number of equal intervals; default ``DEFAULT_GRID``.

    Returns:
        :class:`~armdyn.motion.Trajectory` sampled at the grid points, with an exact
        ``evaluate`` and the model's joint names (the path's when it has them); ``info``:
        ``method``, ``duration``, ``grid`` (= ``s``), ``sd``, ``sdd`` (the timing at the
        samples), ``qdd_arrival`` (the last interval's q̈ at the end), ``active`` (per
        sample, the constraint that binds: ``"torque 'joint' upper"``, ``"velocity
        'joint'"``, ``"motor envelope 'joint' upper"``, ... or ``""``), ``limits``,
        ``envelope_iterations``, ``motor_treatment``.

    Raises:
        ModelError: a bad argument (named), a model that is not fixed-base or has
            velocity-dependent forces other than dampers (linear in the rates) and the
            actuators' friction (a joint's Coulomb friction, gear contact: named with the
            joint), a path that does not move or whose speed nothing limits.
        SolverError: no feasible timing (naming the grid point, and the limit exceeded at rest
            there when one is).
    """
    who = "time_optimal"
    names = _model_path(who, model, path)
    motors = _checks.flag(who, "motors", motors)
    s = _grid(who, grid)
    v_max = _per_joint(who, "max_velocity", max_velocity, model.coord_velocity_limit, names)
    a_max = _per_joint(who, "max_acceleration", max_acceleration, None, names)
    tau_max = _per_joint(who, "max_torque", max_torque, model.coord_effort_limit, names)
    along = _along(who, model, path, s)
    p = _problem(model, along, names, v_max, a_max, tau_max, motors)
    x, u, lin, t, iterations = _iterate(who, p)
    sd = np.sqrt(x)
    info = {
        "method": "time_optimal (TOPP-RA: toppra's controllable sets, exact forward pass)",
        "duration": float(t[-1]),
        "grid": s.copy(),
        "s": s.copy(),
        "sd": sd,
        "sdd": u.copy(),
        "active": _active(p, lin, x, u),
        "limits": {"max_velocity": v_max, "max_acceleration": a_max, "max_torque": tau_max},
        "envelope_iterations": iterations,
        "qdd_arrival": along.d1[-1] * u[-2],
        "motor_treatment": "conservative: speed terms (dampers, viscous friction, envelope) by "
        "tangents and secants (exact at convergence where they bind), gear efficiency branches "
        "and Coulomb friction by their worst case",
    }
    return _trajectory(path, t, s, sd, u, info, names)


def _trajectory(path: Path, t, s, sd, u, info, names) -> Trajectory:
    q, d1, d2 = path.evaluate(s)
    qd = d1 * sd[:, None]
    qdd = d1 * u[:, None] + d2 * (sd**2)[:, None]
    last = len(t) - 1

    def evaluate(times: np.ndarray):
        times = np.asarray(times, dtype=float)
        i = np.clip(np.searchsorted(t, times, side="right") - 1, 0, last)
        tau = times - t[i]
        acc = u[i]
        sdot = sd[i] + acc * tau
        sp = np.clip(s[i] + sd[i] * tau + 0.5 * acc * tau**2, 0.0, 1.0)
        qs, e1, e2 = path.evaluate(sp)
        return qs, e1 * sdot[:, None], e1 * acc[:, None] + e2 * (sdot**2)[:, None]

    names = path.names if path.names is not None else names
    return Trajectory(t, q, qd, qdd, names=names, info={**path.info, **info}, evaluate=evaluate)


# --- the shortest repeated cycle --------------------------------------------------------------

#: the motor checks of the repeated cycle (armdyn.sizing.motor.motor_cycle_values' margins)
CYCLE_CHECKS = ("peak_torque", "speed", "envelope", "continuous_torque", "winding_temperature")


def _scaled(traj: Trajectory, k: float) -> Trajectory:
    """The same motion slowed uniformly by ``k`` ≥ 1: t → k t, q̇ → q̇/k, q̈ → q̈/k²."""
    base = traj._evaluate

    def evaluate(times: np.ndarray):
        q, qd, qdd = base(np.asarray(times, dtype=float) / k)
        return q, qd / k, qdd / (k * k)

    return Trajectory(
        traj.t * k,
        traj.q,
        traj.qd / k,
        traj.qdd / (k * k),
        names=traj.names,
        info=dict(traj.info),
        evaluate=evaluate,
    )


def _cycle_margins(model, traj: Trajectory, dwell: float, actuators, options) -> dict:
    """{(joint, check): margin} of the repeated cycle (motion + dwell, periodic steady state).
    A sample is added a millionth of the last interval before the end, with that interval's
    motion (the arrival: still moving, the braking torque through the gear's branch of that
    motion): the samples' trapezoid rule of the RMS and the losses then keeps the last interval
    whole, and the end sample holds (s̈ = 0, the torque of the dwell)."""
    from armdyn.sizing.cycle import duty_cycle
    from armdyn.sizing.motor import motor_cycle_values

    t = traj.t
    t_arrival = t[-1] - 1e-6 * (t[-1] - t[-2])
    q_a, qd_a, qdd_a = traj._evaluate(np.array([t_arrival]))
    samples = [
        np.concatenate([x[:-1], extra, x[-1:]])
        for x, extra in zip(
            (t, traj.q, traj.qd, traj.qdd), ([t_arrival], q_a, qd_a, qdd_a), strict=True
        )
    ]
    cycle = duty_cycle(model, tuple(samples), dwell=dwell, repeat=None)
    out = {}
    for act in actuators:
        load = cycle.joint_load(str(act.joint))
        motor = {f: getattr(act.motor, f) for f in _core.Motor.FIELDS}
        motor = {f: np.array([np.nan if v is None else float(v)]) for f, v in motor.items()}
        values = motor_cycle_values(
            load, act.gear_ratio, act.efficiency, act.rotor_inertia, motor, options
        )
        for check in CYCLE_CHECKS:
            out[(str(act.joint), check)] = float(values[check][0])
    return out


#: a margin passes from 1 − this (the time-optimal motion meets its peaks to round-off)
_MARGIN_TOL = 1e-9


def _passes(margins: dict) -> bool:
    return all(not (m < 1.0 - _MARGIN_TOL) for m in margins.values())  # NaN: not checked


def _least(margins: dict) -> tuple[tuple[str, str], float]:
    checked = {k: v for k, v in margins.items() if not np.isnan(v)}
    key = min(checked, key=checked.get)
    return key, checked[key]


def shortest_cycle(
    model: Any,
    path: Path,
    *,
    dwell: float,
    max_velocity=None,
    max_acceleration=None,
    max_torque=None,
    grid: int | np.ndarray | None = None,
    options=None,
    tolerance: float = 1e-4,
    max_slowdown: float = 1e3,
) -> Trajectory:
    """The shortest cycle (the path's motion, then ``dwell`` seconds at rest, repeated forever)
    whose motors stay within their peak torque, speed and envelope **and** their continuous
    (RMS) torque and winding temperature in the periodic steady state.

    How: :func:`time_optimal` (peaks, speeds, envelopes, joint limits), then an outer search on
    a uniform slowdown k ≥ 1 of that profile (t → k t, q̇ → q̇/k, q̈ → q̈/k²: the same path) for
    the smallest k whose cycle passes every motor check of :mod:`armdyn.sizing` (the margins of
    :func:`armdyn.sizing.motor.motor_cycle_values` on :func:`armdyn.sizing.duty_cycle` with
    ``repeat=None``: the copper loss with the winding's resistance rising with its temperature,
    the one- or two-node thermal model of the motor's datasheet). The slowdown is bracketed by
    doubling, then bisected to ``tolerance`` (relative): the cycle returned passes; one
    ``tolerance`` faster fails. A slowdown lowers the dynamic torques (as 1/k²) and lengthens
    the motion; it need not be monotone in every check (gravity; the envelope's speed term),
    so the result is the smallest passing k of the bracket found, not a proof that no faster
    passing k exists below it. The motor-side torque of the checks is the sizing's (no
    motor-side friction: :func:`~armdyn.sizing.motor.motor_cycle_values`). The cycle repeats
    the path from its start: give a closed path (there and back) for a real cycle.

    Args:
        model, path, max_velocity, max_acceleration, max_torque, grid: as :func:`time_optimal`
            (motors on). The model needs an actuator with an :class:`armdyn.Motor`.
        dwell: the rest after each motion [s], ≥ 0.
        options: :class:`armdyn.sizing.options.SizingOptions` (ambient temperature, copper
            coefficient); default the sizing's.
        tolerance: the relative precision of the slowdown, in (0, 0.1].
        max_slowdown: the largest slowdown tried (> 1).

    Returns:
        :class:`~armdyn.motion.Trajectory` of one period (the motion, then the dwell's two
        samples); ``info``: ``period``, ``motion_duration``, ``dwell``, ``slowdown`` (k),
        ``time_optimal_duration``, ``binding`` (``(joint, check)`` of least margin: a thermal
        check when k > 1, else a peak check or ``None`` when the motors are not what limits
        the time-optimal motion), ``margins`` ({(joint, check): margin} of the cycle
        returned), and the time-optimal ``info``.

    Raises:
        ModelError: bad arguments (named), no actuator with a motor.
        SolverError: no feasible timing, or no slowdown up to ``max_slowdown`` passes (naming
            the check that still fails: e.g. holding against gravity during the dwell heats the
            winding beyond its limit).
    """
    who = "shortest_cycle"
    from armdyn.sizing.cycle import MAX_DWELL
    from armdyn.sizing.options import sizing_options

    dwell = float(_checks.number(who, "dwell", dwell, lo=0.0, hi=MAX_DWELL))
    tolerance = float(_checks.number(who, "tolerance", tolerance, lo=0.0, hi=0.1, lo_open=True))
    max_slowdown = float(
        _checks.number(who, "max_slowdown", max_slowdown, lo=1.0, hi=1e6, lo_open=True)
    )
    options = sizing_options(options)
    _model_path(who, model, path)
    actuators = [a for a in _actuators(model) if getattr(a, "motor", None) is not None]
    if not actuators:
        raise _core.ModelError(
            f"{who}: the model has no actuator with a motor (ModelBuilder.add_actuator(..., "
            "motor=armdyn.Motor(...))): there is no thermal limit to meet"
        )
    fastest = time_optimal(
        model,
        path,
        max_velocity=max_velocity,
        max_acceleration=max_acceleration,
        max_torque=max_torque,
        motors=True,
        grid=grid,
    )

    def check(k: float):
        traj = _scaled(fastest, k) if k != 1.0 else fastest
        return traj, _cycle_margins(model, traj, dwell, actuators, options)

    best, margins = check(1.0)
    k_best = 1.0
    if not _passes(margins):
        k_lo, k_best = 1.0, 2.0
        best, margins = check(k_best)
        while not _passes(margins):
            if k_best >= max_slowdown:
                key, value = _least(margins)
                raise _core.SolverError(
                    f"{who}: no cycle slowed down up to {max_slowdown:g}x passes the motor "
                    f"checks: joint {key[0]!r}'s {key[1]} margin is {value:.4g} (< 1) at that "
                    f"slowdown (with a dwell of {dwell:g} s)"
                )
            k_lo, k_best = k_best, min(2.0 * k_best, max_slowdown)
            best, margins = check(k_best)
        while k_best - k_lo > tolerance * k_best:
            mid = 0.5 * (k_lo + k_best)
            traj, m = check(mid)
            if _passes(m):
                k_best, best, margins = mid, traj, m
            else:
                k_lo = mid
    binding = _least(margins)[0] if k_best > 1.0 else _peak_binding(fastest, margins)
    info = {
        **fastest.info,
        "method": "shortest_cycle (time_optimal, then a uniform slowdown for the thermal checks)",
        "period": k_best * fastest.duration + dwell,
        "motion_duration": k_best * fastest.duration,
        "dwell": dwell,
        "slowdown": k_best,
        "time_optimal_duration": fastest.duration,
        "binding": binding,
        "margins": margins,
    }
    best.info = info
    if dwell > 0.0:
        best = best.then_hold(dwell)
        best.info.update(info)
    return best


def _peak_binding(fastest: Trajectory, margins: dict):
    """At no slowdown: the motor check the time-optimal motion binds (a peak, speed or
    envelope check within 1e-6 of its limit), else None (joint limits bind)."""
    key, value = _least(margins)
    return key if value <= 1.0 + 1e-6 else None
