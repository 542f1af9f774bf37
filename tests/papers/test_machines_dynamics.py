"""Actuator torques of closed-loop machines against independent references (issue 36): the
four-bar's from its constrained Lagrange equations derived by SymPy, the delta robot's by
virtual work on its closed-form kinematics (numpy, no armdyn call); armdyn's side is
``driven_inverse_dynamics`` (the Cartesian formulation with the actuated joints driven). A
forward ``simulate`` driven by the reference torques (``add_joint_torque``) follows the
prescribed motion over 5 s."""

import armdyn as ad
import numpy as np
import pytest
import sympy as sp
from armdyn.scenes import four_bar
from armdyn.scenes import machines as mc

T_END = 5.0

# ---------------------------------------------------------------------------------------------
# the four-bar (armdyn.scenes.four_bar's defaults): crank a, coupler b, rocker c, ground d in
# the x-y plane, gravity -y, links of masses m with centres at their midpoints and moments of
# inertia 0.5 m r^2 about z (r = 0.01)
A_LEN, B_LEN, C_LEN, D_LEN, START = 0.3, 0.6, 0.5, 0.7, np.pi / 3
MASSES, RADIUS, G = (1.0, 2.0, 1.5), 0.01, 9.81


def _four_bar_equations():
    """Lambdified closure(th) -> (Phi, Phi_th) and dynamics(th, thd) -> (M, h + dV/dth,
    gamma = d(Phi_th thd)/dth thd) (h: the velocity terms, V the potential), for the absolute
    link angles th = (crank from the ground pivot O, coupler from the crank pin, rocker from
    the ground pivot D)."""
    th = sp.symbols("th1:4")
    thd = sp.symbols("thd1:4")

    def unit(angle):
        return sp.Matrix([sp.cos(angle), sp.sin(angle)])

    pa = A_LEN * unit(th[0])
    pd = sp.Matrix([D_LEN, 0])
    centres = [pa / 2, pa + B_LEN * unit(th[1]) / 2, pd + C_LEN * unit(th[2]) / 2]
    q, qd = sp.Matrix(th), sp.Matrix(thd)
    kinetic, potential = 0, 0
    for m, x, w in zip(MASSES, centres, thd, strict=True):
        v = x.jacobian(q) * qd
        kinetic += m * (v.T * v)[0] / 2 + 0.5 * m * RADIUS**2 * w**2 / 2
        potential += m * G * x[1]
    mass = sp.hessian(kinetic, thd)
    dkdq = sp.Matrix([kinetic]).jacobian(q).T
    h = (mass * qd).jacobian(q) * qd - dkdq
    dv = sp.Matrix([potential]).jacobian(q).T
    phi = pa + B_LEN * unit(th[1]) - pd - C_LEN * unit(th[2])
    phi_q = phi.jacobian(q)
    gamma = (phi_q * qd).jacobian(q) * qd
    closure = sp.lambdify([th], [phi, phi_q], "numpy", cse=True)
    dynamics = sp.lambdify([th, thd], [mass, h + dv, gamma], "numpy", cse=True)
    return closure, dynamics


