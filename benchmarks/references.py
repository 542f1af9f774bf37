"""Independent reference solutions of the standard problems, by methods other than armdyn's.

Each is derived by hand in minimal coordinates, not from the Cartesian model:

- A01 pendulum: the closed form with Jacobi elliptic functions.
- A02 N-four-bar: on its one-DOF branch all cranks stay parallel and the couplers translate, so
  the motion is a single pendulum-like ODE in the crank angle, integrated at rtol 1e-13.
- Andrews' squeezer: the seven-angle equations of Hairer & Wanner (1996, §VII.7) with their six
  loop constraints as an index-1 DAE (accelerations and multipliers from the augmented system
  at every right-hand side), integrated with SciPy's DOP853 at rtol 1e-13. The Test Set's
  published end values at t = 0.03 s check it (``ANDREWS_TEST_SET_T003``).

The same right-hand sides serve as the SciPy peer in :mod:`benchmarks.workprecision`.
"""

from __future__ import annotations

import numpy as np
from armdyn.scenes.standard import SQUEEZER, G

from benchmarks.peers.pinocchio import mass_matrix, pinocchio_tree

# --- A01 ------------------------------------------------------------------------------------


def pendulum_closed_form(t, length=1.0, theta0=np.pi / 2, g=G):
    """Angle from the downward vertical of a mass-point pendulum released at rest from
    ``theta0``: θ(t) = 2 asin(k sn(K − ω t | k²)), k = sin(θ0/2), ω² = g / L."""
    from scipy.special import ellipj, ellipk

    k = np.sin(theta0 / 2)
    m = k * k
    kk = ellipk(m)
    w = np.sqrt(g / length)
    # sn has period 4K: reduce the argument before calling ellipj
    arg = np.mod(kk - w * np.asarray(t, dtype=float), 4 * kk)
    sn = ellipj(arg, m)[0]
    return 2 * np.arcsin(k * sn)


def a01_points(t) -> np.ndarray:
    """(n, 2) positions of P1 for IFToMM A01 (released horizontal at x = +1, gravity −y)."""
    th = pendulum_closed_form(t)
    return np.column_stack([np.sin(th), -np.cos(th)])


def a01_rhs():
    """θ'' = −(g/L) sin θ as a first-order system y = (θ, θ')."""
    w2 = G

    def f(_t, y):
        return np.array([y[1], -w2 * np.sin(y[0])])

    return f, np.array([np.pi / 2, 0.0])


# --- A02 ------------------------------------------------------------------------------------


def a02_rhs(n=40, speed=1.0):
    """Crank angle φ from +x on the parallel branch: J φ'' = −m g L cos φ ((n+1)/2 + n), with
    J = (n+1) m L²/3 + n m L² (cranks about their pivots, couplers translating). y = (φ, φ')."""
    inertia = (n + 1) / 3.0 + n
    grav = G * ((n + 1) / 2.0 + n)
    c = grav / inertia

    def f(_t, y):
        return np.array([y[1], -c * np.cos(y[0])])

    return f, np.array([np.pi / 2, -speed])


def a02_points(t, n=40, rtol=1e-13):
    """(n_t, 2) positions of B0 on the one-DOF branch (DOP853 at ``rtol``, dense output)."""
    from scipy.integrate import solve_ivp

    f, y0 = a02_rhs(n)
    t = np.asarray(t, dtype=float)
    sol = solve_ivp(f, (0.0, t[-1]), y0, method="DOP853", rtol=rtol, atol=rtol, t_eval=t)
    return np.column_stack([np.cos(sol.y[0]), np.sin(sol.y[0])])


# --- Andrews' squeezer -----------------------------------------------------------------------

# Test Set for IVP solvers (Mazzia & Magherini, release 2.4, 2008), problem "andrews": reference
# angles (β, Θ, γ, Φ, δ, Ω, ε) at t = 0.03 s
ANDREWS_TEST_SET_T003 = np.array(
    [
        0.1581077119629904e2,
        -0.1575637105984298e2,
        0.4082224013073101e-1,
        -0.5347301163226948,
        0.5244099658805304,
        0.5347301163226948,
        0.1048080741042263e1,
    ]
)


