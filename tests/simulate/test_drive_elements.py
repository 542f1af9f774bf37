"""Joint friction (viscous + smoothed Coulomb) and PD motors with a torque limit, against closed
forms, and against the Lagrange validator (which evaluates the same force laws in joint space,
away from the Cartesian path)."""

import armdyn as ad
import numpy as np
import pytest
from armdyn import _core
from scipy.optimize import brentq

G = 9.81


def block(incline=0.0, mass=2.0, coulomb=4.0, v_smooth=1e-4, viscous=0.0):
    """A block on a prismatic joint along a slope of `incline` rad (positive q goes down)."""
    direction = (np.cos(incline), 0.0, -np.sin(incline))
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -G))
    b.add_body("block", mass, [0.01, 0.01, 0.01], position=(0.0, 0.0, 0.0))
    b.add_prismatic("rail", "ground", "block", point=(0, 0, 0), axis=direction)
    b.add_joint_friction("rail", viscous=viscous, coulomb=coulomb, smoothing_velocity=v_smooth)
    return b.finalize()


def test_coulomb_friction_stopping_distance_and_time():
    """v0 = 1 m/s, F_c = 4 N, m = 2 kg: stops after m v0 / F_c = 0.5 s at m v0² / (2 F_c) = 0.25 m
    (smoothing 1e-4 m/s changes that by O(v_s)). 'auto' sees the stiff friction law and picks
    the implicit integrator."""
    model = block()
    res = ad.simulate(
        model, 1.0, integrator="auto", rtol=1e-9, atol=1e-11, output_dt=0.05, q0=[0.0], qd0=[1.0]
    )
    assert res.stats["integrator"] == "trbdf2"
    assert "friction" in res.stats["integrator_reason"]
    assert res.q[-1, 0] == pytest.approx(0.25, abs=1e-5)
    moving = res.t[np.abs(res.qd[:, 0]) > 1e-3]
    assert moving[-1] == pytest.approx(0.45, abs=1e-9)  # last output before the stop at 0.5 s
    assert abs(res.qd[-1, 0]) <= 1e-6


def test_smoothed_coulomb_creep_on_an_incline():
    """On a slope where gravity (m g sin α) is below F_c, the smoothed law creeps at the
    velocity where F_c tanh(v / v_s) = m g sin α."""
    alpha, mass, fc, vs = np.radians(10.0), 2.0, 4.0, 1e-3
    model = block(incline=alpha, mass=mass, coulomb=fc, v_smooth=vs)
    res = ad.simulate(model, 0.5, integrator="trbdf2", rtol=1e-10, atol=1e-12, output_dt=0.25)
    creep = vs * np.arctanh(mass * G * np.sin(alpha) / fc)
    assert res.qd[-1, 0] == pytest.approx(creep, rel=1e-7)


def bar_with_motor(kp, kd, limit=1e300, viscous=0.0, mass=2.0, length=0.5, reference=0.0):
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -G))
    b.add_body(
        "bar",
        mass,
        [1e-3, mass * length**2 / 12, mass * length**2 / 12],
        position=(length / 2, 0, 0),
    )
    b.add_revolute("pitch", "ground", "bar", point=(0, 0, 0), axis=(0, -1, 0))
    b.add_motor("pitch", reference, kp=kp, kd=kd, torque_limit=limit)
    if viscous:
        b.add_joint_friction("pitch", viscous=viscous)
    return b.finalize()


def test_pd_motor_static_deflection():
    """A PD motor holding a horizontal bar sags until kp (0 − q) = m g (l/2) cos q."""
    m, length, kp, kd = 2.0, 0.5, 200.0, 20.0
    model = bar_with_motor(kp, kd, mass=m, length=length)
    res = ad.simulate(model, 3.0, rtol=1e-10, atol=1e-12, output_dt=0.5)
    sag = brentq(lambda q: kp * (-q) - m * G * length / 2 * np.cos(q), -1.0, 0.0, xtol=1e-15)
    assert res.q[-1, 0] == pytest.approx(sag, abs=1e-9)


def test_motor_torque_limit_lets_the_bar_sink_to_the_balance_angle():
    """With the torque limited below m g l/2, the saturated motor balances gravity where
    m g (l/2) cos q = limit (viscous friction damps the motion)."""
    m, length, limit = 2.0, 0.5, 2.0
    model = bar_with_motor(200.0, 20.0, limit=limit, viscous=0.5, mass=m, length=length)
    res = ad.simulate(model, 20.0, rtol=1e-10, atol=1e-12, output_dt=1.0)
    assert res.q[-1, 0] == pytest.approx(-np.arccos(limit / (m * G * length / 2)), abs=1e-7)


