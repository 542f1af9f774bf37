"""Joint trajectories: point-to-point moves and moves through via points under velocity,
acceleration and jerk limits (trapezoidal or jerk-limited "double-S" velocity profiles, each
joint on its own or all joints synchronised), splines through waypoints at given times (cubic
with end conditions, quintic), and the geometric path through joint waypoints that
:func:`armdyn.motion.time_optimal` times.

Limited profiles come from `ruckig <https://github.com/pantor/ruckig>`_ (Berscheid & Kröger,
RSS 2021): its time-optimal third-order solver is exact (closed-form phases, no sampling) and
well kept, so it is not rewritten here. The trapezoidal profile is ruckig's with an infinite jerk
limit (its second-order solver). Synchronised joints use ruckig's phase synchronisation (the
joints move on the straight line in joint space, proportional to each other) where possible and
its time synchronisation otherwise (all joints start and arrive together); per joint
(``synchronize=False``) each joint runs its own time-optimal profile and then holds its goal.

Via points. Intermediate waypoints are a ruckig *Pro* feature: the community version installed
here refuses them offline (it would call ruckig's cloud API). So a move through waypoints is
chained from one ruckig solve per segment, each starting from the state the previous one ended
in. ``stop_at_waypoints=True`` stops at every waypoint (rest to rest, each segment
time-optimal). Without stopping, this module chooses the velocity each joint passes a waypoint
with (at zero acceleration), by the heuristic rule of Biagiotti & Melchiorri (*Trajectory
Planning for Automatic Machines and Robots*, 2008, ch. 4, for the velocities of multipoint
trajectories) applied to the chord velocities of the rest-to-rest segments: zero where the
joint turns back (or stays) at the waypoint, else the mean of the two chord velocities; then
bounded by the joint's velocity limit and by the speed it could stop from within half of either
adjacent segment, so that no segment needs to overshoot its waypoint or back up (the tests
check this on fine grids). These pass-through velocities are a choice, not ruckig Pro's
time-optimal ones: the move is continuous in position and velocity (and, jerk-limited, in
acceleration), within every limit, faster than stopping, but not time-optimal through the
waypoints.

Every planner returns an :class:`armdyn.motion.Trajectory` sampled every ``dt`` (the end
included) whose ``evaluate`` is exact: for ruckig segments the constant-jerk phases of ruckig's
own profile integrated in closed form (what ``ruckig.Trajectory.at_time`` computes, vectorised);
for splines their piecewise polynomial. So ``traj.sample(...)`` re-grids without interpolation
error. Its ``info`` holds the method, the limits used and the segment durations.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt

from armdyn import _checks, _core
from armdyn.motion.trajectory import Path, Trajectory

__all__ = ["drive_profile", "point_to_point", "spline", "through_waypoints", "waypoint_path"]

#: most samples a planner returns (the bound of Trajectory.sample)
MAX_SAMPLES = 10_000_000
#: most waypoints a limited move goes through (one ruckig solve per segment and joint group)
MAX_WAYPOINTS = 100_000
#: most joints
MAX_JOINTS = 10_000
#: most values (samples x joints) in each of a returned trajectory's q, qd, qdd
MAX_VALUES = 20_000_000

_PROFILES = ("double_s", "trapezoidal")
_CUBIC_ENDS = ("clamped", "natural", "not-a-knot", "periodic")


# ---------------------------------------------------------------- argument checks


def _points(who: str, name: str, x, n: int | None = None) -> np.ndarray:
    """``x`` as an (m, joints) array of finite joint positions: (m,) is m points of one joint
    when ``n == 1``, else one point; ``n``: the joint count required (None: any)."""
    a = np.asarray(_checks.array(who, name, x, finite=True), dtype=float)
    if a.ndim == 0:
        a = a.reshape(1, 1)
    elif a.ndim == 1:
        a = a[:, None] if n == 1 else a[None, :]
    if a.ndim != 2 or a.shape[1] < 1 or a.shape[0] < 1:
        raise _core.ModelError(f"{who}: {name} must be a 2-D array (points, joints), got {a.shape}")
    if n is not None and a.shape[1] != n:
        raise _core.ModelError(f"{who}: {name} has {a.shape[1]} joints, expected {n}")
    if a.shape[1] > MAX_JOINTS:
        raise _core.ModelError(f"{who}: {name} has {a.shape[1]} joints (> {MAX_JOINTS})")
    return a


def _vector(who: str, name: str, x, n: int) -> np.ndarray:
    """One configuration: a scalar (one joint) or (n,)."""
    a = np.atleast_1d(np.asarray(_checks.array(who, name, x, finite=True), dtype=float))
    if a.ndim != 1 or (n and len(a) != n) or len(a) < 1:
        want = f"have shape ({n},)" if n else "be a 1-D array of joint positions"
        raise _core.ModelError(f"{who}: {name} must {want}, got shape {a.shape}")
    if len(a) > MAX_JOINTS:
        raise _core.ModelError(f"{who}: {name} has {len(a)} joints (> {MAX_JOINTS})")
    return a


def _limit(who: str, name: str, value, n: int, *, allow_inf: bool = False) -> np.ndarray:
    """A positive limit: a scalar (every joint) or (n,); each entry > 0, finite unless
    ``allow_inf`` (then inf means no limit)."""
    a = np.atleast_1d(np.asarray(_checks.array(who, name, value), dtype=float))
    if a.ndim != 1 or len(a) not in (1, n):
        raise _core.ModelError(
            f"{who}: {name} must be a scalar or have shape ({n},) (one per joint), got {a.shape}"
        )
    a = np.broadcast_to(a, (n,)).copy()
    bad = np.isnan(a) | ~(a > 0.0) | (np.isinf(a) & (not allow_inf))
    if bad.any():
        j = int(np.argmax(bad))
        allowed = "positive" + (" (inf: no limit)" if allow_inf else " and finite")
        raise _core.ModelError(f"{who}: {name}[{j}] = {float(a[j])!r} must be {allowed}")
    return a


def _model_joints(who: str, model, n: int) -> tuple[str, ...] | None:
    """The model's coordinate names after checking it moves ``n`` joints of a fixed base."""
    if model is None:
        return None
    if not isinstance(model, _core.Model):
        raise _core.ModelError(f"{who}: model must be an armdyn.Model, got {type(model).__name__}")
    names = tuple(model.coord_names)
    if len(names) != len(model.dof_names):
        raise _core.ModelError(
            f"{who}: the model's coordinates are not its rates (a floating base's quaternion): "
            "plan the joints of a fixed-base model"
        )
    if len(names) != n:
        raise _core.ModelError(
            f"{who}: {n} joints given, the model has {len(names)}: {list(names)}"
        )
    return names


