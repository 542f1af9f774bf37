"""Cartesian moves of a named frame: a straight line (:func:`linear_move`) or a circular arc
through a via point (:func:`arc_move`), the orientation interpolated by slerp, solved by inverse
kinematics into a joint :class:`~armdyn.motion.Path` (:class:`CartesianPath`).

The path is exact at any ``s``, not only at its knots: :meth:`CartesianPath.evaluate` solves the
inverse kinematics there (Newton, warm-started from the nearest knot with that knot's tangent),
so the frame stays on the line or arc to the solver's tolerance wherever the timing samples it,
and gives ``dq/ds = J^-1 dx/ds`` and ``d²q/ds² = J^-1 (d²x/ds² - J̇ dq/ds)`` (``J`` the frame
Jacobian's kept rows and moving joints: square, as the path needs a unique ``q(s)``).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from armdyn import _checks, _core

__all__ = ["CartesianPath", "arc_move", "linear_move"]
from armdyn.motion.ik import (
    ROWS,
    Task,
    check_pose,
    check_position,
    pose_error,
    rotation_exp,
    rotation_log,
    solve,
)
from armdyn.motion.trajectory import Path

_MIN_DS = 1e-7  # the smallest knot spacing the refinement tries before giving up
_MAX_KNOTS = 10_000  # each costs about a millisecond of inverse kinematics


class _Geometry:
    """The Cartesian path ``x(s)``, s in [0, 1]: positions (r, 3) and their first two
    s-derivatives, and the orientation ``R(s) = exp(s phi) R0`` (slerp: a constant angular
    rate ``phi`` per unit s, world axes)."""

    def __init__(self, r0: np.ndarray, r1: np.ndarray, who: str) -> None:
        self.r0 = r0
        self.phi = rotation_log(r1 @ r0.T)
        if np.linalg.norm(self.phi) > np.pi - 1e-6:
            raise _core.ModelError(
                f"{who}: the target's orientation is a half turn from the start's: the slerp "
                "between them has no unique axis (split the move)"
            )
        self.length = 0.0

    @property
    def angle(self) -> float:
        return float(np.linalg.norm(self.phi))

    def position(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        raise NotImplementedError

    def at(self, s: np.ndarray):
        """``(p (r, 3), R (r, 3, 3), xi (r, 6), xi' (r, 6))``: the pose at ``s`` and the frame's
        twist per unit s ``[dp/ds; w]`` and its s-derivative."""
        p, dp, ddp = self.position(s)
        r = rotation_exp(s[:, None] * self.phi) @ self.r0
        w = np.broadcast_to(self.phi, p.shape)
        xi = np.concatenate([dp, w], axis=1)
        dxi = np.concatenate([ddp, np.zeros_like(ddp)], axis=1)
        return p, r, xi, dxi


class _Line(_Geometry):
    def __init__(self, p0, p1, r0, r1, who) -> None:
        super().__init__(r0, r1, who)
        self.p0, self.d = p0, p1 - p0
        self.length = float(np.linalg.norm(self.d))

    def position(self, s):
        p = self.p0 + s[:, None] * self.d
        return p, np.broadcast_to(self.d, p.shape), np.zeros_like(p)


class _Arc(_Geometry):
    """The circle through ``p0``, ``via``, ``p1``, from ``p0`` through ``via`` to ``p1``:
    ``p(s) = c + rho (cos(theta s) u + sin(theta s) v)``."""

    def __init__(self, p0, via, p1, r0, r1, who) -> None:
        super().__init__(r0, r1, who)
        a, b = via - p0, p1 - p0
        n = np.cross(a, b)
        scale = np.linalg.norm(a) * np.linalg.norm(b)
        if scale == 0.0 or np.linalg.norm(n) <= 1e-9 * scale:
            raise _core.ModelError(
                f"{who}: the start, via and target positions are collinear or coincide: no "
                "circle passes through them"
            )
        c = p0 + (a @ a * np.cross(b, n) + b @ b * np.cross(n, a)) / (2.0 * (n @ n))
        self.c, self.rho = c, float(np.linalg.norm(p0 - c))
        self.u = (p0 - c) / self.rho
        self.v = np.cross(n / np.linalg.norm(n), self.u)
        at_via, at_end = self._angle(via), self._angle(p1)
        if at_via > at_end:  # via lies beyond p1 this way round: go the other way
            self.v = -self.v
            at_end = 2.0 * np.pi - at_end
        self.theta = at_end
        self.length = self.rho * self.theta

    def _angle(self, x) -> float:
        d = x - self.c
        return float(np.mod(np.arctan2(d @ self.v, d @ self.u), 2.0 * np.pi))

    def position(self, s):
        ang = self.theta * s[:, None]
        cos, sin = np.cos(ang), np.sin(ang)
        radial = cos * self.u + sin * self.v
        tangent = -sin * self.u + cos * self.v
        p = self.c + self.rho * radial
        return p, self.rho * self.theta * tangent, -self.rho * self.theta**2 * radial


class CartesianPath(Path):
    """A joint :class:`~armdyn.motion.Path` that moves a frame along a Cartesian line or arc.

    Besides the knots ``s`` and their configurations ``q``: ``poses`` (m, 4, 4) the frame's
    target pose at each knot (the frame is there to the solver's tolerance in the rows the
    ``mask`` keeps) and
    ``manipulability`` (m,) at each knot (over the kept rows). :meth:`evaluate` is exact at
    any ``s`` (inverse kinematics there). ``info``: ``method``, ``frame``, ``length`` [m],
    ``rotation`` [rad], ``lowest_manipulability`` (over the knots), ``refined_knots`` (the
    knots the step limiting added), ``mask`` (the rows followed), ``tol``, ``max_joint_step``.
    """

    __slots__ = ("_dq", "_geometry", "_min", "_task", "_tol", "manipulability", "poses")

    def _solve_at(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        task, geo = self._task, self._geometry
        i = np.clip(np.searchsorted(self.s, s), 1, len(self.s) - 1)
        i = np.where(s - self.s[i - 1] <= self.s[i] - s, i - 1, i)  # the nearest knot
        start = self.q[i] + self._dq[i] * (s - self.s[i])[:, None]
        p, r, xi, dxi = geo.at(s)
        q = _newton_rows(task, p, r, start, self._tol, s)
        _within_limits(task, q, s)
        return _derivatives(task, q, xi, dxi, s, p, self._min)[:3]


def _square(task: Task, j: np.ndarray) -> np.ndarray:
    """The kept rows and the moving joints' columns of Jacobians (r, 6, n): (r, k, k)."""
    return j[:, task.rows][:, :, task.chain]


def _newton_rows(task: Task, p, r, q0: np.ndarray, tol: float, s: np.ndarray) -> np.ndarray:
    """Newton on each row (batched ``frame_pose`` / ``frame_jacobian``) from ``q0`` (r, n) to
    the poses ``(p, R)``; SolverError naming the first ``s`` that does not converge in 30
    steps."""
    q = q0.copy()
    todo = np.arange(len(q))
    pos = task.rows < 3
    for _ in range(30):
        e = pose_error(task.pose(q[todo]), p[todo], r[todo])[:, task.rows]
        err = np.maximum(np.linalg.norm(e[:, pos], axis=1), np.linalg.norm(e[:, ~pos], axis=1))
        left = err > tol
        todo, e = todo[left], e[left]
        if len(todo) == 0:
            return q
        j = _square(task, task.jacobian(q[todo]))
        try:
            step = np.linalg.solve(j, e[:, :, None])[:, :, 0]
        except np.linalg.LinAlgError:
            break
        q[todo[:, None], task.chain] += step
    k = int(todo[0]) if len(todo) else 0
    raise _core.SolverError(
        f"{task.who}: the inverse kinematics at s = {s[k]:.9g} (position "
        f"{np.round(p[k], 6).tolist()}) does not converge to tol = {tol:g} from the nearest knot"
    )


def _within_limits(task: Task, q: np.ndarray, s: np.ndarray) -> None:
    bad = (q < task.lower) | (q > task.upper)
    if bad.any():
        k, i = (int(x) for x in np.argwhere(bad)[0])
        raise _core.SolverError(
            f"{task.who}: at s = {s[k]:.9g} joint {task.names[i]!r} leaves its limits "
            f"[{task.lower[i]:g}, {task.upper[i]:g}] (q = {q[k, i]:.9g})"
        )


def _derivatives(task: Task, q, xi, dxi, s, p, min_manip: float):
    """``(q, dq/ds, d²q/ds², det J)`` from the frame's twist per unit s ``xi`` and its
    derivative; SolverError naming the first ``s`` (position ``p``) where the manipulability
    ``|det J|`` (J square: the kept rows, the moving joints) is below ``min_manip`` or zero."""
    j = task.jacobian(q)
    js = _square(task, j)
    det = np.linalg.det(js)
    low = np.flatnonzero((np.abs(det) < min_manip) | (det == 0.0))
    if len(low):
        k = int(low[0])
        raise _core.SolverError(
            f"{task.who}: singularity at s = {s[k]:.9g} (position "
            f"{np.round(p[k], 6).tolist()} m): manipulability {abs(det[k]):.3g} < "
            f"min_manipulability = {min_manip:g}"
        )
    dq = np.zeros_like(q)
    dq[:, task.chain] = np.linalg.solve(js, xi[:, task.rows, None])[:, :, 0]
    bias = task.jdot_qdot(q, j, dq)[:, task.rows]
    ddq = np.zeros_like(q)
    ddq[:, task.chain] = np.linalg.solve(js, (dxi[:, task.rows] - bias)[:, :, None])[:, :, 0]
    return q, dq, ddq, det


def _check_square(task: Task) -> None:
    k, n = len(task.rows), len(task.chain)
    if k != n:
        kept = ", ".join(ROWS[i] for i in task.rows)
        raise _core.ModelError(
            f"{task.who}: frame {task.frame!r} is moved by {n} joints but the move keeps {k} "
            f"rows ({kept}): a path needs as many joints as kept rows for a unique q(s) (choose "
            f"{n} rows with mask=..., e.g. a planar arm [1, 1, 0, 0, 0, 1])"
        )


def _grid(who: str, geo: _Geometry, samples, max_step, max_joint_step: float) -> np.ndarray:
    """The first knots: ``samples`` evenly spaced, or as many as keep the frame's steps within
    ``max_step`` [m] and its rotation steps within ``max_joint_step`` [rad]."""
    if samples is not None and max_step is not None:
        raise _core.ModelError(f"{who}: give at most one of samples and max_step")
    if samples is not None:
        count = _checks.integer(who, "samples", samples, lo=2, hi=_MAX_KNOTS)
    else:
        step = _checks.number(
            who, "max_step", 0.01 if max_step is None else max_step, lo=0.0, lo_open=True
        )
        need = max(geo.length / step, geo.angle / max_joint_step)
        if need >= _MAX_KNOTS:
            raise _core.ModelError(
                f"{who}: max_step = {step:g} m (and max_joint_step = {max_joint_step:g} for the "
                f"rotation) gives {need:.3g} knots (at most {_MAX_KNOTS})"
            )
        count = max(2, int(np.ceil(need - 1e-9)) + 1)
    return np.linspace(0.0, 1.0, count)


class _Knots:
    """The knots solved so far (s, q, dq/ds, signed det J; the manipulability is |det J|)."""

    def __init__(self, task: Task, geo: _Geometry, min_manip: float) -> None:
        self.task, self.geo, self.min_manip = task, geo, min_manip
        self.s, self.q, self.dq, self.det = [], [], [], []

    @property
    def m(self) -> list[float]:
        return [abs(d) for d in self.det]

    def add(self, s: float, q: np.ndarray) -> None:
        """Add the IK solution ``q`` at ``s``, with its tangent; SolverError at a singularity:
        the manipulability below ``min_manip`` there, or det J changing sign since the last
        knot (det J is continuous along a continuous path: it crossed zero in between)."""
        ss = np.array([s])
        p, _, xi, dxi = self.geo.at(ss)
        _, dq, _, det = _derivatives(self.task, q[None, :], xi, dxi, ss, p, self.min_manip)
        if self.det and np.sign(det[0]) != np.sign(self.det[-1]):
            mid = self.geo.at(np.array([0.5 * (s + self.s[-1])]))[0][0]
            raise _core.SolverError(
                f"{self.task.who}: singularity met between s = {self.s[-1]:.9g} and {s:.9g} "
                f"(position {np.round(mid, 6).tolist()} m between them): det J changes sign "
                f"(manipulability {abs(self.det[-1]):.3g} and {abs(det[0]):.3g} at those knots)"
            )
        self.s.append(s)
        self.q.append(q)
        self.dq.append(dq[0])
        self.det.append(float(det[0]))


def _unreachable(task, geo, s, q, e, knots, tol) -> _core.SolverError:
    p = geo.at(np.array([s]))[0][0]
    pos = np.linalg.norm(e[task.rows < 3]) if np.any(task.rows < 3) else 0.0
    rot = np.linalg.norm(e[task.rows >= 3]) if np.any(task.rows >= 3) else 0.0
    held = task.at_limits(q)
    held = f"; joints at their limits: {', '.join(map(repr, held))}" if held else ""
    return _core.SolverError(
        f"{task.who}: the pose at s = {s:.9g} (position {np.round(p, 6).tolist()} m) is "
        f"unreachable from the path so far (inverse kinematics residual {pos:.3g} m, "
        f"{rot:.3g} rad, tol = {tol:g}{held}; the last solved knot s = {knots.s[-1]:.9g} has "
        f"manipulability {knots.m[-1]:.3g})"
    )


def _solve_knots(task, geo, q_start, grid, *, tol, max_joint_step, min_manip):
    """Walk the knots from s = 0: each solved by inverse kinematics from the last knot's
    tangent prediction; a step whose joints move more than ``max_joint_step`` (or stray from the
    prediction by more than half that: another branch) is halved (a knot inserted) down to
    1e-7 in s. SolverError at the first unreachable pose, at a knot whose manipulability is
    below ``min_manip`` or where det J changes sign between two knots (a singularity
    crossed)."""
    knots = _Knots(task, geo, min_manip)
    knots.add(0.0, q_start)  # the path starts at q_start's pose
    planned, k = list(grid[1:]), 0
    added = 0
    while k < len(planned):
        s0, s1 = knots.s[-1], planned[k]
        pred = knots.q[-1] + knots.dq[-1] * (s1 - s0)
        p, r, _, _ = geo.at(np.array([s1]))
        q, e, _, ok = solve(task, p[0], r[0], pred, tol=tol, max_iterations=50, damping=1e-12)
        jump = np.max(np.abs(q - knots.q[-1]))
        if ok and jump <= max_joint_step and np.max(np.abs(q - pred)) <= 0.5 * max_joint_step:
            knots.add(s1, q)
            k += 1
            continue
        if s1 - s0 < _MIN_DS:
            if ok:
                raise _core.SolverError(
                    f"{task.who}: the joint path jumps at s = {s1:.9g} (by {jump:.3g} rad or "
                    f"m over ds = {s1 - s0:.3g}): the branch is lost near a singularity "
                    f"(manipulability {knots.m[-1]:.3g} at s = {s0:.9g})"
                )
            raise _unreachable(task, geo, s1, q, e, knots, tol)
        if len(planned) + 1 >= _MAX_KNOTS:
            raise _core.SolverError(
                f"{task.who}: the step limiting needs more than {_MAX_KNOTS} knots (at s = "
                f"{s0:.9g}, max_joint_step = {max_joint_step:g}): raise max_joint_step"
            )
        planned.insert(k, 0.5 * (s0 + s1))
        added += 1
    return knots, added


def _build(who, model, frame, q_start, make_geometry, options) -> CartesianPath:
    """Check the arguments, solve the knots, verify the midpoints, return the path."""
    task = Task(who, model, frame, options["mask"])
    _check_square(task)
    q_start = task.check_q("q_start", q_start, within_limits=True)
    tol = _checks.number(who, "tol", options["tol"], lo=0.0, lo_open=True)
    max_joint_step = _checks.number(
        who, "max_joint_step", options["max_joint_step"], lo=0.0, lo_open=True
    )
    min_manip = _checks.number(who, "min_manipulability", options["min_manipulability"], lo=0.0)
    start = task.pose(q_start)
    geo = make_geometry(task, start[:3, 3], start[:3, :3])
    grid = _grid(who, geo, options["samples"], options["max_step"], max_joint_step)
    knots, added = _solve_knots(
        task, geo, q_start, grid, tol=tol, max_joint_step=max_joint_step, min_manip=min_manip
    )
    s = np.asarray(knots.s)
    p, r, _, _ = geo.at(s)
    poses = np.zeros((len(s), 4, 4))
    poses[:, :3, :3], poses[:, :3, 3], poses[:, 3, 3] = r, p, 1.0
    path = CartesianPath.__new__(CartesianPath)
    path._task, path._geometry, path._tol, path._min = task, geo, tol, min_manip
    path._dq = np.asarray(knots.dq)
    path.poses, path.manipulability = poses, np.asarray(knots.m)
    info = dict(
        method=who,
        frame=task.frame,
        length=geo.length,
        rotation=geo.angle,
        lowest_manipulability=float(np.min(path.manipulability)),
        tol=tol,
        max_joint_step=max_joint_step,
        refined_knots=added,
        mask=[ROWS[i] for i in task.rows],
    )
    Path.__init__(
        path,
        s,
        np.asarray(knots.q),
        evaluate=path._solve_at,
        names=tuple(model.coord_names),
        info=info,
    )
    _check_midpoints(path, max_joint_step)
    return path


def _check_midpoints(path: CartesianPath, max_joint_step: float) -> None:
    """The exact evaluation between the knots stays on the knots' branch and within the limits
    (SolverError otherwise, naming s)."""
    mid = 0.5 * (path.s[1:] + path.s[:-1])
    q, _, _ = path.evaluate(mid)
    gap = np.max(np.abs(q - 0.5 * (path.q[1:] + path.q[:-1])), axis=1)
    bad = np.flatnonzero(gap > 0.5 * max_joint_step)
    if len(bad):
        k = int(bad[0])
        raise _core.SolverError(
            f"{path._task.who}: between the knots s = {path.s[k]:.9g} and {path.s[k + 1]:.9g} "
            f"the inverse kinematics leaves the knots' branch (by {gap[k]:.3g})"
        )


def _target(who: str, target, r0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A 4x4 pose, or a position (3,) that keeps the start's orientation."""
    a = _checks.array(who, "target", target)
    if a.shape == (3,):
        return check_position(who, "target", a), r0
    return check_pose(who, "target", a)


def _options(**kw):
    return kw


def linear_move(
    model,
    frame: str | int,
    q_start: npt.ArrayLike,
    target: npt.ArrayLike,
    *,
    samples: int | None = None,
    max_step: float | None = None,
    orientation: str = "slerp",
    max_joint_step: float = 0.05,
    min_manipulability: float = 1e-4,
    tol: float = 1e-12,
    mask: npt.ArrayLike | None = None,
) -> CartesianPath:
    """The joint path that moves ``frame`` in a straight line from its pose at ``q_start`` to
    ``target``, the orientation interpolated by slerp (a constant rotation rate about one
    axis), both linear in ``s``.

    Args:
        model: a fixed-base :class:`armdyn.Model` (coordinates = rates; no joint between the
            frame and the ground may follow another through a coupling).
        frame: a name or an index of ``model.frame_names``.
        q_start: where the move starts (n_coords,), within the joint limits.
        target: the end pose (4, 4) ``[R p; 0 0 0 1]``, or a position (3,) keeping the start's
            orientation.
        samples: the number of evenly spaced first knots (2 to 10000); or
        max_step: the largest step of the frame between first knots [m] (default 0.01;
            rotations in steps of at most ``max_joint_step`` rad). Knots are then added where
            the joints move more than ``max_joint_step`` between two, or stray from the
            previous knot's tangent by more than half that (step limiting; at most 10000
            knots in all, SolverError beyond). Between the knots, each midpoint is evaluated
            once more to check that it stays on the branch and within the joint limits.
        orientation: ``"slerp"`` (the only interpolation).
        max_joint_step: the largest joint step between knots [rad or m]: keeps the branch
            continuous (a larger step, or one far from the tangent prediction, is halved).
        min_manipulability: SolverError where the manipulability (``|det J|``, J the kept rows
            and the moving joints) is below this, at a knot or wherever the path is evaluated
            (a singularity on the way, or the workspace's boundary); and wherever det J changes
            sign between two knots (a singularity crossed between them), whatever this is.
        tol: the inverse kinematics tolerance, at the knots and wherever the path is evaluated
            [m and rad].
        mask: the rows of ``[vx, vy, vz, wx, wy, wz]`` to follow (6 booleans), as many as
            joints move the frame (a planar 3R arm: ``[1, 1, 0, 0, 0, 1]``); the others are
            free. Default: all six.

    Returns:
        :class:`CartesianPath`, exact at any ``s``.

    Raises:
        ModelError: a bad argument (named), a half-turn rotation (no unique slerp axis).
        SolverError: the first unreachable pose (``s`` and position), the first singularity
            (``s`` and position, or the two knots around it) or the joint path jumping (the
            branch lost).
    """
    who = "linear_move"
    _checks.choice(who, "orientation", orientation, ("slerp",))

    def make(task, p0, r0):
        p1, r1 = _target(who, target, r0)
        return _Line(p0, p1, r0, r1, who)

    opts = _options(
        samples=samples,
        max_step=max_step,
        max_joint_step=max_joint_step,
        min_manipulability=min_manipulability,
        tol=tol,
        mask=mask,
    )
    return _build(who, model, frame, q_start, make, opts)


def arc_move(
    model,
    frame: str | int,
    q_start: npt.ArrayLike,
    via: npt.ArrayLike,
    target: npt.ArrayLike,
    *,
    samples: int | None = None,
    max_step: float | None = None,
    orientation: str = "slerp",
    max_joint_step: float = 0.05,
    min_manipulability: float = 1e-4,
    tol: float = 1e-12,
    mask: npt.ArrayLike | None = None,
) -> CartesianPath:
    """The joint path that moves ``frame`` along the circular arc from its position at
    ``q_start`` through the point ``via`` (3,) to ``target`` (at a constant angular rate in
    ``s``), the orientation interpolated by slerp from the start's to the target's (the via
    point has no orientation). Arguments, return and errors as :func:`linear_move`; also
    ModelError when the three positions are collinear or two coincide."""
    who = "arc_move"
    _checks.choice(who, "orientation", orientation, ("slerp",))

    def make(task, p0, r0):
        v = _checks.array(who, "via", via)
        if v.shape != (3,):
            raise _core.ModelError(f"{who}: via must be a position (3,), got shape {v.shape}")
        v = check_position(who, "via", v)
        p1, r1 = _target(who, target, r0)
        return _Arc(p0, v, p1, r0, r1, who)

    opts = _options(
        samples=samples,
        max_step=max_step,
        max_joint_step=max_joint_step,
        min_manipulability=min_manipulability,
        tol=tol,
        mask=mask,
    )
    return _build(who, model, frame, q_start, make, opts)
