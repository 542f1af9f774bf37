"""Estimation of the dynamic parameters from a logged motion (issue 35).

``tau = Y(q, qd, qdd) pi`` is linear in pi, and only the base parameters ``beta = M pi``
(:class:`armdyn.identification.BaseParameters`) are identifiable: ``Y pi = Y_b beta``.
:func:`identify` stacks the base regressor over the log's samples and

1. **least squares** (``method="ols"``), or **weighted least squares** (``method="wls"``,
   Gautier's method): each joint's rows weighted by ``1 / sigma_j``, ``sigma_j`` the standard
   deviation of that joint's residual after an ordinary fit, re-estimated once from the
   weighted fit's residuals and refitted (two weighted solves). A joint whose residual is zero
   to round-off would get an infinite weight: every ``sigma_j`` is floored at ``1e-3`` times
   the largest (and a log fitted exactly to round-off keeps unit weights). Each joint's rows
   are compressed once (the R factor of ``[Y_b,j  tau_j]``, Q not formed), so a reweighting
   costs a QR of n_dofs small triangles, not of the log;
2. **outliers**: the samples (rows of the log) where any joint's weighted residual exceeds
   ``outlier_threshold`` times the weighted residual's standard deviation are removed, and step
   1 is redone once on the rest (``Identification.outliers`` lists them). A fit exact to
   round-off has no outliers;
3. **uncertainty**: ``cov(beta) = s^2 (A_w^T A_w)^-1`` with ``A_w`` the weighted stacked base
   regressor and ``s^2 = |r_w|^2 / (rows - n_base)``; ``beta_std`` its diagonal's root;
4. **a physically consistent estimate** (``physical=True``): the full pi minimising the same
   weighted residual ``|W (Y_b M pi - tau)|^2`` subject to every body's pseudo-inertia PSD, its
   mass ``>= 1e-6`` times the model's total mass, ``fv, fc, Ia >= 0``; in the compressed form
   ``|R M pi - Q^T b_w|^2`` (``A_w = Q R``, so the solver sees n_base rows, not the log's), plus
   a regulariser ``gamma |pi - pi_nominal|^2`` that fixes the non-identifiable directions at
   the nominal model's: ``gamma = 1e-4 s_min^2``, ``s_min`` the smallest singular value of R
   (the data's smallest curvature along a base parameter: the regulariser pulls no
   identifiable direction by more than ~1e-4 of its own curvature). Two solvers, the same
   problem:

   - ``solver="sdp"``: a semidefinite program through cvxpy (Clarabel), the pseudo-inertias
     as 4x4 PSD variables, the objective in units of the noise variance (so Clarabel's
     absolute tolerance is far below a meaningful change); cvxpy is a runtime dependency
     (imported on first use);
   - ``solver="log-cholesky"``: the log-Cholesky parametrisation (Rucker & Wensing 2022:
     ``J = U U^T``, U upper triangular with ``exp`` on its diagonal, so every J is positive
     definite) with ``scipy.optimize.least_squares`` (trust region, friction bounds as box
     bounds, analytic Jacobian, at most 500 evaluations), started at the least-squares
     estimate projected onto the consistent set.

   The default is chosen by the measurement of ``benchmarks/identification_fit.py`` (see
   :func:`identify`). The result is clipped onto the constraints (eigenvalues at 0, masses at
   the floor, friction at 0: a change of the solver's tolerance's size) and checked with
   :func:`armdyn.identification.is_physical`.

Coordinate parameters (fv, fc, offset, Ia) that the base parameters do not contain
(``base_parameters(friction=False)`` or ``offsets=False``) are held at the nominal model's:
their torque is subtracted from the log's before the fit.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass, field

import numpy as np

from armdyn import _core
from armdyn.identification import export
from armdyn.identification import physical as _phys
from armdyn.identification.base import one_blas_thread

__all__ = ["Identification", "identify"]

_SIGMA_FLOOR = 1e-3  # sigma_j >= _SIGMA_FLOOR * max(sigma)
_EXACT = 1e-11  # residual rms below _EXACT * rms(tau): a fit exact to round-off
_RANK_TOL = 1e-10  # singular values of R below _RANK_TOL * the largest: rank deficient
_MASS_FLOOR = 1e-6  # masses >= _MASS_FLOOR * the nominal total mass
_GAMMA = 1e-4  # regulariser weight relative to the smallest curvature of the data
_SOLVERS = ("sdp", "log-cholesky")
_SDP_UNIT_CAP = 1e12  # SDP: objective scale at most this x the normalised one
_LC_MAX_NFEV = 500  # log-Cholesky: least_squares evaluations at most
_LC_TR_SOLVER = "exact"  # log-Cholesky: trust-region steps by SVD (LSMR measured slower)
_LC_EXP_MAX = 60.0  # log-Cholesky: |alpha|, |d_i| clipped there (exp finite, squared too)


# ----------------------------------------------------------------------------------- result
@dataclass
class Identification:
    """The result of :func:`identify` (fields as in the issue 35 spec)."""

    model: object
    base: object
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
    outliers: np.ndarray
    #: details: ``weights`` (n_dofs,) of the final fit's rows, ``s2`` its weighted residual
    #: variance; with ``physical``: the solver's ``status``, the compressed ``cost`` of pi and
    #: ``cost_ls`` of the least-squares pi, the regulariser's ``gamma``
    info: dict = field(default_factory=dict)

    def predict(self, q, qd, qdd) -> np.ndarray:
        """The identified model's joint torques ``Y(q, qd, qdd) @ pi`` (offsets included): one
        state (1-D inputs) -> (n_dofs,), or a batch (2-D, rows = samples) -> (rows, n_dofs)."""
        y = _core.joint_torque_regressor(self.model, q, qd, qdd)
        return y @ self.pi

    def table(self):
        """Per base parameter: ``name``, ``nominal`` (the nominal model's), ``ls`` (the
        least-squares estimate), ``std`` (its standard deviation), ``identified`` (``beta``:
        the physically consistent one when ``physical``) -- a pandas DataFrame."""
        import pandas as pd

        nominal = self.base.beta(_core.dynamic_parameters(self.model))
        return pd.DataFrame(
            {
                "name": list(self.base.names),
                "nominal": nominal,
                "ls": self.beta_ls,
                "std": self.beta_std,
                "identified": self.beta,
            }
        )

    def parameters(self):
        """Per entry of pi: ``name``, ``nominal``, ``identified`` -- a pandas DataFrame. Only
        the base combinations are identified; the rest of ``identified`` is the nominal
        model's (the regulariser's or :meth:`BaseParameters.complete`'s choice)."""
        import pandas as pd

        return pd.DataFrame(
            {
                "name": list(self.base.param_names),
                "nominal": _core.dynamic_parameters(self.model),
                "identified": self.pi,
            }
        )

    def identified_model(self, *, urdf=None):
        """The model with the identified pi (``armdyn.identification.with_parameters``; the
        offsets, not a model parameter, are dropped)."""
        return export.with_parameters(self.model, self.pi, urdf=urdf)


