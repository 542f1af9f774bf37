"""Planar slider-crank, modelled in 3-D, driven at constant crank speed.

Reference (closed-form kinematics): crank angle theta(t) = theta0 + w t, crank pin
B = r (cos theta, sin theta, 0), slider pin C = (x, 0, 0) with
    x(t)  = r cos(theta) + sqrt(l^2 - r^2 sin^2(theta)),
    x'(t) = -r w sin(theta) - r^2 w sin(theta) cos(theta) / sqrt(l^2 - r^2 sin^2(theta)).
Drive torque: gravity off and ideal joints, so the drive power equals dT/dt, T the closed-form
kinetic energy (crank at constant speed, rod in planar motion, slider in translation); dT/dt is
taken by a 4th-order central difference of the closed form.

Two closures of the loop: all revolute joints (3-D redundant: 20 rows, rank 17) and a
non-redundant universal + spherical closure (17 rows).
"""

import armdyn as ad
import numpy as np
import pytest
from conftest import (
    GRAVITY,
    body_index,
    body_pose,
    body_vel,
    quat_to_rot,
    random_inertia,
    random_quat,
    tol,
)

R_CRANK = 0.1
L_ROD = 0.35
THETA0 = 0.4
W = 2.0 * np.pi
Z = np.array([0.0, 0.0, 1.0])


def slider_x(theta):
    return R_CRANK * np.cos(theta) + np.sqrt(L_ROD**2 - (R_CRANK * np.sin(theta)) ** 2)


def slider_xd(theta, w):
    s, c = np.sin(theta), np.cos(theta)
    return -R_CRANK * w * s - R_CRANK**2 * w * s * c / np.sqrt(L_ROD**2 - (R_CRANK * s) ** 2)


def build(rng, closure="revolute", profile=None, gravity=(0.0, 0.0, 0.0)):
    b_pin = R_CRANK * np.array([np.cos(THETA0), np.sin(THETA0), 0.0])
    c_pin = np.array([slider_x(THETA0), 0.0, 0.0])
    geo = {
        "crank": dict(m=0.8, c=0.5 * b_pin + np.array([0.01, -0.02, 0.03])),
        "rod": dict(m=0.5, c=0.5 * (b_pin + c_pin)),
        "slider": dict(m=1.2, c=c_pin.copy()),
    }
    b = ad.ModelBuilder(gravity=gravity)
    for name, g in geo.items():
        g["J"] = random_inertia(rng, g["m"])
        g["e"] = random_quat(rng)
        b.add_body(name, g["m"], g["J"], position=g["c"], orientation=g["e"])
    b.add_revolute("crank_pivot", "ground", "crank", (0.0, 0.0, 0.0), Z)
    if closure == "revolute":
        b.add_revolute("crank_pin", "crank", "rod", b_pin, Z)
        b.add_revolute("slider_pin", "rod", "slider", c_pin, Z)
    else:
        rod_dir = (c_pin - b_pin) / L_ROD
        b.add_universal("crank_pin", "crank", "rod", b_pin, Z, np.cross(Z, rod_dir))
        b.add_spherical("slider_pin", "rod", "slider", c_pin)
    b.add_prismatic("slide", "ground", "slider", c_pin, (1.0, 0.0, 0.0))
    if profile is None:
        # natural spline through two samples = straight line, extrapolated linearly
        profile = ad.profiles.spline([0.0, 10.0], [0.0, 10.0 * W])
    b.add_drive("crank_pivot", profile, name="motor")
    model = b.finalize()
    for g in geo.values():
        r = quat_to_rot(g["e"])
        g["Jzz_world"] = (r @ g["J"] @ r.T)[2, 2]
    return model, geo


def closed_form_kinetic_energy(geo, t):
    """Kinetic energy of the driven mechanism at time t (gravity-independent)."""
    th = THETA0 + W * t
    s, c = np.sin(th), np.cos(th)
    # crank: rotation about the z axis through the origin at constant speed
    cc = geo["crank"]["c"]
    v_crank = W * np.array([-cc[1], cc[0], 0.0])  # w z x c (c rotates rigidly with the crank)
    t_crank = 0.5 * geo["crank"]["m"] * v_crank @ v_crank + 0.5 * geo["crank"]["Jzz_world"] * W**2
    bp, bpd = R_CRANK * np.array([c, s]), R_CRANK * W * np.array([-s, c])
    cp, cpd = np.array([slider_x(th), 0.0]), np.array([slider_xd(th, W), 0.0])
    d, dd = cp - bp, cpd - bpd
    beta_d = (d[0] * dd[1] - d[1] * dd[0]) / (d @ d)
    v_mid = 0.5 * (bpd + cpd)
    t_rod = 0.5 * geo["rod"]["m"] * v_mid @ v_mid + 0.5 * geo["rod"]["Jzz_world"] * beta_d**2
    t_slider = 0.5 * geo["slider"]["m"] * cpd[0] ** 2
    return t_crank + t_rod + t_slider


def d_dt(f, t, h=1e-5):
    return (-f(t + 2 * h) + 8 * f(t + h) - 8 * f(t - h) + f(t - 2 * h)) / (12 * h)