class FourBarReference:
    """Torque on the crank (and the loop multipliers) for a prescribed crank motion."""

    def __init__(self):
        self.f = _four_bar_equations()
        pa = A_LEN * np.array([np.cos(START), np.sin(START)])
        pd = np.array([D_LEN, 0.0])
        dist = np.linalg.norm(pd - pa)
        x = (B_LEN**2 - C_LEN**2 + dist**2) / (2 * dist)
        e = (pd - pa) / dist
        pb = pa + x * e + np.sqrt(B_LEN**2 - x**2) * np.array([-e[1], e[0]])
        self.last = np.array([np.arctan2(*(pb - pa)[::-1]), np.arctan2(*(pb - pd)[::-1])])

    def torque(self, crank, crank_rate, crank_acc):
        closure, dynamics = self.f
        th = np.array([START + crank, *self.last])
        for _ in range(50):  # Newton on the loop closure for the coupler and rocker angles
            r, jac = (np.asarray(x, float) for x in closure(th))
            step = np.linalg.solve(jac[:, 1:], r.ravel())
            th[1:] -= step
            if np.abs(step).max() < 1e-15:
                break
        r, jac = (np.asarray(x, float) for x in closure(th))
        assert np.abs(r).max() < 1e-14
        self.last = th[1:].copy()
        thd = np.array([crank_rate, 0.0, 0.0])
        thd[1:] = -np.linalg.solve(jac[:, 1:], jac[:, 0] * crank_rate)
        mass, forces, gamma = (np.asarray(x, float) for x in dynamics(th, thd))
        thdd = np.array([crank_acc, 0.0, 0.0])
        thdd[1:] = -np.linalg.solve(jac[:, 1:], jac[:, 0] * crank_acc + gamma.ravel())
        # M thdd + h + dV/dth = (tau, 0, 0) + Phi_th^T lambda
        system = np.column_stack([[1.0, 0.0, 0.0], -jac.T])
        return np.linalg.solve(system, mass @ thdd + forces.ravel())[0]


def crank_motion(t):
    """The prescribed crank coordinate (0 at the assembly): 5 turns in 5 s with a wobble.

    Driven by torques alone the four-bar is unstable along slow motions (gravity tips the
    linkage like an inverted pendulum): along a crank swinging at 0.4 Hz, or turning at a
    quarter turn per second, the forward run ends 6e-3 / 9e-8 rad away from the motion after
    5 s whatever the integrator's tolerance (rtol 1e-12 and 1e-14 alike: the round-off grows,
    not the truncation error), so no forward run can follow those to 1e-8. One turn per second
    keeps the motion inertia-dominated (1e-11). Figures: ``python
    tests/papers/test_machines_dynamics.py``."""
    t = np.asarray(t, float)
    w = np.pi
    q = 2 * np.pi * t + 0.3 * np.sin(w * t)
    return q, 2 * np.pi + 0.3 * w * np.cos(w * t), -0.3 * w**2 * np.sin(w * t)


@pytest.fixture(scope="module")
def four_bar_run():
    def drive(t):
        return tuple(float(x) for x in crank_motion(t))

    model = four_bar(crank_drive=drive)
    t = np.linspace(0.0, T_END, 101)
    ref = FourBarReference()
    tau = np.array([ref.torque(*crank_motion(ti)) for ti in t])
    return model, t, ad.driven_inverse_dynamics(model, t), tau


def test_four_bar_torque_equals_constrained_lagrange(four_bar_run):
    _, t, idr, tau = four_bar_run
    np.testing.assert_allclose(idr.q[:, 0], crank_motion(t)[0], atol=1e-12)
    assert np.abs(tau).max() > 1.0  # gravity and inertia load the crank
    np.testing.assert_allclose(idr.drive_forces[:, 0], tau, rtol=0, atol=1e-10)


def test_four_bar_forward_run_follows_the_motion(four_bar_run):
    _, _, idr, _ = four_bar_run
    ref = FourBarReference()
    cache = {}

    def torque(t):
        if t not in cache:
            cache.clear()
            cache[t] = ref.torque(*crank_motion(t))
        return cache[t], 0.0, 0.0

    free = four_bar(crank_torque=torque)
    res = ad.simulate(
        free, T_END, u0=idr.u[0], v0=idr.v[0], integrator="dop853", rtol=1e-12, atol=1e-12,
        output_dt=0.05,
    )  # fmt: skip
    assert res.t[-1] == pytest.approx(T_END)
    np.testing.assert_allclose(res.q[:, 0], crank_motion(res.t)[0], rtol=0, atol=1e-8)


# ---------------------------------------------------------------------------------------------
# the delta robot (armdyn.scenes.machines.delta_robot's documented geometry)