# ------------------------------------------------------------------------------ input checks
def _log_field(log, name, shape, joint_names):
    if not hasattr(log, name):
        raise _core.ModelError(f"identify: log has no field '{name}' (a MotionLog)")
    a = np.asarray(getattr(log, name), dtype=float)
    if a.shape != shape:
        raise _core.ModelError(f"identify: log.{name} must have shape {shape}, got {a.shape}")
    bad = np.argwhere(~np.isfinite(a))
    if bad.size:
        row = int(bad[0][0])
        col = f", joint {joint_names[bad[0][1]]}" if a.ndim == 2 else ""
        raise _core.ModelError(
            f"identify: log.{name} is not finite at row {row}{col} ({a[tuple(bad[0])]})"
        )
    return a


def _check_log(model, log):
    if model.n_free:
        raise _core.ModelError(
            "identify: the model has a floating base; identification from joint logs takes "
            "fixed-base models"
        )
    coords = list(model.coord_names)
    names = list(getattr(log, "joint_names", []))
    if names != coords:
        missing = [c for c in coords if c not in names]
        extra = [c for c in names if c not in coords]
        raise _core.ModelError(
            f"identify: log.joint_names {names} do not match the model's coord_names {coords}"
            f" (missing {missing}, unknown {extra}): a log of another model?"
        )
    t = np.asarray(getattr(log, "t", None), dtype=float)
    n = t.shape[0] if t.ndim == 1 else -1
    if n < 1:
        raise _core.ModelError(f"identify: log.t must be 1-D and non-empty, got {t.shape}")
    q = _log_field(log, "q", (n, model.n_coords), coords)
    qd, qdd, tau = (_log_field(log, f, (n, model.n_dofs), coords) for f in ("qd", "qdd", "tau"))
    return q, qd, qdd, tau


