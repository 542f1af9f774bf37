"""Joints at rest on their stops (issue 36: the joint-space stops chattered).

The UR5 falling under gravity with its limits enforced came to rest with its elbow and its
wrist_3 on their stops; in joint space the run recorded 96 222 stop events in 96 987 steps
(12-14 s) where the Cartesian one took 19 events: each impact of one stop gave the other, at
rest, a separating rate of round-off size, and the rest test, which bounded that rate by the
stop's acceleration with its own holding force included (zero), released it; the two stops took
turns. The rest test now bounds it by the acceleration without the stop's own force, and
simulate's coordinates="auto" no longer keeps such scenes Cartesian.

References: the static joint torques of inverse dynamics (armdyn's and Pinocchio's RNEA) at the
pose held, the closed-form release time of a pendulum whose load reverses, Poisson's law and
the energy of a pendulum bouncing on its stop, the mirror symmetry of a mechanism whose two
stops engage at one instant, and the two formulations against each other.
"""

from __future__ import annotations

import armdyn as ad
import numpy as np
import pytest

from tests.simulate.test_joint_limits import double_pendulum

G = 9.81
COORDINATES = ["cartesian", "joint"]
TIGHT = dict(rtol=1e-10, atol=1e-12)


def _energy_never_rises(r, tol):
    E = r.kinetic_energy + r.potential_energy
    assert (E - np.minimum.accumulate(E)).max() <= tol


def _events_change_the_contact(ev):
    """Each stop's events follow its state: "release" only from rest, "rest" and "bounce" only
    from free; one event per stop and instant."""
    keys = list(zip(ev["t"], ev["joint"], ev["side"], strict=True))
    assert len(set(keys)) == len(keys)
    engaged = {}
    for j, s, k in zip(ev["joint"], ev["side"], ev["kind"], strict=True):
        on = engaged.get((j, s), False)
        assert (k == "release") == on, (j, s, k)
        engaged[(j, s)] = k == "rest"


