"""A planned motion's joint torques as a run the sizing functions take: :func:`trajectory_run`
(inverse dynamics at every sample) and its :class:`TrajectoryRun`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from armdyn import _checks, _core
from armdyn._runs import model_of as _model_of
from armdyn.sizing.limits import limit_violations

if TYPE_CHECKING:
    import pandas as pd


@dataclass
class TrajectoryRun:
    """Joint torques along a planned motion (:func:`trajectory_run`), shaped like a run's
    result so that :func:`sizing_report` and :func:`limit_violations` take it.

    Attributes:
        t: (n,) times [s].
        q: (n, len(model.coord_names)) coordinates.
        qd, qdd: (n, len(model.dof_names)) rates and accelerations.
        joint_torques: (n, len(model.dof_names)) ``armdyn.inverse_dynamics`` at each sample.
        reaction_forces, reaction_torques: (n, len(model.joint_names), 3)
            ``armdyn.joint_reactions`` at each sample: what each joint's constraint applies to
            its child at the joint point, in the child's joint frame (every joint, fixed ones
            included; zero about/along a joint's free axes, where the joint torque acts), as
            ``SimulationResult.reaction_forces/reaction_torques``. None on a run not made by
            :func:`trajectory_run`.
        actuators: ``{joint: armdyn.actuators.MotorSide}`` for every actuator of the model
            (empty without actuators).
        model: the model the torques were computed with (:func:`trajectory_run` sets it; the
            default model of :func:`sizing_report`, :func:`limit_violations` and
            :func:`gear_ratio_sweep`).
    """

    t: npt.NDArray[np.float64]
    q: npt.NDArray[np.float64]
    qd: npt.NDArray[np.float64]
    qdd: npt.NDArray[np.float64]
    joint_torques: npt.NDArray[np.float64]
    actuators: dict[str, Any] = field(default_factory=dict)
    model: _core.Model | None = field(default=None, repr=False, compare=False)
    reaction_forces: npt.NDArray[np.float64] | None = field(default=None, repr=False)
    reaction_torques: npt.NDArray[np.float64] | None = field(default=None, repr=False)

    def limit_violations(self, model: _core.Model | None = None) -> pd.DataFrame:
        """See :func:`limit_violations`; ``model`` default :attr:`model`."""
        return limit_violations(_model_of(self, model, "TrajectoryRun.limit_violations"), self)


def trajectory_run(
    model: _core.Model,
    t: npt.ArrayLike,
    q: npt.ArrayLike | None = None,
    qd: npt.ArrayLike | None = None,
    qdd: npt.ArrayLike | None = None,
) -> TrajectoryRun:
    """The joint torques of a tree model along a planned motion: ``armdyn.inverse_dynamics``
    (recursive Newton–Euler, gravity, force elements and, with actuators, the reflected rotor
    terms included) at every sample, and every joint's reaction there
    (``armdyn.joint_reactions``), as a result :func:`sizing_report` takes.

    Args:
        model: a joint-space model (``model.joint_space``).
        t: (n,) strictly increasing times [s], or an ``armdyn.motion.Trajectory`` (then
            without q, qd, qdd).
        q: (n, len(model.coord_names)); qd, qdd: (n, len(model.dof_names)).

    Raises:
        ModelError: shapes that do not match the model, non-increasing times, or a model the
            joint-space inverse dynamics does not cover.
    """
    from armdyn.motion.trajectory import Trajectory

    if isinstance(t, Trajectory):
        if not (q is None and qd is None and qdd is None):
            raise _core.ModelError("trajectory_run: give a Trajectory alone, or t, q, qd, qdd")
        t, q, qd, qdd = t
    elif q is None or qd is None or qdd is None:
        raise _core.ModelError("trajectory_run: q, qd and qdd are required with times t")
    t = np.atleast_1d(_checks.array("trajectory_run", "t", t, finite=True))
    q, qd, qdd = (
        np.atleast_2d(_checks.array("trajectory_run", name, x, finite=True))
        for name, x in (("q", q), ("qd", qd), ("qdd", qdd))
    )
    nq, nv = len(model.coord_names), len(model.dof_names)
    if t.ndim != 1 or q.shape != (len(t), nq) or qd.shape != (len(t), nv) or qdd.shape != qd.shape:
        raise _core.ModelError(
            f"trajectory_run: expected t (n,), q (n, {nq}) over {list(model.coord_names)}, qd and "
            f"qdd (n, {nv}); got t {t.shape}, q {q.shape}, qd {qd.shape}, qdd {qdd.shape}"
        )
    if len(t) > 1 and not np.all(np.diff(t) > 0.0):
        raise _core.ModelError("trajectory_run: times must be strictly increasing")
    from armdyn.actuators import motor_side_of_result

    tau = np.asarray(_core.inverse_dynamics(model, q, qd, qdd, t), dtype=float)
    forces, torques = _core.joint_reactions(model, q, qd, qdd, t)
    run = TrajectoryRun(
        t=t.copy(),
        q=q.copy(),
        qd=qd.copy(),
        qdd=qdd.copy(),
        joint_torques=tau,
        model=model,
        reaction_forces=forces,
        reaction_torques=torques,
    )
    if getattr(model, "actuators", None):
        run.actuators = motor_side_of_result(model, run)
    return run