class DeltaReference:
    """Virtual work on the delta's closed-form kinematics: arms turning about fixed axes
    (moment of inertia I about the pivot, first moment S), a translating plate of mass m held
    by the parallelograms: tau = I qdd + dV/dq + J^T m (p'' + g z), J = dp/dq."""

    def __init__(self, g: mc.DeltaGeometry):
        self.g = g
        phi = np.deg2rad([0.0, 120.0, 240.0])
        self.radial = np.column_stack([np.cos(phi), np.sin(phi), np.zeros(3)])
        r, length = g.radius, g.arm
        self.inertia = g.arm_mass * (r**2 / 4 + length**2 / 3) + g.elbow_mass * length**2
        self.moment = g.arm_mass * length / 2 + g.elbow_mass * length

    def sphere_centres(self, q):
        """Q_i (the elbow moved by the plate offset) and its first two derivatives in q_i."""
        g, z = self.g, np.array([0.0, 0.0, 1.0])
        ang = g.theta0 + np.asarray(q)[:, None]
        c, s = np.cos(ang), np.sin(ang)
        centre = (g.base - g.plate) * self.radial + g.arm * (c * self.radial - s * z)
        return centre, g.arm * (-s * self.radial - c * z), g.arm * (-c * self.radial + s * z)

    def plate(self, q):
        """The plate centre: the lower intersection of the three spheres |p - Q_i| = rod."""
        centre = self.sphere_centres(q)[0]
        normals = 2 * (centre[0] - centre[1:])
        rhs = np.sum(centre[0] ** 2) - np.sum(centre[1:] ** 2, axis=1)
        line = np.cross(normals[0], normals[1])
        base = np.linalg.lstsq(normals, rhs, rcond=None)[0]  # the minimum-norm point
        off = base - centre[0]
        a, b, c = line @ line, 2 * off @ line, off @ off - self.g.rod**2
        roots = (-b + np.array([-1.0, 1.0]) * np.sqrt(b * b - 4 * a * c)) / (2 * a)
        candidates = base + roots[:, None] * line
        p = candidates[np.argmin(candidates[:, 2])]
        for _ in range(3):  # polish on the three spheres
            d = p - centre
            p = p - np.linalg.solve(2 * d, np.sum(d * d, axis=1) - self.g.rod**2)
        return p

    def torques(self, q, qd, qdd):
        g = self.g
        centre, d1, d2 = self.sphere_centres(q)
        p = self.plate(q)
        rows = p - centre  # G = rows: G p' = diag(rows . d1) qd
        k = np.sum(rows * d1, axis=1)
        jac = np.linalg.solve(rows, np.diag(k))
        pd = jac @ qd
        rel = pd - d1 * qd[:, None]
        pdd = np.linalg.solve(
            rows, np.sum(rows * (d2 * qd[:, None] ** 2 + d1 * qdd[:, None]), axis=1)
            - np.sum(rel * rel, axis=1),
        )  # fmt: skip
        force = g.plate_mass * (pdd + np.array([0.0, 0.0, 9.81]))
        gravity = -9.81 * self.moment * np.cos(g.theta0 + q)
        return self.inertia * qdd + gravity + jac.T @ force


AMPLITUDES, FREQUENCIES = (0.35, 0.25, 0.3), (0.5, 0.8, 0.65)


def arm_motion(t):
    """(q, qd, qdd) (3,) of the arms at t: q_i = A_i sin(2 pi f_i t)."""
    a, w = np.array(AMPLITUDES), 2 * np.pi * np.array(FREQUENCIES)
    return a * np.sin(w * t), a * w * np.cos(w * t), -a * w**2 * np.sin(w * t)


