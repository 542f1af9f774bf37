"""Base parameters: the identifiable combinations of the dynamic parameters.

The torques are linear in the parameters, ``tau = Y(q, qd, qdd) @ pi``
(:func:`armdyn.joint_torque_regressor`), but many columns of ``Y`` are zero (a parameter that
never shows in the torques: the first link's mass on a fixed base) or combinations of others (a
link's ``Izz`` and the next link's mass times the squared link length act alike about a fixed
axis). Only the *base parameters* ``beta`` can be identified from torques: a minimal set of
linear combinations of ``pi`` with ``Y @ pi == Y_b @ beta`` for every state, ``Y_b`` the
regressor's independent columns.

:func:`base_parameters` finds them numerically (Gautier 1990; Khalil & Dombre 2002, ch. 12):
``Y`` stacked over random states, QR with column pivoting, the numerical rank, the independent
columns ``b`` and the dependent ones ``d`` with ``Y_d = Y_b K``, ``K = R11^-1 R12``; then
``beta = pi_b + K pi_d``.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import scipy.linalg
import threadpoolctl

from armdyn import _checks, _core

__all__ = ["BaseParameters", "base_parameters"]

#: default rank tolerance: a pivot |R_ii| counts when > RANK_TOL * |R_00| (columns scaled to unit
#: norm first)
RANK_TOL = 1e-8
#: a column whose norm is below this fraction of the largest column's norm is structurally zero
ZERO_COLUMN = 1e-10
#: entries of K (on unit-norm columns: dimensionless) below this are round-off, set to 0
K_ZERO = 1e-10

#: (get, set) symbol pairs of the OpenBLAS builds numpy and scipy ship or link
_FRICTION = (".fv", ".fc")
_OFFSET = (".offset",)


@dataclass(frozen=True, eq=False)  # arrays: compared by identity
class BaseParameters:
    """The base parameters of a model (from :func:`base_parameters`).

    Attributes:
        param_names: the names of pi (:func:`armdyn.dynamic_parameter_names`).
        independent: (n_base,) int, the indices in pi of the base columns (ascending).
        matrix: (n_base, n_params), ``beta = matrix @ pi``; ``matrix[:, independent]`` is the
            identity, and ``Y @ pi == Y[..., independent] @ beta`` for every state (when friction
            or offsets were left out, for pi with those entries zero).
        names: each base parameter as an expression of pi's names, e.g.
            ``"shoulder_link.Izz + 0.0784 upper_arm_link.m"`` (coefficients to 6 digits).
        rank: n_base, the numerical rank of the stacked regressor.
    """

    param_names: list[str]
    independent: np.ndarray
    matrix: np.ndarray
    names: list[str]
    rank: int

    def regressor(self, y: npt.ArrayLike) -> np.ndarray:
        """The base regressor ``Y_b = y[..., independent]`` of a regressor ``y`` (n, p) or a
        batch (rows, n, p)."""
        y = _checks.array("BaseParameters.regressor", "y", y)
        if y.ndim < 2 or y.shape[-1] != len(self.param_names):
            raise _core.ModelError(
                f"BaseParameters.regressor: y must have {len(self.param_names)} columns (one "
                f"per dynamic parameter) in its last axis, got shape {y.shape}"
            )
        return y[..., self.independent]

    def beta(self, pi: npt.ArrayLike) -> np.ndarray:
        """The base parameters of a parameter vector ``pi`` (n_params,): ``matrix @ pi``."""
        pi = _checks.array("BaseParameters.beta", "pi", pi, ndim=1, finite=True)
        self._length("BaseParameters.beta", "pi", pi, len(self.param_names))
        return self.matrix @ pi

    def complete(self, beta: npt.ArrayLike, pi_ref: npt.ArrayLike) -> np.ndarray:
        """The parameter vector closest to ``pi_ref`` (2-norm) whose base parameters are
        ``beta``: ``pi_ref + matrix^+ (beta - matrix @ pi_ref)`` (the least-norm correction)."""
        who = "BaseParameters.complete"
        beta = _checks.array(who, "beta", beta, ndim=1, finite=True)
        pi_ref = _checks.array(who, "pi_ref", pi_ref, ndim=1, finite=True)
        self._length(who, "beta", beta, self.rank)
        self._length(who, "pi_ref", pi_ref, len(self.param_names))
        gap = beta - self.matrix @ pi_ref
        step = np.linalg.lstsq(self.matrix, gap, rcond=None)[0]
        return pi_ref + step

    @staticmethod
    def _length(who: str, name: str, a: np.ndarray, n: int) -> None:
        if a.shape != (n,):
            raise _core.ModelError(f"{who}: {name} must have shape ({n},), got {a.shape}")

    def __repr__(self) -> str:
        return f"<BaseParameters {self.rank} of {len(self.param_names)} parameters>"


@contextlib.contextmanager
def one_blas_thread() -> Iterator[None]:
    """Run the block with the BLAS libraries on one thread (threadpoolctl; restored after). The
    identification's matrices are small (hundreds of rows): BLAS threads gain nothing there and,
    on a loaded machine, wait for each other: a QR of a 1080 x 178 regressor took 5 s with
    OpenBLAS's threads on the shared 2-core machine at load 16, milliseconds on one."""
    with threadpoolctl.threadpool_limits(limits=1, user_api="blas"):
        yield


