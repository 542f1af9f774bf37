"""Motor-side maths (armdyn.actuators) against hand-computed closed forms, and the energy
balance. The actuators are stand-ins (SimpleNamespace) with the attributes of
``model.actuators`` entries, so the maths is tested without the C++ actuator model.

Conventions (armdyn.actuators): ω = N q̇, T_rot = J ω̇ + b ω + c tanh(ω / v_s) (v_s the
actuator's friction_smoothing, default 1e-3 |N|, add_actuator's), the joint torque
τ includes N T_rot, τ_gear = τ − N T_rot, T = T_rot + τ_gear / (N η) when τ_gear q̇ ≥ 0 else
T_rot + τ_gear η / N, i = T / k_t, P_el = T ω + R i².
"""

from types import SimpleNamespace

import armdyn as ad
import numpy as np
import pytest
from armdyn.actuators import (
    ROTOR_COULOMB_SMOOTHING,
    motor_side,
    motor_side_of_result,
    rotor_torque,
)


def actuator(n=50.0, j=2e-5, eta=1.0, b=0.0, c=0.0, motor=None, joint="j1"):
    return SimpleNamespace(
        joint=joint,
        rotor_joint=f"{joint}_rotor",
        dof=0,
        gear_ratio=n,
        rotor_inertia=j,
        efficiency=eta,
        friction_viscous=b,
        friction_coulomb=c,
        motor=motor,
        gyroscopic=False,
    )


def motor(**kw):
    fields = [f for f in ad.sizing.MOTOR_FIELDS if f != "name"]
    return SimpleNamespace(name="m", **{f: kw.get(f) for f in fields})


def test_rotor_only_joint_under_constant_acceleration():
    """No load: τ = N² J α + N² b α t (c = 0), so τ_gear = 0 and T = J N α + b N α t =: A + B t,
    ω = N α t =: W t. Exactly, ∫₀ᵀ T ω dt = W (A T²/2 + B T³/3) and ∫ R i² dt =
    (R/k²)(A² T + A B T² + B² T³/3); the trapezoid rule on a uniform grid adds exactly
    h²/12 (f'(T) − f'(0)) for these polynomials of degree ≤ 3 (Euler–Maclaurin)."""
    n, j, b, alpha, k_t, r = 40.0, 3e-5, 2e-4, 2.0, 0.05, 1.2
    t = np.linspace(0.0, 1.5, 301)
    h, tend = t[1] - t[0], t[-1]
    qd, qdd = alpha * t, np.full_like(t, alpha)
    tau = n * n * j * qdd + n * n * b * qd
    act = actuator(n=n, j=j, b=b, motor=motor(torque_constant=k_t, resistance=r))
    s = motor_side(act, t, qd, qdd, tau)
    a_, b_, w_ = j * n * alpha, b * n * alpha, n * alpha
    np.testing.assert_allclose(s.speed, w_ * t, rtol=1e-15)
    np.testing.assert_allclose(s.torque, a_ + b_ * t, rtol=1e-13)
    np.testing.assert_allclose(s.load_torque, 0.0, atol=1e-13)
    np.testing.assert_allclose(s.current, (a_ + b_ * t) / k_t, rtol=1e-13)
    # mechanical: f = (A + B t) W t, f' = W (A + 2 B t)
    # copper: f = R/k² (A + B t)², f' = 2 R B/k² (A + B t)
    mech = w_ * (a_ * tend**2 / 2 + b_ * tend**3 / 3) + h**2 / 12 * w_ * 2 * b_ * tend
    copper = r / k_t**2 * (a_**2 * tend + a_ * b_ * tend**2 + b_**2 * tend**3 / 3)
    copper += h**2 / 12 * 2 * r * b_ / k_t**2 * (b_ * tend)
    assert s.energy[-1] == pytest.approx(mech + copper, rel=1e-12)
    assert s.integral("loss_copper") == pytest.approx(copper, rel=1e-12)
    # the rotor's kinetic energy ½ J ω² plus the viscous loss b ∫ ω² (its trapezoid error too)
    ke = 0.5 * j * (w_ * tend) ** 2  # J ω ω̇ = J W² t is linear: the trapezoid rule is exact
    friction = b * w_**2 * tend**3 / 3 + h**2 / 12 * b * 2 * w_**2 * tend
    assert s.integral("mechanical_power") == pytest.approx(ke, rel=1e-12)
    assert s.integral("loss_friction") == pytest.approx(friction, rel=1e-12)
    assert s.energy_regenerated[-1] == 0.0 and s.copper_included


