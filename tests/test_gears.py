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


@pytest.mark.parametrize("integrator", ["dopri5", "trbdf2"])
def test_contact_onset_is_located_at_the_closed_form_time(integrator):
    model = gear_pair()
    res = ad.simulate(model, 0.01, integrator=integrator, rtol=1e-9, atol=1e-12, output_dt=0.001)
    ev = res.events
    assert ev["gear"][0] == "mesh" and ev["onset"][0]
    # located on the dense output; the remaining 1e-8 is the integration error of θ_a at rtol 1e-9
    assert ev["t"][0] == pytest.approx(np.sqrt(GAP * IA / (RA * T)), rel=1e-7)
    # onsets and separations alternate (tooth impacts and rebounds)
    assert all(a != b for a, b in zip(ev["onset"][:-1], ev["onset"][1:], strict=True))
    assert len(ev["t"]) >= 2


def test_undamped_contact_conserves_energy_with_the_work_of_the_torque():
    model = gear_pair(hc_damping=0.0)
    res = ad.simulate(model, 0.02, rtol=1e-11, atol=1e-13, output_dt=0.0005)
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