def _check_options(method, solver, outlier_threshold):
    if method not in ("ols", "wls"):
        raise _core.ModelError(f"identify: method must be 'ols' or 'wls', got {method!r}")
    if solver not in _SOLVERS:
        raise _core.ModelError(f"identify: solver must be one of {_SOLVERS}, got {solver!r}")
    if outlier_threshold is not None and not (
        isinstance(outlier_threshold, numbers.Real)
        and not isinstance(outlier_threshold, bool)
        and 0 < outlier_threshold < np.inf
    ):
        raise _core.ModelError(
            f"identify: outlier_threshold must be a number > 0 (residual sigmas) or None, "
            f"got {outlier_threshold!r}"
        )


# ----------------------------------------------------------------------- least squares core
@dataclass
class _Fit:
    beta: np.ndarray
    r: np.ndarray  # R of the QR of the weighted stacked regressor A_w (n_base, n_base)
    c: np.ndarray  # Q^T b_w (b_w the weighted stacked torques)
    res: np.ndarray  # unweighted residual (N, n_dofs)
    w: np.ndarray  # weights (n_dofs,)
    s2: float  # weighted residual variance |r_w|^2 / (rows - n_base)


def _rank_error(sv, vt, base, rows, n_samples):
    n_base = len(base.names)
    rank = int(np.sum(sv > _RANK_TOL * sv[0])) if sv.size and sv[0] > 0 else 0
    weak = np.argsort(-np.abs(vt[-1]))[:3] if vt is not None else []
    names = ", ".join(repr(base.names[i]) for i in weak)
    cond = sv[0] / sv[-1] if sv.size and sv[-1] > 0 else np.inf
    return _core.SolverError(
        f"identify: rank deficient: the log excites only {rank} of the {n_base} base "
        f"parameters (rank of the stacked base regressor over {n_samples} samples, {rows} "
        f"rows; condition number {cond:.3g}){'; the least excited: ' + names if names else ''}."
        " Record a richer excitation (armdyn.identification.fourier_excitation) with more "
        "samples"
    )


def _compress(yb, tau):
    """Per joint j, the R factor of [Y_b,j  tau_j] (QR, Q not formed): the weighted problem of
    any per-joint weights is then the stack of w_j times these small triangles."""
    import scipy.linalg as sla

    n_samples, n_dofs, n_base = yb.shape
    out = []
    for j in range(n_dofs):
        aug = np.empty((n_samples, n_base + 1))
        aug[:, :n_base] = yb[:, j, :]
        aug[:, n_base] = tau[:, j]
        out.append(sla.qr(aug, mode="r", check_finite=False)[0][: n_base + 1])
    return out


