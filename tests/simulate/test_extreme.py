"""Extreme cases: redundant and singular mechanisms, a 1e6 mass ratio, a fast heavy top over
10⁶ steps. Each is checked against an independent reference: a reduced-coordinate model
integrated by SciPy, the numpy recursive Newton–Euler, a symmetry of the mechanism, or the
gyroscopic closed form."""

import armdyn as ad
import numpy as np
import pytest
from armdyn import _core
from conftest import rel_err, to_armdyn, tol
from oracles.numpy_rne import serial_chain
from scipy.integrate import solve_ivp

# ----------------------------------------------------------------------------------------------
# redundant constraints
# ----------------------------------------------------------------------------------------------


def test_bricard_mobility_motion_and_symmetry():
    model = ad.scenes.bricard()
    assert model.mobility == 1  # while Grübler's count gives 0
    assert len(model.redundant_rows) == 1
    res = ad.simulate(model, 2.0, rtol=1e-10, atol=1e-12, output_dt=0.05)
    # it moves (a large swing), on the constraints, conserving energy
    assert np.ptp(res.q[:, 0]) > 2.0
    assert np.max(res.position_residual) <= 1e-12
    energy = res.total_energy
    assert np.max(np.abs(energy - energy[0])) <= 1e-8 * np.max(res.kinetic_energy)
    # threefold symmetry of the cube Bricard: J0 = J2 = J4 and J1 = J3 = J5 along the motion
    q = res.q
    assert np.max(np.abs(q[:, [2, 4]] - q[:, [0]])) <= 1e-8
    assert np.max(np.abs(q[:, [3, 5]] - q[:, [1]])) <= 1e-8
    # reactions are the minimum-norm ones: delta = pinv(zeta^T) (eta - Gamma vdot)
    u, v = res.u[10], res.v[10]
    vdot, delta = ad.body_accelerations(model, u, v)
    zeta = np.asarray(ad.evaluate_constraints(model, u, v)["zeta"])
    rhs = np.asarray(ad.body_forces(model, u, v)) - ad.body_mass_matrix(model) @ vdot
    assert rel_err(delta, np.linalg.pinv(zeta.T, rcond=1e-10) @ rhs) <= 1e-8


def four_bar_reference(model, phi0, t_end, times):
    """Reduced-coordinate model of the planar four-bar of armdyn.scenes.four_bar (crank angle
    phi), Lagrange equation M(phi) phi'' + M'(phi) phi'^2 / 2 + V'(phi) = 0 with M and V from the
    closed-form position analysis, integrated by SciPy's DOP853."""
    a, b_len, c, d = 0.3, 0.6, 0.5, 0.7
    masses = np.asarray(model.masses)
    izz = np.asarray(model.inertias)[:, 2, 2]
    g = 9.81
    pd = np.array([d, 0.0])

    def pose(phi):
        """Centres of mass and unit link directions, shape phi.shape + (3, 2) (vectorised)."""
        phi = np.asarray(phi, float)[..., None]
        pa = a * np.concatenate([np.cos(phi), np.sin(phi)], axis=-1)
        dist = np.linalg.norm(pd - pa, axis=-1, keepdims=True)
        x = (b_len**2 - c**2 + dist**2) / (2 * dist)
        h = np.sqrt(b_len**2 - x**2)
        e = (pd - pa) / dist
        pb = pa + x * e + h * np.stack([-e[..., 1], e[..., 0]], axis=-1)
        coms = np.stack([pa / 2, (pa + pb) / 2, (pb + pd) / 2], axis=-2)
        # unit directions of the links (their angles' rates are |d dir / d phi|)
        dirs = np.stack([pa / a, (pb - pa) / b_len, (pd - pb) / c], axis=-2)
        return coms, dirs

    def deriv(f, x, k=1e-3):
        """Fourth-order central difference; f is evaluated once, at the four points stacked."""
        x = np.asarray(x, float)
        y = np.moveaxis(f(x[..., None] + k * np.array([-2.0, -1.0, 1.0, 2.0])), x.ndim, 0)
        return (y[0] - 8 * y[1] + 8 * y[2] - y[3]) / (12 * k)

    def mass(phi):
        dc = deriv(lambda s: pose(s)[0], phi)
        dd = deriv(lambda s: pose(s)[1], phi)
        return np.sum(masses * np.sum(dc**2, axis=-1), axis=-1) + np.sum(
            izz * np.sum(dd**2, axis=-1), axis=-1
        )

    def potential(phi):
        return np.sum(masses * g * pose(phi)[0][..., 1], axis=-1)

    def rhs(_t, y):
        phi, w = y
        dm = float(deriv(mass, phi))
        dv = float(deriv(potential, phi))
        return [w, -(0.5 * dm * w * w + dv) / float(mass(phi))]

    sol = solve_ivp(
        rhs, (0, t_end), [phi0, 0.0], method="DOP853", rtol=1e-12, atol=1e-12, t_eval=times
    )
    return sol.y[0]


def test_four_bar_in_3d_moves_like_the_planar_reduced_model():
    phi0 = np.pi / 3
    model = ad.scenes.four_bar(crank_angle=phi0)
    assert model.mobility == 1 and len(model.redundant_rows) == 3
    res = ad.simulate(model, 1.0, rtol=1e-11, atol=1e-12, output_dt=0.1)
    ref = four_bar_reference(model, phi0, 1.0, res.t)
    crank = phi0 + res.q[:, list(model.joint_coord_names).index("A")]
    assert np.ptp(ref) > 0.5  # it swings
    assert np.max(np.abs(crank - ref)) <= 1e-7