def random_states(
    model: _core.Model, samples: int, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``samples`` random states (rows): positions uniform within the joint limits where both
    are finite, else in [-pi, pi] (a floating base's position in [-1, 1] m and a random unit
    quaternion), velocities and accelerations standard normal."""
    lo = np.asarray(model.coord_lower, dtype=float)
    hi = np.asarray(model.coord_upper, dtype=float)
    finite = np.isfinite(lo) & np.isfinite(hi)
    lo = np.where(finite, lo, -np.pi)
    hi = np.where(finite, hi, np.pi)
    q = rng.uniform(lo, hi, size=(samples, model.n_coords))
    names = list(model.coord_names)
    for i, name in enumerate(names):
        if name.endswith(":e0") and i + 3 < len(names) and names[i + 3].endswith(":e3"):
            quat = rng.normal(size=(samples, 4))
            q[:, i : i + 4] = quat / np.linalg.norm(quat, axis=1, keepdims=True)
            if i >= 3 and names[i - 3].endswith(":x"):  # a free joint's position
                q[:, i - 3 : i] = rng.uniform(-1.0, 1.0, size=(samples, 3))
    qd = rng.normal(size=(samples, model.n_dofs))
    qdd = rng.normal(size=(samples, model.n_dofs))
    return q, qd, qdd


def _kept_columns(names: list[str], friction: bool, offsets: bool) -> np.ndarray:
    drop = (() if friction else _FRICTION) + (() if offsets else _OFFSET)
    return np.array([not n.endswith(drop) for n in names]) if drop else np.ones(len(names), bool)


def _expression(names: list[str], j: int, coefs: np.ndarray, dependent: np.ndarray) -> str:
    """``names[j] + c1 name1 - c2 name2 ...`` (coefficients to 6 significant digits)."""
    text = names[j]
    for c, k in zip(coefs, dependent, strict=True):
        if c == 0.0:
            continue
        mag = abs(c)
        shown = "" if f"{mag:.6g}" == "1" else f"{mag:.6g} "
        text += f" {'-' if c < 0 else '+'} {shown}{names[k]}"
    return text


def base_parameters(
    model: _core.Model,
    *,
    samples: int = 200,
    seed: int = 0,
    tol: float | None = None,
    friction: bool = True,
    offsets: bool = True,
) -> BaseParameters:
    """The base parameters of ``model``, found numerically.

    ``Y`` (:func:`armdyn.joint_torque_regressor`) is stacked over ``samples`` random states
    (:func:`random_states`, ``seed``). Each column is scaled to unit 2-norm before the QR with
    column pivoting (``scipy.linalg.qr(pivoting=True)``), so the rank and the choice of columns do
    not depend on the parameters' units (a mass column in N/kg, an inertia column in 1/s^2);
    among exactly proportional columns the first in pi's order is kept (a 1e-6 weight breaks
    the tie); columns below 1e-10 of the largest norm are structurally zero and never chosen.
    The numerical rank is the number of pivots ``|R_ii| > tol * |R_00|`` (``tol`` default
    :data:`RANK_TOL` = 1e-8: on the UR5, the Panda and the solo12 the singular values of the
    stacked regressor fall from above 1e-6 to below 1e-12 of the largest at the rank,
    tests/identification/test_base.py::test_rank_equals_svd_rank_and_is_stable). The dependent
    columns are ``Y_d = Y_b K``, ``K = R11^-1 R12`` (entries below 1e-10 on the scaled columns
    set to 0), and ``beta = pi_b + K pi_d``.

    Args:
        model: any model the regressor takes (fixed or floating base).
        samples: random states stacked (the rows are ``samples * n_dofs``: at least as many
            as the parameters kept, so that the rank is not capped by the rows).
        seed: the random generator's seed.
        tol: the relative rank tolerance (0 < tol < 1), default :data:`RANK_TOL`.
        friction: keep the joints' viscous and Coulomb friction parameters (``fv``, ``fc``);
            False leaves them out (their columns of ``matrix`` are zero).
        offsets: keep the joints' torque offsets (``offset``); False leaves them out.

    Raises:
        ModelError: a bad argument; a model the regressor refuses (springs, loads, ...).
    """
    who = "base_parameters"
    if not isinstance(model, _core.Model):
        raise _core.ModelError(f"{who}: model must be an armdyn.Model, got {type(model).__name__}")
    samples = _checks.integer(who, "samples", samples, lo=1, hi=1_000_000)
    seed = _checks.integer(who, "seed", seed, lo=0, hi=2**63 - 1)
    tol = _checks.number(who, "tol", RANK_TOL if tol is None else tol, lo=0.0, lo_open=True, hi=1.0)
    friction = _checks.flag(who, "friction", friction)
    offsets = _checks.flag(who, "offsets", offsets)
    names = list(_core.dynamic_parameter_names(model))
    if model.n_dofs == 0:
        raise _core.ModelError(f"{who}: the model has no joint (no degree of freedom)")
    if samples * model.n_dofs * len(names) > 50_000_000:
        raise _core.ModelError(
            f"{who}: samples = {samples} gives a {samples * model.n_dofs} x {len(names)} "
            "regressor (> 5e7 entries); use fewer samples"
        )
    kept = _kept_columns(names, friction, offsets)
    need = -(-int(kept.sum()) // model.n_dofs)
    if samples < need:
        raise _core.ModelError(
            f"{who}: samples = {samples} gives {samples * model.n_dofs} regressor rows for "
            f"{int(kept.sum())} parameters: the rank needs at least {need} samples"
        )
    q, qd, qdd = random_states(model, samples, np.random.default_rng(seed))
    y = _core.joint_torque_regressor(model, q, qd, qdd).reshape(-1, len(names))
    with one_blas_thread():
        return _from_stack(names, y, tol, kept)


def _from_stack(names: list[str], y: np.ndarray, tol: float, kept: np.ndarray) -> BaseParameters:
    """The base parameters of a stacked regressor ``y`` (rows, p), only ``kept`` columns."""
    p = len(names)
    norms = np.linalg.norm(y, axis=0)
    live = kept & (norms > ZERO_COLUMN * norms.max()) if norms.max() > 0 else kept & False
    cols = np.flatnonzero(live)
    if cols.size == 0:
        raise _core.ModelError("base_parameters: every regressor column is zero")
    # unit-norm columns, times a weight 1 + 1e-6 (p - j) / p: among columns that are exactly
    # proportional (a tie for the pivot) the first in pi's order is chosen, so the base
    # parameters are named after the earlier bodies' parameters (the textbook regrouping onto
    # ``Izz`` of link j of the next links' masses) and do not depend on round-off
    weight = 1.0 + 1e-6 * (p - cols) / p
    norms = norms.copy()
    norms[cols] /= weight
    ys = y[:, cols] / norms[cols]
    # the pivoted QR of the tall matrix equals that of its triangular factor (same column norms
    # and inner products): an unpivoted QR first, then the pivoted one on a (p, p) matrix
    if ys.shape[0] > ys.shape[1]:
        ys = np.linalg.qr(ys, mode="r")
    _, r, perm = scipy.linalg.qr(ys, mode="economic", pivoting=True)
    diag = np.abs(np.diag(r))
    rank = int(np.sum(diag > tol * diag[0]))
    k_s = scipy.linalg.solve_triangular(r[:rank, :rank], r[:rank, rank:])
    k_s[np.abs(k_s) < K_ZERO] = 0.0
    base_cols, dep_cols = cols[perm[:rank]], cols[perm[rank:]]
    # unscale: Ys = Y D^-1, so beta = pi_b + D_b^-1 K_s D_d pi_d
    k = k_s / norms[base_cols][:, None] * norms[dep_cols][None, :]
    order = np.argsort(base_cols)
    base_cols, k = base_cols[order], k[order]
    matrix = np.zeros((rank, p))
    matrix[np.arange(rank), base_cols] = 1.0
    matrix[:, dep_cols] = k
    exprs = []
    for i, j in enumerate(base_cols):
        dep_order = np.argsort(dep_cols)
        exprs.append(_expression(names, int(j), k[i, dep_order], dep_cols[dep_order]))
    return BaseParameters(
        param_names=names,
        independent=base_cols.astype(int),
        matrix=matrix,
        names=exprs,
        rank=rank,
    )