def _solve(yb, tau, tri, w, base):
    import scipy.linalg as sla

    n_samples, n_dofs, n_base = yb.shape
    rows = n_samples * n_dofs
    stack = np.vstack([wj * t for wj, t in zip(w, tri, strict=True)])
    if stack.shape[0] < n_base:  # fewer rows than base parameters
        _, sv, vt = np.linalg.svd(stack[:, :n_base])
        sv = np.concatenate([sv, np.zeros(n_base - sv.size)])
        raise _rank_error(sv, vt, base, rows, n_samples)
    raug = sla.qr(stack, mode="r", check_finite=False)[0]
    r, c = raug[:n_base, :n_base], raug[:n_base, n_base]
    sv = np.linalg.svd(r, compute_uv=False)
    if sv[0] == 0.0 or sv[-1] <= _RANK_TOL * sv[0]:
        _, sv, vt = np.linalg.svd(r)
        raise _rank_error(sv, vt, base, rows, n_samples)
    beta = sla.solve_triangular(r, c, check_finite=False)
    res = tau - yb @ beta
    s2 = float(np.sum((res * w) ** 2) / max(rows - n_base, 1))
    return _Fit(beta, r, c, res, w, s2)


def _joint_sigma(res, n_base):
    n, n_dofs = res.shape
    dof = max(n - n_base / n_dofs, 1.0)
    return np.sqrt(np.sum(res**2, axis=0) / dof)


def _weights(res, n_base, exact):
    sigma = _joint_sigma(res, n_base)
    if exact or sigma.max() == 0.0:
        return np.ones_like(sigma)
    return 1.0 / np.maximum(sigma, _SIGMA_FLOOR * sigma.max())


def _fit_once(yb, tau, method, base, scale):
    tri = _compress(yb, tau)
    fit = _solve(yb, tau, tri, np.ones(tau.shape[1]), base)
    exact = _is_exact(fit.res, scale)
    if method == "wls":
        for _ in range(2):  # weights from OLS, then re-estimated once from the WLS residual
            fit = _solve(yb, tau, tri, _weights(fit.res, yb.shape[2], exact), base)
    return fit, exact


def _is_exact(res, scale):
    return float(np.sqrt(np.mean(res**2))) <= _EXACT * scale


def _least_squares(yb, tau, method, threshold, base):
    scale = max(float(np.sqrt(np.mean(tau**2))), np.finfo(float).tiny)
    fit, exact = _fit_once(yb, tau, method, base, scale)
    keep = np.arange(tau.shape[0])
    if threshold is not None and not exact and fit.s2 > 0.0:
        rw = np.abs(fit.res * fit.w[None, :]) / np.sqrt(fit.s2)
        bad = np.any(rw > threshold, axis=1)
        if bad.any():
            keep = np.flatnonzero(~bad)
            fit, exact = _fit_once(yb[keep], tau[keep], method, base, scale)
    return fit, keep, exact


# ------------------------------------------------------------------ physically consistent
@dataclass
class _Problem:
    """min |a pi - c|^2 + gamma |pi - pi_nom|^2 subject to the physical constraints."""

    a: np.ndarray  # (n_base, n_params): R M / s
    c: np.ndarray  # (n_base,)
    gamma: float
    pi_nom: np.ndarray
    n_bodies: int
    fixed: np.ndarray  # bool (n_params,): coordinate parameters held at nominal
    nonneg: np.ndarray  # bool (n_params,): fv, fc, Ia
    mass_floor: float
    unit: float  # cost() * unit: in units of the weighted noise variance

    def cost(self, pi):
        d = self.a @ pi - self.c
        return float(d @ d + self.gamma * np.sum((pi - self.pi_nom) ** 2)) * self.unit


