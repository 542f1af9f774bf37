"""Validation: a model's predicted joint torques against a log's measured ones.

:func:`validate` predicts the torques of a :class:`~armdyn.identification.log.MotionLog`'s
samples ``(q, qd, qdd)`` and compares them with the log's measured ``tau``, per joint:

- a model (``armdyn.Model``): its :func:`armdyn.inverse_dynamics` (the model's friction and
  rotor inertias included; a model has no sensor offset);
- a model and a parameter vector ``pi`` (:func:`armdyn.dynamic_parameters`' layout):
  ``joint_torque_regressor(model, q, qd, qdd) @ pi`` (offsets included);
- an identification (:class:`~armdyn.identification.estimate.Identification`, anything with
  ``predict(q, qd, qdd)``): its prediction, the identified offsets included.

With ``e = tau_predicted - tau_measured`` over the ``N`` samples: ``rmse = sqrt(mean(e**2))``,
``rel_rmse = rmse / sqrt(mean(tau_measured**2))`` (the error against the measured torque's RMS;
0 when both are 0, infinite when only the measured RMS is), ``max_error = max |e|`` and
``max_error_time`` the log's time of that sample (the first when tied). The validation should
use data the fit did not see (another motion, or :meth:`MotionLog.split`'s second part).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from armdyn import _core

if TYPE_CHECKING:
    import pandas as pd

#: samples predicted per call (the regressor of a block is CHUNK x n_dofs x n_params floats)
CHUNK = 1024


@dataclass(frozen=True)
class Validation:
    """Measured against predicted joint torques on one log (see the module notes).

    Attributes:
        t: (N,) the samples' times [s].
        tau_measured: (N, n_dofs) the log's torques.
        tau_predicted: (N, n_dofs) the prediction.
        joint_names: the columns' joints (the model's ``dof_names``).
        rmse: (n_dofs,) root-mean-square error per joint.
        max_error: (n_dofs,) largest absolute error per joint.
        max_error_time: (n_dofs,) the time of that error [s].
        rel_rmse: (n_dofs,) ``rmse`` over the measured torque's RMS.
        label: what predicted (``"identified"``, ``"nominal"``...), for tables and reports.
    """

    t: np.ndarray
    tau_measured: np.ndarray
    tau_predicted: np.ndarray
    joint_names: list[str]
    rmse: np.ndarray
    max_error: np.ndarray
    max_error_time: np.ndarray
    rel_rmse: np.ndarray
    label: str = ""

    @property
    def error(self) -> np.ndarray:
        """(N, n_dofs) ``tau_predicted - tau_measured``."""
        return self.tau_predicted - self.tau_measured

    @property
    def rms_measured(self) -> np.ndarray:
        """(n_dofs,) the measured torque's RMS per joint."""
        return np.sqrt(np.mean(self.tau_measured**2, axis=0))

    def table(self) -> pd.DataFrame:
        """One row per joint: ``rmse, rel_rmse, max_error, max_error_time, rms_measured``."""
        import pandas as pd

        return pd.DataFrame(
            {
                "rmse": self.rmse,
                "rel_rmse": self.rel_rmse,
                "max_error": self.max_error,
                "max_error_time": self.max_error_time,
                "rms_measured": self.rms_measured,
            },
            index=pd.Index(list(self.joint_names), name="joint"),
        )

    def largest_errors(self, count: int = 5) -> pd.DataFrame:
        """The ``count`` largest absolute errors of each joint (largest first): ``joint, t,
        measured, predicted, error``."""
        import pandas as pd

        from armdyn import _checks

        count = _checks.integer("Validation.largest_errors", "count", count, lo=1)
        err = self.error
        rows = []
        for j, name in enumerate(self.joint_names):
            order = np.argsort(-np.abs(err[:, j]), kind="stable")[:count]
            for k in order:
                rows.append(
                    (
                        name,
                        float(self.t[k]),
                        float(self.tau_measured[k, j]),
                        float(self.tau_predicted[k, j]),
                        float(err[k, j]),
                    )
                )
        return pd.DataFrame(rows, columns=["joint", "t", "measured", "predicted", "error"])