def squeezer_terms(q, qd):
    """Mass matrix M (7×7), forces f (7), constraints g (6), their Jacobian Gq (6×7) and the
    velocity-squared term of the constraint acceleration, gqq = d/dt(Gq) qd (6), of the
    seven-angle formulation (Hairer & Wanner 1996, §VII.7)."""
    p = SQUEEZER
    m1, m2, m3, m4, m5, m6, m7 = p["m"]
    i1, i2, i3, i4, i5, i6, i7 = p["I"]
    be, th, ga, ph, de, om, ep = q
    bed, thd, gad, phd, ded, omd, epd = qd
    d, da, e, ea, rr, ra = p["d"], p["da"], p["e"], p["ea"], p["rr"], p["ra"]
    ss, sa, sb, sc, sd = p["ss"], p["sa"], p["sb"], p["sc"], p["sd"]
    ta, tb, u, ua, ub, zf, zt, fa = (p[k] for k in ("ta", "tb", "u", "ua", "ub", "zf", "zt", "fa"))
    xa, ya, xb, yb, xc, yc = (p[k] for k in ("xa", "ya", "xb", "yb", "xc", "yc"))
    sth, cth = np.sin(th), np.cos(th)
    sph, cph = np.sin(ph), np.cos(ph)
    som, com = np.sin(om), np.cos(om)
    sga, cga = np.sin(ga), np.cos(ga)

    M = np.zeros((7, 7))
    M[0, 0] = m1 * ra**2 + m2 * (rr**2 - 2 * da * rr * cth + da**2) + i1 + i2
    M[1, 0] = M[0, 1] = m2 * (da**2 - da * rr * cth) + i2
    M[1, 1] = m2 * da**2 + i2
    M[2, 2] = m3 * (sa**2 + sb**2) + i3
    M[3, 3] = m4 * (e - ea) ** 2 + i4
    M[4, 3] = M[3, 4] = m4 * ((e - ea) ** 2 + zt * (e - ea) * sph) + i4
    M[4, 4] = (
        m4 * (zt**2 + 2 * zt * (e - ea) * sph + (e - ea) ** 2) + m5 * (ta**2 + tb**2) + i4 + i5
    )
    M[5, 5] = m6 * (zf - fa) ** 2 + i6
    M[6, 5] = M[5, 6] = m6 * ((zf - fa) ** 2 - u * (zf - fa) * som) + i6
    M[6, 6] = (
        m6 * ((zf - fa) ** 2 - 2 * u * (zf - fa) * som + u**2) + m7 * (ua**2 + ub**2) + i6 + i7
    )

    xd = sd * cga + sc * sga + xb
    yd = sd * sga - sc * cga + yb
    lang = np.hypot(xd - xc, yd - yc)
    force = -p["c0"] * (lang - p["l0"]) / lang
    fx, fy = force * (xd - xc), force * (yd - yc)
    f = np.array(
        [
            p["mom"] - m2 * da * rr * thd * (thd + 2 * bed) * sth,
            m2 * da * rr * bed**2 * sth,
            fx * (sc * cga - sd * sga) + fy * (sd * cga + sc * sga),
            m4 * zt * (e - ea) * ded**2 * cph,
            -m4 * zt * (e - ea) * phd * (phd + 2 * ded) * cph,
            -m6 * u * (zf - fa) * epd**2 * com,
            m6 * u * (zf - fa) * omd * (omd + 2 * epd) * com,
        ]
    )

    # the three loops through E: E from body 2 equals E from bodies 3, 4 (via 5) and 6 (via 7)
    bt, pd, oe = be + th, ph + de, om + ep
    g = np.array(
        [
            rr * np.cos(be) - d * np.cos(bt) - ss * sga - xb,
            rr * np.sin(be) - d * np.sin(bt) + ss * cga - yb,
            rr * np.cos(be) - d * np.cos(bt) - e * np.sin(pd) - zt * np.cos(de) - xa,
            rr * np.sin(be) - d * np.sin(bt) + e * np.cos(pd) - zt * np.sin(de) - ya,
            rr * np.cos(be) - d * np.cos(bt) - zf * np.cos(oe) - u * np.sin(ep) - xa,
            rr * np.sin(be) - d * np.sin(bt) - zf * np.sin(oe) + u * np.cos(ep) - ya,
        ]
    )
    Gq = np.zeros((6, 7))
    Gq[0, :2] = (-rr * np.sin(be) + d * np.sin(bt), d * np.sin(bt))
    Gq[1, :2] = (rr * np.cos(be) - d * np.cos(bt), -d * np.cos(bt))
    Gq[2, :2] = Gq[0, :2]
    Gq[3, :2] = Gq[1, :2]
    Gq[4, :2] = Gq[0, :2]
    Gq[5, :2] = Gq[1, :2]
    Gq[0, 2] = -ss * cga
    Gq[1, 2] = -ss * sga
    Gq[2, 3:5] = (-e * np.cos(pd), -e * np.cos(pd) + zt * np.sin(de))
    Gq[3, 3:5] = (-e * np.sin(pd), -e * np.sin(pd) - zt * np.cos(de))
    Gq[4, 5:7] = (zf * np.sin(oe), zf * np.sin(oe) - u * np.cos(ep))
    Gq[5, 5:7] = (-zf * np.cos(oe), -zf * np.cos(oe) - u * np.sin(ep))

    # d/dt(Gq) qd: second derivatives of g along qd
    btd, pdd, oed = bed + thd, phd + ded, omd + epd
    common_x = -rr * np.cos(be) * bed**2 + d * np.cos(bt) * btd**2
    common_y = -rr * np.sin(be) * bed**2 + d * np.sin(bt) * btd**2
    gqq = np.array(
        [
            common_x + ss * sga * gad**2,
            common_y - ss * cga * gad**2,
            common_x + e * np.sin(pd) * pdd**2 + zt * np.cos(de) * ded**2,
            common_y - e * np.cos(pd) * pdd**2 + zt * np.sin(de) * ded**2,
            common_x + zf * np.cos(oe) * oed**2 + u * np.sin(ep) * epd**2,
            common_y + zf * np.sin(oe) * oed**2 - u * np.cos(ep) * epd**2,
        ]
    )
    return M, f, g, Gq, gqq