def _within_range(who: str, model, points: np.ndarray, name: str) -> None:
    """ModelError naming the first waypoint and joint outside the model's position range."""
    if model is None:
        return
    lo, hi = np.asarray(model.coord_lower), np.asarray(model.coord_upper)
    bad = (points < lo) | (points > hi)
    if bad.any():
        k, j = (int(i) for i in np.argwhere(bad)[0])
        raise _core.ModelError(
            f"{who}: {name}[{k}] puts joint '{model.coord_names[j]}' at {points[k, j]:g}, "
            f"outside its range [{lo[j]:g}, {hi[j]:g}]"
        )


def _velocity_limit(who: str, max_velocity, model, n: int, names) -> np.ndarray:
    if max_velocity is not None:
        return _limit(who, "max_velocity", max_velocity, n)
    if model is None:
        raise _core.ModelError(f"{who}: give max_velocity (or a model with velocity limits)")
    v = np.asarray(model.coord_velocity_limit, dtype=float)
    bad = ~(np.isfinite(v) & (v > 0.0))
    if bad.any():
        j = int(np.argmax(bad))
        raise _core.ModelError(
            f"{who}: joint '{names[j]}' has no velocity limit in the model "
            f"(coord_velocity_limit = {v[j]:g}): give max_velocity"
        )
    return v.copy()


def _limits(who: str, n: int, max_velocity, max_acceleration, max_jerk, profile, model, names):
    """(profile, v, a, j): the checked limits, (n,) each; j is inf for the trapezoid."""
    profile = _checks.choice(who, "profile", profile, _PROFILES)
    v = _velocity_limit(who, max_velocity, model, n, names)
    if max_acceleration is None:
        raise _core.ModelError(f"{who}: give max_acceleration (a scalar or one per joint)")
    a = _limit(who, "max_acceleration", max_acceleration, n)
    if profile == "trapezoidal":
        if max_jerk is not None:
            raise _core.ModelError(
                f"{who}: max_jerk is not used by profile='trapezoidal' (use profile='double_s')"
            )
        return profile, v, a, np.full(n, np.inf)
    if max_jerk is None:
        raise _core.ModelError(
            f"{who}: profile='double_s' needs max_jerk (or use profile='trapezoidal')"
        )
    return profile, v, a, _limit(who, "max_jerk", max_jerk, n)


def _grid(who: str, t0: float, t1: float, dt, n: int) -> np.ndarray:
    """``t0, t0 + dt, ...`` and ``t1``: at most MAX_SAMPLES samples and MAX_VALUES values of
    ``n`` joints."""
    step = float(_checks.number(who, "dt", dt, lo=0.0, lo_open=True))  # type: ignore[arg-type]
    span = t1 - t0
    if span <= 0.0:
        return np.array([t0])
    count = span / step
    if not count < MAX_SAMPLES:
        raise _core.ModelError(
            f"{who}: dt = {step:g} s over {span:g} s gives {count:.3g} samples (> {MAX_SAMPLES})"
        )
    if not count * n < MAX_VALUES:
        raise _core.ModelError(
            f"{who}: dt = {step:g} s over {span:g} s gives {count:.3g} samples of {n} joints "
            f"(> {MAX_VALUES} values)"
        )
    k = int(np.ceil(count - 1e-9))
    grid = t0 + step * np.arange(k)
    grid = np.append(grid[grid < t1], t1)
    if len(grid) > 1 and not np.all(np.diff(grid) > 0.0):
        raise _core.ModelError(
            f"{who}: dt = {step:g} s is below the floating-point resolution of times near {t1:g} s"
        )
    return grid


# ---------------------------------------------------------------- ruckig segments


def _ruckig():
    try:
        import ruckig  # type: ignore[import-not-found]
    except ImportError as err:  # pragma: no cover - a runtime dependency
        raise _core.ModelError(
            "armdyn.motion: the jerk-limited profiles need the 'ruckig' package "
            "(pip install ruckig)"
        ) from err
    return ruckig


