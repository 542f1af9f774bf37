"""Physical consistency of a dynamic parameter vector pi (issue 35).

A body's 10 parameters ``(m, mcx, mcy, mcz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz)`` (about its parameter
frame, :func:`armdyn.dynamic_parameter_names`) are those of a real rigid body -- a non-negative
mass density -- exactly when the 4x4 pseudo-inertia

    J = [[0.5 tr(I) 1 - I, h], [h^T, m]],   h = (mcx, mcy, mcz),

is positive semidefinite (Wensing, Kim, Slotine 2018). With m > 0 that is the triangle
inequality on the principal moments of inertia about the centre of mass (each no larger than
the sum of the other two; the moments themselves non-negative). The joint parameters: viscous
and Coulomb friction ``fv, fc >= 0`` and the reflected rotor inertia ``Ia >= 0``; the offsets
are free.
"""

from __future__ import annotations

import numpy as np

from armdyn import _core

__all__ = ["is_physical", "parameter_layout", "physical_violations", "pseudo_inertia"]

_BODY_KEYS = ("m", "mcx", "mcy", "mcz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")
_COORD_KEYS = ("fv", "fc", "offset", "Ia")


def _inertia(pi10: np.ndarray) -> np.ndarray:
    _, _, _, _, ixx, ixy, iyy, ixz, iyz, izz = pi10
    return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])


def pseudo_inertia(pi10) -> np.ndarray:
    """The 4x4 pseudo-inertia J of one body's 10 parameters (Pinocchio's order).

    ``J = [[0.5 tr(I) 1 - I, h], [h^T, m]]``: the second moments of the mass distribution
    ``[[int x x^T dm, int x dm], [int x^T dm, int dm]]``, PSD for every real body.
    """
    p = np.asarray(pi10, dtype=float)
    if p.shape != (10,):
        raise _core.ModelError(f"pseudo_inertia: pi10 must have shape (10,), got {p.shape}")
    inertia = _inertia(p)
    j = np.empty((4, 4))
    j[:3, :3] = 0.5 * np.trace(inertia) * np.eye(3) - inertia
    j[:3, 3] = p[1:4]
    j[3, :3] = p[1:4]
    j[3, 3] = p[0]
    return j


def pi10_from_pseudo_inertia(j: np.ndarray) -> np.ndarray:
    """The inverse of :func:`pseudo_inertia` (also batched: (..., 4, 4) -> (..., 10))."""
    sigma = j[..., :3, :3]
    tr = np.trace(sigma, axis1=-2, axis2=-1)
    inertia = tr[..., None, None] * np.eye(3) - sigma
    out = np.empty((*j.shape[:-2], 10))
    out[..., 0] = j[..., 3, 3]
    out[..., 1:4] = j[..., :3, 3]
    out[..., 4] = inertia[..., 0, 0]
    out[..., 5] = inertia[..., 0, 1]
    out[..., 6] = inertia[..., 1, 1]
    out[..., 7] = inertia[..., 0, 2]
    out[..., 8] = inertia[..., 1, 2]
    out[..., 9] = inertia[..., 2, 2]
    return out


def parameter_layout(names: list[str]) -> tuple[list[str], list[str]]:
    """The bodies and the coordinates of a pi's names (:func:`armdyn.dynamic_parameter_names`):
    pi[10 k: 10 k + 10] is body k's, then pi[10 nb + 4 c: ...] coordinate c's."""
    bodies: list[str] = []
    i = 0
    while i + 10 <= len(names) and names[i].endswith(".m") and names[i + 9].endswith(".Izz"):
        bodies.append(names[i][:-2])
        i += 10
    rest = names[i:]
    if len(rest) % 4 or any(
        not rest[k].endswith("." + _COORD_KEYS[k % 4]) for k in range(len(rest))
    ):
        raise _core.ModelError("parameter names do not follow dynamic_parameter_names' layout")
    coords = [rest[k][: -len(".fv")] for k in range(0, len(rest), 4)]
    return bodies, coords


def _check_pi(model, pi) -> tuple[np.ndarray, list[str], list[str]]:
    names = list(_core.dynamic_parameter_names(model))
    p = np.asarray(pi, dtype=float)
    if p.shape != (len(names),):
        raise _core.ModelError(
            f"pi must have shape ({len(names)},) (the model's dynamic_parameter_names), "
            f"got {p.shape}"
        )
    bad = np.flatnonzero(~np.isfinite(p))
    if bad.size:
        raise _core.ModelError(f"pi[{bad[0]}] ({names[bad[0]]}) is not finite: {p[bad[0]]}")
    bodies, coords = parameter_layout(names)
    return p, bodies, coords


def _body_violations(body: str, p10: np.ndarray, tol: float) -> list[str]:
    m = p10[0]
    j = pseudo_inertia(p10)
    scale = max(np.trace(j), np.finfo(float).tiny)
    out = []
    if not m > tol * scale:
        out.append(f"{body}: mass {m:.6g} kg is not positive")
    if m > 0.0:
        c = p10[1:4] / m
        i_c = _inertia(p10) - m * (c @ c * np.eye(3) - np.outer(c, c))
        mom = np.linalg.eigvalsh(i_c)  # ascending
        if mom[0] < -tol * scale:
            out.append(
                f"{body}: a principal moment of inertia about the centre of mass is negative "
                f"({mom[0]:.6g} kg m^2)"
            )
        if mom[0] + mom[1] < mom[2] - tol * scale:
            out.append(
                f"{body}: triangle inequality fails: principal moments about the centre of "
                f"mass {mom[0]:.6g} + {mom[1]:.6g} < {mom[2]:.6g} kg m^2"
            )
    lam = np.linalg.eigvalsh(j)[0]
    if lam < -tol * scale:
        out.append(f"{body}: pseudo-inertia not positive semidefinite (eigenvalue {lam:.6g})")
    return out


def physical_violations(model, pi, tol: float = 1e-9) -> list[str]:
    """What makes pi (the model's layout) not physically consistent, one message per failure,
    naming the body or the coordinate: a mass not positive, a negative principal moment or a
    failed triangle inequality (about the centre of mass), a pseudo-inertia eigenvalue below
    zero; a negative ``fv``, ``fc`` or ``Ia``. ``tol`` is relative: a body's bounds are
    ``-tol * tr(J)`` (its mass ``> tol * tr(J)``), a coordinate's ``-tol * max(|fv|, |fc|, |Ia|,
    1e-300)``. Empty when consistent. ModelError on pi of the wrong shape or not finite."""
    p, bodies, coords = _check_pi(model, pi)
    out: list[str] = []
    for k, body in enumerate(bodies):
        out += _body_violations(body, p[10 * k : 10 * k + 10], tol)
    base = 10 * len(bodies)
    for c, coord in enumerate(coords):
        fv, fc, _, ia = p[base + 4 * c : base + 4 * c + 4]
        floor = -tol * max(abs(fv), abs(fc), abs(ia), 1e-300)
        for key, val in (("fv", fv), ("fc", fc), ("Ia", ia)):
            if val < floor:
                out.append(f"{coord}.{key} = {val:.6g} is negative")
    return out


def is_physical(model, pi, tol: float = 1e-9) -> bool:
    """True when pi is physically consistent (:func:`physical_violations` is empty)."""
    return not physical_violations(model, pi, tol)