def squeezer_accelerations(q, qd):
    """Index-1 form: [M Gᵀ; G 0][q''; λ] = [f; −gqq]; returns (q'', λ)."""
    M, f, _g, Gq, gqq = squeezer_terms(q, qd)
    K = np.zeros((13, 13))
    K[:7, :7] = M
    K[:7, 7:] = Gq.T
    K[7:, :7] = Gq
    sol = np.linalg.solve(K, np.concatenate([f, -gqq]))
    return sol[:7], sol[7:]


def squeezer_rhs():
    """First-order right-hand side y = (q, q') of the index-1 form, and y0 (at rest)."""

    def f(_t, y):
        return np.concatenate([y[7:], squeezer_accelerations(y[:7], y[7:])[0]])

    return f, np.concatenate([np.array(SQUEEZER["q0"]), np.zeros(7)])


def squeezer_angles(t, rtol=1e-13):
    """(n_t, 7) reference angles on the times ``t`` (DOP853 at ``rtol`` with dense output)."""
    from scipy.integrate import solve_ivp

    f, y0 = squeezer_rhs()
    t = np.asarray(t, dtype=float)
    sol = solve_ivp(f, (0.0, t[-1]), y0, method="DOP853", rtol=rtol, atol=rtol, t_eval=t)
    return sol.y[:7].T


# --- the geared arm (six-DOF paper), without backlash ------------------------------------------


def _quintic(t: float, y1, t0: float, t1: float):
    """Rest-to-rest quintic from 0 at t0 to y1 at t1: value and rate at the scalar time t."""
    tau = min(max((t - t0) / (t1 - t0), 0.0), 1.0)  # scalar: np.clip costs microseconds
    s = tau**3 * (10.0 - 15.0 * tau + 6.0 * tau**2)
    sd = 30.0 * tau**2 * (1.0 - tau) ** 2 / (t1 - t0)
    return y1 * s, y1 * sd