@pytest.fixture(scope="module")
def delta_run():
    drives = {
        name: ad.profiles.sine(a, f)
        for name, a, f in zip(mc.DELTA_ACTUATED, AMPLITUDES, FREQUENCIES, strict=True)
    }
    for k, profile in enumerate(drives.values()):  # the profiles are the motion above
        for ti in (0.3, 1.7):
            np.testing.assert_allclose(
                profile.eval(ti), [x[k] for x in arm_motion(ti)], rtol=1e-14, atol=1e-14
            )
    model = mc.delta_robot(drives=drives)
    t = np.linspace(0.0, T_END, 101)
    ref = DeltaReference(mc.DeltaGeometry())
    tau = np.array([ref.torques(*arm_motion(ti)) for ti in t])
    return model, t, ad.driven_inverse_dynamics(model, t), tau, ref


def test_delta_torques_equal_virtual_work(delta_run):
    model, t, idr, tau, ref = delta_run
    k = model.body_names.index("plate")
    plates = np.array([ref.plate(arm_motion(ti)[0]) for ti in t])
    np.testing.assert_allclose(idr.u[:, 7 * k : 7 * k + 3], plates, atol=1e-12)
    assert np.abs(tau).max() > 2.0 and np.ptp(tau, axis=0).min() > 0.2  # gravity and inertia
    np.testing.assert_allclose(idr.drive_forces, tau, rtol=0, atol=1e-10)


def _reference_torque(ref, k, cache):
    """Arm k's reference torque as a profile (the three share `cache`: one solve per time)."""

    def profile(t):
        if t not in cache:
            cache.clear()
            cache[t] = ref.torques(*arm_motion(t))
        return float(cache[t][k]), 0.0, 0.0

    return profile


def test_delta_forward_run_follows_the_motion(delta_run):
    _, _, idr, _, ref = delta_run
    cache = {}
    free = mc.delta_robot(
        torques={n: _reference_torque(ref, k, cache) for k, n in enumerate(mc.DELTA_ACTUATED)}
    )
    res = ad.simulate(
        free, T_END, u0=idr.u[0], v0=idr.v[0], integrator="dop853", rtol=1e-12, atol=1e-12,
        output_dt=0.05,
    )  # fmt: skip
    assert res.t[-1] == pytest.approx(T_END)
    want = np.array([arm_motion(ti)[0] for ti in res.t])
    np.testing.assert_allclose(res.q[:, :3], want, rtol=0, atol=1e-8)


# ---------------------------------------------------------------------------------------------
# the joint-level API on the loop models (independent coordinates: the actuated joints)


def test_four_bar_inverse_dynamics_on_the_crank(four_bar_run):
    """ad.inverse_dynamics of the undriven four-bar in its independent coordinate (the crank,
    added first) gives the reference torque along the same motion."""
    _, t, _, tau = four_bar_run
    free = four_bar()
    assert list(free.coord_names) == ["A"]
    q, qd, qdd = (x[:, None] for x in crank_motion(t))
    np.testing.assert_allclose(ad.inverse_dynamics(free, q, qd, qdd)[:, 0], tau, rtol=0, atol=1e-10)


def test_delta_inverse_dynamics_on_the_arms(delta_run):
    _, t, _, tau, _ = delta_run
    free = mc.delta_robot()
    assert tuple(free.coord_names) == mc.DELTA_ACTUATED
    q, qd, qdd = (np.array([arm_motion(ti)[k] for ti in t]) for k in range(3))
    np.testing.assert_allclose(ad.inverse_dynamics(free, q, qd, qdd), tau, rtol=0, atol=1e-10)


@pytest.mark.parametrize("machine", ["palletizer", "delta"])
def test_trajectory_run_of_a_cycle_is_the_driven_inverse_dynamics(machine):
    """trajectory_run takes a machine's cycle in its actuated coordinates: the joint torques
    are driven_inverse_dynamics' drive forces (so sizing_report and select_drivetrain take the
    machines as they take serial arms)."""
    cycle = mc.pick_and_place(machine).sample(dt=0.01)
    build = mc.palletizer if machine == "palletizer" else mc.delta_robot
    run = ad.trajectory_run(build(), cycle)
    driven = ad.driven_inverse_dynamics(build(drives=cycle), run.t)
    scale = np.abs(driven.drive_forces).max()
    np.testing.assert_allclose(run.joint_torques, driven.drive_forces, rtol=0, atol=1e-12 * scale)