@pytest.mark.parametrize("closure", ["revolute", "universal_spherical"])
def test_driven_slider_crank(rng, closure):
    model, geo = build(rng, closure)
    assert model.nb == 3 and not model.is_tree
    assert model.mobility == 1
    if closure == "revolute":
        assert model.nc == 4 * 5 + 1
        assert len(model.redundant_rows) == 3
    else:
        assert model.nc == 5 + 4 + 3 + 5 + 1
        assert len(model.redundant_rows) == 0

    t_end = 2.0
    res = ad.simulate(model, t_end, integrator="dopri5", rtol=1e-10, atol=1e-10, output_dt=1e-3)
    t = res.t
    theta = THETA0 + W * t
    ks = body_index(model, "slider")
    xs, es = body_pose(res.u, ks)
    vs, ws = body_vel(res.v, ks)

    # drive: crank coordinate follows the profile exactly
    # res.q's columns: every joint coordinate (model.joint_coord_names; a loop model's
    # coord_names are its independent coordinates)
    iq = list(model.joint_coord_names).index("crank_pivot")
    np.testing.assert_allclose(res.q[:, iq], W * t, rtol=0, atol=tol(1e-9))
    np.testing.assert_allclose(res.qd[:, iq], W, rtol=0, atol=tol(1e-9))
    # slider kinematics
    np.testing.assert_allclose(xs[:, 0], slider_x(theta), rtol=0, atol=tol(1e-9))
    np.testing.assert_allclose(vs[:, 0], slider_xd(theta, W), rtol=0, atol=tol(1e-9))
    np.testing.assert_allclose(xs[:, 1:], 0.0, rtol=0, atol=tol(1e-9))
    np.testing.assert_allclose(vs[:, 1:], 0.0, rtol=0, atol=tol(1e-9))
    np.testing.assert_allclose(ws, 0.0, rtol=0, atol=tol(1e-9))  # slider does not rotate
    np.testing.assert_allclose(
        es * np.sign(es @ geo["slider"]["e"])[:, None],
        np.tile(geo["slider"]["e"], (len(t), 1)),
        rtol=0,
        atol=tol(1e-9),
    )
    # slider coordinate = displacement from assembly along +x
    np.testing.assert_allclose(
        res.q[:, list(model.joint_coord_names).index("slide")],
        slider_x(theta) - slider_x(THETA0),
        rtol=0,
        atol=tol(1e-9),
    )
    # crank pin position from the crank body's pose
    kc = body_index(model, "crank")
    xc, ec = body_pose(res.u, kc)
    r0 = quat_to_rot(geo["crank"]["e"])
    pin0 = R_CRANK * np.array([np.cos(THETA0), np.sin(THETA0), 0.0])
    pin_body = r0.T @ (pin0 - geo["crank"]["c"])
    pin = np.array([quat_to_rot(e) @ pin_body for e in ec]) + xc
    np.testing.assert_allclose(pin[:, 0], R_CRANK * np.cos(theta), rtol=0, atol=tol(1e-9))
    np.testing.assert_allclose(pin[:, 1], R_CRANK * np.sin(theta), rtol=0, atol=tol(1e-9))

    # constraint residuals
    assert np.max(res.position_residual) <= tol(1e-10)
    assert np.max(res.velocity_residual) <= tol(1e-10)

    # kinetic energy and the drive torque from the power balance
    ke_ref = np.array([closed_form_kinetic_energy(geo, ti) for ti in t])
    np.testing.assert_allclose(res.kinetic_energy, ke_ref, rtol=0, atol=tol(1e-9) * ke_ref.max())
    tau_ref = (
        np.array([d_dt(lambda s: closed_form_kinetic_energy(geo, s), ti) for ti in t[::10]]) / W
    )
    tau = np.asarray(res.drive_forces)[::10, 0]
    assert np.max(np.abs(tau_ref)) > 1e-3
    np.testing.assert_allclose(tau, tau_ref, rtol=0, atol=tol(1e-7) * np.max(np.abs(tau_ref)))


def test_callable_drive_with_gravity(rng):
    """Same mechanism, a Python-callable constant-speed drive, gravity on: kinematics are
    unchanged (the mechanism is fully driven)."""
    model, _ = build(rng, "revolute", profile=lambda t: (W * t, W, 0.0), gravity=GRAVITY)
    res = ad.simulate(model, 0.5, integrator="dopri5", rtol=1e-10, atol=1e-10, output_dt=0.01)
    theta = THETA0 + W * res.t
    ks = body_index(model, "slider")
    xs, _ = body_pose(res.u, ks)
    vs, _ = body_vel(res.v, ks)
    np.testing.assert_allclose(xs[:, 0], slider_x(theta), rtol=0, atol=tol(1e-9))
    np.testing.assert_allclose(vs[:, 0], slider_xd(theta, W), rtol=0, atol=tol(1e-9))
    assert np.max(res.position_residual) <= tol(1e-10)
    assert np.max(res.velocity_residual) <= tol(1e-10)