class GearedArmReference:
    """The backlash-free geared arm (``geared_arm_6dof(backlash=0)``, 44 bodies) in its six arm
    joint angles p, by a second library: Pinocchio's CRBA and RNEA on the open tree of the same
    bodies (:func:`benchmarks.peers.pinocchio.pinocchio_tree` of ``ideal_gears=False``: rotors and
    shafts free), reduced by the gear ratios. Each train's rolling conditions
    r1 q_motor + R1 q_shaft = 0 and r2 q_shaft + R2 q_joint = 0 give q = T p with a constant T,
    so T^T M(Tp) T p'' = T^T (Q - b(Tp, Tp')): M from CRBA, b (gravity, Coriolis, centrifugal)
    from RNEA at zero acceleration, Q the PD motor torques
    clamp(kp (N ref(t) - q_m) + kd (N ref'(t) - q_m'), ±limit) on the rotors, with the quintic
    references written out here. Nothing of armdyn's Newton–Euler/KKT path is used."""

    def __init__(self, **scene):
        import inspect

        import pinocchio as pin
        from armdyn.papers.geared_arm import JOINTS, geared_arm_6dof

        defaults = {k: v.default for k, v in inspect.signature(geared_arm_6dof).parameters.items()}
        self.scene = dict(defaults, **scene, backlash=0.0, n_motors=1, control="motor")
        self.tree = tree = geared_arm_6dof(**dict(self.scene, ideal_gears=False))
        self.pin = pin
        self.pm, self.idx = pinocchio_tree(tree)
        self.pd = self.pm.createData()
        names = list(tree.coord_names)
        n = len(names)
        self.T = np.zeros((n, 6))
        self.motor = np.array([names.index(f"{j[0]}_motor") for j in JOINTS])
        for j, (name, _p, _a, _pt, R2, r2, R1, r1, _e) in enumerate(JOINTS):
            self.T[names.index(name), j] = 1.0
            self.T[names.index(f"{name}_shaft"), j] = -R2 / r2
            self.T[self.motor[j], j] = (R1 / r1) * (R2 / r2)  # the train's ratio N
        self.ratio = self.T[self.motor, np.arange(6)]

    def motor_torques(self, t, q, qd):
        """PD motor torques on the rotor coordinates (tree coordinate order)."""
        s = self.scene
        ref, rate = _quintic(t, self.ratio * np.asarray(s["targets"]), s["t_start"], s["t_end"])
        e = ref - q[self.motor]
        u = s["kp"] * np.arctan2(np.sin(e), np.cos(e)) + s["kd"] * (rate - qd[self.motor])
        Q = np.zeros(q.size)
        Q[self.motor] = np.clip(u, -s["torque_limit"], s["torque_limit"])
        return Q

    def tree_terms(self, q, qd):
        """M(q) and b(q, qd) of the open tree in armdyn's coordinate order."""
        pin, i = self.pin, self.idx
        qp = np.zeros(self.pm.nq)
        vp = np.zeros(self.pm.nv)
        qp[i], vp[i] = q, qd
        M = mass_matrix(pin, self.pm, self.pd, qp)
        b = pin.rnea(self.pm, self.pd, qp, vp, np.zeros(self.pm.nv))
        return M[np.ix_(i, i)], b[i]

    def lagrange_check(self, times, seed: int = 0) -> float:
        """Worst relative difference, over random states (q, qd, qdd uniform in [-3, 3]) at the
        given times, between these tree equations (M qdd + b - Q) and the torques of armdyn's
        independent Lagrange validator on the same open tree."""
        from armdyn.validation import LagrangeValidator

        lv = LagrangeValidator(self.tree)
        n = len(self.idx)
        rng = np.random.default_rng(seed)
        worst = 0.0
        for t in times:
            q, qd, qdd = (rng.uniform(-3.0, 3.0, n) for _ in range(3))
            m, b = self.tree_terms(q, qd)
            mine = m @ qdd + b - self.motor_torques(t, q, qd)
            val = lv.torques(q, qd, qdd, t)
            worst = max(worst, float(np.abs(mine - val).max() / np.abs(val).max()))
        return worst

    def rhs(self):
        T = self.T

        def f(t, y):
            p, pd = y[:6], y[6:]
            q, qd = T @ p, T @ pd
            M, b = self.tree_terms(q, qd)
            pdd = np.linalg.solve(T.T @ M @ T, T.T @ (self.motor_torques(t, q, qd) - b))
            return np.concatenate([pd, pdd])

        return f, np.zeros(12)

    def angles(self, t, rtol=1e-12, method="DOP853"):
        """(n_t, 6) arm joint angles on the times ``t`` (SciPy's ``method``, DOP853 by default,
        at ``rtol`` = ``atol``, dense output). The rotors' damping makes the equations stiff:
        ``"Radau"`` needs about 8x fewer evaluations at rtol 1e-10 (1.6e-12 from DOP853 at
        1e-12 over the first second)."""
        from scipy.integrate import solve_ivp

        f, y0 = self.rhs()
        t = np.asarray(t, dtype=float)
        sol = solve_ivp(f, (0.0, t[-1]), y0, method=method, rtol=rtol, atol=rtol, t_eval=t)
        if not sol.success:
            raise RuntimeError(f"geared-arm reference: {sol.message}")
        return sol.y[:6].T
