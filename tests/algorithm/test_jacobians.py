"""Constraint jacobians zeta and bias terms xi, rhs against finite differences along motions.

For every joint type a two-body model ground - body1 - body2 (both joints of that type, random
geometry) is evaluated at random states OFF the constraint manifold (the functions are defined
everywhere; Euler parameters are kept unit) with random velocities v = (xdot world, omega body).
Along the motion with constant v,
    x(t0 + s) = x + s xdot,      e(t0 + s) = e (x) exp(1/2 s omega)     (exact for constant omega),
so with f(s) = f(u(t0 + s), t0 + s):
    df/ds   = zeta v - rhs          (rhs = -partial f / partial t, zero without drives)
    d2f/ds2 = xi                    (zeta v' + xi = d2f/dt2 and v' = 0 on this path)
which holds whatever sign convention the rows use. Derivatives by 4th-order central
differences (h = 1e-3: truncation ~1e-12, round-off ~1e-13 / ~1e-10). Rheonomic drives are
included with their profiles (sine: xi then carries -y''(t)).
"""

import armdyn as ad
import numpy as np
import pytest
from conftest import GRAVITY, quat_exp, quat_mul, random_inertia, random_quat, random_unit, tol

JOINT_ROWS = {
    "revolute": 5,
    "prismatic": 5,
    "cylindrical": 4,
    "spherical": 3,
    "fixed": 6,
    "universal": 4,
    "inline": 2,
    "distance": 1,
}
H = 1e-3


def add_joint(b, kind, name, parent, child, point, rng):
    axis = random_unit(rng)
    if kind == "revolute":
        b.add_revolute(name, parent, child, point, axis)
    elif kind == "prismatic":
        b.add_prismatic(name, parent, child, point, axis)
    elif kind == "cylindrical":
        b.add_cylindrical(name, parent, child, point, axis)
    elif kind == "spherical":
        b.add_spherical(name, parent, child, point)
    elif kind == "fixed":
        b.add_fixed(name, parent, child, point)
    elif kind == "universal":
        axis2 = np.cross(axis, random_unit(rng))
        b.add_universal(name, parent, child, point, axis, axis2 / np.linalg.norm(axis2))
    elif kind == "inline":
        b.add_inline(name, parent, child, point, axis)
    elif kind == "distance":
        # a rod from the point to a second point one unit away
        b.add_distance(name, parent, point, child, point + axis)
    else:  # pragma: no cover
        raise ValueError(kind)


def two_body_model(rng, kind, drives=()):
    b = ad.ModelBuilder(gravity=GRAVITY)
    for i in range(2):
        m = rng.uniform(0.5, 2.0)
        b.add_body(
            f"body{i + 1}",
            m,
            random_inertia(rng, m),
            position=rng.normal(scale=0.5, size=3),
            orientation=random_quat(rng),
        )
    add_joint(b, kind, "j1", "ground", "body1", rng.normal(scale=0.5, size=3), rng)
    add_joint(b, kind, "j2", "body1", "body2", rng.normal(scale=0.5, size=3), rng)
    for joint, coord, profile in drives:
        b.add_drive(joint, profile, coord=coord)
    return b.finalize()


def advance(u, v, s):
    """State after moving for time s with constant v (x world, omega body)."""
    u = np.array(u, dtype=float)
    nb = len(u) // 7
    out = u.copy()
    for k in range(nb):
        out[7 * k : 7 * k + 3] = u[7 * k : 7 * k + 3] + s * v[6 * k : 6 * k + 3]
        e, w = u[7 * k + 3 : 7 * k + 7], v[6 * k + 3 : 6 * k + 6]
        out[7 * k + 3 : 7 * k + 7] = quat_mul(e, quat_exp(s * w))
    return out


def random_state(rng, model, spread=0.05):
    """Assembled state moved off the manifold (unit quaternions kept) and random velocities."""
    u = np.array(model.u0, dtype=float)
    for k in range(model.nb):
        u[7 * k : 7 * k + 3] += spread * rng.normal(size=3)
        e = quat_mul(u[7 * k + 3 : 7 * k + 7], quat_exp(2 * spread * rng.normal(size=3)))
        u[7 * k + 3 : 7 * k + 7] = e / np.linalg.norm(e)
    v = rng.normal(size=model.nv)
    return u, v


def derivatives(fun, h=H):
    fm2, fm1, f0, fp1, fp2 = (np.asarray(fun(s), dtype=float) for s in (-2 * h, -h, 0.0, h, 2 * h))
    d1 = (-fp2 + 8 * fp1 - 8 * fm1 + fm2) / (12 * h)
    d2 = (-fp2 + 16 * fp1 - 30 * f0 + 16 * fm1 - fm2) / (12 * h * h)
    return d1, d2


