"""Reading a run's joint-rate columns and joint torques, and the trapezoid rule over its
samples, shared by :mod:`armdyn.sizing` and :mod:`armdyn.actuators`."""

from __future__ import annotations

import numpy as np

from armdyn import _core


def column_names(model) -> list[str]:
    names = getattr(model, "joint_dof_names", None)
    return list(names if names is not None else model.dof_names)


def checked(model, result, caller: str):
    """(t, column names, qd, efforts per column (NaN where none)) after checking that the
    result belongs to the model. The columns are ``model.joint_dof_names`` (a run's ``qd``),
    or ``model.dof_names`` for a result over the independent coordinates (a
    :class:`armdyn.sizing.TrajectoryRun` of a coupled model). Efforts:
    ``result.joint_torques`` when the result has them, else the drives' efforts summed per
    driven coordinate."""
    if not (hasattr(result, "t") and hasattr(result, "qd")):
        raise _core.ModelError(
            f"{caller}: result must be a SimulationResult, InverseDynamicsResult or "
            f"TrajectoryRun, got {type(result).__name__}"
        )
    names = column_names(model)
    t = np.asarray(result.t, dtype=float)
    qd = np.asarray(result.qd, dtype=float)
    if t.ndim != 1:
        raise _core.ModelError(f"{caller}: result.t must be one-dimensional, got shape {t.shape}")
    if qd.ndim == 2 and qd.shape[1] != len(names) and qd.shape[1] == len(model.dof_names):
        names = list(model.dof_names)
    if qd.ndim != 2 or qd.shape != (len(t), len(names)):
        raise _core.ModelError(
            f"{caller}: result.qd has shape {qd.shape} but the model has {len(names)} joint "
            f"rate columns ({names}) and the result {len(t)} samples: the result is not from "
            "this model"
        )
    drive_forces = getattr(result, "drive_forces", None)
    if drive_forces is not None:
        n_drives = len(model.drive_names)
        forces = np.asarray(drive_forces, dtype=float)
        if forces.ndim != 2 or forces.shape != (len(t), n_drives):
            raise _core.ModelError(
                f"{caller}: result.drive_forces has shape {forces.shape} but the model has "
                f"{n_drives} drives ({list(model.drive_names)}) and the result {len(t)} "
                "samples: the result is not from this model"
            )
    joint_torques = getattr(result, "joint_torques", None)
    if joint_torques is not None:
        tau = np.asarray(joint_torques, dtype=float)
        if tau.shape != qd.shape:
            raise _core.ModelError(
                f"{caller}: result.joint_torques has shape {tau.shape}, result.qd {qd.shape}: "
                "the result is inconsistent"
            )
        return t, names, qd, tau.copy()
    if drive_forces is None:
        raise _core.ModelError(f"{caller}: the result has neither joint_torques nor drive_forces")
    tau = np.full(qd.shape, np.nan)
    for d, col in enumerate(model.drive_coords):
        if not 0 <= col < len(names):
            raise _core.ModelError(
                f"{caller}: drive {model.drive_names[d]!r} acts on column {col}, outside the "
                f"{len(names)} joint rate columns"
            )
        tau[:, col] = np.where(np.isnan(tau[:, col]), 0.0, tau[:, col]) + forces[:, d]
    return t, names, qd, tau


def model_of(result, model, caller: str):
    """``model`` when given, else the model the result holds (``result.model``: a
    SimulationResult, InverseDynamicsResult or TrajectoryRun made by armdyn holds it); a result
    without one and no model passed is a ModelError naming ``model``."""
    if model is not None:
        return model
    held = getattr(result, "model", None)
    if held is None:
        raise _core.ModelError(
            f"{caller}: model is required: the result holds no model (result.model is None); "
            "pass the model the run was made with as model="
        )
    return held


def trapezoid_steps(y, t) -> np.ndarray:
    """The trapezoid rule's area of each sample interval, ½ (y[k] + y[k+1]) (t[k+1] − t[k]),
    per column when ``y`` is 2-D: the one place the rule is written (:func:`trapezoid`,
    :func:`armdyn.actuators.cumulative_trapezoid`)."""
    y = np.asarray(y, dtype=float)
    dt = np.diff(t)
    return 0.5 * (y[1:] + y[:-1]) * (dt[:, None] if y.ndim == 2 else dt)


def trapezoid(y, t) -> np.ndarray:
    """∫ y dt over the samples, per column of a 2-D ``y`` (trapezoid rule)."""
    return np.sum(trapezoid_steps(y, t), axis=0)


def time_mean(y, t) -> float:
    """(1 / (t[-1] − t[0])) ∫ y dt of a 1-D ``y`` (trapezoid rule)."""
    return float(trapezoid(np.asarray(y)[:, None], t)[0] / (t[-1] - t[0]))