def _solve(start, v0, goal, v1, limits, where: str):
    """One ruckig segment of len(start) joints from (start, v0, 0) to (goal, v1, 0)."""
    rk = _ruckig()
    n = len(start)
    vmax, amax, jmax = limits
    inp = rk.InputParameter(n)
    inp.current_position, inp.current_velocity = list(start), list(v0)
    inp.current_acceleration = [0.0] * n
    inp.target_position, inp.target_velocity = list(goal), list(v1)
    inp.target_acceleration = [0.0] * n
    inp.max_velocity, inp.max_acceleration = list(vmax), list(amax)
    inp.max_jerk = list(jmax)
    inp.synchronization = rk.Synchronization.Phase
    traj = rk.Trajectory(n)
    try:
        result = rk.Ruckig(n).calculate(inp, traj)
    except getattr(rk, "RuckigError", RuntimeError) as err:  # names the step and the joint
        first = str(err).strip().splitlines()[0].replace("[ruckig] ", "").strip()
        first = first.removesuffix(" input:")
        raise _core.SolverError(
            f"{where}: ruckig found no profile ({first}; are the distances and limits of "
            "sensible scales?)"
        ) from None
    if result != rk.Result.Working or not np.isfinite(traj.duration):
        raise _core.SolverError(f"{where}: ruckig found no profile ({result})")
    return traj


def _phases(segment) -> np.ndarray | None:
    """(joints, 5, 8): per joint of a ruckig segment its 7 phases' start times (and the end),
    jerks (0 after the end), and the acceleration, velocity and position at each phase start
    (and at the end); None when a brake phase precedes the profile (then ``at_time``)."""
    try:
        profiles = segment.profiles[0]
        out = np.zeros((len(profiles), 5, 8))
        for d, prof in enumerate(profiles):
            if prof.brake.duration > 0.0 or prof.accel.duration > 0.0:
                return None
            out[d, 0, 1:] = np.cumsum(prof.t)
            out[d, 1, :7] = prof.j
            out[d, 2], out[d, 3], out[d, 4] = prof.a, prof.v, prof.p
    except (AttributeError, ValueError):  # a ruckig whose bindings do not show the phases
        return None
    return out


class _Chain:
    """Consecutive ruckig segments of one group of joints (every joint when synchronised, one
    joint otherwise), each starting where the previous ended; holds the last state after.

    Evaluation integrates each segment's constant-jerk phases in closed form from ruckig's own
    phase data (``Profile.t, j, a, v, p``: the arithmetic of ``Trajectory.at_time``, vectorised
    over the samples), and the ruckig objects are let go; a segment with a brake phase (or
    ``phases=False``) keeps them and evaluates with ``at_time`` per sample."""

    CHUNK = 1 << 16  # samples per vectorised block (bounds the temporaries)

    def __init__(self, joints: list[int], segments: list, phases: bool = True) -> None:
        self.joints = joints
        self.durations = np.array([s.duration for s in segments])
        self.starts = np.concatenate([[0.0], np.cumsum(self.durations)])
        tables = [_phases(s) for s in segments] if phases else [None]
        ok = [x for x in tables if x is not None]
        self.tables: np.ndarray | None = np.stack(ok) if len(ok) == len(tables) else None
        self.segments = segments if self.tables is None else None

    @property
    def duration(self) -> float:
        return float(self.starts[-1])

    def at(self, t: np.ndarray) -> np.ndarray:
        """(3, len(t), len(joints)): position, velocity, acceleration at times ``t``."""
        k = np.clip(np.searchsorted(self.starts, t, side="right") - 1, 0, len(self.durations) - 1)
        local = np.clip(t - self.starts[k], 0.0, self.durations[k])
        out = np.empty((3, len(t), len(self.joints)))
        if self.segments is not None:
            for i in range(len(t)):
                out[:, i] = self.segments[k[i]].at_time(float(local[i]))
            return out
        for lo in range(0, len(t), self.CHUNK):
            part = slice(lo, lo + self.CHUNK)
            out[:, part] = self._integrate(k[part], local[part])
        return out

    def phase_synchronized(self) -> np.ndarray | None:
        """Per segment: do the moving joints share their phase times (ruckig's phase
        synchronisation: the straight line in joint space), or only the duration (its time
        synchronisation)? None without the phase data."""
        if self.tables is None:
            return None
        starts, v, p = self.tables[:, :, 0, :], self.tables[:, :, 3, :], self.tables[:, :, 4, :]
        moving = (p[:, :, 0] != p[:, :, 7]) | np.any(v != 0.0, axis=2)
        out = np.empty(len(starts), dtype=bool)
        for k, (st, mv) in enumerate(zip(starts, moving, strict=True)):
            rows = st[mv]
            out[k] = len(rows) == 0 or bool(np.allclose(rows, rows[0], rtol=1e-9, atol=1e-12))
        return out

    def _integrate(self, k: np.ndarray, tau: np.ndarray) -> np.ndarray:
        n = len(self.joints)
        flat = np.asarray(self.tables).reshape(-1, 5, 8)  # row: segment * joints + joint
        out = np.empty((3, len(k), n))
        for d in range(n):
            row = k * n + d
            phase = np.sum(tau[:, None] >= flat[row, 0, 1:], axis=1)  # 7: after the end
            h = tau - flat[row, 0, phase]
            j, a, v, p = (flat[row, r, phase] for r in (1, 2, 3, 4))
            out[0, :, d] = p + h * (v + h * (a / 2.0 + h * j / 6.0))
            out[1, :, d] = v + h * (a + h * j / 2.0)
            out[2, :, d] = a + h * j
        return out