def _open_loop_growth():
    """The four-bar driven by its reference torques along three crank motions, at two
    tolerances: the largest deviation from the motion over 5 s (the figures of crank_motion's
    docstring and docs/mechanisms.md)."""
    w = 2 * np.pi * 0.4
    motions = {
        "swing 1.2 sin(2 pi 0.4 t)": lambda t: (
            1.2 * np.sin(w * t), 1.2 * w * np.cos(w * t), -1.2 * w**2 * np.sin(w * t),
        ),
        "quarter turn per second": lambda t: (
            np.pi / 2 * t + 0.3 * np.sin(np.pi * t), np.pi / 2 + 0.3 * np.pi * np.cos(np.pi * t),
            -0.3 * np.pi**2 * np.sin(np.pi * t),
        ),
        "one turn per second (the test's)": crank_motion,
    }  # fmt: skip
    for name, motion in motions.items():
        start = ad.driven_inverse_dynamics(four_bar(crank_drive=lambda t, m=motion: m(t)), [0.0])
        for tol in (1e-12, 1e-14):
            ref, cache = FourBarReference(), {}

            def torque(t, ref=ref, cache=cache, motion=motion):
                if t not in cache:
                    cache.clear()
                    cache[t] = ref.torque(*motion(t))
                return cache[t], 0.0, 0.0

            res = ad.simulate(
                four_bar(crank_torque=torque), T_END, u0=start.u[0], v0=start.v[0],
                integrator="dop853", rtol=tol, atol=tol, output_dt=0.05,
            )  # fmt: skip
            err = np.abs(res.q[:, 0] - motion(res.t)[0]).max()
            print(f"{name}: rtol {tol:g}: largest deviation over {T_END:g} s {err:.1e} rad")


def _agreement():
    """The largest differences the tests assert (torques, forward runs), printed."""
    t = np.linspace(0.0, T_END, 101)
    idr = ad.driven_inverse_dynamics(four_bar(crank_drive=lambda x: crank_motion(x)), t)
    ref = FourBarReference()
    tau = np.array([ref.torque(*crank_motion(ti)) for ti in t])
    print(
        "four-bar: crank torque vs SymPy's constrained Lagrange equations: largest difference "
        f"{np.abs(idr.drive_forces[:, 0] - tau).max():.1e} N m "
        f"(|tau| up to {np.abs(tau).max():.1f})"
    )
    drives = dict(
        zip(mc.DELTA_ACTUATED, map(ad.profiles.sine, AMPLITUDES, FREQUENCIES), strict=True)
    )
    idr = ad.driven_inverse_dynamics(mc.delta_robot(drives=drives), t)
    ref = DeltaReference(mc.DeltaGeometry())
    tau = np.array([ref.torques(*arm_motion(ti)) for ti in t])
    print(
        f"delta: arm torques vs virtual work: largest difference "
        f"{np.abs(idr.drive_forces - tau).max():.1e} N m (|tau| up to {np.abs(tau).max():.1f})"
    )
    cache = {}
    torques = {n: _reference_torque(ref, k, cache) for k, n in enumerate(mc.DELTA_ACTUATED)}
    res = ad.simulate(
        mc.delta_robot(torques=torques), T_END, u0=idr.u[0], v0=idr.v[0], integrator="dop853",
        rtol=1e-12, atol=1e-12, output_dt=0.05,
    )  # fmt: skip
    want = np.array([arm_motion(ti)[0] for ti in res.t])
    print(
        f"delta: forward run's largest deviation over 5 s {np.abs(res.q[:, :3] - want).max():.1e}"
    )


if __name__ == "__main__":  # python tests/papers/test_machines_dynamics.py
    _agreement()
    _open_loop_growth()