def test_force_laws_agree_with_the_lagrange_validator():
    """Along a free run with a tracking motor, Coulomb and viscous friction, the Euler–Lagrange
    equations with the same force laws need no extra actuation: the validator returns ≈ 0."""
    ref = _core.profiles.sine(0.6, 0.5, 0.0, 0.0)
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -G))
    b.add_body("upper", 1.5, [1e-3, 0.03, 0.03], position=(0.2, 0, 0))
    b.add_body("fore", 1.0, [1e-3, 0.02, 0.02], position=(0.6, 0, 0))
    b.add_revolute("shoulder", "ground", "upper", point=(0, 0, 0), axis=(0, -1, 0))
    b.add_revolute("elbow", "upper", "fore", point=(0.4, 0, 0), axis=(0, -1, 0))
    b.add_motor("shoulder", ref, kp=80.0, kd=4.0, torque_limit=15.0, feedforward=2.0)
    b.add_joint_friction("shoulder", viscous=0.1, coulomb=0.3, smoothing_velocity=1e-2)
    b.add_joint_friction("elbow", viscous=0.05, coulomb=0.2, smoothing_velocity=1e-2)
    model = b.finalize()
    res = ad.simulate(model, 2.0, rtol=1e-10, atol=1e-12, output_dt=0.05)
    tau = ad.LagrangeValidator(model).torques(res.q, res.qd, res.qdd, res.t)
    assert np.max(np.abs(tau)) <= 1e-8


def test_bad_friction_and_motor_input():
    b = ad.ModelBuilder()
    b.add_body("bar", 1.0, [0.01, 0.01, 0.01], position=(0.5, 0, 0))
    b.add_revolute("pitch", "ground", "bar", point=(0, 0, 0), axis=(0, 1, 0))
    with pytest.raises(ad.ModelError, match=r"pitch.*coulomb"):
        b.add_joint_friction("pitch", coulomb=-1.0)
    with pytest.raises(ad.ModelError, match=r"pitch.*smoothing_velocity"):
        b.add_joint_friction("pitch", coulomb=1.0, smoothing_velocity=0.0)
    with pytest.raises(ad.ModelError, match=r"pitch.*torque_limit"):
        b.add_motor("pitch", 0.0, kp=1.0, kd=0.1, torque_limit=0.0)
    with pytest.raises(ad.ModelError, match=r"pitch.*kp"):
        b.add_motor("pitch", 0.0, kp=-1.0, kd=0.1)
    with pytest.raises(ad.ModelError, match="no_joint"):
        b.add_motor("no_joint", 0.0, kp=1.0, kd=0.1)


@pytest.mark.parametrize("coordinates", ["cartesian", "joint"])
def test_pi_motor_removes_the_static_sag(coordinates):
    """With an integral term the holding error vanishes (the sag of the PD motor is m g (l/2)
    cos q / kp); the integral state is part of the simulation, not of q."""
    m, length = 2.0, 0.5
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -G))
    b.add_body(
        "bar", m, [1e-3, m * length**2 / 12, m * length**2 / 12], position=(length / 2, 0, 0)
    )
    b.add_revolute("pitch", "ground", "bar", point=(0, 0, 0), axis=(0, -1, 0))
    b.add_motor("pitch", 0.0, kp=200.0, kd=20.0, ki=400.0)
    model = b.finalize()
    res = ad.simulate(model, 20.0, rtol=1e-10, atol=1e-12, output_dt=1.0, coordinates=coordinates)
    assert abs(res.q[1, 0]) > 1e-3  # it sags first
    assert abs(res.q[-1, 0]) <= 1e-7
    with pytest.raises(ad.ModelError, match="integral term"):
        ad.LagrangeValidator(model)


def test_saturated_pi_motor_does_not_wind_up():
    """Saturated, the integral stops growing: when the load drops (here the torque limit is
    generous but the reference starts far away) the bar reaches it without a wind-up overshoot
    larger than the PD motor's."""
    m, length = 2.0, 0.5

    def bar(ki):
        b = ad.ModelBuilder(gravity=(0.0, 0.0, -G))
        b.add_body(
            "bar", m, [1e-3, m * length**2 / 12, m * length**2 / 12], position=(length / 2, 0, 0)
        )
        b.add_revolute("pitch", "ground", "bar", point=(0, 0, 0), axis=(0, -1, 0))
        b.add_motor("pitch", 1.0, kp=200.0, kd=20.0, ki=ki, torque_limit=8.0)
        return b.finalize()

    pid = ad.simulate(bar(200.0), 10.0, rtol=1e-10, atol=1e-12, output_dt=0.01)
    assert np.max(pid.q[:, 0]) <= 1.0 + 0.05  # no large overshoot after the saturated climb
    assert pid.q[-1, 0] == pytest.approx(1.0, abs=1e-4)
