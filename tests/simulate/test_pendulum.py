"""Simple (physical) pendulum against closed forms.

Reference: a rigid body of mass m with I_cm about the hinge-parallel axis, CoM at distance L from
the hinge, obeys I_O phi'' = -m g L sin(phi) with I_O = I_cm + m L^2, i.e. the mathematical
pendulum of length L_eq = I_O / (m L). Its exact period at amplitude theta0 is
T = 4 sqrt(L_eq / g) K(k^2), k = sin(theta0 / 2) (scipy.special.ellipk takes the parameter
m = k^2); for small amplitude T -> 2 pi sqrt(L_eq / g) (relative correction theta0^2 / 16).

Crossing times are located on a C^1 cubic Hermite interpolant of the sampled (q, qd), whose
error with output_dt = 1e-3 is ~1e-13 rad, far below what the assertions need.
"""

import armdyn as ad
import numpy as np
import pytest
from conftest import body_pose, body_vel, simple_pendulum, tol
from scipy.interpolate import CubicHermiteSpline
from scipy.special import ellipk


def hermite_roots(t, y, yd, t_min=1e-9):
    """Roots of the cubic Hermite interpolant of samples (t, y, yd), sorted, deduplicated."""
    t = np.asarray(t, dtype=float)
    t_u, idx = np.unique(t, return_index=True)
    spline = CubicHermiteSpline(t_u, np.asarray(y)[idx], np.asarray(yd)[idx])
    roots = np.sort(spline.roots(extrapolate=False))
    roots = roots[roots > t_min]
    if roots.size:
        keep = np.concatenate([[True], np.diff(roots) > 1e-9])
        roots = roots[keep]
    return roots


def exact_period(p):
    return 4.0 * np.sqrt(p.L_eq / p.g) * ellipk(np.sin(0.5 * p.theta0) ** 2)


def measured_periods(p, t_end, rtol, atol):
    res = ad.simulate(p.model, t_end, integrator="dopri5", rtol=rtol, atol=atol, output_dt=1e-3)
    q = res.q[:, 0]
    qd = res.qd[:, 0]
    assert abs(q[0]) <= 1e-12, "joint coordinate must be 0 at the assembly pose"
    phi = p.theta0 + q  # angle from the vertical
    roots = hermite_roots(res.t, phi, qd)
    assert roots.size >= 3, f"expected >= 3 zero crossings, got {roots}"
    # released from rest at +theta0: crossings at T/4, 3T/4, 5T/4
    return np.array([4.0 * roots[0], 2.0 * (roots[1] - roots[0]), roots[2] - roots[0]])


def test_small_angle_period():
    p = simple_pendulum(L=1.0, m=1.0, theta0=1e-4)
    t_lin = 2.0 * np.pi * np.sqrt(p.L_eq / p.g)
    # atol is set relative to the 1e-4 amplitude (1e-12 absolute would be 1e-8 relative)
    periods = measured_periods(p, 1.3 * t_lin, rtol=1e-12, atol=1e-14)
    # the finite-amplitude correction theta0^2/16 = 6e-10 is inside the tolerance
    np.testing.assert_allclose(periods, t_lin, rtol=tol(1e-8), atol=0)


@pytest.mark.parametrize("theta0_deg", [30.0, 90.0, 170.0])
def test_large_angle_period(theta0_deg):
    p = simple_pendulum(L=1.0, m=1.0, theta0=np.radians(theta0_deg))
    period = exact_period(p)
    periods = measured_periods(p, 1.3 * period, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(periods, period, rtol=tol(1e-8), atol=0)


def test_physical_pendulum_length_matters():
    """The closed form used is the physical pendulum: with a large sphere (r = 0.2 L) the
    period differs from the point-mass value by ~0.8 %, and armdyn must follow the former."""
    p = simple_pendulum(L=1.0, m=2.0, theta0=np.radians(60.0), r=0.2)
    period = exact_period(p)
    point_mass = 4.0 * np.sqrt(p.L / p.g) * ellipk(np.sin(0.5 * p.theta0) ** 2)
    assert abs(period / point_mass - 1.0) > 5e-3
    periods = measured_periods(p, 1.3 * period, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(periods, period, rtol=tol(1e-8), atol=0)


def test_joint_coordinate_convention():
    """q = 0 at assembly, positive q = right-handed rotation about +y (the joint axis): the bob
    released at +theta0 swings back, so q becomes negative, and theta0 + q is the angle of the
    CoM from the vertical computed from the Cartesian state."""
    theta0 = 0.5
    p = simple_pendulum(L=1.0, m=1.0, theta0=theta0)
    res = ad.simulate(p.model, 0.6, rtol=1e-10, atol=1e-10, output_dt=0.01)
    x, e = body_pose(res.u, 0)
    xd, w = body_vel(res.v, 0)
    # bob at Ry(phi) (0, 0, -L) = (-L sin phi, 0, -L cos phi)
    phi_u = np.arctan2(-x[:, 0], -x[:, 2])
    np.testing.assert_allclose(res.q[:, 0] + theta0, phi_u, rtol=0, atol=tol(1e-9))
    assert res.q[-1, 0] < -0.1
    # body-frame angular velocity is (0, qd, 0) for a rotation about the body's y axis
    np.testing.assert_allclose(w[:, 1], res.qd[:, 0], rtol=0, atol=tol(1e-9))
    np.testing.assert_allclose(w[:, [0, 2]], 0.0, rtol=0, atol=tol(1e-9))
    # CoM velocity of the rotating bob: d/dt (-L sin phi, 0, -L cos phi)
    phid = res.qd[:, 0]
    np.testing.assert_allclose(xd[:, 0], -p.L * np.cos(phi_u) * phid, rtol=0, atol=tol(1e-9))
    np.testing.assert_allclose(xd[:, 2], p.L * np.sin(phi_u) * phid, rtol=0, atol=tol(1e-9))
    np.testing.assert_allclose(x[:, 1], 0.0, rtol=0, atol=tol(1e-12))
    # Euler parameters: rotation Ry(phi) (e0 >= 0 branch or its negative)
    e_ref = np.stack([np.cos(0.5 * phi_u), 0 * phi_u, np.sin(0.5 * phi_u), 0 * phi_u], axis=1)
    sign = np.sign(np.sum(e * e_ref, axis=1))[:, None]
    np.testing.assert_allclose(e * sign, e_ref, rtol=0, atol=tol(1e-9))
