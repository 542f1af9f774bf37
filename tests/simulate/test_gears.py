"""Gear pair with backlash (dead zone + Hunt–Crossley contact) and event location.

A pinion driven by a constant torque T from the middle of the backlash gap must first turn
freely: contact starts when r_a θ_a = g/2, i.e. at t_c = sqrt(g I_a / (r_a T)) (closed form).
Without damping the pair is conservative: kinetic energy plus the Hertzian contact potential
k d^(n+1)/(n+1) equals the work T θ_a. With damping the teeth settle into contact and the pair
turns like an ideal gear: ω_b / ω_a = −r_a / r_b and α_a = T / (I_a + (r_a/r_b)² I_b)."""

import armdyn as ad
import numpy as np
import pytest

RA, RB, GAP, T = 0.02, 0.05, 1e-3, 0.5
MA, MB = 0.2, 1.0
IA, IB = 0.5 * MA * RA**2, 0.5 * MB * RB**2
K, N = 1e8, 1.5


def gear_pair(hc_damping=0.5, backlash=GAP):
    b = ad.ModelBuilder(gravity=(0.0, 0.0, 0.0))
    b.add_body("pinion", MA, [IA / 2 + 1e-6, IA / 2 + 1e-6, IA], position=(0, 0, 0))
    b.add_body("wheel", MB, [IB / 2 + 1e-6, IB / 2 + 1e-6, IB], position=(RA + RB, 0, 0))
    b.add_revolute("ja", "ground", "pinion", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_revolute("jb", "ground", "wheel", point=(RA + RB, 0, 0), axis=(0, 0, 1))
    b.add_gear_pair(
        "mesh",
        "ja",
        "jb",
        RA,
        RB,
        backlash=backlash,
        stiffness=K,
        exponent=N,
        hc_damping=hc_damping,
    )
    b.add_joint_torque("ja", T)
    return b.finalize()


# the joint-space path (coordinates="joint") against the same closed forms
@pytest.mark.parametrize("coordinates", ["cartesian", "joint"])
@pytest.mark.parametrize("integrator", ["dopri5", "dop853", "trbdf2"])
def test_contact_onset_is_located_at_the_closed_form_time(integrator, coordinates):
    model = gear_pair()
    res = ad.simulate(
        model,
        0.01,
        integrator=integrator,
        rtol=1e-9,
        atol=1e-12,
        output_dt=0.001,
        coordinates=coordinates,
    )
    ev = res.events
    assert ev["gear"][0] == "mesh" and ev["onset"][0]
    # located on the dense output; the remaining 1e-8 is the integration error of θ_a at rtol 1e-9
    assert ev["t"][0] == pytest.approx(np.sqrt(GAP * IA / (RA * T)), rel=1e-7)
    # onsets and separations alternate (tooth impacts and rebounds)
    assert all(a != b for a, b in zip(ev["onset"][:-1], ev["onset"][1:], strict=True))
    assert len(ev["t"]) >= 2


def test_rk4_locates_the_onset_between_its_fixed_steps():
    # before contact the pinion turns at constant acceleration, which RK4 and the cubic Hermite
    # interpolant reproduce exactly, so the located time is exact although it falls between
    # grid points (t_c = 2e-3, dt = 3e-4)
    model = gear_pair()
    res = ad.simulate(model, 0.004, integrator="rk4", dt=3e-4)
    t_c = np.sqrt(GAP * IA / (RA * T))
    assert res.events["onset"][0] and res.events["t"][0] == pytest.approx(t_c, rel=1e-10)
    # the step was cut at the onset: it is one of the output (step) times
    assert np.min(np.abs(res.t - t_c)) <= 1e-12


@pytest.mark.parametrize("coordinates", ["cartesian", "joint"])
@pytest.mark.parametrize("integrator", ["dopri5", "dop853"])
def test_undamped_contact_conserves_energy_with_the_work_of_the_torque(integrator, coordinates):
    model = gear_pair(hc_damping=0.0)
    res = ad.simulate(
        model,
        0.02,
        integrator=integrator,
        rtol=1e-11,
        atol=1e-13,
        output_dt=0.0005,
        coordinates=coordinates,
    )
    qa, qb = res.q[:, 0], res.q[:, 1]
    s = RA * qa + RB * qb
    pen = np.maximum(np.abs(s) - GAP / 2, 0.0)
    potential = K * pen ** (N + 1) / (N + 1)
    balance = res.kinetic_energy + potential - T * qa
    assert res.stats["events"] >= 3  # several impacts and rebounds
    assert np.max(np.abs(balance)) <= 1e-7 * np.max(res.kinetic_energy)


def test_damped_contact_settles_into_an_ideal_gear():
    model = gear_pair(hc_damping=0.5)
    res = ad.simulate(model, 0.3, rtol=1e-9, atol=1e-12, output_dt=0.01)
    assert res.qd[-1, 1] / res.qd[-1, 0] == pytest.approx(-RA / RB, rel=1e-6)
    # acceleration of the settled pair: T / (I_a + (r_a/r_b)^2 I_b), from the last outputs
    alpha = np.polyfit(res.t[-10:], res.qd[-10:, 0], 1)[0]
    assert alpha == pytest.approx(T / (IA + (RA / RB) ** 2 * IB), rel=1e-5)
    # the Lagrange validator, with the same contact law in joint space, needs no extra torque
    tau = ad.LagrangeValidator(model).torques(res.q[-10:], res.qd[-10:], res.qdd[-10:], res.t[-10:])
    assert np.max(np.abs(tau)) <= 1e-6 * T


def test_gear_pair_bad_input():
    b = ad.ModelBuilder()
    b.add_body("a", 1.0, [0.01, 0.01, 0.01], position=(0, 0, 0))
    b.add_body("b", 1.0, [0.01, 0.01, 0.01], position=(1, 0, 0))
    b.add_revolute("ja", "ground", "a", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_prismatic("pb", "ground", "b", point=(1, 0, 0), axis=(1, 0, 0))
    with pytest.raises(ad.ModelError, match=r"'g1'.*'pb'.*revolute"):
        b.add_gear_pair("g1", "ja", "pb", 0.1, 0.1)
    with pytest.raises(ad.ModelError, match=r"'g2'.*both gears.*'ja'"):
        b.add_gear_pair("g2", "ja", "ja", 0.1, 0.1)
    b.add_body("c", 1.0, [0.01, 0.01, 0.01], position=(2, 0, 0))
    b.add_revolute("jc", "ground", "c", point=(2, 0, 0), axis=(0, 0, 1))
    with pytest.raises(ad.ModelError, match=r"'g5'.*r_b"):
        b.add_gear_pair("g5", "ja", "jc", 0.1, -0.1)
    with pytest.raises(ad.ModelError, match=r"'g3'.*nowhere"):
        b.add_gear_pair("g3", "ja", "nowhere", 0.1, 0.1)
    with pytest.raises(ad.ModelError, match=r"'g4'.*backlash"):
        b.add_gear_pair("g4", "ja", "jc", 0.1, 0.1, backlash=-1.0)


# ----------------------------------------------------------------------------------------------
# ideal gear constraint
# ----------------------------------------------------------------------------------------------


def ideal_pair():
    b = ad.ModelBuilder(gravity=(0.0, 0.0, 0.0))
    b.add_body("pinion", MA, [IA / 2 + 1e-6, IA / 2 + 1e-6, IA], position=(0, 0, 0))
    b.add_body("wheel", MB, [IB / 2 + 1e-6, IB / 2 + 1e-6, IB], position=(RA + RB, 0, 0))
    b.add_revolute("ja", "ground", "pinion", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_revolute("jb", "ground", "wheel", point=(RA + RB, 0, 0), axis=(0, 0, 1))
    b.add_gear("mesh", "ja", "jb", RA, RB)
    b.add_joint_torque("ja", T)
    return b.finalize()


@pytest.mark.parametrize("coordinates", ["cartesian", "joint"])
def test_ideal_gear_over_many_turns(coordinates):
    model = ideal_pair()
    assert model.mobility == 1
    assert "gear mesh" in model.summary()
    res = ad.simulate(model, 1.0, rtol=1e-10, atol=1e-12, output_dt=0.05, coordinates=coordinates)
    alpha = T / (IA + (RA / RB) ** 2 * IB)
    assert res.q[-1, 0] == pytest.approx(0.5 * alpha, rel=1e-8)  # ≈ 1000 rad: 160 turns
    assert np.max(np.abs(RA * res.q[:, 0] + RB * res.q[:, 1])) <= 1e-11
    assert np.max(res.position_residual) <= 1e-12


@pytest.mark.parametrize("coordinates", ["cartesian", "joint"])
def test_ideal_gear_on_a_moving_carrier_conserves_energy(coordinates):
    """Both gears ride on a carrier arm pivoting on ground (the gear row touches three bodies):
    free motion conserves energy and keeps r_a q_a + r_b q_b = 0 in relative angles."""
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("carrier", 2.0, [0.01, 0.05, 0.05], position=(0.2, 0, 0))
    b.add_body("pinion", MA, [IA / 2 + 1e-6, IA / 2 + 1e-6, IA], position=(0.1, 0, 0))
    b.add_body("wheel", MB, [IB / 2 + 1e-6, IB / 2 + 1e-6, IB], position=(0.1 + RA + RB, 0, 0))
    b.add_revolute("pivot", "ground", "carrier", point=(0, 0, 0), axis=(0, 1, 0))
    b.add_revolute("ja", "carrier", "pinion", point=(0.1, 0, 0), axis=(0, 1, 0))
    b.add_revolute("jb", "carrier", "wheel", point=(0.1 + RA + RB, 0, 0), axis=(0, 1, 0))
    b.add_gear("mesh", "ja", "jb", RA, RB)
    model = b.finalize()
    assert model.mobility == 2
    u0, v0 = np.asarray(model.u0), np.zeros(model.nv)
    v0[6 + 4] = 30.0  # spin the pinion (body frame y); projection makes the state consistent
    res = ad.simulate(
        model,
        2.0,
        rtol=1e-10,
        atol=1e-12,
        output_dt=0.05,
        u0=u0,
        v0=v0,
        coordinates=coordinates,
    )
    names = list(model.joint_coord_names)
    qa, qb = res.q[:, names.index("ja")], res.q[:, names.index("jb")]
    assert np.max(np.abs(RA * qa + RB * qb)) <= 1e-11
    assert np.ptp(qa) > 10.0  # several turns
    energy = res.total_energy
    assert np.max(np.abs(energy - energy[0])) <= 1e-8 * np.max(res.kinetic_energy)


def test_motor_torque_through_an_ideal_gear_equals_inverse_dynamics_through_the_ratio():
    """A pinion drive lifts a pendulum load on the wheel. The drive torque at the pinion equals
    I_a α_a − (r_a/r_b) τ_b, with τ_b the inverse-dynamics torque of the wheel and load driven
    directly along θ_b = −(r_a/r_b) θ_a (power balance through the ideal gear)."""
    profile_a = ad.profiles.cubic(0.0, -4.0, 0.0, 1.0)  # pinion turns back: wheel lifts the load
    ratio = RA / RB

    def build(direct):
        b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
        # gears turn about x; the load sits 0.1 m off the wheel axis, so gravity loads the wheel
        b.add_body("pinion", MA, [IA, IA / 2 + 1e-6, IA / 2 + 1e-6], position=(0, 0, 0))
        b.add_body("wheel", MB, [IB, IB / 2 + 1e-6, IB / 2 + 1e-6], position=(0, RA + RB, 0))
        b.add_body("load", 0.5, [1e-4, 1e-4, 1e-4], position=(0, RA + RB + 0.1, 0))
        b.add_revolute("ja", "ground", "pinion", point=(0, 0, 0), axis=(1, 0, 0))
        b.add_revolute("jb", "ground", "wheel", point=(0, RA + RB, 0), axis=(1, 0, 0))
        b.add_fixed("arm", "wheel", "load", point=(0, RA + RB + 0.1, 0))
        if direct:
            b.add_drive("ja", profile_a)
            b.add_drive("jb", lambda t: tuple(-ratio * v for v in profile_a.eval(t)))
        else:
            b.add_gear("mesh", "ja", "jb", RA, RB)
            b.add_drive("ja", profile_a)
        return b.finalize()

    geared, direct = build(False), build(True)
    times = np.linspace(0.0, 1.0, 21)
    sim = ad.simulate(geared, 1.0, rtol=1e-10, atol=1e-12, output_dt=0.05)
    idr = ad.driven_inverse_dynamics(direct, times)
    alpha_a = np.array([profile_a.eval(t)[2] for t in times])
    names = list(direct.drive_names)
    tau_b = idr.drive_forces[:, names.index("jb")]
    expected = IA * alpha_a - ratio * tau_b
    assert np.max(np.abs(tau_b)) > 0.1  # the load matters
    assert np.max(np.abs(sim.drive_forces[:, 0] - expected)) <= 1e-9 * np.max(np.abs(expected))
    # and the geared model's own inverse dynamics agrees
    idg = ad.driven_inverse_dynamics(geared, times)
    assert np.max(np.abs(idg.drive_forces[:, 0] - expected)) <= 1e-9 * np.max(np.abs(expected))
