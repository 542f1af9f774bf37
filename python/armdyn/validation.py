"""The Lagrange and geometric validators, and the error metrics of the five-DOF paper.

* :class:`LagrangeValidator` — the complete Euler–Lagrange equations of a tree model in its joint
  coordinates, ``d/dt ∂L/∂q̇ − ∂L/∂q = Q``, built in C++ from joint-space kinematics by automatic
  differentiation, independently of the Newton–Euler/KKT path. :meth:`LagrangeValidator.compare`
  checks a simulation or inverse-dynamics result against it with the paper's metrics.
* :func:`paper_model_3dof` — the paper's printed 3-DOF equations (9)–(11), kept as an explicitly
  named *paper model*: they are ``−∂L/∂θᵢ`` of a planar point-mass arm, without the
  ``d/dt ∂L/∂θ̇ᵢ`` terms.
* :func:`end_effector_position` — generic geometric validator (composed joint transforms, or a
  named frame by :func:`armdyn.frame_pose`), and
  :func:`paper_end_effector_5dof`, the paper's equations (22)–(25).
* :func:`torque_error_metrics` — equation (26) percentage errors and their equation (27) RMS.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from armdyn import _core


def torque_error_metrics(torques: npt.ArrayLike, reference: npt.ArrayLike) -> dict[str, Any]:
    """Equation (26) ``|T − T_ref| / max|T_ref| × 100`` per sample and joint (columns), their
    equation (27) RMS and maximum per joint, ``ref_max`` per joint and ``average`` (the mean of
    the per-joint RMS values, as the paper's Table 2 average)."""
    a = np.asarray(torques, dtype=float)
    r = np.asarray(reference, dtype=float)
    if a.ndim == 1:
        a, r = a[:, None], r[:, None]
    return _core.torque_error_metrics(a, r)


def average_of(values: npt.ArrayLike) -> float:
    """The paper's Table 2 average: the arithmetic mean of the per-joint RMS errors."""
    v = np.asarray(values, dtype=float)
    if v.size == 0 or not np.all(np.isfinite(v)):
        raise _core.ModelError("average_of: need finite values")
    return float(v.mean())


@dataclass
class Comparison:
    """Result of :meth:`LagrangeValidator.compare`."""

    t: npt.NDArray[np.float64]
    multibody: npt.NDArray[np.float64]  # (n, n_coords) efforts from the result, coordinate order
    reference: npt.NDArray[np.float64]  # (n, n_coords) Lagrange torques
    percent: npt.NDArray[np.float64]  # (n, n_coords) equation (26)
    rms: npt.NDArray[np.float64]  # (n_coords,) equation (27)
    max: npt.NDArray[np.float64]
    average: float
    coord_names: list[str]


class LagrangeValidator:
    """Complete Euler–Lagrange equations of a tree model (see the module docstring).

    Args:
        model: a finalized tree model of revolute/prismatic/cylindrical/fixed joints.
        rotational_inertia: ``False`` treats every body as a point mass at its centre of mass
            (a simplified model of the paper's kind).
    """

    def __init__(self, model: _core.Model, rotational_inertia: bool = True) -> None:
        """Derive the equations of ``model`` (ModelError if it is not such a tree)."""
        from armdyn import _checks

        if not isinstance(model, _core.Model):
            raise _core.ModelError(
                f"LagrangeValidator: model must be an armdyn.Model, got {type(model).__name__}"
            )
        inertia = _checks.flag("LagrangeValidator", "rotational_inertia", rotational_inertia)
        self.model = model
        self._v = _core.LagrangeValidator(model, inertia)

    def torques(
        self,
        q: npt.ArrayLike,
        qd: npt.ArrayLike,
        qdd: npt.ArrayLike,
        t: npt.ArrayLike | None = None,
    ) -> npt.NDArray[np.float64]:
        """Generalised actuator forces Q [N m or N] (model joint order) for one sample (1-D q
        (n_coords,), qd and qdd (n_dofs,); returns (n_dofs,)) or rows of samples ((n, ...);
        returns (n, n_dofs)); t [s] a scalar or one per row (default 0)."""
        return self._v.torques(q, qd, qdd, t)

    def mass_matrix(self, q: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """The joint-space mass matrix M(q) (n_dofs, n_dofs) [kg m^2 or kg] of the Lagrangian at
        q (n_coords,)."""
        return self._v.mass_matrix(q)

    def compare(self, result: Any, model: _core.Model | None = None) -> Comparison:
        """Compare the drive efforts of a simulation/inverse-dynamics result with this model.

        ``model`` is the model that produced ``result`` (default: the one the result holds,
        ``result.model``, else the validator's own; it must have the same joint coordinates).
        Every joint coordinate must be driven there; the efforts are reordered to coordinate
        order. Returns the equation (26) errors, their (27) RMS per joint and the average.
        """
        if model is None:
            model = getattr(result, "model", None)
        m = self.model if model is None else model
        if m.n_coords != self.model.n_coords:
            raise _core.ModelError(
                f"LagrangeValidator.compare: the result's model has {m.n_coords} joint "
                f"coordinates, the validator's {self.model.n_coords}"
            )
        coords = list(m.drive_coords)
        if sorted(coords) != list(range(m.n_coords)):
            raise _core.ModelError(
                "LagrangeValidator.compare: every joint coordinate needs exactly one drive; "
                f"drives act on coordinates {coords} of {m.n_coords}"
            )
        mb = np.empty_like(np.asarray(result.drive_forces, dtype=float))
        mb[:, coords] = result.drive_forces
        ref = self.torques(result.q, result.qd, result.qdd, result.t)
        met = torque_error_metrics(mb, ref)
        return Comparison(
            t=np.asarray(result.t),
            multibody=mb,
            reference=ref,
            percent=met["percent"],
            rms=met["rms"],
            max=met["max"],
            average=float(met["average"]),
            coord_names=list(m.coord_names),
        )


def paper_model_3dof(
    lengths: npt.ArrayLike,
    masses: npt.ArrayLike,
    theta: npt.ArrayLike,
    thetad: npt.ArrayLike,
    g: float = 9.81,
) -> npt.NDArray[np.float64]:
    """The paper's printed equations (9)–(11) (the *paper model*, incomplete by design).

    ``theta``: absolute link angles from the horizontal [rad], one sample (3,) or rows (n, 3);
    ``thetad`` their rates; point masses ``masses`` at the ends of links ``lengths``; ``g > 0``.
    Returns the generalised forces T₁…T₃ conjugate to the absolute angles.
    """
    return _core.paper_3dof_torques(lengths, masses, float(g), theta, thetad)


def paper_end_effector_5dof(
    theta: npt.ArrayLike, h: float, l1: float, l2: float, l34: float
) -> npt.NDArray[np.float64]:
    """The paper's equations (22)–(25): ``[X, Y, Z]`` in the paper's axes (Y up) for
    ``theta = (θ1 twist, θ2, θ3, θ4)`` [rad] taken as printed."""
    return _core.paper_5dof_end_effector(float(h), float(l1), float(l2), float(l34), theta)


def end_effector_position(
    model: _core.Model,
    body: str | None = None,
    point: npt.ArrayLike | None = None,
    q: npt.ArrayLike | None = None,
    *,
    frame: str | None = None,
) -> npt.NDArray[np.float64]:
    """World position of the end effector at joint coordinates ``q`` ((n_coords,) or rows).

    Either ``body`` and ``point`` (body frame, relative to the body's centre of mass), by composed
    joint transforms; or a named ``frame`` of the model (``model.frame_names``, e.g. a URDF
    ``tool0``) with ``point`` an optional offset in the frame's axes (default its origin), by
    :func:`armdyn.frame_pose`.
    """
    if q is None:
        raise _core.ModelError("end_effector_position: q is required")
    if frame is None:
        if body is None or point is None:
            raise _core.ModelError("end_effector_position: give body and point, or frame")
        return _core.end_effector_position(model, body, point, q)
    if body is not None:
        raise _core.ModelError("end_effector_position: give body and point, or frame, not both")
    offset = np.zeros(3) if point is None else np.asarray(point, dtype=float)
    if offset.shape != (3,) or not np.all(np.isfinite(offset)):
        raise _core.ModelError(
            f"end_effector_position: point must be 3 finite numbers, got {offset!r}"
        )
    pose = _core.frame_pose(model, q, frame)
    return pose[..., :3, 3] + pose[..., :3, :3] @ offset
