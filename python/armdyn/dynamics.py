"""Inverse dynamics through driving constraints, on the Cartesian Newton–Euler/KKT path."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from armdyn import _core


@dataclass
class InverseDynamicsResult:
    """Outputs of :func:`inverse_dynamics` on a driven model, one row per time.

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
    """

    t: np.ndarray
    u: np.ndarray
    v: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    drive_forces: np.ndarray
    reaction_forces: np.ndarray
    reaction_torques: np.ndarray
    position_residual: np.ndarray
    velocity_residual: np.ndarray
    stats: dict = field(default_factory=dict)


def inverse_dynamics(model: _core.Model, q=None, qd=None, qdd=None, *, t=None, method=None):
    """Actuator efforts for a prescribed motion.

    Two forms:

    * ``inverse_dynamics(model, t=times)`` — a *driven* model whose drives leave no degree of
      freedom: at each time the position (Newton), velocity and acceleration problems of the
      driven constraints are solved, then the multipliers from ``Γ v' + ζᵀ δ = η``. Returns an
      :class:`InverseDynamicsResult` (drive efforts and joint reactions).
    * ``inverse_dynamics(model, q, qd, qdd, t=0.0)`` — a tree model in joint space: the joint
      torques/forces (model joint order; the model's own drives are ignored). 1-D inputs give a
      (n_coords,) array, 2-D inputs (one sample per row) a (n, n_coords) array; ``t`` may then
      be one time per row. ``method="recursive"`` (the default of this form): O(n) Newton–Euler
      sweeps over the Cartesian bodies (accelerations forward, subtree wrenches backward,
      projected on the joint axes); ``method="kkt"``: every joint coordinate driven to
      (q, qd, qdd) and the KKT multipliers of those drives. Both give the same torques to
      round-off (tests).

    Sign: the torque/force the actuator applies to the child body about/along the joint axis
    (the RNEA/URDF effort convention); gravity and every force element of the model are
    included.

    Raises:
        ModelError: under-driven model (the undriven coordinates are named), wrong shapes, NaN.
        SolverError: the driven constraints are kinematically singular at some time (the
            dependent drive/joint rows are named), or the position problem does not converge.
    """
    if q is None and qd is None and qdd is None:
        if t is None:
            raise _core.ModelError("inverse_dynamics: give t (driven model) or q, qd, qdd")
        if method is not None:
            raise _core.ModelError(
                "inverse_dynamics: method applies to the joint-space form (q, qd, qdd); the "
                "driven form always solves the driven constraints for their multipliers"
            )
        times = np.atleast_1d(np.asarray(t, dtype=float))
        raw = _core._inverse_dynamics_driven(model, times)
        return InverseDynamicsResult(**raw)
    if q is None or qd is None or qdd is None:
        raise _core.ModelError("inverse_dynamics: q, qd and qdd must all be given")
    solver = _core.JointSpaceInverseDynamics(model, method or "recursive")
    q, qd, qdd = (np.asarray(a, dtype=float) for a in (q, qd, qdd))
    if q.ndim == 1:
        return solver(q, qd, qdd, 0.0 if t is None else float(t))
    if q.ndim != 2 or qd.shape != q.shape or qdd.shape != q.shape:
        raise _core.ModelError(
            f"inverse_dynamics: q, qd, qdd must have one shape (n, {model.n_coords}); got "
            f"{q.shape}, {qd.shape}, {qdd.shape}"
        )
    times = np.zeros(len(q)) if t is None else np.broadcast_to(np.asarray(t, float), (len(q),))
    return np.array([solver(q[i], qd[i], qdd[i], float(times[i])) for i in range(len(q))])
