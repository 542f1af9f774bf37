"""The two-node thermal model of a duty cycle (armdyn.sizing.thermal.thermal_cycle) against
closed forms, brute-force repetition and an ODE solver, and its one-node fallback against the
sizing report's first-order model.

Two-node model (rises x = (θ_w, θ_h) above ambient): x' = A x + b P with
A = [[−1/τ_w, 1/τ_w], [R_h/(R_w τ_h), −R_h/(R_w τ_h) − 1/τ_h]], b = (R_w/τ_w, 0). Under a
constant loss P from x(0) = 0: x(t) = x_ss − e^{At} x_ss, x_ss = −A⁻¹ b P = ((R_w + R_h) P,
R_h P); under a ramp P = k t: x(t) = G k t + F k − e^{At} F k, G = −A⁻¹ b, F = A⁻¹ G. The test
evaluates e^{At} by the eigendecomposition of A (numpy.linalg.eig), not the module's formula.
"""

import numpy as np
import pytest
from armdyn.sizing import thermal

RW, RH, TW, TH = 0.6, 1.3, 25.0, 900.0


def a_matrix(rw=RW, rh=RH, tw=TW, th=TH):
    a = np.array([[-1 / tw, 1 / tw], [rh / (rw * th), -rh / (rw * th) - 1 / th]])
    return a, np.array([rw / tw, 0.0])


def expm_eig(a, t):
    lam, v = np.linalg.eig(a)
    return np.einsum("ij,tj,jk->tik", v, np.exp(np.outer(t, lam)), np.linalg.inv(v))


def irregular_grid(n=300, seed=1):
    steps = np.random.default_rng(seed).uniform(0.01, 30.0, n)
    t = np.concatenate([[0.0], np.cumsum(steps)])
    return np.insert(t, 50, t[50])  # a repeated time (zero-length step) on the way


def test_constant_loss_two_node_closed_form():
    t, p = irregular_grid(), 40.0
    net = thermal.thermal_network(RW, RH, TW, TH)
    out = thermal.thermal_cycle(t, np.full((len(t), 1), p), net, np.ones(1), repeat=1)
    a, b = a_matrix()
    x_ss = -np.linalg.solve(a, b) * p
    assert x_ss == pytest.approx([(RW + RH) * p, RH * p], rel=1e-14)
    ref = x_ss - expm_eig(a, t) @ x_ss
    np.testing.assert_allclose(out.winding[:, 0], ref[:, 0], rtol=1e-9, atol=1e-9 * x_ss[0])
    np.testing.assert_allclose(out.housing[:, 0], ref[:, 1], rtol=1e-9, atol=1e-9 * x_ss[1])
    assert out.winding_peak[0] == pytest.approx(np.max(ref[:, 0]), rel=1e-9)
    # the grid reaches 4500 s = 5 τ_h: near the steady state
    assert out.winding_peak[0] > 0.99 * x_ss[0]


def test_ramp_loss_two_node_closed_form():
    t, k = irregular_grid(seed=2), 0.05
    net = thermal.thermal_network(RW, RH, TW, TH)
    out = thermal.thermal_cycle(t, (k * t)[:, None], net, np.ones(1), repeat=1)
    a, b = a_matrix()
    g = -np.linalg.solve(a, b)
    f = np.linalg.solve(a, g)
    ref = np.outer(t, g * k) + f * k - expm_eig(a, t) @ (f * k)
    np.testing.assert_allclose(out.winding[:, 0], ref[:, 0], rtol=1e-9, atol=1e-9 * ref[-1, 0])
    np.testing.assert_allclose(out.housing[:, 0], ref[:, 1], rtol=1e-9, atol=1e-9 * ref[-1, 1])


def cycle_grid():
    """A 3 s motion (100 samples, a current bump) then a 2 s dwell at a holding current."""
    tm = np.linspace(0.0, 3.0, 100)
    i2 = (3.5 + 5.0 * np.sin(np.pi * tm / 3.0)) ** 2
    t = np.concatenate([tm, [3.0, 5.0]])
    return t, np.concatenate([i2, [16.0, 16.0]])


def candidates():
    """A two-node motor and a one-node one (R_th, τ_th only)."""
    return thermal.thermal_network(
        [0.5, np.nan], [1.0, np.nan], [20.0, np.nan], [150.0, np.nan], [np.nan, 2.0], [np.nan, 30.0]
    )


R_REF, ALPHA = 0.8, 0.00393