def _problem(fit, base, pi_nom, n_bodies):
    # scaled so the solver sees O(1) numbers: a = R M / |R|_2 (a noise-free fit's s2 is ~0);
    # the regulariser relative to the smallest curvature is scale-free, the costs reported in
    # units of the weighted noise variance (chi-square) when there is noise
    sv = np.linalg.svd(fit.r, compute_uv=False)
    k = float(sv[0])
    a = fit.r @ np.asarray(base.matrix, dtype=float) / k
    c = fit.c / k
    gamma = _GAMMA * float(sv[-1] / sv[0]) ** 2
    unit = k * k / fit.s2 if fit.s2 > 0 else 1.0
    n = pi_nom.size
    coord = np.arange(n) >= 10 * n_bodies
    fixed = coord & ~np.any(np.asarray(base.matrix) != 0.0, axis=0)
    kind = (np.arange(n) - 10 * n_bodies) % 4
    nonneg = coord & ~fixed & (kind != 2)
    mass_floor = _MASS_FLOOR * float(sum(pi_nom[10 * k] for k in range(n_bodies)))
    return _Problem(a, c, gamma, pi_nom, n_bodies, fixed, nonneg, max(mass_floor, 1e-12), unit)


def _body_map():
    """T (10, 16): pi10 = T @ vec(J) (row-major vec of the 4x4 pseudo-inertia)."""
    t = np.zeros((10, 16))

    def e(i, j):
        return 4 * i + j

    t[0, e(3, 3)] = 1.0
    for k in range(3):
        t[1 + k, e(k, 3)] = 1.0
    # I = tr(S) 1 - S, S = J[:3, :3]
    t[4, [e(1, 1), e(2, 2)]] = 1.0  # Ixx
    t[5, e(0, 1)] = -1.0  # Ixy
    t[6, [e(0, 0), e(2, 2)]] = 1.0  # Iyy
    t[7, e(0, 2)] = -1.0  # Ixz
    t[8, e(1, 2)] = -1.0  # Iyz
    t[9, [e(0, 0), e(1, 1)]] = 1.0  # Izz
    return t


def _solve_sdp(p: _Problem):
    import cvxpy as cp

    nb = p.n_bodies
    n = p.pi_nom.size
    js = [cp.Variable((4, 4), PSD=True) for _ in range(nb)]
    x = cp.Variable(n - 10 * nb)
    t = _body_map()
    parts = [t @ cp.vec(j, order="C") for j in js] + [x]
    pi = cp.hstack(parts)
    cons = [j[3, 3] >= p.mass_floor for j in js]
    coord_nonneg = np.flatnonzero(p.nonneg[10 * nb :])
    coord_fixed = np.flatnonzero(p.fixed[10 * nb :])
    if coord_nonneg.size:
        cons.append(x[coord_nonneg] >= 0)
    if coord_fixed.size:
        cons.append(x[coord_fixed] == p.pi_nom[10 * nb :][coord_fixed])
    # the objective in units of the noise variance (capped for a noise-free log): Clarabel's
    # absolute gap tolerance (1e-8) is then far below a statistically meaningful change
    f = np.sqrt(min(p.unit, _SDP_UNIT_CAP))
    obj = cp.sum_squares(f * p.a @ pi - f * p.c) + f * f * p.gamma * cp.sum_squares(pi - p.pi_nom)
    prob = cp.Problem(cp.Minimize(obj), cons)
    try:
        prob.solve(solver=cp.CLARABEL)
    except cp.error.SolverError as err:
        raise _core.SolverError(
            f"identify: the physically consistent estimate (SDP, Clarabel) failed: {err}; "
            "solver='log-cholesky' solves the same problem"
        ) from err
    if prob.status not in ("optimal", "optimal_inaccurate") or pi.value is None:
        raise _core.SolverError(
            f"identify: the physically consistent estimate (SDP, Clarabel) failed: {prob.status}; "
            "solver='log-cholesky' solves the same problem"
        )
    return np.asarray(pi.value, dtype=float), prob.status


# ---- log-Cholesky
_U_INDEX = ((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3))


