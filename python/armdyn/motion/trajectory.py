"""The two shapes every motion tool of :mod:`armdyn.motion` speaks: a :class:`Trajectory` (a
timed joint motion, samples ``t, q, qd, qdd``) and a :class:`Path` (a geometric joint path
``q(s)``, ``s`` in [0, 1], with its first two derivatives in ``s``, not yet timed).

Planners return trajectories (point-to-point profiles, splines through timed waypoints, the
least-energy motion) or paths (waypoints without times, Cartesian moves); the time-optimal timing
turns a path into a trajectory. A trajectory unpacks as ``t, q, qd, qdd``, so
``armdyn.trajectory_run(model, *traj)`` (or ``trajectory_run(model, traj)``) sizes it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import numpy.typing as npt

from armdyn import _checks, _core

#: evaluate(t) -> (q, qd, qdd), each (len(t), n): the exact motion between the samples
Evaluator = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]


def _rows(who: str, name: str, x, n_rows: int, n_cols: int | None) -> np.ndarray:
    a = np.asarray(_checks.array(who, name, x, finite=True), dtype=float)
    if a.ndim == 1 and n_cols in (None, 1) and n_rows != 1:
        a = a[:, None]
    a = np.atleast_2d(a)
    if a.ndim != 2 or a.shape[0] != n_rows or (n_cols is not None and a.shape[1] != n_cols):
        want = f"({n_rows}, {n_cols if n_cols is not None else 'n'})"
        raise _core.ModelError(f"{who}: {name} must have shape {want}, got {a.shape}")
    return a


def _increasing(who: str, name: str, x) -> np.ndarray:
    a = np.atleast_1d(np.asarray(_checks.array(who, name, x, finite=True), dtype=float))
    if a.ndim != 1 or len(a) < 1:
        raise _core.ModelError(f"{who}: {name} must be a 1-D array of at least one value")
    if len(a) > 1 and not np.all(np.diff(a) > 0.0):
        i = int(np.argmin(np.diff(a) > 0.0))
        raise _core.ModelError(
            f"{who}: {name} must be strictly increasing ({name}[{i + 1}] = {a[i + 1]:g} after "
            f"{name}[{i}] = {a[i]:g})"
        )
    return a


class Trajectory:
    """A timed joint motion: ``t`` (n,) strictly increasing [s], ``q`` (n, n_coords), ``qd`` and
    ``qdd`` (n, n_dofs), sampled on a grid; ``evaluate`` (when the planner has it) gives the exact
    motion at any time in ``[t[0], t[-1]]``, so :meth:`sample` re-grids without interpolation
    error. ``info`` holds what the planner reports (method, limits met, manipulability, ...).

    Unpacks as ``t, q, qd, qdd``: ``armdyn.trajectory_run(model, *traj)``.
    """

    __slots__ = ("_evaluate", "info", "names", "q", "qd", "qdd", "t")

    def __init__(
        self,
        t: npt.ArrayLike,
        q: npt.ArrayLike,
        qd: npt.ArrayLike,
        qdd: npt.ArrayLike,
        *,
        names: tuple[str, ...] | list[str] | None = None,
        info: dict[str, Any] | None = None,
        evaluate: Evaluator | None = None,
    ) -> None:
        """The samples (checked: finite, t strictly increasing, matching rows; copied as
        float arrays), optional joint names (one per column of qd), planner info and exact
        evaluator ``evaluate(t) -> (q, qd, qdd)``."""
        who = "Trajectory"
        self.t = _increasing(who, "t", t)
        n = len(self.t)
        self.q = _rows(who, "q", q, n, None)
        self.qd = _rows(who, "qd", qd, n, None)
        self.qdd = _rows(who, "qdd", qdd, n, self.qd.shape[1])
        self.names = tuple(names) if names is not None else None
        if self.names is not None and len(self.names) != self.qd.shape[1]:
            raise _core.ModelError(
                f"{who}: {len(self.names)} names for {self.qd.shape[1]} joint rates"
            )
        self.info = dict(info or {})
        self._evaluate = evaluate

    def __iter__(self) -> Iterator[np.ndarray]:
        return iter((self.t, self.q, self.qd, self.qdd))

    def __len__(self) -> int:
        return len(self.t)

    def __repr__(self) -> str:
        method = self.info.get("method")
        return (
            f"<Trajectory {len(self.t)} samples over {self.duration:.6g} s, "
            f"{self.qd.shape[1]} joints{f', {method}' if method else ''}>"
        )

    @property
    def duration(self) -> float:
        """``t[-1] - t[0]`` [s]."""
        return float(self.t[-1] - self.t[0])

    def sample(self, t: npt.ArrayLike | None = None, *, dt: float | None = None) -> Trajectory:
        """The same motion on another grid: times ``t`` (within ``[t[0], t[-1]]``) or a step
        ``dt`` from ``t[0]`` to ``t[-1]`` (the end included). Exact with an evaluator; otherwise
        each sample interval is a quintic matching ``q, qd, qdd`` at both ends.

        Raises:
            ModelError: neither or both of ``t`` and ``dt``, times outside the motion.
        """
        who = "Trajectory.sample"
        if (t is None) == (dt is None):
            raise _core.ModelError(f"{who}: give exactly one of t and dt")
        if dt is not None:
            step = _checks.number(who, "dt", dt, lo=0.0, lo_open=True)
            count = int(np.ceil(self.duration / step - 1e-9))
            if count > 10_000_000:
                raise _core.ModelError(f"{who}: dt = {step:g} s gives {count} samples (> 1e7)")
            grid = np.append(self.t[0] + step * np.arange(count), self.t[-1])
        else:
            grid = _increasing(who, "t", t)
        span = 1e-12 * max(1.0, abs(self.t[-1]))
        if grid[0] < self.t[0] - span or grid[-1] > self.t[-1] + span:
            raise _core.ModelError(
                f"{who}: times [{grid[0]:g}, {grid[-1]:g}] outside the motion's "
                f"[{self.t[0]:g}, {self.t[-1]:g}] s"
            )
        grid = np.clip(grid, self.t[0], self.t[-1])
        q, qd, qdd = (self._evaluate or self._quintic)(grid)
        return Trajectory(
            grid, q, qd, qdd, names=self.names, info=self.info, evaluate=self._evaluate
        )

    def _quintic(self, grid: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        if self.q.shape[1] != self.qd.shape[1]:
            raise _core.ModelError(
                "Trajectory.sample: a floating base's quaternion cannot be interpolated "
                "(this trajectory has no evaluator)"
            )
        if len(self.t) == 1:
            shape = (len(grid), 1)
            return np.tile(self.q, shape), np.tile(self.qd, shape), np.tile(self.qdd, shape)
        i = np.clip(np.searchsorted(self.t, grid, side="right") - 1, 0, len(self.t) - 2)
        h = (self.t[i + 1] - self.t[i])[:, None]
        x = ((grid - self.t[i]) / h[:, 0])[:, None]
        q0, q1 = self.q[i], self.q[i + 1]
        v0, v1 = self.qd[i] * h, self.qd[i + 1] * h
        a0, a1 = self.qdd[i] * h**2, self.qdd[i + 1] * h**2
        # quintic Hermite: p(x) = q0 + v0 x + a0/2 x^2 + c3 x^3 + c4 x^4 + c5 x^5
        d = q1 - q0 - v0 - a0 / 2
        c3 = 10 * d - 4 * (v1 - v0 - a0) + (a1 - a0) / 2
        c4 = -15 * d + 7 * (v1 - v0 - a0) - (a1 - a0)
        c5 = 6 * d - 3 * (v1 - v0 - a0) + (a1 - a0) / 2
        q = q0 + x * (v0 + x * (a0 / 2 + x * (c3 + x * (c4 + x * c5))))
        qd = (v0 + x * (a0 + x * (3 * c3 + x * (4 * c4 + x * 5 * c5)))) / h
        qdd = (a0 + x * (6 * c3 + x * (12 * c4 + x * 20 * c5))) / h**2
        return q, qd, qdd

    def then_hold(self, dwell: float, *, samples: int = 2) -> Trajectory:
        """This motion followed by ``dwell`` seconds at rest at its last position (``samples``
        extra samples; the motion must end at rest: zero rates. An acceleration at the end, as
        the least-energy motion's, steps to zero as the hold begins)."""
        who = "Trajectory.then_hold"
        dwell = _checks.number(who, "dwell", dwell, lo=0.0, lo_open=True)
        samples = _checks.integer(who, "samples", samples, lo=1)
        if np.any(np.abs(self.qd[-1]) > 1e-9):
            raise _core.ModelError(f"{who}: the motion does not end at rest")
        extra = self.t[-1] + dwell * np.arange(1, samples + 1) / samples
        zeros = np.zeros((samples, self.qd.shape[1]))
        return Trajectory(
            np.concatenate([self.t, extra]),
            np.vstack([self.q, np.tile(self.q[-1], (samples, 1))]),
            np.vstack([self.qd, zeros]),
            np.vstack([self.qdd, zeros]),
            names=self.names,
            info={**self.info, "dwell": dwell},
        )


#: evaluate(s) -> (q, dq/ds, d2q/ds2), each (len(s), n)
PathEvaluator = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]


