"""Duty cycles: a planned motion plus a dwell at its last pose, repeated N times or forever
(:func:`duty_cycle`, :class:`DutyCycle`), and the load one joint's drivetrain carries along it
(:meth:`DutyCycle.joint_load`, :class:`JointLoad`), which the vectorised motor, gearbox and
bearing checks take.

The cycle is kinematic: whatever the motion came with, its joint torques are recomputed by
inverse dynamics on the cycle's model (:func:`armdyn.sizing.trajectory_run`), so that
:meth:`DutyCycle.with_model` (the same motion on a model carrying other actuators' masses)
gives the new loads. During the dwell the arm holds the motion's last pose at rest: the
motion must end at rest (every rate zero to ``REST_TOLERANCE`` of its largest magnitude along
the motion), and the holding torques are the inverse dynamics at rest (gravity, springs). One
period's samples are the motion's, then the dwell's start and end (the dwell's start repeats
the motion's last time: the torque jumps there from the motion's last torque to the holding
one, a step of zero length). Peaks, RMS values and the thermal model take these samples.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from armdyn import _checks, _core

#: a motion ends at rest when every rate's last sample is at most this fraction of its largest
#: magnitude along the motion (plus REST_ABSOLUTE)
REST_TOLERANCE = 1e-6
#: absolute part of the rest test [rad/s or m/s]
REST_ABSOLUTE = 1e-9
#: the longest dwell [s] (about three years): longer is a stored machine, not a duty cycle
MAX_DWELL = 1e8

_WHO = "duty_cycle"


@dataclass(frozen=True)
class JointLoad:
    """The load one joint's drivetrain carries over one period of a :class:`DutyCycle` (SI,
    arrays over the period's n samples).

    Attributes:
        joint: the joint's name (a revolute or prismatic joint's coordinate).
        t: (n,) times [s].
        speed, acceleration: (n,) the joint's rate and acceleration (0 in the dwell).
        torque: (n,) the load torque the gearbox output delivers: the joint torque of the
            inverse dynamics without the joint's own actuator (when the model has one, its
            reflected rotor torque N T_rot is taken off).
        gravity_torque: (n,) the torque that holds the pose at rest (gravity and springs).
        force, moment: (n, 3) the joint's reaction wrench (on the child at the joint point, in
            the child's joint frame; ``SimulationResult.reaction_forces`` / ``_torques``).
        axis: (3,) the joint axis in that frame (z).
        inertia: (n,) the joint's diagonal of the mass matrix, its own actuator's N² J taken
            off.
        moving: (n,) False at the dwell's samples.
        period: the period [s] (motion + dwell).
        repeat: the number of periods, None for forever.
    """

    joint: str
    t: npt.NDArray[np.float64]
    speed: npt.NDArray[np.float64]
    acceleration: npt.NDArray[np.float64]
    torque: npt.NDArray[np.float64]
    gravity_torque: npt.NDArray[np.float64]
    force: npt.NDArray[np.float64]
    moment: npt.NDArray[np.float64]
    axis: npt.NDArray[np.float64]
    inertia: npt.NDArray[np.float64]
    moving: npt.NDArray[np.bool_]
    period: float
    repeat: int | None


@dataclass
class _Motion:
    """A motion's samples over the model's coordinates."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray


class DutyCycle:
    """A duty cycle (:func:`duty_cycle`): one period's samples, the motion's then the dwell's.

    Attributes:
        model: the model the torques were computed with.
        names: the columns of ``qd``, ``torque`` … (``model.dof_names``).
        t: (n,) times [s]; q (n, len(model.coord_names)); qd, qdd (n, ndof).
        torque: (n, ndof) inverse dynamics along the period (the model's actuators included).
        gravity_torque: (n, ndof) the holding torques at each sample's pose (at rest).
        reaction_forces, reaction_torques: (n, n_joints, 3) every joint's reaction along the
            period (``armdyn.joint_reactions``: as ``SimulationResult`` reports them).
        inertia: (n, ndof) the mass matrix's diagonal.
        moving: (n,) False at the dwell's samples.
        period: the period [s]; dwell: the dwell [s]; repeat: periods (None: forever).
    """

    def __init__(self, model, motion: _Motion, dwell: float, repeat: int | None):
        """Build with :func:`duty_cycle` (it checks the arguments); ``motion`` its samples."""
        self.model = model
        self._motion = motion
        self.dwell = dwell
        self.repeat = repeat
        self.names = list(model.dof_names)
        _check_rest(motion, self.names)
        self._build(model, motion, dwell)

    def _build(self, model, m: _Motion, dwell: float) -> None:
        from armdyn.sizing.trajectory import trajectory_run

        n_m = len(m.t)
        run = trajectory_run(model, m.t, m.q, m.qd, m.qdd)
        self._actuators = {str(a.joint): a for a in (getattr(model, "actuators", None) or [])}
        if dwell > 0.0:
            t_d = np.array([m.t[-1], m.t[-1] + dwell])
            rest = np.zeros((2, m.qd.shape[1]))
            self.t = np.concatenate([m.t, t_d])
            self.q = np.concatenate([m.q, np.repeat(m.q[-1:], 2, axis=0)])
            self.qd = np.concatenate([m.qd, rest])
            self.qdd = np.concatenate([m.qdd, rest])
        else:
            self.t, self.q, self.qd, self.qdd = m.t.copy(), m.q.copy(), m.qd.copy(), m.qdd.copy()
        zero = np.zeros_like(self.qd)
        self.gravity_torque = np.asarray(
            _core.inverse_dynamics(model, self.q, zero, zero, self.t), dtype=float
        )
        self.torque = np.concatenate([run.joint_torques, self.gravity_torque[n_m:]])
        self.moving = np.arange(len(self.t)) < n_m
        self.period = float(self.t[-1] - self.t[0])
        m_diag = np.asarray(_core.mass_matrix(model, self.q), dtype=float)
        self.inertia = np.diagonal(m_diag, axis1=1, axis2=2).copy()
        self.reaction_forces, self.reaction_torques = _reactions(
            model, self.t, self.q, self.qd, self.qdd
        )

    def with_model(self, model) -> DutyCycle:
        """The same motion, dwell and repeat on another model (same coordinates): the loads
        recomputed."""
        _check_columns(model, self._motion.q, self._motion.qd)
        return DutyCycle(model, self._motion, self.dwell, self.repeat)

    def joint_load(self, joint: str) -> JointLoad:
        """The :class:`JointLoad` of ``joint`` (a revolute or prismatic joint of the model's
        coordinates; ModelError naming it otherwise)."""
        joint = _checks.text("DutyCycle.joint_load", "joint", joint)
        if joint not in self.names:
            raise _core.ModelError(
                f"DutyCycle.joint_load: {joint!r} is not a joint coordinate ({self.names})"
            )
        names = list(self.model.joint_names)
        types = list(self.model.joint_types)
        if joint not in names or types[names.index(joint)] not in ("revolute", "prismatic"):
            raise _core.ModelError(
                f"DutyCycle.joint_load: {joint!r} is not a revolute or prismatic joint"
            )
        k, j = self.names.index(joint), names.index(joint)
        torque, inertia = self.torque[:, k].copy(), self.inertia[:, k].copy()
        own = self._actuators.get(joint)
        if own is not None:
            from armdyn.actuators import rotor_torque

            n = float(own.gear_ratio)
            torque -= n * rotor_torque(own, self.qd[:, k], self.qdd[:, k])
            inertia -= n * n * float(own.rotor_inertia)
        return JointLoad(
            joint=joint,
            t=self.t.copy(),
            speed=self.qd[:, k].copy(),
            acceleration=self.qdd[:, k].copy(),
            torque=torque,
            gravity_torque=self.gravity_torque[:, k].copy(),
            force=self.reaction_forces[:, j].copy(),
            moment=self.reaction_torques[:, j].copy(),
            axis=np.array([0.0, 0.0, 1.0]),
            inertia=inertia,
            moving=self.moving.copy(),
            period=self.period,
            repeat=self.repeat,
        )

    def __repr__(self) -> str:
        return (
            f"DutyCycle({len(self.names)} joints, period {self.period:.6g} s, dwell "
            f"{self.dwell:.6g} s, repeat {'forever' if self.repeat is None else self.repeat})"
        )


def _reactions(model, t, q, qd, qdd) -> tuple[np.ndarray, np.ndarray]:
    """Every joint's reaction wrench along the period: the one call to
    ``armdyn.joint_reactions`` (part of the cycle's loads: the output bearing's checks)."""
    from armdyn import _core as core

    forces, torques = core.joint_reactions(model, q, qd, qdd, t)
    return np.asarray(forces, dtype=float), np.asarray(torques, dtype=float)


def _check_columns(model, q: np.ndarray, qd: np.ndarray) -> None:
    nq, nv = len(model.coord_names), len(model.dof_names)
    if q.shape[1] != nq or qd.shape[1] != nv:
        raise _core.ModelError(
            f"{_WHO}: the motion has {q.shape[1]} coordinates and {qd.shape[1]} rates, the "
            f"model {nq} ({list(model.coord_names)}) and {nv}"
        )