def heavy_and_light(light=0.01):
    """A heavy link on j1 (about +y at the origin, its centre 1 m below) carrying a light bob on
    j2 0.3 m further: j1 starts on its lower stop (0.3), which gravity loads; the bob falls onto
    j2's upper stop (-0.6), which gravity loads too. The bob's impacts give j1, at rest, a
    separating rate of a few 1e-5 rad/s (the coupling of the light link), within the rest
    test's apex bound: before the fix every such impact released j1, whose return released j2,
    without end (20 000 steps by t = 0.28 s, in both formulations)."""
    b = ad.ModelBuilder(gravity=(0, 0, -G))
    b.add_body("a", 1.0, np.eye(3) * 1e-2, position=(0, 0, -1.0))
    b.add_body("b", light, np.eye(3) * 1e-2 * light, position=(0, 0, -1.3))
    b.add_revolute("j1", "ground", "a", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    b.add_revolute("j2", "a", "b", (0.0, 0.0, -1.0), (0.0, 1.0, 0.0))
    b.set_joint_limits("j1", 0.3, 1.5)
    b.set_joint_limits("j2", -1.5, -0.6)
    return b.finalize()


HL_LIMITS = np.array([0.3, -0.6])


@pytest.mark.parametrize("coordinates", COORDINATES)
def test_a_light_link_landing_while_the_heavy_one_rests_does_not_chatter(coordinates):
    """The run ends with both joints on their stops, held by the static torques inverse
    dynamics gives there; a handful of events, each a real contact change, no joint beyond a
    stop, energy never rising."""
    m = heavy_and_light()
    r = ad.simulate(
        m, 3.0, q0=[0.3, -1.2], qd0=[0, 0], output_dt=1e-2, coordinates=coordinates, **TIGHT
    )
    assert r.error is None
    ev = r.events["limits"]
    assert len(ev["t"]) < 30
    assert r.stats["steps"] < 500
    _events_change_the_contact(ev)
    np.testing.assert_allclose(r.q[-1], HL_LIMITS, atol=1e-12)
    held = ad.inverse_dynamics(m, HL_LIMITS, np.zeros(2), np.zeros(2))
    assert held[0] > 0 > held[1]  # the lower stop pushes up, the upper one down
    np.testing.assert_allclose(r.limit_forces["force"][-1], held, rtol=1e-9)
    assert np.maximum(r.q - m.coord_upper, m.coord_lower - r.q).max() <= 1e-9
    _energy_never_rises(r, 1e-8)


def mirrored(stops=(0.3, 1.2)):
    """A body on j1 (about +y at the origin) carrying two mirrored pendulums on j2 and j3 (about
    +y at x = +-0.3): the mirror x -> -x maps j2 to j3 with the angle's sign flipped (and keeps
    j1 at 0), so that released at +-0.9 they fall onto j2's lower stop and j3's upper stop at
    one instant. The two stops are coupled through j1 (an off-diagonal Delassus term)."""
    lo, hi = stops
    b = ad.ModelBuilder(gravity=(0, 0, -G))
    b.add_body("a", 2.0, np.diag([0.02, 0.03, 0.02]), position=(0, 0, -0.5))
    b.add_body("b", 0.5, np.eye(3) * 1e-3, position=(0.3, 0, -1.0))
    b.add_body("c", 0.5, np.eye(3) * 1e-3, position=(-0.3, 0, -1.0))
    b.add_revolute("j1", "ground", "a", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    b.add_revolute("j2", "a", "b", (0.3, 0.0, -0.5), (0.0, 1.0, 0.0))
    b.add_revolute("j3", "a", "c", (-0.3, 0.0, -0.5), (0.0, 1.0, 0.0))
    b.set_joint_limits("j1", -1.0, 1.0)
    b.set_joint_limits("j2", lo, hi)
    b.set_joint_limits("j3", -hi, -lo)
    return b.finalize()


@pytest.mark.parametrize("coordinates", COORDINATES)
@pytest.mark.parametrize("e", [0.0, 0.5])
def test_two_coupled_stops_engaging_at_one_instant_rest_together(coordinates, e):
    """Both stops are struck at one instant (one event each, at the same time, every time);
    plastic, both rest at once; at e = 0.5 they bounce together until the series accumulates,
    then rest together. At the end they are held by the static torques inverse dynamics gives
    (j1's zero by the symmetry), with j1 still at 0."""
    m = mirrored()
    r = ad.simulate(
        m,
        2.0,
        q0=[0.0, 0.9, -0.9],
        qd0=[0, 0, 0],
        restitution=e,
        output_dt=1e-2,
        coordinates=coordinates,
        **TIGHT,
    )
    assert r.error is None
    ev = r.events["limits"]
    _events_change_the_contact(ev)
    assert 2 <= len(ev["t"]) < 60
    # in pairs: j2 (lower) and j3 (upper) at one instant, of one kind
    t = np.asarray(ev["t"])
    assert len(t) % 2 == 0
    for k in range(0, len(t), 2):
        assert t[k + 1] - t[k] <= 1e-9
        assert {(ev["joint"][k], ev["side"][k]), (ev["joint"][k + 1], ev["side"][k + 1])} == {
            ("j2", "lower"),
            ("j3", "upper"),
        }
        assert ev["kind"][k] == ev["kind"][k + 1]
    if e == 0.0:
        assert list(ev["kind"]) == ["rest", "rest"]
    else:
        assert ev["kind"][0] == "bounce" and ev["kind"][-1] == "rest"
    q_end = np.array([0.0, 0.3, -0.3])
    np.testing.assert_allclose(r.q[-1], q_end, atol=1e-9)
    held = ad.inverse_dynamics(m, q_end, np.zeros(3), np.zeros(3))
    assert abs(held[0]) <= 1e-12 and held[1] > 0 > held[2]  # lower stop up, upper down
    force = r.limit_forces["force"][-1]
    names = list(r.limit_forces["names"])
    assert force[names.index("j1")] == 0.0
    np.testing.assert_allclose(
        [force[names.index("j2")], force[names.index("j3")]], held[1:], rtol=1e-8
    )
    _energy_never_rises(r, 1e-8)


def _pinocchio_gravity_torques(q):
    pin = pytest.importorskip("pinocchio")
    pm = pin.Model()
    pm.gravity.linear = np.array([0, 0, -G])
    j1 = pm.addJoint(0, pin.JointModelRY(), pin.SE3.Identity(), "j1")
    pm.appendBodyToJoint(
        j1, pin.Inertia(1.0, np.array([0, 0, -1.0]), np.eye(3) * 1e-3), pin.SE3.Identity()
    )
    j2 = pm.addJoint(j1, pin.JointModelRY(), pin.SE3(np.eye(3), np.array([0, 0, -1.0])), "j2")
    pm.appendBodyToJoint(
        j2, pin.Inertia(0.7, np.array([0, 0, -1.0]), np.eye(3) * 1e-3), pin.SE3.Identity()
    )
    return pin.rnea(pm, pm.createData(), np.asarray(q, float), np.zeros(2), np.zeros(2))


@pytest.mark.parametrize("coordinates", COORDINATES)
def test_a_chain_resting_on_its_stops_for_10_s_stays_exactly_on_them(coordinates):
    """Released at (1, 1) the chain lands on both lower stops within 0.6 s and then rests for
    the remaining 9.4 s: two "rest" events, no release, the joints on their limits (to the
    round-off of the poses) at zero rate (joint space: exactly, the pinned state), the stops'
    torques equal to the gravity torques of Pinocchio's RNEA at the limits, all along; a few
    dozen steps."""
    model = double_pendulum((0.3, 1.5), (0.4, 1.5))
    r = ad.simulate(
        model, 10.0, q0=[1.0, 1.0], qd0=[0.0, 0.0], output_dt=1e-2, coordinates=coordinates
    )
    ev = r.events["limits"]
    assert list(ev["kind"]) == ["rest", "rest"]
    on = r.t > max(ev["t"]) + 1e-9
    assert r.t[on][0] < 0.6 and on.sum() > 900
    assert r.stats["steps"] < 100
    q_lim = np.array([0.3, 0.4])
    # (the q reported are read back from the bodies' poses: a few ulps)
    np.testing.assert_allclose(r.q[on], np.broadcast_to(q_lim, r.q[on].shape), rtol=0, atol=1e-15)
    if coordinates == "joint":
        assert np.all(r.qd[on] == 0.0)
    else:
        np.testing.assert_allclose(r.qd[on], 0.0, atol=1e-20)
    tau = _pinocchio_gravity_torques(q_lim)
    np.testing.assert_allclose(
        r.limit_forces["force"][on], np.broadcast_to(tau, (on.sum(), 2)), rtol=1e-10
    )
    np.testing.assert_allclose(
        tau, ad.inverse_dynamics(model, q_lim, np.zeros(2), np.zeros(2)), rtol=1e-12
    )
    np.testing.assert_allclose(r.qdd[on], 0.0, atol=1e-9)


def pendulum(lower, upper):
    """A 1 kg bob on a massless 1 m arm, hinged about +y at the origin, hanging at q = 0;
    gravity's torque is -m g L sin q."""
    b = ad.ModelBuilder(gravity=(0, 0, -G))
    b.add_body("bob", 1.0, np.eye(3) * 1e-4, position=(0, 0, -1.0))
    b.add_revolute("hinge", "ground", "bob", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    b.set_joint_limits("hinge", lower, upper)
    return b


@pytest.mark.parametrize("coordinates", COORDINATES)
def test_a_reversing_load_lifts_the_joint_off_its_stop_when_it_changes_sign(coordinates):
    """Resting on its lower stop at 0.5 rad (gravity's torque -m g L sin 0.5 into it) under a
    joint torque rising from 0 to 2 m g L sin 0.5 along a quintic over [0, 1] s: the load on
    the stop changes sign when the input passes m g L sin 0.5, at t = 0.5 s (the quintic's
    midpoint); until then the stop holds with m g L sin 0.5 (1 - 2 s(t)), s(t) = 10 t^3 -
    15 t^4 + 6 t^5; then the joint leaves it."""
    q_lim = 0.5
    X = G * np.sin(q_lim)
    b = pendulum(q_lim, 2.0)
    b.add_joint_torque("hinge", ad.profiles.quintic(0.0, 2 * X, 0.0, 1.0))
    model = b.finalize()
    r = ad.simulate(
        model, 1.0, q0=[q_lim], qd0=[0.0], output_dt=1e-3, coordinates=coordinates, **TIGHT
    )
    assert r.error is None
    ev = r.events["limits"]
    assert list(ev["kind"]) == ["rest", "release"] and ev["t"][0] == 0.0
    np.testing.assert_allclose(ev["t"][1], 0.5, rtol=1e-9)
    before = r.t < ev["t"][1]
    np.testing.assert_allclose(r.q[before, 0], q_lim, atol=1e-12)
    s = 10 * r.t**3 - 15 * r.t**4 + 6 * r.t**5
    np.testing.assert_allclose(
        r.limit_forces["force"][before, 0], X * (1 - 2 * s[before]), rtol=1e-9, atol=1e-12
    )
    after = r.t > ev["t"][1] + 1e-9
    assert np.all(r.limit_forces["force"][after, 0] == 0.0)
    assert np.all(np.diff(r.q[after, 0]) > 0) and r.q[-1, 0] > q_lim + 1e-3


@pytest.mark.parametrize("coordinates", COORDINATES)
@pytest.mark.parametrize("e", [0.3, 0.7])
def test_bounces_shrink_to_rest_on_the_stop(coordinates, e):
    """Released at 1.2 rad onto its lower stop at 0.3 (gravity into it): each rebound leaves at
    e times its impact rate, so the flights 2 v / a shrink by e (a = g sin 0.3 / J near the
    stop); the series ends at rest once a rebound's apex is within the stop's tolerance 1e-9,
    after at most log(sqrt(2 a 1e-9) / v0) / log e + 2 bounces; energy never rises; the joint
    then rests on the limit held by g sin 0.3."""
    q_lim, J = 0.3, 1.0 + 1e-4
    model = pendulum(q_lim, 3.0).finalize()
    r = ad.simulate(
        model, 6.0, q0=[1.2], qd0=[0.0], restitution=e, coordinates=coordinates, **TIGHT
    )
    assert r.error is None
    ev = r.events["limits"]
    kinds, t = list(ev["kind"]), np.asarray(ev["t"])
    _events_change_the_contact(ev)
    assert kinds[-1] == "rest" and set(kinds[:-1]) == {"bounce"}
    a = G * np.sin(q_lim) / J
    v0 = np.sqrt(2 * G * (np.cos(q_lim) - np.cos(1.2)) / J)  # the first impact rate
    n_max = np.log(np.sqrt(2 * a * 1e-9) / v0) / np.log(e) + 2
    assert 2 <= len(kinds) <= n_max
    flights = np.diff(t)[:-1]  # between bounces (the last one ends in the summed series)
    # the flights whose apex a (flight / 2)^2 / 2 is below 1e-4 rad (a constant near the
    # stop): each e times the one before
    low = np.flatnonzero(a * (flights / 2) ** 2 / 2 < 1e-4)
    assert len(low) >= 3
    np.testing.assert_allclose(flights[low[1:]] / flights[low[:-1]], e, rtol=1e-3)
    _energy_never_rises(r, 1e-9)
    after = r.t > t[-1] + 1e-9
    np.testing.assert_allclose(r.q[after, 0], q_lim, atol=1e-12)
    np.testing.assert_allclose(r.limit_forces["force"][after, 0], G * np.sin(q_lim), rtol=1e-9)
    assert r.q[:, 0].min() >= q_lim - 1e-9


@pytest.mark.parametrize("e", [0.0, 0.5])
def test_the_two_formulations_agree_at_rest(e):
    """The heavy-and-light chain in both formulations: the same events (joint, side, kind) at
    the same times, the same final state and stop torques, to the integration tolerance."""
    m = heavy_and_light(light=0.05)
    kw = dict(q0=[0.3, -1.2], qd0=[0, 0], output_dt=1e-2, restitution=e, **TIGHT)
    rj = ad.simulate(m, 3.0, coordinates="joint", **kw)
    rc = ad.simulate(m, 3.0, coordinates="cartesian", **kw)
    ej, ec = rj.events["limits"], rc.events["limits"]
    for f in ("joint", "side", "kind"):
        assert list(ej[f]) == list(ec[f])
    np.testing.assert_allclose(ej["t"], ec["t"], atol=1e-7)
    np.testing.assert_allclose(rj.q[-1], rc.q[-1], atol=1e-7)
    np.testing.assert_allclose(
        rj.limit_forces["force"][-1], rc.limit_forces["force"][-1], rtol=1e-7
    )
    np.testing.assert_allclose(rj.reaction_forces[-1], rc.reaction_forces[-1], rtol=1e-7, atol=1e-9)


def _ur5_fall(coordinates=None):
    """The UR5 of benchmarks.cartesian_fd: released from UR5_Q0 at rest, 5 s, rtol 1e-8."""
    from benchmarks import common

    path = common.robot_urdf("ur5")
    assert path is not None, "example-robot-data is part of the test extra"
    m = ad.load_urdf(str(path))
    kw = dict(rtol=1e-8, atol=1e-10, output_dt=0.05, q0=np.array(common.UR5_Q0), qd0=np.zeros(6))
    if coordinates is not None:
        kw["coordinates"] = coordinates
    return m, ad.simulate(m, 5.0, **kw)


@pytest.mark.parametrize("coordinates", COORDINATES)
def test_the_ur5_fall_holds_its_limits_with_few_events(coordinates):
    """Issue target: the UR5 falling with its limits enforced (the elbow and wrist_3 come to
    rest on their stops for a while) stays within its limits with a few dozen events at most
    (before: 96 222 events in 96 987 steps in joint space) and holds its stops with the static
    torques while at rest."""
    m, r = _ur5_fall(coordinates)
    assert r.error is None
    ev = r.events["limits"]
    assert r.stats["events"] < 100 and len(ev["t"]) < 100
    assert r.stats["steps"] < 5000
    _events_change_the_contact(ev)
    assert np.maximum(r.q - m.coord_upper, m.coord_lower - r.q).max() <= 1e-9
    assert {"elbow_joint", "wrist_3_joint"} <= {
        j for j, k in zip(ev["joint"], ev["kind"], strict=True) if k == "rest"
    }
    _energy_never_rises(r, 1e-6)


def test_the_plain_ur5_fall_runs_in_joint_space_and_matches_the_cartesian_one():
    """coordinates="auto" (the default) takes joint space with the stops enforced: bit for bit
    the coordinates="joint" run; the Cartesian run's tables, stop torques and events agree to
    the integration error."""
    _, plain = _ur5_fall()
    _, joint = _ur5_fall("joint")
    _, cart = _ur5_fall("cartesian")
    assert plain.stats["formulation"].startswith("joint space")
    for f in ("q", "qd", "qdd", "reaction_forces", "reaction_torques"):
        np.testing.assert_array_equal(getattr(plain, f), getattr(joint, f))
    np.testing.assert_array_equal(plain.limit_forces["force"], joint.limit_forces["force"])
    ej, ec = joint.events["limits"], cart.events["limits"]
    assert list(zip(ej["joint"], ej["side"], ej["kind"], strict=True)) == list(
        zip(ec["joint"], ec["side"], ec["kind"], strict=True)
    )
    np.testing.assert_allclose(ej["t"], ec["t"], atol=1e-6)
    np.testing.assert_allclose(joint.q, cart.q, atol=1e-5)
    np.testing.assert_allclose(
        joint.limit_forces["force"], cart.limit_forces["force"], rtol=1e-4, atol=1e-4
    )
    np.testing.assert_allclose(joint.reaction_forces, cart.reaction_forces, rtol=1e-4, atol=1e-3)


@pytest.mark.parametrize("integrator", ["dopri5", "dop853"])
def test_cartesian_angles_over_many_turns_follow_the_joint_space_ones(integrator):
    """A pendulum thrown over the top turns many times (its stops at +-100 rad are in play but
    never reached) at a loose tolerance, with rejected steps: the Cartesian run's unwrapped
    angle (its tracking saved at each accepted step and restored after each rejected one)
    follows the joint-space one, with no jump of a turn. (A guard, not a reproduction: no run
    found here loses a turn to a rejected step without the restore.)"""
    model = pendulum(-100.0, 100.0).finalize()
    kw = dict(q0=[0.0], qd0=[12.0], output_dt=1e-2, integrator=integrator, rtol=1e-5, atol=1e-7)
    rc = ad.simulate(model, 3.0, coordinates="cartesian", **kw)
    rj = ad.simulate(model, 3.0, coordinates="joint", **kw)
    assert rc.stats["rejected"] > 0
    assert rc.q[-1, 0] > 4 * np.pi  # turns
    assert np.abs(np.diff(rc.q[:, 0])).max() < 0.2
    np.testing.assert_allclose(rc.q[:, 0], rj.q[:, 0], atol=1e-2)
