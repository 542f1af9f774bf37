"""Synthetic logs for the report's and the command's tests (issue 35).

``true_parameters``: a perturbed parameter vector (each body's 10 parameters scaled, friction and
offsets added: still physically consistent); ``synthetic_log``: a "measured" log of it along a
sum of sines, with Gaussian noise, torques ``joint_torque_regressor @ pi_true``, as a
:class:`armdyn.identification.MotionLog`."""

from __future__ import annotations

import armdyn as ad
import numpy as np
from armdyn.identification import log_from_arrays


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
    return log_from_arrays(model, t, q, tau, qd, qdd)