class Path:
    """A geometric joint path ``q(s)``, ``s`` in [0, 1] (fixed-base coordinates: ``q`` and its
    derivatives have the same columns), not yet timed. ``s`` (m,) are its knots (where the
    planner solved it: the waypoints, the Cartesian move's samples) and ``q`` (m, n) the
    configurations there; :meth:`evaluate` gives ``q, dq/ds, d2q/ds2`` anywhere: the planner's
    exact evaluator when it has one, else a natural cubic spline through the knots (C2, zero
    second derivative at both ends).
    """

    __slots__ = ("_evaluate", "info", "names", "q", "s")

    def __init__(
        self,
        s: npt.ArrayLike,
        q: npt.ArrayLike,
        *,
        evaluate: PathEvaluator | None = None,
        names: tuple[str, ...] | list[str] | None = None,
        info: dict[str, Any] | None = None,
    ) -> None:
        """Knots ``s`` (strictly increasing from 0 to 1) and configurations ``q`` (one row per
        knot), with the planner's exact ``evaluate(s) -> (q, dq/ds, d2q/ds2)`` when it has one."""
        who = "Path"
        self.s = _increasing(who, "s", s)
        if len(self.s) < 2 or self.s[0] != 0.0 or self.s[-1] != 1.0:
            raise _core.ModelError(f"{who}: s must run from 0 to 1 over at least two knots")
        self.q = _rows(who, "q", q, len(self.s), None)
        self.names = tuple(names) if names is not None else None
        self.info = dict(info or {})
        if evaluate is None:
            from scipy.interpolate import CubicSpline

            spline = CubicSpline(self.s, self.q, axis=0, bc_type="natural")
            d1, d2 = spline.derivative(1), spline.derivative(2)

            def evaluate(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
                return spline(x), d1(x), d2(x)

        self._evaluate = evaluate

    def __repr__(self) -> str:
        kind = self.info.get("method")
        return f"<Path {len(self.s)} knots, {self.q.shape[1]} joints{f', {kind}' if kind else ''}>"

    @property
    def n_joints(self) -> int:
        """The number of joint coordinates (columns of ``q``)."""
        return self.q.shape[1]

    def evaluate(self, s: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(q, dq/ds, d2q/ds2)`` at path parameters ``s`` in [0, 1], each (len(s), n)."""
        x = np.atleast_1d(np.asarray(_checks.array("Path.evaluate", "s", s, finite=True), float))
        if x.ndim != 1 or np.any(x < 0.0) or np.any(x > 1.0):
            raise _core.ModelError("Path.evaluate: s must be a 1-D array within [0, 1]")
        return self._evaluate(x)

    def timed(
        self, t: npt.ArrayLike, s: npt.ArrayLike, sd: npt.ArrayLike, sdd: npt.ArrayLike, **info
    ) -> Trajectory:
        """The trajectory of this path under the timing ``s(t)`` (samples ``t, s, ṡ, s̈``):
        ``q = q(s)``, ``qd = q'(s) ṡ``, ``qdd = q'(s) s̈ + q''(s) ṡ²``."""
        t = _increasing("Path.timed", "t", t)
        s, sd, sdd = (np.asarray(x, dtype=float).reshape(len(t)) for x in (s, sd, sdd))
        q, d1, d2 = self.evaluate(np.clip(s, 0.0, 1.0))
        return Trajectory(
            t,
            q,
            d1 * sd[:, None],
            d1 * sdd[:, None] + d2 * (sd**2)[:, None],
            names=self.names,
            info={**self.info, **info},
        )
