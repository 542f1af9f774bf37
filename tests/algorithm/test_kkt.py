"""ad.accelerations against a dense reference solve of the KKT system

    [ Gamma  zeta^T ] [ v'    ]   [ eta ]
    [ zeta   0      ] [ delta ] = [ -xi ]

assembled in numpy from ad.mass_matrix, ad.generalized_forces and ad.evaluate_constraints, on a
random spatial arm (tree, full row rank) and on closed planar loops modelled in 3-D with
revolute joints only, which are redundant (four-bar: 20 rows, rank 17; five-bar: 25 rows,
rank 22). For redundant systems v' and zeta^T delta are unique and delta is the minimum-norm
multiplier; the reference computes v' in the null space of zeta and delta = pinv(zeta^T) (eta -
Gamma v'), and, as a cross-check of the reference itself, also by np.linalg.lstsq on the full
(singular) KKT matrix, whose minimum-norm solution has the same v' and the minimum-norm delta.

Gamma and eta are themselves checked against their closed forms: Gamma = blockdiag(m I, J_body),
eta = (m g, -omega x J omega) per body when gravity is the only load. Finally the Cartesian
accelerations of the tree arm are compared with the numpy recursive Newton-Euler reference.
"""

import armdyn as ad
import numpy as np
import pytest
from conftest import (
    GRAVITY,
    from_armdyn,
    random_inertia,
    random_quat,
    rel_err,
    spatial_arm,
    to_armdyn,
    tol,
)
from scipy.linalg import null_space

REL = 1e-10


def reference_solution(model, u, v, t=0.0):
    gamma = np.asarray(ad.body_mass_matrix(model), dtype=float)
    eta = np.asarray(ad.body_forces(model, u, v, t), dtype=float)
    c = ad.evaluate_constraints(model, u, v, t)
    zeta = np.asarray(c["zeta"], dtype=float)
    xi = np.asarray(c["xi"], dtype=float)
    nv, nc = model.nv, zeta.shape[0]
    # null-space solution
    vp = np.linalg.lstsq(zeta, -xi, rcond=None)[0]
    n = null_space(zeta)
    z = np.linalg.solve(n.T @ gamma @ n, n.T @ (eta - gamma @ vp)) if n.size else np.zeros(0)
    vdot = vp + n @ z
    delta = np.linalg.pinv(zeta.T) @ (eta - gamma @ vdot)
    # cross-check: minimum-norm least-squares solution of the full KKT system
    kkt = np.block([[gamma, zeta.T], [zeta, np.zeros((nc, nc))]])
    sol = np.linalg.lstsq(kkt, np.concatenate([eta, -xi]), rcond=None)[0]
    assert rel_err(sol[:nv], vdot) < 1e-9
    assert rel_err(sol[nv:], delta) < 1e-8
    # the reference really solves the equations
    assert rel_err(gamma @ vdot + zeta.T @ delta, eta) < 1e-11
    assert np.max(np.abs(zeta @ vdot + xi)) < 1e-11 * (1 + np.max(np.abs(xi)))
    return vdot, delta, zeta


def check_against_reference(model, u, v, t=0.0, redundant=False):
    vdot, delta = ad.body_accelerations(model, u, v, t)
    vdot, delta = np.asarray(vdot, dtype=float), np.asarray(delta, dtype=float)
    vdot_ref, delta_ref, zeta = reference_solution(model, u, v, t)
    assert vdot.shape == (model.nv,) and delta.shape == (model.nc,)
    assert rel_err(vdot, vdot_ref) <= tol(REL)
    assert rel_err(zeta.T @ delta, zeta.T @ delta_ref) <= tol(REL)
    # minimum-norm multipliers (unique anyway when zeta has full row rank)
    assert rel_err(delta, delta_ref) <= tol(REL if not redundant else 10 * REL)


# ----------------------------------------------------------------------------------------------
# spatial arm (tree)
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("prismatic", [False, True])
def test_arm_gamma_eta_closed_form(rng, prismatic):
    arm = spatial_arm(rng, prismatic=prismatic)
    model = arm.model
    gamma = np.asarray(ad.body_mass_matrix(model))
    ref = np.zeros((model.nv, model.nv))
    for k in range(arm.n):
        ref[6 * k : 6 * k + 3, 6 * k : 6 * k + 3] = arm.masses[k] * np.eye(3)
        ref[6 * k + 3 : 6 * k + 6, 6 * k + 3 : 6 * k + 6] = arm.inertias_body[k]
    np.testing.assert_allclose(gamma, ref, rtol=0, atol=1e-14)
    u = np.array(model.u0, dtype=float)
    v = rng.normal(size=model.nv)
    eta = np.asarray(ad.body_forces(model, u, v))
    eta_ref = np.zeros(model.nv)
    for k in range(arm.n):
        w = v[6 * k + 3 : 6 * k + 6]
        eta_ref[6 * k : 6 * k + 3] = arm.masses[k] * np.array(GRAVITY)
        eta_ref[6 * k + 3 : 6 * k + 6] = -np.cross(w, arm.inertias_body[k] @ w)
    np.testing.assert_allclose(eta, eta_ref, rtol=0, atol=1e-13)


@pytest.mark.parametrize("prismatic", [False, True])
def test_arm_accelerations(rng, prismatic):
    arm = spatial_arm(rng, prismatic=prismatic)
    model = arm.model
    assert model.is_tree and not len(model.redundant_rows)
    for _ in range(3):
        q = to_armdyn(arm.perm, rng.uniform(-1.5, 1.5, arm.n))
        qd = to_armdyn(arm.perm, rng.normal(size=arm.n))
        u, v = ad.state_from_joints(model, q, qd)
        check_against_reference(model, np.asarray(u), np.asarray(v))
        # off the manifold the KKT system is still regular
        u_off = np.array(u, dtype=float)
        for k in range(model.nb):
            u_off[7 * k : 7 * k + 3] += 0.01 * rng.normal(size=3)
            e = u_off[7 * k + 3 : 7 * k + 7] + 0.01 * rng.normal(size=4)
            u_off[7 * k + 3 : 7 * k + 7] = e / np.linalg.norm(e)
        check_against_reference(model, u_off, rng.normal(size=model.nv))