def lift(direction, eta=0.8, n=100.0, b=1e-4, c=0.02, j=1e-4):
    """A load torque τ_L = m g r = 12 N m held while the joint turns at ±v (q̈ = 0)."""
    v, tau_l, k_t, r = 0.5, 12.0, 0.1, 0.8
    t = np.linspace(0.0, 2.0, 11)
    qd = np.full_like(t, direction * v)
    qdd = np.zeros_like(t)
    w = n * direction * v
    t_rot = b * w + c * np.tanh(w / (ROTOR_COULOMB_SMOOTHING * n))  # default v_s = 1e-3 |N|
    tau = np.full_like(t, tau_l + n * t_rot)
    act = actuator(n=n, j=j, eta=eta, b=b, c=c, motor=motor(torque_constant=k_t, resistance=r))
    return motor_side(act, t, qd, qdd, tau), dict(
        v=v, tau_l=tau_l, k_t=k_t, r=r, w=w, t_rot=t_rot, t=t, eta=eta, n=n
    )


def test_constant_torque_lift_motoring():
    s, p = lift(+1.0)
    expect_t = p["t_rot"] + p["tau_l"] / (p["n"] * p["eta"])
    np.testing.assert_allclose(s.torque, expect_t, rtol=1e-14)
    np.testing.assert_allclose(s.load_torque, p["tau_l"], rtol=1e-14)
    i = expect_t / p["k_t"]
    power = expect_t * p["w"] + p["r"] * i**2
    np.testing.assert_allclose(s.electrical_power, power, rtol=1e-14)
    assert s.energy[-1] == pytest.approx(power * 2.0, rel=1e-14)
    assert s.energy_regenerated[-1] == 0.0
    gear = p["tau_l"] * p["v"] * (1 / p["eta"] - 1)
    np.testing.assert_allclose(s.loss_gear, gear, rtol=1e-14)
    np.testing.assert_allclose(s.mechanical_power, p["tau_l"] * p["v"], rtol=1e-14)


def test_lowering_the_load_regenerates_through_the_gear():
    """Lowering: q̇ = −v while the joint still holds +τ_L, so τ_gear q̇ < 0: the load drives the
    gear, which passes on only η of its power, T = T_rot + τ_L η / N with ω < 0 (T_rot < 0: the
    friction opposes ω). P_el = T ω + R i² < 0: the motor regenerates |P_el| every second."""
    s, p = lift(-1.0)
    expect_t = p["t_rot"] + p["tau_l"] * p["eta"] / p["n"]
    np.testing.assert_allclose(s.torque, expect_t, rtol=1e-14)
    power = expect_t * p["w"] + p["r"] * (expect_t / p["k_t"]) ** 2
    assert np.all(power < 0.0)
    np.testing.assert_allclose(s.electrical_power, power, rtol=1e-14)
    assert s.energy[-1] == pytest.approx(power * 2.0, rel=1e-14)
    assert s.energy_regenerated[-1] == pytest.approx(-power * 2.0, rel=1e-14)
    # the gear loss is (1 − η) of the power the load returns
    np.testing.assert_allclose(s.loss_gear, p["tau_l"] * p["v"] * (1 - p["eta"]), rtol=1e-14)
    assert np.all(s.loss_friction > 0.0)


def test_braking_a_pure_inertia_with_a_lossy_gear():
    """A link of inertia I_L decelerating from ω₀: τ_gear = I_L q̈ < 0 with q̇ > 0, so
    T = J N q̈ + I_L q̈ η / N (no friction). With q̇ = v₀ − a t over [0, v₀/a], exactly
    ∫ T ω dt = (J N² + η I_L) ∫ q̈ q̇ dt = −(J N² + η I_L) v₀² / 2 (a linear integrand: the
    trapezoid rule is exact)."""
    n, j, eta, i_l, v0, a = 30.0, 5e-5, 0.7, 0.4, 3.0, 6.0
    t = np.linspace(0.0, v0 / a, 51)
    qd, qdd = v0 - a * t, np.full_like(t, -a)
    tau = i_l * qdd + n * n * j * qdd
    s = motor_side(actuator(n=n, j=j, eta=eta), t, qd, qdd, tau)
    moving = qd > 0.0  # at the stop (q̇ = 0) no power flows: the motoring branch, τ_gear/(N η)
    assert moving.sum() == 50
    np.testing.assert_allclose(s.torque[moving], (j * n + i_l * eta / n) * qdd[moving], rtol=1e-14)
    assert s.torque[-1] == pytest.approx((j * n + i_l / (n * eta)) * qdd[-1], rel=1e-14)
    assert not s.copper_included and s.current is None and s.notes
    exact = -(j * n * n + eta * i_l) * v0**2 / 2
    assert s.energy[-1] == pytest.approx(exact, rel=1e-13)
    assert s.energy_regenerated[-1] == pytest.approx(-exact, rel=1e-13)
    assert s.integral("loss_gear") == pytest.approx((1 - eta) * i_l * v0**2 / 2, rel=1e-13)