def _u_of(theta):
    """theta (nb, 10) = (alpha, d1, d2, d3, s12, s23, s13, t1, t2, t3) -> U (nb, 4, 4)."""
    nb = theta.shape[0]
    theta = theta.copy()
    theta[:, :4] = np.clip(theta[:, :4], -_LC_EXP_MAX, _LC_EXP_MAX)  # trial steps stay finite
    u = np.zeros((nb, 4, 4))
    u[:, 0, 0], u[:, 1, 1], u[:, 2, 2] = np.exp(theta[:, 1:4]).T
    u[:, 0, 1], u[:, 1, 2], u[:, 0, 2] = theta[:, 4:7].T
    u[:, 0, 3], u[:, 1, 3], u[:, 2, 3] = theta[:, 7:10].T
    u[:, 3, 3] = 1.0
    return u * np.exp(theta[:, 0])[:, None, None]


def _theta_of(j):
    """The log-Cholesky coordinates of positive definite pseudo-inertias j (nb, 4, 4)."""
    rev = j[:, ::-1, ::-1]
    u = np.linalg.cholesky(rev)[:, ::-1, ::-1]  # J = U U^T, U upper triangular
    ea = u[:, 3, 3]
    v = u / ea[:, None, None]
    th = np.empty((j.shape[0], 10))
    th[:, 0] = np.log(ea)
    th[:, 1:4] = np.log(np.stack([v[:, 0, 0], v[:, 1, 1], v[:, 2, 2]], axis=1))
    th[:, 4:7] = np.stack([v[:, 0, 1], v[:, 1, 2], v[:, 0, 2]], axis=1)
    th[:, 7:10] = np.stack([v[:, 0, 3], v[:, 1, 3], v[:, 2, 3]], axis=1)
    return th


def _dpi_dtheta(theta):
    """pi10 (nb, 10) and its Jacobian (nb, 10, 10) in theta."""
    u = _u_of(theta)
    t = _body_map()
    j = u @ np.swapaxes(u, 1, 2)
    pi10 = (j.reshape(-1, 16)) @ t.T
    jac = np.empty((*theta.shape, 10))
    jac[:, :, 0] = 2.0 * pi10  # d/dalpha: U -> U(1 + da), J -> J(1 + 2 da)
    for i, (r, c) in enumerate(_U_INDEX):
        du = np.zeros_like(u)
        du[:, r, c] = u[:, r, c] if r == c else u[:, 3, 3]
        dj = du @ np.swapaxes(u, 1, 2)
        dj = dj + np.swapaxes(dj, 1, 2)
        jac[:, :, i + 1] = dj.reshape(-1, 16) @ t.T
    return pi10, jac


def _project_pd(j, floor_rel, mass_floor):
    """Eigenvalues of each J clipped at floor_rel * tr(J) (and the mass at mass_floor)."""
    lam, v = np.linalg.eigh(j)
    tr = np.maximum(np.trace(j, axis1=1, axis2=2), mass_floor)
    lam = np.maximum(lam, floor_rel * tr[:, None])
    out = (v * lam[:, None, :]) @ np.swapaxes(v, 1, 2)
    out[:, 3, 3] = np.maximum(out[:, 3, 3], mass_floor)
    return 0.5 * (out + np.swapaxes(out, 1, 2))


def _pseudo_all(pi, nb):
    return np.stack([_phys.pseudo_inertia(pi[10 * k : 10 * k + 10]) for k in range(nb)])