def _stop_speed(d: np.ndarray, a: np.ndarray, j: np.ndarray) -> np.ndarray:
    """The largest speed from which a joint (at zero acceleration) stops within distance ``d``
    under acceleration ``a`` and jerk ``j`` (inf: trapezoidal): d = v sqrt(v/j) below v = a²/j,
    else d = v²/(2a) + v a/(2j) (the deceleration phase of a double-S profile)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        trapezoid = np.sqrt(2.0 * a * d)
        corner = a**3 / j**2
        low = np.cbrt(j * d**2)
        high = 0.5 * (-(a**2) / j + np.sqrt(a**4 / j**2 + 8.0 * a * d))
        v = np.where(d <= corner, low, high)
    return np.where(np.isinf(j), trapezoid, v)


def _pass_velocities(points, rest_durations, limits) -> np.ndarray:
    """(m, n) velocities at the waypoints (zero at both ends): Biagiotti & Melchiorri's rule on
    the rest-to-rest chord velocities, bounded by the stop distance of half of either
    adjacent segment and the velocity limit."""
    vmax, amax, jmax = limits
    step = np.diff(points, axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        chord = np.where(rest_durations[:, None] > 0.0, step / rest_durations[:, None], 0.0)
    before, after = chord[:-1], chord[1:]
    same = np.sign(before) * np.sign(after) > 0.0
    v = np.where(same, 0.5 * (before + after), 0.0)
    room = 0.5 * np.minimum(np.abs(step[:-1]), np.abs(step[1:]))
    bound = np.minimum(_stop_speed(room, amax, jmax), vmax)
    v = np.sign(v) * np.minimum(np.abs(v), bound)
    zero = np.zeros((1, points.shape[1]))
    return np.vstack([zero, v, zero])


def _chain(
    who: str, points, joints, limits, stop: bool, names=None, phases: bool = True
) -> tuple[_Chain, np.ndarray]:
    """The chain of ruckig segments through ``points`` (m, len(joints)) and its waypoint
    velocities."""
    m, n = points.shape
    lim = tuple(x[joints] for x in limits)
    zero = np.zeros(n)
    if len(joints) > 1:
        label = "the joints"
    else:
        label = f"joint '{names[joints[0]]}'" if names else f"joint {joints[0]}"

    def where(k):
        return f"{who}: segment {k} (waypoint {k} to {k + 1}) of {label}"

    rest = [_solve(points[k], zero, points[k + 1], zero, lim, where(k)) for k in range(m - 1)]
    if stop or m == 2:
        return _Chain(joints, rest, phases), np.zeros((m, n))
    vel = _pass_velocities(points, np.array([s.duration for s in rest]), lim)
    segs = [
        _solve(points[k], vel[k], points[k + 1], vel[k + 1], lim, where(k)) for k in range(m - 1)
    ]
    return _Chain(joints, segs, phases), vel


def _limited(who: str, points, limits, synchronize: bool, stop: bool, dt, names, info):
    """The Trajectory through ``points`` (m, n) chained from ruckig segments."""
    n = points.shape[1]
    groups = [list(range(n))] if synchronize else [[j] for j in range(n)]
    chains, velocities = [], np.zeros_like(points)
    for g in groups:
        chain, vel = _chain(who, points[:, g], g, limits, stop, names)
        chains.append(chain)
        velocities[:, g] = vel
    duration = max(c.duration for c in chains)
    if not np.isfinite(duration):
        raise _core.SolverError(f"{who}: ruckig returned a non-finite duration")

    def evaluate(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        t = np.clip(np.asarray(t, dtype=float), 0.0, duration)
        out = np.empty((3, len(t), n))
        for c in chains:
            out[:, :, c.joints] = c.at(t)
        return out[0], out[1], out[2]

    grid = _grid(who, 0.0, duration, dt, n)
    if synchronize:
        segment_durations = chains[0].durations
    else:
        segment_durations = np.array([c.durations for c in chains])
    info.update(
        synchronize=synchronize,
        duration=duration,
        segment_durations=segment_durations,
        waypoint_velocities=velocities,
        max_velocity=limits[0],
        max_acceleration=limits[1],
        max_jerk=None if np.all(np.isinf(limits[2])) else limits[2],
    )
    if synchronize:
        info["phase_synchronized"] = chains[0].phase_synchronized()
    else:
        info["joint_durations"] = np.array([c.duration for c in chains])
    return Trajectory(grid, *evaluate(grid), names=names, info=info, evaluate=evaluate)


# ---------------------------------------------------------------- public planners


def point_to_point(
    start: npt.ArrayLike,
    goal: npt.ArrayLike,
    *,
    max_velocity: npt.ArrayLike | None = None,
    max_acceleration: npt.ArrayLike | None = None,
    max_jerk: npt.ArrayLike | None = None,
    profile: str = "double_s",
    synchronize: bool = True,
    dt: float = 0.001,
    model: _core.Model | None = None,
) -> Trajectory:
    """The time-optimal move from rest at ``start`` to rest at ``goal`` under the limits.

    Args:
        start, goal: joint positions, (n,) (a scalar: one joint).
        max_velocity: > 0, finite; a scalar or (n,). Default: ``model.coord_velocity_limit``
            (then every joint must have one).
        max_acceleration: > 0, finite; a scalar or (n,) (required).
        max_jerk: > 0, finite; a scalar or (n,); required by ``profile="double_s"``, refused
            by ``"trapezoidal"``.
        profile: ``"double_s"`` (jerk-limited, continuous acceleration) or ``"trapezoidal"``
            (velocity trapezoid, acceleration steps).
        synchronize: all joints start and arrive together (phase-synchronised on the straight
            line in joint space where possible); False: each joint its own fastest profile,
            then it holds its goal.
        dt: the sample step [s] (the end is a sample; at most ``MAX_SAMPLES`` samples and
            ``MAX_VALUES`` samples x joints).
        model: a fixed-base model: its joint count and names, its position range (start and
            goal must lie in it) and its velocity limits as the default.

    Returns:
        :class:`Trajectory` from t = 0, exact ``evaluate``; ``info``: method, profile,
        synchronize, duration, segment_durations, the limits, phase_synchronized
        (synchronised: did ruckig move the joints on the straight line?), joint_durations
        (per joint).

    Raises:
        ModelError: a bad argument (named: NaN, inf, a limit ≤ 0, shapes, dt giving too many
            samples, a position outside the model's range).
        SolverError: ruckig finds no profile (distances and limits of wildly different
            scales), naming the joint.
    """
    who = "point_to_point"
    a = _vector(who, "start", start, 0)
    b = _vector(who, "goal", goal, len(a))
    names = _model_joints(who, model, len(a))
    synchronize = _checks.flag(who, "synchronize", synchronize)
    profile, *limits = _limits(
        who, len(a), max_velocity, max_acceleration, max_jerk, profile, model, names
    )
    points = np.vstack([a, b])
    _within_range(who, model, points, "[start, goal]")
    info: dict[str, Any] = {"method": "point_to_point", "profile": profile}
    return _limited(who, points, limits, synchronize, True, dt, names, info)


def through_waypoints(
    waypoints: npt.ArrayLike,
    *,
    max_velocity: npt.ArrayLike | None = None,
    max_acceleration: npt.ArrayLike | None = None,
    max_jerk: npt.ArrayLike | None = None,
    profile: str = "double_s",
    synchronize: bool = True,
    stop_at_waypoints: bool = False,
    dt: float = 0.001,
    model: _core.Model | None = None,
) -> Trajectory:
    """A move from rest at ``waypoints[0]`` through every waypoint to rest at the last, under
    the limits (see :func:`point_to_point` for them and the module docstring for how the
    velocities at the waypoints are chosen).

    Args:
        waypoints: (m, n) joint positions, m ≥ 2 (at most ``MAX_WAYPOINTS``); (m,) is one joint.
        stop_at_waypoints: stop at each waypoint (each segment time-optimal, rest to rest);
            False: pass through them (velocities by Biagiotti & Melchiorri's rule, bounded).
        synchronize: all joints pass each waypoint together (the waypoints are configurations);
            False: each joint runs through its own column on its own time.

    Returns:
        :class:`Trajectory` from t = 0 with exact ``evaluate``; ``info``: method, profile,
        synchronize, stop_at_waypoints, duration, segment_durations ((m-1,) or, per joint,
        (n, m-1)), waypoint_times and phase_synchronized (per segment; synchronised),
        waypoint_velocities (m, n), the limits, joint_durations (per joint).

    Raises:
        ModelError: a bad argument (named), fewer than two waypoints, a waypoint outside the
            model's range (naming the waypoint and joint).
        SolverError: ruckig finds no profile for a segment (named).
    """
    who = "through_waypoints"
    arr = np.asarray(_checks.array(who, "waypoints", waypoints))
    points = _points(who, "waypoints", waypoints, 1 if arr.ndim == 1 else None)
    m, n = points.shape
    if m < 2:
        raise _core.ModelError(f"{who}: waypoints must hold at least two points, got {m}")
    if m > MAX_WAYPOINTS:
        raise _core.ModelError(f"{who}: waypoints holds {m} points (> {MAX_WAYPOINTS})")
    names = _model_joints(who, model, n)
    synchronize = _checks.flag(who, "synchronize", synchronize)
    stop = _checks.flag(who, "stop_at_waypoints", stop_at_waypoints)
    profile, *limits = _limits(
        who, n, max_velocity, max_acceleration, max_jerk, profile, model, names
    )
    _within_range(who, model, points, "waypoints")
    info: dict[str, Any] = {
        "method": "through_waypoints",
        "profile": profile,
        "stop_at_waypoints": stop,
    }
    traj = _limited(who, points, limits, synchronize, stop, dt, names, info)
    if synchronize:
        traj.info["waypoint_times"] = np.concatenate([[0.0], np.cumsum(info["segment_durations"])])
    return traj


# ---------------------------------------------------------------- splines


def _spline_args(who, times, waypoints):
    t = np.atleast_1d(np.asarray(_checks.array(who, "times", times, finite=True), dtype=float))
    if t.ndim != 1:
        raise _core.ModelError(f"{who}: times must be 1-D, got shape {t.shape}")
    arr = np.asarray(_checks.array(who, "waypoints", waypoints))
    points = _points(who, "waypoints", waypoints, 1 if arr.ndim == 1 else None)
    if len(t) != len(points):
        raise _core.ModelError(f"{who}: {len(t)} times for {len(points)} waypoints")
    if len(t) < 2:
        raise _core.ModelError(f"{who}: waypoints must hold at least two points, got {len(t)}")
    if len(t) > MAX_SAMPLES:
        raise _core.ModelError(f"{who}: {len(t)} waypoints (> {MAX_SAMPLES})")
    steps = np.diff(t)
    if not np.all(steps > 0.0):
        i = int(np.argmin(steps > 0.0))
        raise _core.ModelError(
            f"{who}: times must be strictly increasing (times[{i + 1}] = {t[i + 1]:g} after "
            f"times[{i}] = {t[i]:g})"
        )
    return t, points


def _end_velocities(who, end_velocities, n: int, allowed: bool) -> np.ndarray:
    if end_velocities is None:
        return np.zeros((2, n))
    if not allowed:
        raise _core.ModelError(f"{who}: end_velocities only go with end_conditions='clamped'")
    v = np.asarray(_checks.array(who, "end_velocities", end_velocities, finite=True), float)
    if v.shape == (2,) and n == 1:
        v = v[:, None]
    if v.shape != (2, n):
        raise _core.ModelError(
            f"{who}: end_velocities must have shape (2, {n}) (start, end), got {v.shape}"
        )
    return v


def _piecewise(t, points, kind, end_conditions, v_ends):
    """The scipy PPoly (in t) of the spline."""
    from scipy.interpolate import CubicSpline, PPoly, make_interp_spline

    if kind == "cubic":
        bc = end_conditions if end_conditions != "clamped" else ((1, v_ends[0]), (1, v_ends[1]))
        return CubicSpline(t, points, axis=0, bc_type=bc)
    zero = np.zeros(points.shape[1])
    bc = ([(1, v_ends[0]), (2, zero)], [(1, v_ends[1]), (2, zero)])
    b = make_interp_spline(t, points, k=5, bc_type=bc, axis=0)
    # its pieces as Taylor polynomials about each time (the B-spline's right-hand derivatives)
    c = np.stack([b(t[:-1], nu=5 - m) / math.factorial(5 - m) for m in range(6)])
    return PPoly(c, t)


def _finite_spline(who, t, points, kind, end_conditions, v_ends):
    """The spline's PPoly; ModelError when its coefficients or those of its first three
    derivatives overflow (waypoints too far apart for their times)."""
    with np.errstate(all="ignore"):
        try:
            poly = _piecewise(t, points, kind, end_conditions, v_ends)
            finite = all(np.all(np.isfinite(poly.derivative(k).c)) for k in range(4))
        except (ValueError, np.linalg.LinAlgError):
            finite = False
    if not finite:
        raise _core.ModelError(
            f"{who}: the spline overflows: the waypoints are too far apart (or the times too "
            "close) for its coefficients to be finite"
        )
    return poly


def _extrema(poly, order: int) -> np.ndarray:
    """(4, joints): per joint the least value of the ``order``-th derivative, where, the
    largest, where (exact: at a breakpoint or a root of the next derivative)."""
    from scipy.interpolate import PPoly

    d, dd = poly.derivative(order), poly.derivative(order + 1)
    n = d.c.shape[2]
    out = np.empty((4, n))
    for j in range(n):
        roots = PPoly(dd.c[:, :, j], dd.x).roots(extrapolate=False)
        cand = np.concatenate([d.x, roots[np.isfinite(roots)]])
        val = d(cand)[:, j]
        lo, hi = int(np.argmin(val)), int(np.argmax(val))
        out[:, j] = val[lo], cand[lo], val[hi], cand[hi]
    return out


def _peaks(poly, order: int) -> tuple[np.ndarray, np.ndarray]:
    """Per joint: the largest |d^order q/dt^order| over the spline and where it is reached."""
    lo, lo_at, hi, hi_at = _extrema(poly, order)
    top = np.abs(hi) >= np.abs(lo)
    return np.where(top, np.abs(hi), np.abs(lo)), np.where(top, hi_at, lo_at)


def _stays_in_range(who: str, poly, model, names, var: str) -> None:
    """SolverError when the spline takes a joint outside the model's position range between
    its waypoints (naming the joint, the value and where)."""
    if model is None:
        return
    lo, lo_at, hi, hi_at = _extrema(poly, 0)
    lower, upper = np.asarray(model.coord_lower), np.asarray(model.coord_upper)
    for j, name in enumerate(names):
        for value, at, bad in (
            (lo[j], lo_at[j], lo[j] < lower[j]),
            (hi[j], hi_at[j], hi[j] > upper[j]),
        ):
            if bad:
                raise _core.SolverError(
                    f"{who}: the spline takes joint '{name}' to {value:.6g} at {var} = {at:.6g}, "
                    f"outside its range [{lower[j]:g}, {upper[j]:g}] (between the waypoints)"
                )


def _check_spline_limits(who, poly, names, max_velocity, max_acceleration, model, n, info):
    """info's exact peak velocity and acceleration per joint; SolverError over a limit."""
    limits = {}
    if max_velocity is not None:
        limits["max_velocity"] = _limit(who, "max_velocity", max_velocity, n, allow_inf=True)
    elif model is not None:
        limits["max_velocity"] = np.asarray(model.coord_velocity_limit, dtype=float)
    if max_acceleration is not None:
        limits["max_acceleration"] = _limit(
            who, "max_acceleration", max_acceleration, n, allow_inf=True
        )
    for order, key in ((1, "max_velocity"), (2, "max_acceleration")):
        peak, when = _peaks(poly, order)
        info["peak_" + key[4:]] = peak
        lim = limits.get(key)
        if lim is None:
            continue
        info[key] = lim
        over = peak > lim * (1.0 + 1e-12)
        if over.any():
            j = int(np.argmax(np.where(over, peak / lim, 0.0)))
            label = f"'{names[j]}'" if names else str(j)
            raise _core.SolverError(
                f"{who}: joint {label} reaches {key[4:]} {peak[j]:.6g} at t = {when[j]:.6g} s, "
                f"above {key} {lim[j]:g} (slow the waypoints' times)"
            )


def spline(
    times: npt.ArrayLike,
    waypoints: npt.ArrayLike,
    *,
    kind: str = "quintic",
    end_conditions: str = "clamped",
    end_velocities: npt.ArrayLike | None = None,
    max_velocity: npt.ArrayLike | None = None,
    max_acceleration: npt.ArrayLike | None = None,
    dt: float = 0.001,
    model: _core.Model | None = None,
) -> Trajectory:
    """The interpolating spline through ``waypoints`` at ``times``.

    Args:
        times: (m,) strictly increasing [s], m ≥ 2.
        waypoints: (m, n) joint positions ((m,): one joint).
        kind: ``"quintic"``: the C4 quintic spline (degree 5, continuous up to the fourth
            derivative) with the end velocities given and zero end accelerations (two
            waypoints: the classic quintic move); ``"cubic"``: the C2 cubic spline with
            ``end_conditions``.
        end_conditions: cubic only: ``"clamped"`` (the end velocities given), ``"natural"``
            (zero end accelerations), ``"not-a-knot"``, ``"periodic"`` (first waypoint equal
            to the last: velocity and acceleration match across the ends).
        end_velocities: (2, n) velocities at the first and last time (default zero) for
            ``"quintic"`` and clamped cubics.
        max_velocity, max_acceleration: optional limits (scalars or (n,), > 0, inf: none;
            velocity default: the model's ``coord_velocity_limit``). The spline's exact peaks
            are checked against them.
        dt: the sample step [s]; model: a fixed-base model (joint names, range, limits).

    Returns:
        :class:`Trajectory` from ``times[0]`` with exact ``evaluate``; ``info``: method, kind,
        end_conditions, times, peak_velocity and peak_acceleration (per joint, exact), limits.

    Raises:
        ModelError: a bad argument (named), fewer than two waypoints, times not increasing,
            a periodic spline whose ends differ, a waypoint outside the model's range.
        SolverError: the spline exceeds a velocity or acceleration limit, or leaves the
            model's range between the waypoints (naming the joint, the value and the time).
    """
    who = "spline"
    t, points = _spline_args(who, times, waypoints)
    n = points.shape[1]
    kind = _checks.choice(who, "kind", kind, ("quintic", "cubic"))
    end_conditions = _checks.choice(who, "end_conditions", end_conditions, _CUBIC_ENDS)
    if kind == "quintic" and end_conditions != "clamped":
        raise _core.ModelError(f"{who}: end_conditions apply to kind='cubic' only")
    if end_conditions == "periodic" and not np.allclose(points[0], points[-1], rtol=0, atol=0):
        raise _core.ModelError(f"{who}: a periodic spline's last waypoint must equal its first")
    v_ends = _end_velocities(who, end_velocities, n, end_conditions == "clamped")
    names = _model_joints(who, model, n)
    _within_range(who, model, points, "waypoints")
    poly = _finite_spline(who, t, points, kind, end_conditions, v_ends)
    d1, d2 = poly.derivative(1), poly.derivative(2)
    t0, t1 = float(t[0]), float(t[-1])
    info: dict[str, Any] = {
        "method": "spline",
        "kind": kind,
        "end_conditions": end_conditions,
        "times": t,
        "segment_durations": np.diff(t),
        "duration": t1 - t0,
    }
    _stays_in_range(who, poly, model, names, "t")
    _check_spline_limits(who, poly, names, max_velocity, max_acceleration, model, n, info)

    def evaluate(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        x = np.clip(np.asarray(x, dtype=float), t0, t1)
        return poly(x), d1(x), d2(x)

    grid = _grid(who, t0, t1, dt, n)
    return Trajectory(grid, *evaluate(grid), names=names, info=info, evaluate=evaluate)


def waypoint_path(waypoints: npt.ArrayLike, *, model: _core.Model | None = None) -> Path:
    """The smooth geometric path through joint ``waypoints`` for :func:`time_optimal`: the
    natural cubic spline (C2) in the cumulative chord length (the knot of waypoint k is the
    joint-space distance travelled to it over the total): waypoints on one straight line give
    exactly that line at constant dq/ds, and, unlike a clamped spline, dq/ds is not forced to
    zero at the ends (where a zero path speed would make the timing singular).

    Args:
        waypoints: (m, n), m ≥ 2, no two consecutive equal ((m,): one joint).
        model: a fixed-base model (joint names; each waypoint must lie in its range).

    Returns:
        :class:`Path` with knots at the waypoints and an exact evaluator; ``info``: method,
        chord_lengths.

    Raises:
        ModelError: a bad argument (named), fewer than two waypoints, two consecutive equal
            waypoints (naming them), a waypoint outside the model's range.
        SolverError: the spline leaves a joint's range between the waypoints (naming the
            joint, the value and s).
    """
    from scipy.interpolate import CubicSpline

    who = "waypoint_path"
    arr = np.asarray(_checks.array(who, "waypoints", waypoints))
    points = _points(who, "waypoints", waypoints, 1 if arr.ndim == 1 else None)
    m, n = points.shape
    if m < 2:
        raise _core.ModelError(f"{who}: waypoints must hold at least two points, got {m}")
    if m > MAX_SAMPLES:
        raise _core.ModelError(f"{who}: {m} waypoints (> {MAX_SAMPLES})")
    names = _model_joints(who, model, n)
    _within_range(who, model, points, "waypoints")
    with np.errstate(over="ignore", invalid="ignore"):
        chords = np.linalg.norm(np.diff(points, axis=0), axis=1)
    if not np.all(np.isfinite(chords)):
        k = int(np.argmin(np.isfinite(chords)))
        raise _core.ModelError(
            f"{who}: the distance from waypoints[{k}] to waypoints[{k + 1}] overflows"
        )
    if not np.all(chords > 0.0):
        k = int(np.argmin(chords > 0.0))
        raise _core.ModelError(f"{who}: waypoints[{k}] and waypoints[{k + 1}] are equal")
    with np.errstate(over="ignore"):
        total = float(np.sum(chords))
    if not np.isfinite(total):
        raise _core.ModelError(f"{who}: the waypoints' distances overflow (total length inf)")
    s = np.concatenate([[0.0], np.cumsum(chords) / total])
    s[-1] = 1.0
    if not np.all(np.diff(s) > 0.0):
        k = int(np.argmin(np.diff(s) > 0.0))
        raise _core.ModelError(
            f"{who}: waypoints[{k}] to waypoints[{k + 1}] is too short beside the path's "
            f"length {total:g} (its knot would repeat)"
        )
    with np.errstate(all="ignore"):
        poly = CubicSpline(s, points, axis=0, bc_type="natural")
        finite = all(np.all(np.isfinite(poly.derivative(k).c)) for k in range(3))
    if not finite:
        raise _core.ModelError(f"{who}: the path overflows: the waypoints are too far apart")
    _stays_in_range(who, poly, model, names, "s")
    d1, d2 = poly.derivative(1), poly.derivative(2)

    def evaluate(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return poly(x), d1(x), d2(x)

    info = {
        "method": "waypoint_path (natural cubic spline in chord length)",
        "chord_lengths": chords,
    }
    return Path(s, points, evaluate=evaluate, names=names, info=info)


def drive_profile(
    traj: Trajectory, joint: int | str
) -> Callable[[float], tuple[float, float, float]]:
    """One joint of ``traj`` as ``ModelBuilder.add_drive`` takes it: a callable ``t -> (q, qd,
    qdd)``, exact where ``traj`` has an evaluator (every planner of this module's does), and at
    rest at the end position after the motion (and at the start position before it) when the
    motion ends (starts) at rest. A Python drive runs at every evaluation of the simulation:
    correct, but slower than ``armdyn.profiles``.

    Args:
        traj: a :class:`Trajectory` (fixed-base columns).
        joint: the column: an index, or a name of ``traj.names``.

    Raises:
        ModelError: an unknown joint (when built); a time outside the motion whose end is not
            at rest, or a non-finite time (when called, naming the time).
    """
    who = "drive_profile"
    if not isinstance(traj, Trajectory):
        raise _core.ModelError(f"{who}: traj must be an armdyn.motion.Trajectory")
    n = traj.qd.shape[1]
    if traj.q.shape[1] != n:
        raise _core.ModelError(f"{who}: traj has a floating base's quaternion; drive joints only")
    if isinstance(joint, str):
        if traj.names is None or joint not in traj.names:
            raise _core.ModelError(f"{who}: joint {joint!r} is not one of traj.names {traj.names}")
        j = traj.names.index(joint)
    else:
        j = int(_checks.integer(who, "joint", joint, lo=0, hi=n - 1))  # type: ignore[arg-type]
    t0, t1 = float(traj.t[0]), float(traj.t[-1])
    rest = [bool(abs(traj.qd[i, j]) <= 1e-12 and abs(traj.qdd[i, j]) <= 1e-9) for i in (0, -1)]
    ends = (float(traj.q[0, j]), float(traj.q[-1, j]))

    def profile(t: float) -> tuple[float, float, float]:
        if not np.isfinite(t):
            raise _core.ModelError(f"{who}: time {t!r} is not finite")
        for side, outside in ((0, t < t0), (1, t > t1)):
            if outside:
                if not rest[side]:
                    raise _core.ModelError(
                        f"{who}: t = {t:g} s is outside the motion [{t0:g}, {t1:g}] s, which "
                        f"is not at rest at its {('start', 'end')[side]}"
                    )
                return ends[side], 0.0, 0.0
        s = traj.sample([t])
        return float(s.q[0, j]), float(s.qd[0, j]), float(s.qdd[0, j])

    return profile