def test_negative_gear_ratio_mirrors_the_motor():
    rng = np.random.default_rng(3)
    t = np.sort(rng.uniform(0, 1, 40))
    qd, qdd, tau = rng.normal(size=(3, 40))
    m = motor(torque_constant=0.07, resistance=0.5)
    pos = motor_side(actuator(n=20.0, j=1e-4, eta=0.9, b=1e-3, c=0.01, motor=m), t, qd, qdd, tau)
    neg = motor_side(actuator(n=-20.0, j=1e-4, eta=0.9, b=1e-3, c=0.01, motor=m), t, qd, qdd, tau)
    np.testing.assert_allclose(neg.speed, -pos.speed, rtol=1e-15)
    np.testing.assert_allclose(neg.torque, -pos.torque, rtol=1e-14)
    np.testing.assert_allclose(neg.electrical_power, pos.electrical_power, rtol=1e-14)


@pytest.mark.parametrize("n", [35.0, -35.0])
def test_rotor_torque_is_the_one_motor_side_splits_off(n):
    """T_rot = J N q̈ + b N q̇ + c tanh(N q̇ / v_s) (v_s = 1e-3 |N|, add_actuator's default) is
    written once: motor_side's load share is τ − N T_rot bit for bit with rotor_torque's T_rot,
    which the sizing report, its what-if actuators and the gear-ratio sweep use
    (armdyn.sizing.rotor_torque is the same function)."""
    rng = np.random.default_rng(5)
    t = np.cumsum(rng.uniform(1e-3, 1e-2, 200))
    qd, qdd, tau = 0.05 * rng.normal(size=200), rng.normal(size=200), rng.normal(size=200)
    j, b, c = 3e-5, 2e-4, 0.03
    act = actuator(n=n, j=j, eta=0.8, b=b, c=c)
    t_rot = rotor_torque(act, qd, qdd)
    smoothing = 1e-3 * abs(n)
    closed = j * n * qdd + b * n * qd + c * np.tanh(n * qd / smoothing)
    np.testing.assert_allclose(t_rot, closed, rtol=1e-13, atol=1e-13 * np.max(np.abs(closed)))
    # the Coulomb term is in its smooth range for some samples and saturated for others
    assert np.any(np.abs(n * qd) < smoothing) and np.any(np.abs(n * qd) > 3 * smoothing)
    s = motor_side(act, t, qd, qdd, tau)
    assert np.array_equal(s.load_torque, tau - n * t_rot)
    assert ad.sizing.rotor_torque is rotor_torque


@pytest.mark.parametrize("with_motor", [True, False])
def test_energy_balance_on_random_samples(with_motor):
    """P_el = P_mech + copper + friction + gear at every sample, so the energies balance to
    round-off; the joint torque's work is P_mech + friction."""
    rng = np.random.default_rng(11)
    t = np.cumsum(rng.uniform(1e-3, 1e-2, 500))
    qd = 2.0 * np.sin(3.0 * t) + 0.3 * rng.normal(size=500)
    qdd = rng.normal(size=500) * 5.0
    tau = 20.0 * np.cos(2.0 * t) + rng.normal(size=500)
    m = motor(torque_constant=0.08, resistance=0.6) if with_motor else None
    s = motor_side(actuator(n=80.0, j=3e-5, eta=0.75, b=2e-4, c=0.03, motor=m), t, qd, qdd, tau)
    assert np.any(s.loss_gear > 0) and np.all(s.loss_gear >= 0) and np.all(s.loss_friction >= 0)
    assert np.any(s.electrical_power < 0) and np.any(s.electrical_power > 0)
    losses = s.integral("loss_copper") + s.integral("loss_friction") + s.integral("loss_gear")
    mech = s.integral("mechanical_power")
    assert abs(s.energy[-1] - losses - mech) <= 1e-9 * abs(mech)
    joint_work = float(
        np.sum(0.5 * (tau * qd)[1:] * np.diff(t) + 0.5 * (tau * qd)[:-1] * np.diff(t))
    )
    assert joint_work == pytest.approx(mech + s.integral("loss_friction"), rel=1e-9)
    # the regenerated energy is the integral of the negative part, counted positive
    neg = np.minimum(s.electrical_power, 0.0)
    assert s.energy_regenerated[-1] == pytest.approx(-np.trapezoid(neg, t), rel=1e-12)