def _check_rest(m: _Motion, names: list[str]) -> None:
    """The motion ends at rest (ModelError naming the first joint that does not)."""
    scale = np.max(np.abs(m.qd), axis=0)
    moving = np.abs(m.qd[-1]) > REST_TOLERANCE * scale + REST_ABSOLUTE
    if np.any(moving):
        k = int(np.argmax(moving))
        raise _core.ModelError(
            f"{_WHO}: the motion does not end at rest: joint {names[k]!r} moves at "
            f"{m.qd[-1, k]:.6g} at its last sample (t = {m.t[-1]:.6g} s); a duty cycle holds "
            "the last pose during the dwell and repeats the motion"
        )


def _motion(model, motion) -> _Motion:
    """The motion's samples over the model's coordinates from a TrajectoryRun, a
    SimulationResult, a trajectory CSV path or a (t, q, qd, qdd) tuple."""
    if isinstance(motion, (str, os.PathLike)):
        from armdyn.sizing.files import read_trajectory

        return _Motion(*read_trajectory(motion, model))
    if isinstance(motion, tuple) and len(motion) == 4:
        t, q, qd, qdd = motion
        return _Motion(*_arrays(t, q, qd, qdd))
    if not all(hasattr(motion, a) for a in ("t", "q", "qd", "qdd")):
        raise _core.ModelError(
            f"{_WHO}: motion must be a TrajectoryRun, a SimulationResult, a trajectory CSV "
            f"path or (t, q, qd, qdd), got {type(motion).__name__}"
        )
    from armdyn.sizing.motor import _independent_q

    q = _independent_q(model, motion)
    if q is None:
        raise _core.ModelError(
            f"{_WHO}: the motion's coordinates do not match the model's {list(model.coord_names)}"
        )
    qd, qdd = (_rate_columns(model, getattr(motion, a), a) for a in ("qd", "qdd"))
    return _Motion(*_arrays(motion.t, q, qd, qdd))


def _rate_columns(model, x, name: str) -> np.ndarray:
    """A result's rates over ``model.dof_names`` (its columns may be every joint's)."""
    x = np.atleast_2d(np.asarray(x, dtype=float))
    dofs = list(model.dof_names)
    if x.shape[1] == len(dofs):
        return x
    full = list(getattr(model, "joint_dof_names", []))
    if x.shape[1] == len(full) and all(d in full for d in dofs):
        return x[:, [full.index(d) for d in dofs]]
    raise _core.ModelError(
        f"{_WHO}: motion.{name} has {x.shape[1]} columns, the model {len(dofs)} ({dofs})"
    )


def _arrays(t, q, qd, qdd):
    t = np.atleast_1d(_checks.array(_WHO, "t", t, finite=True)).astype(float)
    q, qd, qdd = (
        np.atleast_2d(_checks.array(_WHO, name, x, finite=True)).astype(float)
        for name, x in (("q", q), ("qd", qd), ("qdd", qdd))
    )
    if t.ndim != 1 or len(t) < 2 or any(len(x) != len(t) for x in (q, qd, qdd)):
        raise _core.ModelError(
            f"{_WHO}: the motion needs two samples or more with t (n,) and q, qd, qdd (n, ...); "
            f"got t {t.shape}, q {q.shape}, qd {qd.shape}, qdd {qdd.shape}"
        )
    if not np.all(np.diff(t) > 0.0):
        raise _core.ModelError(f"{_WHO}: the motion's times must be strictly increasing")
    return t, q, qd, qdd


def duty_cycle(model, motion: Any, dwell: float = 0.0, repeat: int | None = None) -> DutyCycle:
    """A duty cycle: ``motion``, then ``dwell`` seconds holding its last pose, repeated
    ``repeat`` times (None: forever).

    Args:
        model: a joint-space model (the torques are its inverse dynamics along the motion).
        motion: a :class:`armdyn.sizing.TrajectoryRun`, an :class:`armdyn.SimulationResult`
            of a joint-space model (its joint columns), a trajectory CSV path (the format of
            ``armdyn size``: :func:`armdyn.sizing.files.read_trajectory`) or ``(t, q, qd,
            qdd)``. Its times must be strictly increasing and it must end at rest.
        dwell: the hold after the motion [s], finite, 0 ≤ dwell ≤ ``MAX_DWELL``.
        repeat: a positive integer, or None (the periodic steady state).

    The repeated cycle goes on from the dwell's end to the motion's first sample: a motion
    meant to repeat starts where it ends (not checked; its start need not be at rest).

    Returns:
        :class:`DutyCycle`.

    Raises:
        ModelError: a bad dwell or repeat (named), a motion that does not match the model
            or does not end at rest (naming the joint), a bad CSV (file, column, row).
    """
    dwell = float(_checks.number(_WHO, "dwell", dwell, lo=0.0, hi=MAX_DWELL))
    repeat = _checks.integer(_WHO, "repeat", repeat, lo=1, none=True)
    m = _motion(model, motion)
    _check_columns(model, m.q, m.qd)
    return DutyCycle(model, m, dwell, repeat)