def test_periodic_state_equals_brute_force_repetition():
    """The closed-form periodic state (fixed point of the period map, copper R(T) included)
    against stepping through 600 repeated periods from ambient (one long grid, repeat=1):
    their last periods agree to 0.01 K (the brute force is 1e-3 K from its limit: the slowest
    mode, e^(−5 s · 600 / τ) with τ < 160 s), and ``repeat=600`` equals the brute force."""
    t, i2 = cycle_grid()
    net = candidates()
    m = 600
    period = t[-1] - t[0]
    # the periods in turn (each period's end and the next one's start share a time)
    long_t = np.concatenate([t + j * period for j in range(m)])
    long_i2 = np.tile(i2, m)
    q = np.repeat(i2[:, None], 2, axis=1)
    args = (np.full(2, R_REF), np.full(2, ALPHA * R_REF))
    brute = thermal.thermal_cycle(
        long_t, np.repeat(long_i2[:, None], 2, axis=1), net, *args, repeat=1
    )
    last_w = brute.winding[-len(t) :]
    periodic = thermal.thermal_cycle(t, q, net, *args, repeat=None)
    assert np.max(np.abs(periodic.winding - last_w)) < 0.01
    assert np.max(np.abs(periodic.housing[:, 0] - brute.housing[-len(t) :, 0])) < 0.01
    assert periodic.winding_peak == pytest.approx(np.max(last_w, axis=0), abs=0.01)
    assert np.isnan(periodic.housing_peak[1])  # one-node: no housing
    repeated = thermal.thermal_cycle(t, q, net, *args, repeat=m)
    np.testing.assert_allclose(repeated.winding, last_w, rtol=1e-9)
    np.testing.assert_allclose(repeated.winding_peak, np.max(brute.winding, axis=0), rtol=1e-9)
    # the resistance's rise matters here: without it the temperatures are lower
    cold = thermal.thermal_cycle(t, q, net, np.full(2, R_REF), 0.0, repeat=None)
    assert np.all(periodic.winding_peak > cold.winding_peak + 1.0)


def test_copper_resistance_against_an_ode_solver():
    """R(T_w) at each sample's temperature, the loss linear between samples (the module's
    rule) against the exact nonlinear model C_w θ_w' = R_ref (1 + α θ_w) i(t)² − …
    (scipy's solve_ivp, tight tolerances, i² linear between samples) over three periods from
    ambient: within 1e-4 K at every sample of a 30 K+ rise."""
    from scipy.integrate import solve_ivp

    t, i2 = cycle_grid()
    period = t[-1] - t[0]
    tt = np.concatenate([t + j * period for j in range(3)])
    ii = 5.0 * np.tile(i2, 3)  # a strong current: a rise of tens of kelvin in 15 s
    net = thermal.thermal_network(0.5, 1.0, 20.0, 150.0)
    out = thermal.thermal_cycle(tt, ii[:, None], net, np.full(1, R_REF), ALPHA * R_REF, repeat=1)
    a, b = a_matrix(0.5, 1.0, 20.0, 150.0)
    keep = np.concatenate([[True], np.diff(tt) > 0])

    def rhs(s, x):  # i² linear between samples; at a repeated time the later sample starts
        k = min(np.searchsorted(tt, s, side="right") - 1, len(tt) - 2)
        cur = ii[k] + (ii[k + 1] - ii[k]) * (s - tt[k]) / (tt[k + 1] - tt[k])
        return a @ x + b * R_REF * (1 + ALPHA * x[0]) * cur

    sol = solve_ivp(rhs, (0, tt[-1]), [0.0, 0.0], t_eval=tt[keep], rtol=1e-11, atol=1e-11,
                    max_step=0.05, method="DOP853")  # fmt: skip
    np.testing.assert_allclose(out.winding[keep, 0], sol.y[0], atol=1e-4)
    np.testing.assert_allclose(out.housing[keep, 0], sol.y[1], atol=1e-4)
    assert sol.y[0].max() > 30.0  # the resistance rises by more than 12 % here


def test_runaway_is_infinite():
    """α R i² R_th ≥ 1: the copper's rise outruns the cooling, no periodic state exists."""
    t, i2 = cycle_grid()
    net = thermal.thermal_network(0.5, 1.0, 20.0, 150.0)
    q = 400.0 * i2[:, None] / i2.min()  # ≥ 400 A²: α R i² (R_w + R_h) ≥ 0.00393·400·1.5 > 1
    out = thermal.thermal_cycle(t, q, net, np.ones(1), ALPHA, repeat=None)
    assert out.winding_peak[0] == np.inf and out.housing_peak[0] == np.inf
    ok = thermal.thermal_cycle(t, q / 20, net, np.ones(1), ALPHA, repeat=None)
    assert np.isfinite(ok.winding_peak[0])


def test_no_thermal_data_is_not_checked():
    net = thermal.thermal_network(np.nan, 1.0, 20.0, 150.0)  # R_w missing, no one-node data
    out = thermal.thermal_cycle(np.array([0.0, 1.0]), np.ones((2, 1)), net, np.ones(1))
    assert not net.valid[0] and np.isnan(out.winding_peak[0]) and np.isnan(out.housing_peak[0])