def compare(t, tau_measured, tau_predicted, joint_names, label: str = "") -> Validation:
    """The :class:`Validation` of given measured and predicted torques ((N, n_dofs) each, finite,
    N >= 1; ``t`` (N,))."""
    t = np.asarray(t, dtype=float).reshape(-1)
    meas = np.asarray(tau_measured, dtype=float)
    pred = np.asarray(tau_predicted, dtype=float)
    if meas.ndim != 2 or meas.shape != pred.shape or meas.shape[0] != t.size or t.size == 0:
        raise _core.ModelError(
            f"validate: measured {meas.shape} and predicted {pred.shape} torques must both be "
            f"(N, n_dofs) with N = len(t) = {t.size} >= 1"
        )
    if len(joint_names) != meas.shape[1]:
        raise _core.ModelError(
            f"validate: {len(joint_names)} joint names for {meas.shape[1]} torque columns"
        )
    for what, values in (("measured torques", meas), ("predicted torques", pred), ("t", t)):
        bad = np.argwhere(~np.isfinite(values.reshape(values.shape[0], -1)))
        if len(bad):
            row, col = bad[0]
            culprit = f", joint {joint_names[col]!r}" if values.ndim == 2 else ""
            raise _core.ModelError(f"validate: the {what} are not finite at sample {row}{culprit}")
    err = pred - meas
    rmse = np.sqrt(np.mean(err**2, axis=0))
    rms = np.sqrt(np.mean(meas**2, axis=0))
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(
            rms > 0.0, rmse / np.where(rms > 0.0, rms, 1.0), np.where(rmse > 0, np.inf, 0)
        )
    worst = np.argmax(np.abs(err), axis=0)
    cols = np.arange(err.shape[1])
    return Validation(
        t=t,
        tau_measured=meas,
        tau_predicted=pred,
        joint_names=[str(n) for n in joint_names],
        rmse=rmse,
        max_error=np.abs(err[worst, cols]),
        max_error_time=t[worst],
        rel_rmse=rel.astype(float),
        label=label,
    )


def _log_arrays(log: Any, n_coords: int, n_dofs: int):
    """The log's ``t, q, qd, qdd, tau`` as float arrays of the model's shapes."""
    try:
        arrays = [np.asarray(getattr(log, k), dtype=float) for k in ("t", "q", "qd", "qdd", "tau")]
    except AttributeError as exc:
        raise _core.ModelError(
            f"validate: log must be a MotionLog (t, q, qd, qdd, tau), got {type(log).__name__}"
        ) from exc
    t, q, qd, qdd, tau = arrays
    n = t.size
    for name, a, width in (("q", q, n_coords), ("qd", qd, n_dofs), ("qdd", qdd, n_dofs)):
        if a.shape != (n, width):
            raise _core.ModelError(
                f"validate: log.{name} has shape {a.shape}, the model needs ({n}, {width})"
            )
    if tau.shape != (n, n_dofs):
        raise _core.ModelError(f"validate: log.tau has shape {tau.shape}, expected ({n}, {n_dofs})")
    for name, a in (("q", q), ("qd", qd), ("qdd", qdd)):
        bad = np.argwhere(~np.isfinite(a))
        if len(bad):
            raise _core.ModelError(f"validate: log.{name} is not finite at sample {bad[0][0]}")
    return t, q, qd, qdd, tau


def _check_joints(log: Any, model) -> None:
    names = getattr(log, "joint_names", None)
    if names is not None and list(names) != list(model.dof_names):
        raise _core.ModelError(
            f"validate: the log's joints {list(names)} are not the model's {list(model.dof_names)}"
        )


def validate(model_or_identification: Any, log: Any, *, pi=None) -> Validation:
    """The :class:`Validation` of a model's (or an identification's) torques on ``log``'s
    samples (see the module notes for what predicts). ``pi``: with a model, the parameter
    vector to predict with (``joint_torque_regressor @ pi``, length
    ``len(dynamic_parameters(model))``); with an identification, it replaces the identified
    one. Raises ModelError when the log does not fit the model (joints, shapes, non-finite
    values) or ``pi`` has the wrong length or non-finite entries."""
    source = model_or_identification
    ident = None if isinstance(source, _core.Model) else source
    model = source if ident is None else getattr(source, "model", None)
    if not isinstance(model, _core.Model):
        raise _core.ModelError(
            f"validate: expected an armdyn.Model or an Identification, got {type(source).__name__}"
        )
    _check_joints(log, model)
    t, q, qd, qdd, tau = _log_arrays(log, model.n_coords, model.n_dofs)
    if t.size == 0:
        raise _core.ModelError("validate: the log has no sample")
    if pi is not None:
        pi = np.asarray(pi, dtype=float).reshape(-1)
        n_params = len(_core.dynamic_parameter_names(model))
        if pi.size != n_params:
            raise _core.ModelError(f"validate: pi has {pi.size} entries, the model {n_params}")
        if not np.all(np.isfinite(pi)):
            raise _core.ModelError(f"validate: pi[{int(np.argmin(np.isfinite(pi)))}] is not finite")

        def predict(*state):
            return _core.joint_torque_regressor(model, *state) @ pi

        label = "pi"
    elif ident is not None:
        predict, label = ident.predict, "identified"
    else:

        def predict(*state):
            return _core.inverse_dynamics(model, *state)

        label = "nominal"
    predicted = np.empty_like(tau)
    for start in range(0, t.size, CHUNK):  # bounded memory: Y is (rows, n_dofs, n_params)
        rows = slice(start, start + CHUNK)
        block = np.asarray(predict(q[rows], qd[rows], qdd[rows]), dtype=float)
        predicted[rows] = block.reshape(predicted[rows].shape)
    return compare(t, tau, predicted, list(model.dof_names), label)