def check_model(rng, model, n_states=3):
    nc, nv = model.nc, model.nv
    c0 = ad.evaluate_constraints(model, model.u0, model.v0, 0.0)
    assert np.max(np.abs(c0["f"])) <= tol(1e-12), "assembled state must satisfy f = 0"
    for _ in range(n_states):
        u, v = random_state(rng, model)
        t0 = rng.uniform(0.1, 2.0)
        c = ad.evaluate_constraints(model, u, v, t0)
        f, zeta, xi, rhs = (np.asarray(c[k], dtype=float) for k in ("f", "zeta", "xi", "rhs"))
        assert f.shape == (nc,) and zeta.shape == (nc, nv)
        assert xi.shape == (nc,) and rhs.shape == (nc,)
        assert np.linalg.matrix_rank(zeta) == nc  # two-body chains are never redundant

        def f_path(s, u=u, v=v, t0=t0):
            return ad.evaluate_constraints(model, advance(u, v, s), v, t0 + s)["f"]

        d1, d2 = derivatives(f_path)
        np.testing.assert_allclose(f_path(0.0), f, rtol=0, atol=1e-15)
        scale1 = 1.0 + np.max(np.abs(d1))
        np.testing.assert_allclose(zeta @ v - rhs, d1, rtol=0, atol=tol(1e-8) * scale1)
        scale2 = 1.0 + np.max(np.abs(d2))
        np.testing.assert_allclose(xi, d2, rtol=0, atol=tol(1e-6) * scale2)

        # explicit time dependence alone: at fixed u, df/dt = -rhs
        def f_time(s, u=u, v=v, t0=t0):
            return ad.evaluate_constraints(model, u, v, t0 + s)["f"]

        dt1, _ = derivatives(f_time)
        np.testing.assert_allclose(-rhs, dt1, rtol=0, atol=tol(1e-8) * (1.0 + np.max(np.abs(dt1))))


@pytest.mark.parametrize("kind", list(JOINT_ROWS))
def test_joint_jacobians(rng, kind):
    model = two_body_model(rng, kind)
    assert model.nb == 2 and model.nv == 12 and model.nq == 14
    assert model.nc == 2 * JOINT_ROWS[kind]
    check_model(rng, model)


def sine(a, f_hz):
    return ad.profiles.sine(a, f_hz)  # phase 0, offset 0: y(0) = 0, the assembly stays valid


DRIVES = {
    "revolute": [("j1", 0, lambda: sine(0.3, 0.7)), ("j2", 0, lambda: sine(0.2, 1.3))],
    "prismatic": [("j1", 0, lambda: sine(0.05, 0.9)), ("j2", 0, lambda: sine(0.1, 0.4))],
    "cylindrical": [
        ("j1", 0, lambda: sine(0.25, 0.6)),
        ("j1", 1, lambda: sine(0.04, 1.1)),
        ("j2", 1, lambda: lambda t: (0.1 * t * t + 0.2 * t, 0.2 * t + 0.2, 0.2)),
    ],
}


@pytest.mark.parametrize("kind", list(DRIVES))
def test_drive_jacobians(rng, kind):
    drives = [(j, c, make()) for j, c, make in DRIVES[kind]]
    model = two_body_model(rng, kind, drives)
    assert model.nc == 2 * JOINT_ROWS[kind] + len(drives)
    assert len(model.drive_names) == len(drives)
    check_model(rng, model)


def test_profiles_closed_form():
    """The profiles drives are built from, against their closed forms."""
    t = np.linspace(-0.5, 3.5, 41)

    def ev(p, ti):
        return np.array(p.eval(float(ti)), dtype=float)

    # constant
    for ti in t:
        np.testing.assert_allclose(ev(ad.profiles.constant(1.7), ti), [1.7, 0, 0], atol=1e-15)
    # sine: offset + A sin(2 pi f t + phase)
    a, fr, ph, off = 0.3, 0.7, 0.4, -0.2
    w = 2 * np.pi * fr
    p = ad.profiles.sine(a, fr, ph, off)
    for ti in t:
        ref = [
            off + a * np.sin(w * ti + ph),
            a * w * np.cos(w * ti + ph),
            -a * w * w * np.sin(w * ti + ph),
        ]
        np.testing.assert_allclose(ev(p, ti), ref, rtol=0, atol=1e-13)
    # cubic and quintic rest-to-rest, constant outside [t0, t1]
    y0, y1, t0, t1 = 0.5, -1.5, 0.5, 2.5
    T = t1 - t0
    for kind, poly in (("cubic", [0, 0, 3, -2]), ("quintic", [0, 0, 0, 10, -15, 6])):
        p = getattr(ad.profiles, kind)(y0, y1, t0, t1)
        P = np.polynomial.Polynomial(poly)
        for ti in t:
            s = min(max((ti - t0) / T, 0.0), 1.0)
            inside = 0.0 < s < 1.0
            ref = [
                y0 + (y1 - y0) * P(s),
                (y1 - y0) * P.deriv(1)(s) / T if inside else 0.0,
                (y1 - y0) * P.deriv(2)(s) / T**2 if inside else 0.0,
            ]
            np.testing.assert_allclose(ev(p, ti), ref, rtol=0, atol=1e-12)
    # spline: natural cubic through the samples, linear extrapolation with the end slopes
    from scipy.interpolate import CubicSpline

    ts = np.array([0.0, 0.7, 1.5, 2.0, 3.0])
    ys = np.array([0.0, 1.0, -0.5, 0.2, 0.9])
    cs = CubicSpline(ts, ys, bc_type="natural")
    p = ad.profiles.spline(ts, ys)
    for ti in t:
        if ts[0] <= ti <= ts[-1]:
            ref = [cs(ti), cs(ti, 1), cs(ti, 2)]
        else:
            te = ts[0] if ti < ts[0] else ts[-1]
            ref = [cs(te) + cs(te, 1) * (ti - te), cs(te, 1), 0.0]
        np.testing.assert_allclose(ev(p, ti), ref, rtol=0, atol=1e-12)
