"""Synthetic logs and a stand-in identification for the report's tests (issue 35).

``synthetic_log``: a "measured" log of a perturbed parameter vector (each body's 10 parameters
scaled, friction and offsets added: still physically consistent) along a sum of sines, with
Gaussian noise; torques from ``joint_torque_regressor @ pi_true``.

``StandIn`` has the fields of the spec's ``Identification`` and is made by ``ols_standin``: base
parameters by QR with column pivoting of the stacked regressor, ordinary least squares, and the
completion closest to the nominal pi. It exists so that the report can be tested before the fit
part is merged; it is not the fit part's estimator."""

from __future__ import annotations

from dataclasses import dataclass, field

import armdyn as ad
import numpy as np
import scipy.linalg


@dataclass(frozen=True)
class Log:
    """MotionLog's fields."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    joint_names: list
    processing: str = "given"


def true_parameters(model, seed=0, scale=0.2, friction=(0.5, 0.8), offsets=0.1):
    """A perturbed pi: body blocks scaled by 1 + U(-scale, scale), fv, fc, offset added."""
    rng = np.random.default_rng(seed)
    names = ad.dynamic_parameter_names(model)
    pi = ad.dynamic_parameters(model).copy()
    for k, n in enumerate(names):
        if n.endswith(".m"):
            pi[k : k + 10] *= 1.0 + rng.uniform(-scale, scale)
    for c in model.coord_names:
        pi[names.index(f"{c}.fv")] += friction[0] * rng.uniform(0.5, 1.0)
        pi[names.index(f"{c}.fc")] += friction[1] * rng.uniform(0.5, 1.0)
        pi[names.index(f"{c}.offset")] = offsets * rng.uniform(-1.0, 1.0)
    return pi


def synthetic_log(model, pi_true, n=600, duration=6.0, noise=0.0, seed=1):
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, duration, n)
    d = model.n_dofs
    w = rng.uniform(0.6, 2.5, (2, d))
    a = rng.uniform(0.4, 1.0, (2, d))
    q = sum(a[k] * np.sin(np.outer(t, w[k]) + k) for k in range(2))
    qd = sum(a[k] * w[k] * np.cos(np.outer(t, w[k]) + k) for k in range(2))
    qdd = sum(-a[k] * w[k] ** 2 * np.sin(np.outer(t, w[k]) + k) for k in range(2))
    tau = ad.joint_torque_regressor(model, q, qd, qdd) @ pi_true
    tau = tau + noise * rng.normal(size=tau.shape)
    return Log(t, q, qd, qdd, tau, list(model.dof_names))


@dataclass(frozen=True)
class Base:
    param_names: list
    independent: np.ndarray
    matrix: np.ndarray
    names: list
    rank: int

    def regressor(self, y):
        return y[..., self.independent]

    def beta(self, pi):
        return self.matrix @ pi

    def complete(self, beta, pi_ref):
        return pi_ref + np.linalg.pinv(self.matrix) @ (beta - self.matrix @ pi_ref)


def qr_base(model, samples=60, seed=3):
    rng = np.random.default_rng(seed)
    d = model.n_dofs
    y = ad.joint_torque_regressor(
        model,
        rng.uniform(-3, 3, (samples, model.n_coords)),
        rng.normal(size=(samples, d)),
        rng.normal(size=(samples, d)),
    ).reshape(samples * d, -1)
    _, r, perm = scipy.linalg.qr(y, mode="economic", pivoting=True)
    rank = int(np.sum(np.abs(np.diag(r)) > 1e-9 * abs(r[0, 0])))
    k = scipy.linalg.solve_triangular(r[:rank, :rank], r[:rank, rank:])
    names = ad.dynamic_parameter_names(model)
    matrix = np.zeros((rank, len(names)))
    matrix[np.arange(rank), perm[:rank]] = 1.0
    matrix[:, perm[rank:]] = k
    matrix[np.abs(matrix) < 1e-10] = 0.0
    exprs = []
    for row in matrix:
        terms = [f"{c:+.4g} {names[j]}" for j, c in enumerate(row) if c != 0]
        exprs.append(" ".join(terms).replace("+1 ", "", 1))
    return Base(names, perm[:rank], matrix, exprs, rank)


@dataclass
class StandIn:
    model: object
    base: Base
    beta: np.ndarray
    beta_std: np.ndarray
    beta_ls: np.ndarray
    pi: np.ndarray
    physical: bool
    method: str
    solver: str
    sigma: np.ndarray
    rmse: np.ndarray
    n_samples: int
    outliers: np.ndarray = field(default_factory=lambda: np.zeros(0, int))

    def predict(self, q, qd, qdd):
        return ad.joint_torque_regressor(self.model, q, qd, qdd) @ self.pi


def ols_standin(model, log, base=None):
    base = base or qr_base(model)
    y = base.regressor(ad.joint_torque_regressor(model, log.q, log.qd, log.qdd))
    a = y.reshape(-1, base.rank)
    b = log.tau.reshape(-1)
    beta, *_ = np.linalg.lstsq(a, b, rcond=None)
    res = (y @ beta) - log.tau
    dof = max(a.shape[0] - base.rank, 1)
    s2 = float(res.reshape(-1) @ res.reshape(-1)) / dof
    std = np.sqrt(np.diag(s2 * np.linalg.inv(a.T @ a)))
    pi = base.complete(beta, ad.dynamic_parameters(model))
    rmse = np.sqrt(np.mean(res**2, axis=0))
    return StandIn(model, base, beta, std, beta, pi, False, "ols", "lstsq", rmse, rmse, len(log.t))