# ----------------------------------------------------------------------------------------------
# singular configurations
# ----------------------------------------------------------------------------------------------


def test_parallelogram_through_its_change_point_is_reported_and_stays_on_its_branch():
    """A parallelogram four-bar driven through the configuration where all links are collinear
    (crank angle π): the loses-rank event is reported with the time and rows, and the motion
    continues on the parallelogram branch (the coupler keeps its orientation: q_B = −q_A)."""
    drive = _core.profiles.spline([0.0, 1.0], [0.0, np.pi])
    model = ad.scenes.four_bar(
        a=0.3, b_len=0.7, c=0.3, d=0.7, crank_angle=np.pi / 2, crank_drive=drive, gravity=0.0
    )
    res = ad.simulate(model, 1.0, rtol=1e-9, atol=1e-10, output_dt=0.05)
    assert res.stats["singular_evaluations"] >= 1
    assert "singular configuration at t=0.5" in res.stats["singular_note"]
    assert "dependent rows" in res.stats["singular_note"]
    names = list(model.joint_coord_names)
    qa, qb = res.q[:, names.index("A")], res.q[:, names.index("B")]
    assert np.max(np.abs(qa + qb)) <= 1e-9
    assert np.max(res.position_residual) <= 1e-12


def test_arm_driven_beyond_full_extension_is_a_clear_error():
    """A planar 2R arm whose tip rides a slider driven past the arm's reach (full extension at
    x = 1 m): the run stops with a SolverError naming the driven slider; the motion before it is
    returned."""
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    x0 = 0.8
    elbow = np.array([x0 / 2, 0.0, np.sqrt(0.25 - (x0 / 2) ** 2)])
    tip = np.array([x0, 0.0, 0.0])
    b.add_body("upper", 1.0, [1e-3, 2e-2, 2e-2], position=elbow / 2)
    b.add_body("fore", 1.0, [1e-3, 2e-2, 2e-2], position=(elbow + tip) / 2)
    b.add_body("slider", 0.5, [1e-3] * 3, position=tip)
    b.add_revolute("shoulder", "ground", "upper", point=(0, 0, 0), axis=(0, 1, 0))
    b.add_revolute("elbow", "upper", "fore", point=elbow, axis=(0, 1, 0))
    b.add_revolute("wrist", "fore", "slider", point=tip, axis=(0, 1, 0))
    b.add_prismatic("guide", "ground", "slider", point=tip, axis=(1, 0, 0))
    b.add_drive("guide", _core.profiles.cubic(0.0, 0.3, 0.0, 1.0))  # to x = 1.1 m
    model = b.finalize()
    with pytest.raises(ad.SolverError, match="guide") as err:
        ad.simulate(model, 1.0, rtol=1e-9, atol=1e-10, output_dt=0.01)
    res = err.value.result
    reach = res.u[:, 14:17]  # slider position
    assert np.all(np.linalg.norm(reach, axis=1) <= 1.0 + 1e-9)
    assert res.t[-1] > 0.5


# ----------------------------------------------------------------------------------------------
# mass ratio 1e6 between neighbouring bodies
# ----------------------------------------------------------------------------------------------


def test_chain_with_mass_ratio_1e6(rng):
    # masses alternating 1e3 and 1e-3 kg, random full inertias and orientations, against the
    # independent numpy RNEA/CRBA model of the same arm
    arm = ad.scenes.mass_ratio_chain(1e6, n=5)
    model, chain, perm, n = arm.model, serial_chain(arm), arm.perm, 5
    assert arm.masses[0] / arm.masses[1] == pytest.approx(1e6)
    for _ in range(3):
        q_ref, qd_ref, tau_ref = rng.normal(size=(3, n))
        q, qd, tau = (to_armdyn(perm, x) for x in (q_ref, qd_ref, tau_ref))
        qdd = ad.forward_dynamics(model, q, qd, tau)
        assert rel_err(qdd[perm], chain.forward(q_ref, qd_ref, tau_ref)) <= tol(1e-8)
    res = ad.simulate(model, 1.0, rtol=1e-10, atol=1e-12, output_dt=0.1)
    energy = res.total_energy
    assert np.max(np.abs(energy - energy[0])) <= 1e-7 * np.max(res.kinetic_energy)
    assert np.max(res.position_residual) <= 1e-12


# ----------------------------------------------------------------------------------------------
# fast heavy top, 10^6 steps
# ----------------------------------------------------------------------------------------------


def test_fast_heavy_top_million_steps():
    """Symmetric top on a spherical joint, spin 1000 rad/s, tilted 30°, started in steady
    precession: 10⁶ RK4 steps (10 s). Drift ≤ 1e-12 at every recorded state, energy bounded,
    and the precession rate equals the gyroscopic closed form m g l / (I3 ω_s) to O(1/ω_s²)."""
    model, u0, v0, omega_p = ad.scenes.heavy_top(spin=1000.0)
    n_steps, dt = 1_000_000, 1e-5
    res = ad.simulate(model, n_steps * dt, integrator="rk4", dt=dt, output_dt=0.01, u0=u0, v0=v0)
    assert res.stats["steps"] == n_steps
    assert np.max(res.position_residual) <= 1e-12
    assert np.max(res.velocity_residual) <= 1e-12
    energy = res.total_energy
    assert np.max(np.abs(energy - energy[0])) / energy[0] <= 1e-12
    x = res.u[:, :3]
    phi = np.unwrap(np.arctan2(x[:, 1], x[:, 0]))
    rate = (phi[-1] - phi[0]) / res.t[-1]
    assert rate == pytest.approx(omega_p, rel=1e-3)
