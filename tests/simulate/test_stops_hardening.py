"""Joint stops that always hold (issue 31).

References: the closed forms of a pendulum on a stop (the energy at rest on it, the flight time
2 v / |a| of a rebound near it, the accumulation time of the geometric series of bounces), the
rates Poisson's law gives two symmetric stops hit at one instant, the constraint residuals of
`limits="ignore"`, and the two formulations and four integrators against each other. Before the
fix (main at 55d38f0) the pendulum below passed its stop once its rebounds became shorter than
a step (0.55 rad beyond at e = 0.5) and a URDF arm on its stops recorded thousands of
"rest"/"release" pairs.
"""

from __future__ import annotations

import armdyn as ad
import numpy as np
import pytest

G = 9.81
INTEGRATORS = ["dopri5", "dop853", "rk4", "trbdf2"]
COORDINATES = ["cartesian", "joint"]
LIMIT = 0.3
J = 1.0 + 1e-4  # the pendulum's m L^2 + I_bob


def _kw(integrator):
    if integrator == "rk4":
        return dict(dt=1e-3)
    return dict(rtol=1e-10, atol=1e-12)


def pendulum():
    """1 kg at 1 m, hinged about +y at the origin, hanging at q = 0, a stop at q = 0.3 (and
    one far above): released at 1.2 rad it falls onto the stop, which gravity pushes it into."""
    b = ad.ModelBuilder(gravity=(0, 0, -G))
    b.add_body("bob", 1.0, np.eye(3) * 1e-4, position=(0, 0, -1.0))
    b.add_revolute("hinge", "ground", "bob", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    b.set_joint_limits("hinge", LIMIT, 3.0)
    return b.finalize()


def _energy_never_rises(r, tol):
    E = r.kinetic_energy + r.potential_energy
    assert (E - np.minimum.accumulate(E)).max() <= tol


def _one_event_per_stop_and_instant(ev):
    keys = list(zip(ev["t"], ev["joint"], ev["side"], strict=True))
    assert len(set(keys)) == len(keys)


def _events_change_the_contact(ev):
    """Each stop's events follow its state: "release" only from rest, "rest" and "bounce" only
    from free (a recorded event is a contact that actually changed)."""
    engaged = {}
    for j, s, k in zip(ev["joint"], ev["side"], ev["kind"], strict=True):
        on = engaged.get((j, s), False)
        assert (k == "release") == on, (j, s, k)
        engaged[(j, s)] = k == "rest"


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("coordinates", COORDINATES)
@pytest.mark.parametrize("e", [0.05, 0.3, 0.5, 0.8, 0.95])
def test_a_bouncing_pendulum_never_passes_its_stop(e, coordinates, integrator):
    """20 s of bouncing on the stop: never beyond it by 1e-6, energy never rising; where the
    bounces accumulate (e <= 0.8 within 20 s) the pendulum ends at rest on the stop with the
    potential energy of the stop, held by m g L sin(0.3)."""
    m = pendulum()
    r = ad.simulate(
        m,
        20.0,
        q0=[1.2],
        restitution=e,
        coordinates=coordinates,
        integrator=integrator,
        output_dt=1e-3,
        **_kw(integrator),
    )
    assert r.error is None
    assert (LIMIT - r.q[:, 0]).max() <= 1e-6
    _energy_never_rises(r, 1e-8 if integrator != "trbdf2" else 1e-6)
    ev = r.events["limits"]
    _one_event_per_stop_and_instant(ev)
    _events_change_the_contact(ev)
    assert ev["kind"][:-1] == ["bounce"] * (len(ev["kind"]) - 1)
    if e <= 0.8:
        assert ev["kind"][-1] == "rest"
        on = r.t > ev["t"][-1] + 1e-9
        np.testing.assert_allclose(r.q[on, 0], LIMIT, atol=1e-12)
        np.testing.assert_allclose(r.kinetic_energy[on], 0.0, atol=1e-20)
        np.testing.assert_allclose(r.potential_energy[on], -G * np.cos(LIMIT), rtol=1e-12)
        force = r.limit_forces["force"][on, 0]
        np.testing.assert_allclose(force, G * np.sin(LIMIT), rtol=1e-9)
    # the bounces before the last: each rebound leaves at e times its impact rate, so that
    # consecutive impacts' rates fall by e (the first few, long flights, resolved exactly)
    assert len(ev["t"]) >= min(4, int(np.log(1e-3) / np.log(e)))


@pytest.mark.parametrize("coordinates", COORDINATES)
def test_the_accumulated_bounces_lose_the_last_rebounds_kinetic_energy(coordinates):
    """The last resolved bounce leaves at qd+ (its apex beyond the tolerance); the next impact
    sums the geometric series of the bounces that would follow: it comes after the flight
    2 qd+ / |a| (a = m g L sin(0.3) / J near the stop), close to the series' accumulation time
    t_b + 2 qd+ / |a| / (1 - e), and the energy lost there is the rebound's 1/2 J qd+^2."""
    e = 0.5
    r = ad.simulate(
        pendulum(),
        4.0,
        q0=[1.2],
        restitution=e,
        coordinates=coordinates,
        rtol=1e-11,
        atol=1e-13,
    )  # an output at every step: the rows at the events
    ev = r.events["limits"]
    assert ev["kind"][-1] == "rest" and ev["kind"][-2] == "bounce"
    t_b, t_r = ev["t"][-2], ev["t"][-1]
    after_b = np.flatnonzero(np.isclose(r.t, t_b, rtol=0, atol=1e-15))[-1]
    after_r = np.flatnonzero(np.isclose(r.t, t_r, rtol=0, atol=1e-15))[-1]
    qd_plus = r.qd[after_b, 0]
    assert qd_plus > 0 and r.q[after_b, 0] == pytest.approx(LIMIT, abs=1e-12)
    a = G * np.sin(LIMIT) / J
    # (the stop fires 1e-12 beyond its limit: 1e-12 / qd+ ~ 1e-8 s more)
    np.testing.assert_allclose(t_r - t_b, 2 * qd_plus / a, rtol=1e-3)
    t_inf = t_b + 2 * qd_plus / a / (1 - e)
    assert 0 <= t_inf - t_r <= 2 * qd_plus / a * e / (1 - e) * (1 + 1e-4)
    E = r.kinetic_energy + r.potential_energy
    np.testing.assert_allclose(E[after_b] - E[after_r], 0.5 * J * qd_plus**2, rtol=1e-6)
    np.testing.assert_allclose(r.kinetic_energy[after_r], 0.0, atol=1e-25)
    # the rebound's apex qd+^2 / (2 a) is beyond the stop's tolerance 1e-9; the next is within
    assert qd_plus**2 / (2 * a) > 1e-9 > (e * qd_plus) ** 2 / (2 * a)


def y_pendulum():
    """A symmetric mechanism: a body on j1 (about y) carrying two mirrored pendulums on j2, j3
    (about x, at y = +-0.3), each with stops at +-0.3; the mirror y -> -y maps j2 to j3 with
    the sign of the angle flipped, so that they reach their stops at one instant."""
    b = ad.ModelBuilder(gravity=(0, 0, -G))
    b.add_body("a", 1.0, np.diag([0.02, 0.03, 0.02]), position=(0, 0, -0.5))
    b.add_body("b", 0.5, np.eye(3) * 1e-3, position=(0, 0.3, -1.0))
    b.add_body("c", 0.5, np.eye(3) * 1e-3, position=(0, -0.3, -1.0))
    b.add_revolute("j1", "ground", "a", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    b.add_revolute("j2", "a", "b", (0.0, 0.3, -0.5), (1.0, 0.0, 0.0))
    b.add_revolute("j3", "a", "c", (0.0, -0.3, -0.5), (1.0, 0.0, 0.0))
    b.set_joint_limits("j2", -0.3, 0.3)
    b.set_joint_limits("j3", -0.3, 0.3)
    return b.finalize()


@pytest.mark.parametrize("coordinates", COORDINATES)
@pytest.mark.parametrize("e", [0.0, 0.5])
def test_two_stops_hit_at_one_instant_rebound_together(coordinates, e):
    """Both pendulums hit at one instant: one event each, at that instant, and Poisson's law
    gives each the rate -e times its impact rate (the stops' impulses push, both)."""
    m = y_pendulum()
    q0, qd0 = [0.0, 0.0, 0.0], [1.0, 2.0, -2.0]
    r = ad.simulate(
        m, 0.6, q0=q0, qd0=qd0, restitution=e, coordinates=coordinates, rtol=1e-11, atol=1e-13
    )
    ev = r.events["limits"]
    first = [k for k in range(len(ev["t"])) if abs(ev["t"][k] - ev["t"][0]) <= 1e-9]
    assert sorted((ev["joint"][k], ev["side"][k]) for k in first) == [
        ("j2", "upper"),
        ("j3", "lower"),
    ]
    assert all(ev["kind"][k] == "bounce" for k in first)  # gravity pulls both off at once
    _one_event_per_stop_and_instant(ev)
    t_hit = ev["t"][0]
    pre = ad.simulate(
        m, t_hit, q0=q0, qd0=qd0, coordinates=coordinates, limits="ignore", rtol=1e-11, atol=1e-13
    )
    i = np.flatnonzero(np.isclose(r.t, t_hit, rtol=0, atol=1e-9))[-1]
    np.testing.assert_allclose(r.qd[i, 1:], -e * pre.qd[-1, 1:], atol=1e-7)
    np.testing.assert_allclose(r.q[i, 1:], [0.3, -0.3], atol=1e-12)
    _energy_never_rises(r, 1e-8)
    assert np.abs(r.q[:, 1:]).max() <= 0.3 + 1e-6


ARM5_AXES = ["0 1 0"] * 5


def arm5(tmp_path, lim=0.3):
    """A 5-joint arm from URDF: five pitch joints along x, each limited to +-lim; released
    straight, it falls onto its stops and comes to rest on all of them."""
    links, joints = ['<link name="base"/>'], []
    for i in range(5):
        links.append(
            f'<link name="l{i}"><inertial><origin xyz="0.2 0 0"/><mass value="{2.0 - 0.3 * i}"/>'
            '<inertia ixx="0.01" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial></link>'
        )
        parent = "base" if i == 0 else f"l{i - 1}"
        xyz = "0 0 0" if i == 0 else "0.4 0 0"
        joints.append(
            f'<joint name="j{i}" type="revolute"><parent link="{parent}"/><child link="l{i}"/>'
            f'<origin xyz="{xyz}"/><axis xyz="{ARM5_AXES[i]}"/>'
            f'<limit lower="{-lim}" upper="{lim}" effort="100" velocity="5"/></joint>'
        )
    path = tmp_path / "arm5.urdf"
    path.write_text('<robot name="arm5">' + "".join(links + joints) + "</robot>")
    return ad.load_urdf(str(path))


@pytest.mark.parametrize("coordinates", COORDINATES)
@pytest.mark.parametrize("e", [0.0, 0.5])
def test_an_arm_resting_on_several_stops_records_only_contact_changes(tmp_path, coordinates, e):
    """The arm ends at rest on all five upper stops, held by the static torques inverse dynamics
    gives; every recorded event changes its stop's contact (no rest and release of one stop at
    one instant); no joint beyond a stop; energy never rises; the Cartesian run keeps its
    velocity constraints to round-off through the impacts (as limits="ignore" does)."""
    m = arm5(tmp_path)
    r = ad.simulate(
        m, 2.5, restitution=e, coordinates=coordinates, output_dt=1e-3, rtol=1e-10, atol=1e-12
    )
    assert r.error is None
    np.testing.assert_allclose(r.q[-1], 0.3, atol=1e-12)
    held = ad.inverse_dynamics(m, r.q[-1], np.zeros(5), np.zeros(5))
    np.testing.assert_allclose(r.limit_forces["force"][-1], held, rtol=1e-8)
    assert np.all(held < 0)  # the upper stops push down
    ev = r.events["limits"]
    _one_event_per_stop_and_instant(ev)
    _events_change_the_contact(ev)
    assert len(ev["t"]) < 400
    assert np.maximum(r.q - m.coord_upper, m.coord_lower - r.q).max() <= 1e-6
    _energy_never_rises(r, 1e-7)
    free = ad.simulate(
        m, 2.5, limits="ignore", coordinates=coordinates, output_dt=1e-3, rtol=1e-10, atol=1e-12
    )
    assert r.velocity_residual.max() <= max(1e-12, 10 * free.velocity_residual.max())
    assert r.position_residual.max() <= max(1e-12, 10 * free.position_residual.max())


def _ur5_limited():
    from benchmarks.common import robots_dir

    base = robots_dir()
    assert base is not None, "example-robot-data is part of the test extra"
    return ad.load_urdf(base / "ur_description" / "urdf" / "ur5_joint_limited_robot.urdf")


def _ur5_fall_within_its_limits(coordinates, integrator, **tolerances):
    """The joint-limited UR5 falling for 5 s at e = 0.5: never more than 1e-6 beyond a stop,
    bouncing, one event per stop and instant, each a real contact change."""
    m = _ur5_limited()
    r = ad.simulate(
        m,
        5.0,
        restitution=0.5,
        coordinates=coordinates,
        integrator=integrator,
        output_dt=1e-3,
        **tolerances,
    )
    assert r.error is None
    assert np.maximum(r.q - m.coord_upper, m.coord_lower - r.q).max() <= 1e-6
    ev = r.events["limits"]
    assert "bounce" in ev["kind"]
    _one_event_per_stop_and_instant(ev)
    _events_change_the_contact(ev)
    return r


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("coordinates", COORDINATES)
def test_the_joint_limited_ur5_bouncing_keeps_within_its_limits(coordinates, integrator):
    """Issue target: the joint-limited UR5 falling for 5 s at e = 0.5 stays within its limits
    (ignoring them, it passes them by 0.28 rad), at tight tolerances: energy never rises and
    the Cartesian velocity residual stays at round-off. (The issue reports 0.10-0.14 rad beyond
    on main; from this start at tight tolerances the build of 55d38f0 held: the failure it had
    is the default-tolerance case below.)"""
    kw = dict(dt=1e-3) if integrator == "rk4" else dict(rtol=1e-9, atol=1e-11)
    if integrator == "trbdf2":  # (the implicit method, for stiff scenes: looser, to stay quick)
        kw = dict(rtol=1e-7, atol=1e-9)
    r = _ur5_fall_within_its_limits(coordinates, integrator, **kw)
    # TR-BDF2 (order 2) at rtol 1e-7 drifts by up to 2e-4 J with the limits ignored
    # (1.9e-4 J Cartesian, 8.6e-5 J joint space); every impact here removes more than 1 J
    _energy_never_rises(r, 5e-4 if integrator == "trbdf2" else 1e-6)
    if coordinates == "cartesian":
        assert r.velocity_residual.max() <= 1e-12


@pytest.mark.parametrize("integrator", ["dopri5", "dop853", "rk4"])
@pytest.mark.parametrize("coordinates", COORDINATES)
def test_the_joint_limited_ur5_at_default_tolerances_keeps_within_its_limits(
    coordinates, integrator
):
    """The same fall at the default tolerances (rk4 at dt = 1e-3): on 55d38f0 the Cartesian
    DOP853 run ended 0.012 rad beyond a limit; every run now stays within 1e-6 of its stops."""
    _ur5_fall_within_its_limits(
        coordinates, integrator, **(dict(dt=1e-3) if integrator == "rk4" else {})
    )


@pytest.mark.parametrize(
    "integrator, coordinates", [("dop853", "cartesian"), ("dop853", "joint"), ("dopri5", "joint")]
)
def test_a_joint_out_past_its_stop_and_back_within_one_step_is_caught(integrator, coordinates):
    """Released at -0.501 rad, the pendulum swings to +0.501, 1e-3 past its stop at 0.5, for
    about 0.04 s. At rtol 1e-4 these integrators step across the whole excursion (with the
    limits ignored no step ends beyond 0.5: no sign change to see); the stop is still hit, at
    the time the pendulum reaches 0.5 (a tight run without stops), and never passed."""
    b = ad.ModelBuilder(gravity=(0, 0, -G))
    b.add_body("bob", 1.0, np.eye(3) * 1e-4, position=(0, 0, -1.0))
    b.add_revolute("hinge", "ground", "bob", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    b.set_joint_limits("hinge", -3.0, 0.5)
    m = b.finalize()
    kw = dict(q0=[-0.501], integrator=integrator, coordinates=coordinates, rtol=1e-4, atol=1e-6)
    free = ad.simulate(m, 1.2, limits="ignore", **kw)
    assert free.q[:, 0].max() < 0.5
    r = ad.simulate(m, 1.2, **kw)
    assert r.events["limits"]["kind"] == ["bounce"]
    assert r.q[:, 0].max() <= 0.5 + 1e-6
    ref = ad.simulate(m, 1.2, q0=[-0.501], limits="ignore", rtol=1e-12, atol=1e-14, output_dt=1e-5)
    t_ref = ref.t[np.argmax(ref.q[:, 0] >= 0.5)]
    np.testing.assert_allclose(r.events["limits"]["t"][0], t_ref, atol=2e-3)