def test_bad_actuator_values_are_named():
    t = np.linspace(0, 1, 5)
    z = np.zeros(5)
    with pytest.raises(ad.ModelError, match=r"'j1'.*efficiency must be in \(0, 1\]"):
        motor_side(actuator(eta=1.2), t, z, z, z)
    with pytest.raises(ad.ModelError, match="gear_ratio must be finite and non-zero"):
        motor_side(actuator(n=0.0), t, z, z, z)
    with pytest.raises(ad.ModelError, match="rotor_inertia must be a positive number"):
        motor_side(actuator(j=-1.0), t, z, z, z)
    with pytest.raises(ad.ModelError, match="one length"):
        motor_side(actuator(), t, z[:4], z, z)
    with pytest.raises(ad.ModelError, match="torque_constant must be a positive number"):
        motor_side(actuator(motor=motor(torque_constant=0.0)), t, z, z, z)


def test_motor_side_of_result_reads_columns_by_name():
    names = ["a", "b", "b_rotor"]
    model = SimpleNamespace(
        joint_dof_names=names,
        dof_names=["a", "b"],
        actuators=[actuator(joint="b", n=10.0, j=1e-3)],
    )
    t = np.linspace(0.0, 1.0, 11)
    qd = np.stack([t, 2 * t, 20 * t], axis=1)
    qdd = np.stack([np.ones_like(t), 2 * np.ones_like(t), 20 * np.ones_like(t)], axis=1)
    tau = np.stack([0 * t, 5.0 + 100 * 1e-3 * 2 + 0 * t, np.full_like(t, np.nan)], axis=1)
    res = SimpleNamespace(t=t, qd=qd, qdd=qdd, joint_torques=tau)
    out = motor_side_of_result(model, res)
    assert list(out) == ["b"]
    np.testing.assert_allclose(out["b"].speed, 20 * t, rtol=1e-15)
    np.testing.assert_allclose(out["b"].load_torque, 5.0, rtol=1e-14)
    np.testing.assert_allclose(out["b"].torque, 1e-3 * 20 + 5.0 / 10.0, rtol=1e-14)
    assert motor_side_of_result(SimpleNamespace(actuators=[]), res) == {}


def test_coulomb_smoothing_and_repeated_samples():
    """v_s is the actuator's friction_smoothing when set, else add_actuator's 1e-3 |N|; at
    q̇ = 2e-3 rad/s on a 50:1 gear, ω = 0.1 rad/s: c tanh(0.1 / 0.05) by default and
    c tanh(0.1 / 0.2) with friction_smoothing = 0.2. A repeated time (an event's output) adds
    nothing to the integrals."""
    from armdyn.actuators import coulomb_smoothing

    t = np.array([0.0, 0.5, 0.5, 1.0])
    qd, qdd, tau = np.full(4, 2e-3), np.zeros(4), np.zeros(4)
    act = actuator(n=-50.0, j=0.0, c=0.3)
    assert coulomb_smoothing(act) == pytest.approx(0.05, rel=1e-15)
    s = motor_side(act, t, qd, qdd, tau)
    # τ_gear = τ − N T_rot = 50 · 0.3 tanh(−0.1 / 0.05): the rotor friction brakes the joint
    np.testing.assert_allclose(s.load_torque, 50.0 * 0.3 * np.tanh(-0.1 / 0.05), rtol=1e-14)
    act.friction_smoothing = 0.2
    s = motor_side(act, t, qd, qdd, tau)
    np.testing.assert_allclose(s.load_torque, 50.0 * 0.3 * np.tanh(-0.1 / 0.2), rtol=1e-14)
    # τ = 0: the gear takes power from the load, so T = T_rot + τ_gear η / N with η = 1: T = 0
    np.testing.assert_allclose(s.torque, 0.0, atol=1e-15)
    assert s.energy[2] == s.energy[1]
    with pytest.raises(ad.ModelError, match="times must not decrease"):
        motor_side(act, t[::-1], qd, qdd, tau)
