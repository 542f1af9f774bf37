"""Inverse dynamics of a driven model: the drives' efforts and the joint reactions along a
prescribed motion, from the driven constraints' multipliers (the Cartesian Newton–Euler/KKT
path)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from armdyn import _checks, _core

if TYPE_CHECKING:
    import pandas as pd


@dataclass
class InverseDynamicsResult:
    """Outputs of :func:`driven_inverse_dynamics`, one row per time.

    Attributes:
        t: (n,) times [s].
        u, v: (n, nq), (n, nv) Cartesian positions and velocities solving the driven constraints.
        q, qd, qdd: (n, n_coords) joint coordinates, rates and accelerations.
        drive_forces: (n, n_drives) actuator torque/force of each drive, applied to the child
            about/along the joint axis (the RNEA/URDF effort convention), τ = −δ_drive.
        reaction_forces, reaction_torques: (n, n_joints, 3) joint reactions on the child at the
            joint point, in the child's joint frame.
        position_residual, velocity_residual: (n,) max |f| and max |ζ v − rhs|.
        stats: Newton iterations, factorisations, run time [s].
        actuators: ``{joint: armdyn.actuators.MotorSide}`` for every actuator of the model
            (motor-side speed, torque, current, power, energy; empty without actuators).
        model: the model the result was computed with (the default model of
            :func:`armdyn.sizing_report`, :func:`armdyn.limit_violations`, ...).
    """

    t: npt.NDArray[np.float64]
    u: npt.NDArray[np.float64]
    v: npt.NDArray[np.float64]
    q: npt.NDArray[np.float64]
    qd: npt.NDArray[np.float64]
    qdd: npt.NDArray[np.float64]
    drive_forces: npt.NDArray[np.float64]
    reaction_forces: npt.NDArray[np.float64]
    reaction_torques: npt.NDArray[np.float64]
    position_residual: npt.NDArray[np.float64]
    velocity_residual: npt.NDArray[np.float64]
    stats: dict[str, Any] = field(default_factory=dict)
    actuators: dict[str, Any] = field(default_factory=dict)
    model: _core.Model | None = field(default=None, repr=False, compare=False)

    def limit_violations(self, model: _core.Model | None = None) -> pd.DataFrame:
        """Spans where this run exceeds the model's velocity and effort limits, as a DataFrame
        (joint, kind, t_start, t_end, worst, limit, samples); see
        :func:`armdyn.sizing.limit_violations`. ``model``: default the one the result was
        computed with (:attr:`model`); a model passed is checked against the result's
        columns."""
        from armdyn.sizing import limit_violations

        return limit_violations(model, self)


def driven_inverse_dynamics(model: _core.Model, t: npt.ArrayLike) -> InverseDynamicsResult:
    """Actuator efforts and joint reactions of a *driven* model along its prescribed motion.

    The model's drives must leave no degree of freedom. At each time of ``t`` (increasing, s)
    the position (Newton), velocity and acceleration problems of the driven constraints are
    solved, then the multipliers from ``Γ v' + ζᵀ δ = η``: the drives' multipliers are the
    actuator efforts (τ = −δ_drive, the torque/force the actuator applies to the child body
    about/along the joint axis), the others the joint reactions.

    For the joint torques of a tree at given ``(q, q̇, q̈)`` use :func:`armdyn.inverse_dynamics`.

    Raises:
        ModelError: under-driven model (the undriven coordinates are named), invalid times.
        SolverError: the driven constraints are kinematically singular at some time (the
            dependent drive/joint rows are named), or the position problem does not converge.
    """
    from armdyn.actuators import motor_side_of_result

    times = np.atleast_1d(_checks.array("driven_inverse_dynamics", "t", t))
    result = InverseDynamicsResult(**_core._inverse_dynamics_driven(model, times))
    result.model = model
    if getattr(model, "actuators", None) and len(times) > 0:
        result.actuators = motor_side_of_result(model, result)
    return result