def _solve_log_cholesky(p: _Problem, pi_start):
    from scipy.optimize import least_squares

    nb = p.n_bodies
    n = p.pi_nom.size
    j0 = _project_pd(_pseudo_all(pi_start, nb), 1e-6, p.mass_floor)
    free = np.flatnonzero(~p.fixed[10 * nb :]) + 10 * nb
    x_c = np.where(p.nonneg, np.maximum(pi_start, 0.0), pi_start)[free]
    x0 = np.concatenate([_theta_of(j0).ravel(), x_c])
    lo = np.concatenate([np.full(10 * nb, -np.inf), np.where(p.nonneg[free], 0.0, -np.inf)])
    sg = np.sqrt(p.gamma)

    def pi_of(x):
        pi = p.pi_nom.copy()
        pi10, jac = _dpi_dtheta(x[: 10 * nb].reshape(nb, 10))
        pi[: 10 * nb] = pi10.ravel()
        pi[free] = x[10 * nb :]
        return pi, jac

    def fun(x):
        pi, _ = pi_of(x)
        return np.concatenate([p.a @ pi - p.c, sg * (pi - p.pi_nom)])

    a_bodies = p.a[:, : 10 * nb].reshape(p.a.shape[0], nb, 10)
    a_free = p.a[:, free]

    def jac(x):
        # pi is block diagonal in x (a body's 10 in its 10 theta, a coordinate's in itself):
        # products per block (einsum), no dense (n_params x n_x) product
        _, jb = pi_of(x)
        top = np.concatenate(
            [np.einsum("rki,kij->rkj", a_bodies, jb).reshape(p.a.shape[0], -1), a_free], axis=1
        )
        low = np.zeros((n, x.size))
        for k in range(nb):
            low[10 * k : 10 * k + 10, 10 * k : 10 * k + 10] = sg * jb[k]
        low[free, 10 * nb + np.arange(free.size)] = sg
        return np.vstack([top, low])

    x0 = np.maximum(x0, lo)
    sol = least_squares(
        fun, x0, jac=jac, bounds=(lo, np.inf), method="trf", x_scale="jac", tr_solver=_LC_TR_SOLVER,
        ftol=1e-12, xtol=1e-12, gtol=1e-12, max_nfev=_LC_MAX_NFEV,
    )  # fmt: skip
    return pi_of(sol.x)[0], f"{sol.status}: {sol.message}"


def _clip_physical(p: _Problem, pi):
    nb = p.n_bodies
    out = pi.copy()
    j = _project_pd(_pseudo_all(pi, nb), 0.0, p.mass_floor)
    out[: 10 * nb] = _phys.pi10_from_pseudo_inertia(j).ravel()
    out[p.nonneg] = np.maximum(out[p.nonneg], 0.0)
    out[p.fixed] = p.pi_nom[p.fixed]
    return out


def _physical(fit, base, pi_nom, n_bodies, solver, pi_ls):
    p = _problem(fit, base, pi_nom, n_bodies)
    if solver == "sdp":
        pi, status = _solve_sdp(p)
    else:
        pi, status = _solve_log_cholesky(p, pi_ls)
    return _clip_physical(p, pi), status, p


# ------------------------------------------------------------------------------- identify
def _base_for(model, base, friction, offsets):
    if base is None:
        from armdyn.identification.base import base_parameters

        return base_parameters(model, friction=friction, offsets=offsets)
    names = list(_core.dynamic_parameter_names(model))
    if list(base.param_names) != names:
        raise _core.ModelError(
            "identify: base.param_names are not this model's dynamic_parameter_names "
            "(base parameters of another model?)"
        )
    return base


def _complete(base, beta, pi_ref):
    if hasattr(base, "complete"):
        return np.asarray(base.complete(beta, pi_ref), dtype=float)
    m = np.asarray(base.matrix, dtype=float)
    return pi_ref + np.linalg.lstsq(m, beta - m @ pi_ref, rcond=None)[0]