@pytest.mark.parametrize("prismatic", [False, True])
def test_arm_accelerations_match_rnea(rng, prismatic):
    """Cartesian accelerations of the tree arm = those implied by the numpy RNEA forward
    dynamics: CoM accelerations (world) and angular accelerations (body frame, R^T alpha)."""
    arm = spatial_arm(rng, prismatic=prismatic)
    model = arm.model
    for _ in range(3):
        q_ref = rng.uniform(-1.5, 1.5, arm.n)
        qd_ref = rng.normal(size=arm.n)
        u, v = ad.state_from_joints(model, to_armdyn(arm.perm, q_ref), to_armdyn(arm.perm, qd_ref))
        vdot, _ = ad.body_accelerations(model, u, v)
        qdd_ref = arm.chain.forward(q_ref, qd_ref, np.zeros(arm.n))
        kin = arm.chain.kinematics(q_ref, qd_ref, qdd_ref)
        ref = np.zeros(model.nv)
        for k in range(arm.n):
            ref[6 * k : 6 * k + 3] = kin["ac"][k]
            ref[6 * k + 3 : 6 * k + 6] = kin["R"][k].T @ kin["alpha"][k]
        vdot = np.asarray(vdot)
        assert rel_err(vdot, ref) <= tol(REL)
        # and the joint-space route agrees
        qdd = from_armdyn(
            arm.perm,
            ad.forward_dynamics(
                model, to_armdyn(arm.perm, q_ref), to_armdyn(arm.perm, qd_ref), np.zeros(arm.n)
            ),
        )
        assert rel_err(qdd, qdd_ref) <= tol(REL)


# ----------------------------------------------------------------------------------------------
# redundant planar loops with revolute joints only
# ----------------------------------------------------------------------------------------------


def planar_loop(rng, points, drive=None):
    """Closed loop ground - link1 - ... - linkn - ground through the given joint points (plane
    z = 0, all revolute axes along z, gravity -y in that plane so the loop really accelerates).
    Bodies have CoMs off the plane and random inertias."""
    points = [np.asarray(p, dtype=float) for p in points]
    nlinks = len(points) - 1
    b = ad.ModelBuilder(gravity=(0.0, -9.81, 0.0))
    for i in range(nlinks):
        m = rng.uniform(0.5, 2.0)
        com = 0.5 * (points[i] + points[i + 1]) + 0.05 * rng.normal(size=3)
        b.add_body(
            f"link{i + 1}", m, random_inertia(rng, m), position=com, orientation=random_quat(rng)
        )
    z = (0.0, 0.0, 1.0)
    names = ["ground"] + [f"link{i + 1}" for i in range(nlinks)] + ["ground"]
    for i, p in enumerate(points):
        b.add_revolute(f"r{i}", names[i], names[i + 1], p, z)
    if drive is not None:
        b.add_drive("r0", drive)
    return b.finalize()


FOUR_BAR = [
    (0.0, 0.0, 0.0),
    (0.3 * np.cos(1.0), 0.3 * np.sin(1.0), 0.0),
    (0.9, 0.55, 0.0),
    (1.0, 0.0, 0.0),
]
FIVE_BAR = [(0.0, 0.0, 0.0), (0.1, 0.4, 0.0), (0.5, 0.7, 0.0), (0.9, 0.5, 0.0), (1.1, 0.0, 0.0)]


def consistent_velocity(rng, model, u, t=0.0):
    c = ad.evaluate_constraints(model, u, np.zeros(model.nv), t)
    zeta = np.asarray(c["zeta"], dtype=float)
    vp = np.linalg.lstsq(zeta, np.asarray(c["rhs"], dtype=float), rcond=None)[0]
    n = null_space(zeta)
    return vp + n @ rng.normal(size=n.shape[1])


@pytest.mark.parametrize(
    "points, mobility", [(FOUR_BAR, 1), (FIVE_BAR, 2)], ids=["four_bar", "five_bar"]
)
def test_redundant_loop(rng, points, mobility):
    model = planar_loop(rng, points)
    nlinks = len(points) - 1
    assert model.nv == 6 * nlinks
    assert model.nc == 5 * len(points)
    assert not model.is_tree
    assert model.mobility == mobility
    assert len(model.redundant_rows) == model.nc - (model.nv - mobility) == 3
    u = np.asarray(model.u0, dtype=float)
    for _ in range(3):
        v = consistent_velocity(rng, model, u)
        check_against_reference(model, u, v, redundant=True)


def test_redundant_driven_four_bar(rng):
    """Rheonomic + redundant: a callable drive with y(0) = 0, y'(0) = 0.7, y''(0) = 0.4."""
    model = planar_loop(
        rng,
        FOUR_BAR,
        drive=lambda t: (
            0.7 * np.sin(t) + 0.2 * t * t,
            0.7 * np.cos(t) + 0.4 * t,
            -0.7 * np.sin(t) + 0.4,
        ),
    )
    assert model.mobility == 1 and len(model.redundant_rows) == 3
    u = np.asarray(model.u0, dtype=float)
    for _ in range(2):
        v = consistent_velocity(rng, model, u, 0.0)
        check_against_reference(model, u, v, 0.0, redundant=True)
