"""Inverse kinematics of a named frame: damped least squares (Levenberg–Marquardt) on
:func:`armdyn.frame_pose` and :func:`armdyn.frame_jacobian` (``LOCAL_WORLD_ALIGNED``: linear rows
then angular rows, world axes at the frame's origin), joint limits respected by an active set;
the manipulability ``sqrt(det(J J^T))``; and the pieces the Cartesian moves share (the checked
task of one frame, pose checks, the pose error, ``J̇ q̇``).

The pose error of a configuration is ``e = [p* - p; log(R* R^T)]`` (metres, then the rotation
vector in world axes, radians): ``J dq = e`` is the Newton step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from armdyn import _checks, _core

__all__ = ["IKResult", "inverse_kinematics", "manipulability"]

#: the rows of a frame Jacobian and of a pose error, in order
ROWS = ("vx", "vy", "vz", "wx", "wy", "wz")
_ROTATION_TOL = 1e-9  # |R^T R - I| a target's rotation may have (it is then projected)
_FAR = 1e9  # [m] no target position beyond this (the errors' squares would overflow long before)
_COORDS = {"revolute": 1, "prismatic": 1, "cylindrical": 2}  # the joints frame_jacobian takes


@dataclass(frozen=True)
class IKResult:
    """What :func:`inverse_kinematics` found: the joint coordinates ``q`` (n_coords,), the
    remaining ``position_error`` [m] and ``orientation_error`` [rad] (norms over the rows the
    ``mask`` keeps), the ``iterations`` taken, the ``manipulability`` at ``q`` (over the kept
    rows) and the joints ``at_limits`` (at a position limit at the solution)."""

    q: np.ndarray
    position_error: float
    orientation_error: float
    iterations: int
    manipulability: float
    at_limits: tuple[str, ...]


def check_model(who: str, model) -> None:
    """ModelError unless ``model`` is a fixed-base tree (its coordinates are its rates: the only
    models whose joint paths ``q(s)`` are vectors)."""
    if not isinstance(model, _core.Model):
        raise _checks.ArgumentTypeError(
            f"{who}: model must be an armdyn.Model, got {type(model).__name__}"
        )
    if model.n_coords != model.n_dofs:
        raise _core.ModelError(
            f"{who}: the model has {model.n_coords} coordinates for {model.n_dofs} rates (a "
            "floating base or a spherical joint's quaternion); Cartesian motion needs a model "
            "whose coordinates are its rates"
        )
    if not model.is_tree:
        raise _core.ModelError(
            f"{who}: the model has closed loops; inverse kinematics needs a tree of joints"
        )
    # a tree whose independent coordinates are fewer than its joint coordinates less the
    # couplings' followers: ideal gears make the others dependent
    if model.n_joint_coords - model.n_coords > len(model.couplings):
        raise _core.ModelError(
            f"{who}: the model has ideal gears (its independent coordinates "
            f"{list(model.coord_names)} move the others through them); inverse kinematics needs "
            "a tree of independent joints"
        )


def check_frame(who: str, model, frame) -> str:
    """The name of ``frame`` (a name or an index into ``model.frame_names``)."""
    names = list(model.frame_names)
    if isinstance(frame, (bool, np.bool_)) or not isinstance(frame, (str, int, np.integer)):
        raise _checks.ArgumentTypeError(
            f"{who}: frame must be a frame name or an index into model.frame_names, "
            f"got {type(frame).__name__}"
        )
    if isinstance(frame, str):
        _checks.text(who, "frame", frame)
        if frame not in names:
            shown = ", ".join(repr(n) for n in names[:10]) + (" ..." if len(names) > 10 else "")
            raise _core.ModelError(f"{who}: unknown frame {frame!r} (known: {shown})")
        return frame
    if not 0 <= int(frame) < len(names):
        raise _core.ModelError(
            f"{who}: frame index {int(frame)} out of range ({len(names)} frames)"
        )
    return names[int(frame)]


def check_mask(who: str, mask) -> np.ndarray:
    """The rows of ``[vx, vy, vz, wx, wy, wz]`` a solve keeps (indices), from 6 booleans."""
    if mask is None:
        return np.arange(6)
    m = np.asarray(mask)
    if m.shape != (6,) or m.dtype.kind not in "biu" or not np.all((m == 0) | (m == 1)):
        raise _core.ModelError(
            f"{who}: mask must be 6 booleans (which of {', '.join(ROWS)} to keep), got "
            f"{_checks._shown(mask)}"
        )
    rows = np.flatnonzero(m)
    if len(rows) == 0:
        raise _core.ModelError(f"{who}: mask keeps no row")
    return rows


def check_position(who: str, name: str, p: np.ndarray) -> np.ndarray:
    """A position (3,): finite and within 1e9 m of the world origin."""
    _checks.finite_entries(who, name, p)
    if np.max(np.abs(p)) > _FAR:
        raise _core.ModelError(
            f"{who}: {name} = {p.tolist()} is farther than {_FAR:g} m from the world origin"
        )
    return p.copy()


def check_pose(who: str, name: str, pose) -> tuple[np.ndarray, np.ndarray]:
    """``(p (3,), R (3, 3))`` of a homogeneous transform ``pose`` (4, 4): finite, last row
    ``[0, 0, 0, 1]``, ``R`` a rotation to 1e-9 (``|R^T R - I|``, det +1), projected onto the
    nearest rotation; ``p`` within 1e9 m of the origin."""
    a = _checks.array(who, name, pose)
    if a.shape != (4, 4):
        raise _core.ModelError(f"{who}: {name} must be a 4x4 pose [R p; 0 0 0 1], got {a.shape}")
    _checks.finite_entries(who, name, a)
    if np.any(a[3] != (0.0, 0.0, 0.0, 1.0)):
        raise _core.ModelError(f"{who}: {name}'s last row must be [0, 0, 0, 1], got {a[3]}")
    r = a[:3, :3]
    off = float(np.max(np.abs(r.T @ r - np.eye(3))))
    if off > _ROTATION_TOL:
        raise _core.ModelError(
            f"{who}: {name}[:3, :3] is not a rotation matrix (|R^T R - I| = {off:.3g} > "
            f"{_ROTATION_TOL:g})"
        )
    if np.linalg.det(r) < 0.0:
        raise _core.ModelError(f"{who}: {name}[:3, :3] is a reflection (det = -1), not a rotation")
    u, _, vt = np.linalg.svd(r)
    return check_position(who, f"{name}[:3, 3]", a[:3, 3]), u @ vt


def rotation_log(r: np.ndarray) -> np.ndarray:
    """The rotation vectors ``theta a`` (..., 3) of rotation matrices (..., 3, 3): ``R = exp([theta
    a]x)``, theta in [0, pi]. With ``R = cos(theta) I + sin(theta) [a]x + (1 - cos(theta)) a a^T``:
    ``v = vee(R - R^T) / 2 = sin(theta) a`` and theta = atan2(|v|, (tr R - 1) / 2) (accurate at
    every angle); the axis is ``v / |v|`` up to a quarter turn, beyond that (where ``|v|`` loses
    precision, up to the half turn where it vanishes) the column of ``(R + R^T) / 2 - cos(theta)
    I = (1 - cos(theta)) a a^T`` with the largest diagonal entry, signed along ``v``."""
    v = 0.5 * np.stack(
        [r[..., 2, 1] - r[..., 1, 2], r[..., 0, 2] - r[..., 2, 0], r[..., 1, 0] - r[..., 0, 1]],
        axis=-1,
    )
    sin = np.linalg.norm(v, axis=-1)
    cos = np.clip(0.5 * (np.trace(r, axis1=-2, axis2=-1) - 1.0), -1.0, 1.0)
    theta = np.arctan2(sin, cos)
    small = theta < 1e-4  # theta / sin(theta) = 1 + theta^2 / 6 + 7 theta^4 / 360 + ...
    scale = np.where(small, 1.0 + theta**2 / 6.0, theta / np.where(small | (sin == 0.0), 1.0, sin))
    w = scale[..., None] * v
    wide = cos < 0.0
    if np.any(wide):
        sym = 0.5 * (r[wide] + np.swapaxes(r[wide], -1, -2)) - cos[wide][:, None, None] * np.eye(3)
        i = np.argmax(np.diagonal(sym, axis1=-2, axis2=-1), axis=-1)
        col = np.take_along_axis(sym, i[:, None, None], axis=-1)[..., 0]
        axis = col / np.linalg.norm(col, axis=-1, keepdims=True)
        sign = np.where(np.sum(axis * v[wide], axis=-1) < 0.0, -1.0, 1.0)
        w[wide] = (sign * theta[wide])[:, None] * axis
    return w


def rotation_exp(w: np.ndarray) -> np.ndarray:
    """The rotation matrices (..., 3, 3) of rotation vectors ``w`` (..., 3) (Rodrigues: ``I +
    sin(t)/t [w]x + (1 - cos(t))/t² [w]x²``, t = |w|, by their series below t = 1e-4)."""
    t = np.linalg.norm(w, axis=-1)[..., None, None]
    small = t < 1e-4
    safe = np.where(small, 1.0, t)
    a = np.where(small, 1.0 - t**2 / 6.0, np.sin(safe) / safe)
    b = np.where(small, 0.5 - t**2 / 24.0, (1.0 - np.cos(safe)) / safe**2)
    k = np.zeros((*w.shape[:-1], 3, 3))
    k[..., 0, 1], k[..., 0, 2], k[..., 1, 2] = -w[..., 2], w[..., 1], -w[..., 0]
    k[..., 1, 0], k[..., 2, 0], k[..., 2, 1] = w[..., 2], -w[..., 1], w[..., 0]
    return np.eye(3) + a * k + b * (k @ k)


def pose_error(poses: np.ndarray, p: np.ndarray, r: np.ndarray) -> np.ndarray:
    """``[p* - p; log(R* R^T)]`` (..., 6) of frame poses (..., 4, 4) against targets ``p``
    (..., 3) and ``R`` (..., 3, 3)."""
    dp = p - poses[..., :3, 3]
    rel = r @ np.swapaxes(poses[..., :3, :3], -1, -2)
    if rel.ndim == 2:  # one pose: the same formulas without numpy's per-call overheads
        return np.concatenate([dp, _rotation_log_one(rel)])
    return np.concatenate([dp, rotation_log(rel)], axis=-1)


def _rotation_log_one(r: np.ndarray) -> np.ndarray:
    """:func:`rotation_log` of one matrix (3, 3), in Python floats."""
    (a, b, c), (d, e, f), (g, h, i) = r.tolist()
    v = (0.5 * (h - f), 0.5 * (c - g), 0.5 * (d - b))
    sin = math.sqrt(v[0] ** 2 + v[1] ** 2 + v[2] ** 2)
    cos = min(1.0, max(-1.0, 0.5 * (a + e + i - 1.0)))
    if cos < 0.0:
        return rotation_log(r[None])[0]
    theta = math.atan2(sin, cos)
    scale = 1.0 + theta**2 / 6.0 if theta < 1e-4 else theta / sin
    return np.array([scale * v[0], scale * v[1], scale * v[2]])


def _chain_order(who: str, model, frame: str) -> list[int] | None:
    """The coordinates of the joints between ground and ``frame``, root first (None when one of
    them is not a revolute, prismatic, cylindrical or fixed joint); ModelError when one of them
    follows another joint through a coupling (its motion is then in the leader's column)."""
    by_child = {}
    for name in model.joint_names:
        jf = model.joint_frame(name)
        by_child[jf["child"]] = (name, jf)
    followers = {c["follower"]: c for c in model.couplings}
    body, order = model.frame(frame)["body"], []
    while body != "ground" and body in by_child:
        name, jf = by_child[body]
        if name in followers:
            raise _core.ModelError(
                f"{who}: joint {name!r}, which moves frame {frame!r}, follows joint "
                f"{followers[name]['leader']!r} through a coupling; inverse kinematics needs "
                "independent joints between the frame and the ground"
            )
        if jf["coord"] >= 0:
            if jf["type"] not in _COORDS:
                return None
            order += [int(jf["coord"]) + k for k in range(_COORDS[jf["type"]])][::-1]
        body = jf["parent"]
    return order[::-1]


class Task:
    """A frame of a model, checked once: its name, the error rows kept, the joint limits and the
    coordinates that move it (``chain``, root first)."""

    def __init__(self, who: str, model, frame, mask=None) -> None:
        check_model(who, model)
        self.who, self.model = who, model
        self.frame = check_frame(who, model, frame)
        self.rows = check_mask(who, mask)
        self.n = model.n_coords
        self.lower = np.asarray(model.coord_lower, dtype=float)
        self.upper = np.asarray(model.coord_upper, dtype=float)
        self.names = list(model.coord_names)
        try:
            j = self.jacobian(np.zeros(self.n))
        except _core.ModelError as err:
            raise _core.ModelError(f"{who}: {err}") from None
        moved = np.flatnonzero(np.any(j != 0.0, axis=0))
        order = _chain_order(who, model, self.frame)
        if order is None or sorted(order) != list(moved):  # pragma: no cover - frame_jacobian
            raise _core.ModelError(  # refuses these models first
                f"{who}: the joints that move frame {self.frame!r} are not a chain of revolute, "
                "prismatic and cylindrical joints"
            )
        self.chain = np.asarray(order, dtype=int)
        if len(self.chain) == 0:
            raise _core.ModelError(f"{who}: frame {self.frame!r} is not moved by any joint")

    # without data=: the core keeps one workspace per thread, so a path evaluates safely from
    # several threads
    def pose(self, q: np.ndarray) -> np.ndarray:
        return _core.frame_pose(self.model, q, self.frame)

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        return _core.frame_jacobian(self.model, q, self.frame)

    def at_limits(self, q: np.ndarray) -> tuple[str, ...]:
        hit = (q <= self.lower) | (q >= self.upper)
        return tuple(self.names[i] for i in np.flatnonzero(hit))

    def check_q(self, name: str, q, *, within_limits: bool) -> np.ndarray:
        """A configuration (n_coords,), finite; within the joint limits when asked."""
        a = _checks.array(self.who, name, q, finite=True)
        if a.shape != (self.n,):
            raise _core.ModelError(
                f"{self.who}: {name} must have shape ({self.n},) (the model's coordinates), "
                f"got {a.shape}"
            )
        if within_limits:
            bad = np.flatnonzero((a < self.lower) | (a > self.upper))
            if len(bad):
                i = int(bad[0])
                raise _core.ModelError(
                    f"{self.who}: {name}[{i}] = {a[i]:g} is outside joint {self.names[i]!r}'s "
                    f"limits [{self.lower[i]:g}, {self.upper[i]:g}]"
                )
        return a.copy()

    def manipulability(self, j: np.ndarray) -> np.ndarray:
        """``sqrt(det(J J^T))`` over the kept rows of Jacobians (..., 6, n)."""
        jr = j[..., self.rows, :]
        det = np.linalg.det(jr @ np.swapaxes(jr, -1, -2))
        return np.sqrt(np.maximum(det, 0.0))

    def jdot_qdot(self, q: np.ndarray, j: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """``J̇ q̇`` (rows, 6) at configurations ``q`` (rows, n) with Jacobians ``j`` (rows, 6, n),
        rates ``qd`` (rows, n): the frame's classical acceleration at ``q̈ = 0``, exact.

        Along the chain (root first), column ``i`` is ``[a_i; w_i]``: a rotation about the
        unit axis ``w_i`` through the point ``r_i`` has ``a_i = w_i x (p - r_i)``, a slide
        along ``a_i`` has ``w_i = 0`` (a cylindrical joint is both, about the same axis). The
        axis turns with the body before the joint (angular velocity ``W_i = sum_{k<i} w_k
        q̇_k``) and the frame's origin moves relative to the axis point at ``W_i x (p - r_i) +
        V_i`` with ``V_i = sum_{k>=i} a_k q̇_k``; so ``ẇ_i = W_i x w_i`` and ``ȧ_i = W_i x a_i +
        w_i x V_i`` (the Jacobi identity folds ``ẇ_i x (p - r_i) + w_i x (W_i x (p - r_i))``
        into ``W_i x a_i``). The two columns of a cylindrical joint share their axis, so their
        order does not matter (``w x w = 0``)."""
        c = self.chain
        jc, qc = j[:, :, c], qd[:, c][:, None, :]
        a, w = jc[:, :3, :], jc[:, 3:, :]
        wq, aq = w * qc, a * qc
        before = np.cumsum(wq, axis=2) - wq
        after = np.flip(np.cumsum(np.flip(aq, axis=2), axis=2), axis=2)
        da = np.cross(before, a, axis=1) + np.cross(w, after, axis=1)
        dw = np.cross(before, w, axis=1)
        return np.concatenate([np.sum(da * qc, axis=2), np.sum(dw * qc, axis=2)], axis=1)


def _damped_step(j: np.ndarray, e: np.ndarray, lam: float) -> np.ndarray:
    """``argmin |J dq - e|² + lam |dq|²`` through the SVD; singular values below 1e-12 of the
    largest (rows no joint moves: a planar arm's out-of-plane rows) are dropped."""
    u, sv, vt = np.linalg.svd(j, full_matrices=False)
    keep = sv > 1e-12 * max(sv[0], 1e-300)
    gain = np.where(keep, sv / (sv**2 + lam), 0.0)
    return vt.T @ (gain * (u.T @ e))


def _limited_step(task: Task, q: np.ndarray, j: np.ndarray, e: np.ndarray, lam: float):
    """The damped step with the joints at a limit that it would push further held (an active
    set, grown until no held joint is pushed out)."""
    free = np.ones(task.n, dtype=bool)
    dq = np.zeros(task.n)
    for _ in range(task.n + 1):
        dq[:] = 0.0
        if free.any():
            dq[free] = _damped_step(j[:, free], e, lam)
        out = free & (((q <= task.lower) & (dq < 0.0)) | ((q >= task.upper) & (dq > 0.0)))
        if not out.any():
            break
        free &= ~out
    return dq


def _norms(task: Task, e: np.ndarray) -> tuple[float, float]:
    pos = task.rows < 3
    return float(np.linalg.norm(e[pos])), float(np.linalg.norm(e[~pos]))


def solve(
    task: Task,
    p: np.ndarray,
    r: np.ndarray,
    q0: np.ndarray,
    *,
    tol: float,
    max_iterations: int,
    damping: float,
) -> tuple[np.ndarray, np.ndarray, int, bool]:
    """Levenberg–Marquardt from ``q0`` (clipped into the limits) towards the pose ``(p, R)``:
    the damping ``E + damping`` with ``E = |e|²/2`` (Sugihara 2011: large far from the target,
    vanishing at it, so the last steps are Newton's), each step halved until the error drops
    (at most 20 times) and projected onto the joint limits. Returns ``(q, e (kept rows),
    iterations, converged)``: converged when both the position and orientation error norms are
    at most ``tol``; not converged when ``max_iterations`` pass or no step lowers the error."""
    q = np.clip(q0, task.lower, task.upper)
    e = pose_error(task.pose(q), p, r)[task.rows]
    cost = 0.5 * float(e @ e)
    for it in range(max_iterations + 1):
        if max(_norms(task, e)) <= tol:
            return q, e, it, True
        if it == max_iterations:
            break
        j = task.jacobian(q)[task.rows]
        dq = _limited_step(task, q, j, e, cost + damping)
        for _ in range(20):
            qn = np.clip(q + dq, task.lower, task.upper)
            en = pose_error(task.pose(qn), p, r)[task.rows]
            cn = 0.5 * float(en @ en)
            if cn < cost:
                break
            dq *= 0.5
        else:
            break
        q, e, cost = qn, en, cn
    return q, e, it, False


def inverse_kinematics(
    model,
    frame: str | int,
    target: npt.ArrayLike,
    q0: npt.ArrayLike,
    *,
    tol: float = 1e-12,
    max_iterations: int = 200,
    damping: float = 1e-12,
    mask: npt.ArrayLike | None = None,
) -> IKResult:
    """Joint coordinates that put ``frame`` at the pose ``target``, starting from ``q0``.

    Damped least squares (Levenberg–Marquardt) on :func:`armdyn.frame_pose` and
    :func:`armdyn.frame_jacobian`: the step ``dq = argmin |J dq - e|² + λ |dq|²`` with the pose
    error ``e = [p* - p; log(R* R^T)]`` (world axes; metres and radians) and ``λ = |e|²/2 +
    damping`` (large far from the target, so the first steps are short; ``damping`` alone at
    the target, where the steps become Newton's and converge quadratically), each step halved
    until the error drops. Joint limits (``model.coord_lower/upper``) are respected: the
    iterates stay within them and a joint at a limit that the step would push further is held
    (an active set). Redundant arms take the least-norm step; the solution is the one this
    descent reaches from ``q0`` (no restarts: give a ``q0`` near the branch you want).

    Args:
        model: a fixed-base :class:`armdyn.Model` (coordinates = rates; no joint between the
            frame and the ground may follow another through a coupling).
        frame: a name or an index of ``model.frame_names``.
        target: the frame's world pose (4, 4) ``[R p; 0 0 0 1]``; ``R`` must be a rotation
            to 1e-9.
        q0: the start (n_coords,); clipped into the joint limits.
        tol: both the position error norm [m] and the orientation error norm [rad] at most this.
        max_iterations: at most this many steps.
        damping: the damping's floor λ at the target (> 0 keeps the step defined at a
            singularity).
        mask: 6 booleans, the rows of ``[vx, vy, vz, wx, wy, wz]`` to solve (default: all);
            the others are left free (a planar arm: ``[1, 1, 0, 0, 0, 1]``).

    Returns:
        :class:`IKResult` (``q``, the errors, iterations, manipulability, joints at limits).

    Raises:
        ModelError: a bad argument (named): an unknown frame, a non-rotation, NaN, shapes.
        SolverError: no convergence (the target is out of reach, blocked by the joint limits,
            or ``q0`` leads to a local minimum): the best errors and the joints at limits.
    """
    who = "inverse_kinematics"
    task = Task(who, model, frame, mask)
    p, r = check_pose(who, "target", target)
    start = task.check_q("q0", q0, within_limits=False)
    tol = _checks.number(who, "tol", tol, lo=0.0, lo_open=True)
    max_iterations = _checks.integer(who, "max_iterations", max_iterations, lo=1, hi=100_000)
    damping = _checks.number(who, "damping", damping, lo=0.0, lo_open=True)
    q, e, iterations, ok = solve(
        task, p, r, start, tol=tol, max_iterations=max_iterations, damping=damping
    )
    pos, rot = _norms(task, e)
    limits = task.at_limits(q)
    if not ok:
        held = f"; joints at their limits: {', '.join(map(repr, limits))}" if limits else ""
        raise _core.SolverError(
            f"{who}: no solution for frame {task.frame!r} at position {np.round(p, 6).tolist()} "
            f"(stopped after {iterations} iterations at position error {pos:.3g} m, "
            f"orientation error {rot:.3g} rad, tol = {tol:g}{held}); the pose may be out of "
            "reach, blocked by the joint limits, or q0 too far from a solution"
        )
    return IKResult(
        q=q,
        position_error=pos,
        orientation_error=rot,
        iterations=iterations,
        manipulability=float(task.manipulability(task.jacobian(q))),
        at_limits=limits,
    )


def manipulability(
    model, q: npt.ArrayLike, frame: str | int, *, mask: npt.ArrayLike | None = None
) -> float | np.ndarray:
    """Yoshikawa's manipulability ``sqrt(det(J J^T))`` of ``frame`` at ``q`` (n_coords,) or at
    each row of ``q`` (rows, n_coords): ``J`` the frame Jacobian's rows kept by ``mask`` (6
    booleans over ``[vx, vy, vz, wx, wy, wz]``; default all). Zero at a singularity, and
    always zero when fewer joints move the frame than rows are kept (a planar arm needs
    ``mask=[1, 1, 0, 0, 0, 1]`` or fewer rows)."""
    who = "manipulability"
    task = Task(who, model, frame, mask)
    a = _checks.array(who, "q", q, finite=True)
    if a.ndim not in (1, 2) or a.shape[-1] != task.n:
        raise _core.ModelError(
            f"{who}: q must have shape ({task.n},) or (rows, {task.n}), got {a.shape}"
        )
    m = task.manipulability(task.jacobian(a))
    return float(m) if a.ndim == 1 else m
