"""``armdyn verify``: accuracy figures against independent references.

Prints (and returns) four groups of numbers, each against a reference that shares no code with
the solver:
1. simple pendulum periods against the closed form with the complete elliptic integral;
2. energy and angular-momentum conservation (double pendulum, torque-free asymmetric body);
3. constraint drift over a 10⁴-step RK4 run (double pendulum and a closed-loop slider-crank);
4. ``forward_dynamics`` of random spatial 6-DOF arms against M⁻¹ (τ − b) from the complete
   Euler–Lagrange equations of :class:`armdyn.LagrangeValidator` (built by automatic
   differentiation of the joint-space kinematics, independently of the Newton–Euler paths).
"""

from __future__ import annotations

import time

import numpy as np

import armdyn as ad
from armdyn import scenes
from armdyn._rotation import quat_to_rot
from armdyn.scenes.extreme import random_spatial_arm

# the runs are of the paper's Cartesian formulation, whose accuracy the figures document
# (simulate's default, coordinates="auto", may take joint space for the open trees)
CART = "cartesian"


def _crossing(t, y, k):
    """Root of y(t) in [t[k], t[k+1]] from a degree-6 polynomial through 7 samples around it."""
    lo = max(0, min(k - 3, len(t) - 7))
    ts, ys = t[lo : lo + 7], y[lo : lo + 7]
    t0 = ts[3]
    p = np.polynomial.Polynomial.fit(ts - t0, ys, 6)
    roots = [r.real + t0 for r in p.roots() if abs(r.imag) < 1e-9]
    return min(roots, key=lambda r: abs(r - 0.5 * (t[k] + t[k + 1])))


def pendulum_period(theta0, rtol=1e-12, length=1.0, mass=1.0, radius=1e-3, g=9.81):
    """(simulated, closed-form) period of a physical pendulum released at rest from theta0."""
    from scipy.special import ellipk

    model = scenes.simple_pendulum(length, mass, theta0, radius, g)
    i_pivot = 0.4 * mass * radius**2 + mass * length**2
    omega0 = np.sqrt(mass * g * length / i_pivot)
    exact = 4.0 / omega0 * ellipk(np.sin(theta0 / 2) ** 2)
    dt = exact / 400
    res = ad.simulate(model, 0.6 * exact, rtol=rtol, atol=rtol, output_dt=dt, coordinates=CART)
    # half a period: the angular velocity returns to zero at the opposite extreme
    qd = res.qd[:, 0]
    k = next(i for i in range(5, len(qd) - 1) if qd[i] * qd[i + 1] <= 0)
    return 2.0 * _crossing(res.t, qd, k), exact


def conservation(rtol=1e-10):
    out = {}
    dp = scenes.double_pendulum()
    r = ad.simulate(dp, 10.0, rtol=rtol, atol=rtol, output_dt=0.01, coordinates=CART)
    e = r.total_energy
    out["double pendulum energy (rel. to peak kinetic)"] = (
        np.abs(e - e[0]).max() / r.kinetic_energy.max()
    )
    fb = scenes.free_body((1.0, 2.0, 3.0))
    v0 = fb.v0.copy()
    v0[3:6] = [0.3, 1.0, 0.2]
    r = ad.simulate(fb, 10.0, rtol=rtol, atol=rtol, output_dt=0.01, v0=v0, coordinates=CART)
    e = r.total_energy
    out["free body energy (rel.)"] = np.abs(e - e[0]).max() / e[0]
    rots = np.array([quat_to_rot(u[3:7]) for u in r.u])
    h = np.einsum("nij,jk,nk->ni", rots, np.diag([1.0, 2.0, 3.0]), r.v[:, 3:6])
    out["free body angular momentum (rel.)"] = np.abs(h - h[0]).max() / np.linalg.norm(h[0])
    return out


def drift(steps=10_000, dt=1e-3):
    out = {}
    for name, model in [
        ("double pendulum", scenes.double_pendulum()),
        ("slider-crank (closed loop, driven)", scenes.slider_crank()),
    ]:
        r = ad.simulate(model, steps * dt, integrator="rk4", dt=dt, output_dt=dt, coordinates=CART)
        out[name] = (len(r.t) - 1, r.position_residual.max(), r.velocity_residual.max())
    return out


def lagrange_crosscheck(n_arms=5, seed=1):
    """Worst relative difference of ``forward_dynamics`` from the Lagrange validator's
    accelerations M(q)⁻¹ (τ − b(q, q̇)), b the validator's torques at zero acceleration, over
    5 random states of each of ``n_arms`` random spatial 6-DOF arms (every second one with
    prismatic joints)."""
    rng = np.random.default_rng(seed)
    worst = 0.0
    for k in range(n_arms):
        model = random_spatial_arm(rng, 6, prismatic=(k % 2 == 1)).model
        lagrange = ad.LagrangeValidator(model)
        for _ in range(5):
            q, qd, tau = rng.normal(size=(3, 6))
            a = ad.forward_dynamics(model, q, qd, tau)
            bias = lagrange.torques(q, qd, np.zeros(6))
            b = np.linalg.solve(lagrange.mass_matrix(q), tau - bias)
            worst = max(worst, np.abs(a - b).max() / np.abs(b).max())
    return worst


def main() -> int:
    start = time.perf_counter()
    print("armdyn verify: accuracy against independent references\n")
    print(
        "1. Simple pendulum period vs closed form 4 sqrt(I/(m g L)) K(sin^2(theta0/2)), rtol=1e-12"
    )
    for deg in (1e-3 * 180 / np.pi, 30.0, 90.0, 170.0):
        sim, exact = pendulum_period(np.radians(deg))
        print(
            f"   theta0 = {deg:8.4f} deg: T = {sim:.12f} s, exact {exact:.12f} s, "
            f"rel. error {abs(sim - exact) / exact:.1e}"
        )
    print("\n2. Conservation over 10 s, DOPRI5 rtol = atol = 1e-10")
    for k, v in conservation().items():
        print(f"   {k}: {v:.1e}")
    print("\n3. Constraint drift, RK4 dt = 1e-3, 10^4 steps, every step recorded")
    for k, (n, rf, rv) in drift().items():
        print(f"   {k}: {n} steps, max |f| = {rf:.1e}, max |zeta v - rhs| = {rv:.1e}")
    print(
        "\n4. forward_dynamics vs Euler-Lagrange (LagrangeValidator), "
        "5 random spatial 6-DOF arms x 5 states"
    )
    print(f"   max relative difference in qdd: {lagrange_crosscheck():.1e}")
    print(f"\n(done in {time.perf_counter() - start:.1f} s)")
    return 0