def identify(
    model,
    log,
    *,
    base=None,
    method="wls",
    physical=True,
    solver="sdp",
    outlier_threshold=3.0,
    friction=True,
    offsets=True,
) -> Identification:
    """Identify the base parameters of ``model`` (fixed base) from ``log`` (a
    :class:`armdyn.identification.MotionLog`: t, q, qd, qdd, tau, joint_names =
    ``model.coord_names``). See the module's docstring for the method.

    base: :class:`BaseParameters` of this model (default ``base_parameters(model,
    friction=friction, offsets=offsets)``); method ``"ols"`` or ``"wls"``; physical: also the
    physically consistent estimate (``beta`` and ``pi`` are then that one's); solver ``"sdp"``
    or ``"log-cholesky"`` (the same problem). Default ``"sdp"``, by the measurement of
    ``python -m benchmarks.identification_fit --repeats 3`` (benchmarks/results/
    identification_fit.json: 10,000 noisy samples of a perturbed Panda, 8 coordinates, 78 base
    parameters, and UR5, 58; each with the truth inside the consistent set and on its boundary,
    fc = 0; whole identify() calls, median of 3, on the shared 2-core machine at load 6-10):
    both solvers end physically consistent at the same cost (to 6e-4 relative; the costs are
    in units of the noise variance, and differ by < 2e-5 of it), but the SDP reports optimality
    and took 4.5 / 0.53 / 1.4 / 0.75 s (Panda / UR5 / Panda at fc = 0 / UR5 at fc = 0) against
    log-Cholesky's 12.9 / 3.0 / 4.6 / 2.8 s, which stopped at its 500-evaluation cap in 3 of
    the 4: the optima lie on the boundary (the SDP's smallest pseudo-inertia eigenvalue is
    <= 5e-7 in all four), which log-Cholesky's exp-parametrised interior only creeps toward.
    log-Cholesky needs no cvxpy. friction, offsets: for the default base (a given ``base`` has
    its own columns).
    outlier_threshold: residual sigmas (> 0), or None for no outlier rejection.

    Raises ModelError on a log of another model (joint names), of the wrong shapes, not finite
    (naming the field and row), a floating base, bad options; SolverError when the log does not
    excite every base parameter (the rank deficiency, the least excited combinations).
    """
    _check_options(method, solver, outlier_threshold)
    q, qd, qdd, tau = _check_log(model, log)
    with one_blas_thread():  # small / tall matrices: OpenBLAS threads only spin (base.py)
        return _identify(model, (q, qd, qdd, tau), base, method, physical, solver,
                         outlier_threshold, friction, offsets)  # fmt: skip


def _identify(model, arrays, base, method, physical, solver, outlier_threshold, friction, offsets):
    q, qd, qdd, tau = arrays
    base = _base_for(model, base, friction, offsets)
    pi_nom = np.asarray(_core.dynamic_parameters(model), dtype=float)
    bodies, _ = _phys.parameter_layout(list(base.param_names))
    y = _core.joint_torque_regressor(model, q, qd, qdd)
    matrix = np.asarray(base.matrix, dtype=float)
    held = np.arange(pi_nom.size) >= 10 * len(bodies)
    held &= ~np.any(matrix != 0.0, axis=0)
    tau_eff = tau - y[..., held] @ pi_nom[held]
    yb = y[..., np.asarray(base.independent)]
    del y
    fit, keep, _ = _least_squares(yb, tau_eff, method, outlier_threshold, base)
    beta_std = np.sqrt(fit.s2 * np.sum(np.linalg.inv(fit.r) ** 2, axis=1))
    pi_ls = _complete(base, fit.beta, pi_nom)
    info = {"weights": fit.w, "s2": fit.s2}
    if physical:
        pi, status, prob = _physical(fit, base, pi_nom, len(bodies), solver, pi_ls)
        info.update(status=status, cost=prob.cost(pi), cost_ls=prob.cost(pi_ls), gamma=prob.gamma)
    else:
        pi = pi_ls
    beta = matrix @ pi
    res = tau_eff[keep] - yb[keep] @ beta
    return Identification(
        model=model,
        base=base,
        beta=beta,
        beta_std=beta_std,
        beta_ls=fit.beta,
        pi=pi,
        physical=bool(physical),
        method=method,
        solver=solver if physical else "",
        sigma=_joint_sigma(fit.res, yb.shape[2]),
        rmse=np.sqrt(np.mean(res**2, axis=0)),
        n_samples=int(tau.shape[0]),
        outliers=np.setdiff1d(np.arange(tau.shape[0]), keep),
        info=info,
    )
