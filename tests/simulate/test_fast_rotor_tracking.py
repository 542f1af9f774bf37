"""A fast rotor through an ideal gear, run in Cartesian coordinates: the multi-turn angles of
the gear row are followed by their rates between projections (``Data::track_by_rates``), so a
long step of a high-order integrator that turns the rotor by more than half a turn keeps the
turn its rate leads to. Before that, the nearest branch was taken: dop853 at rtol 1e-6 ended a
0.5 s run of the geared pendulum below at 84.2 rad of rotor instead of 95.3 (a turn lost per
long step, the link thrown by 2 pi / 100 each time), and at rtol 1e-4 it turned the wrong way.

``driven_inverse_dynamics`` tracks its angles the same way from one time to the next: on a
20 ms grid its rotor table lost a turn at every time.

References: the closed forms of a free gear train (constant speeds) and of the driven train's
effort, and the joint-space run, which integrates the angles themselves and shares no tracking
with the Cartesian one."""

import armdyn as ad
import numpy as np
import pytest

RATIO = 100.0  # rotor turns per link turn
W0 = 400.0  # rotor speed [rad/s]


def geared(link_axis):
    """A rotor about z (a thin disc) driving a link about link_axis through an ideal gear
    q_rotor + RATIO q_link = 0."""
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("rotor", 0.5, np.diag([2e-4, 2e-4, 4e-4]), position=(0, 0, 0))
    b.add_body("link", 2.0, np.diag([0.02, 0.02, 0.004]), position=(0.3, 0, 0.5))
    b.add_revolute("jm", "ground", "rotor", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_revolute("jl", "ground", "link", point=(0, 0, 0.5), axis=link_axis)
    b.add_gear("g", "jm", "jl", 1.0, RATIO)
    return b.finalize()


def run(model, integrator, tol, coordinates, t_end=0.5):
    return ad.simulate(
        model,
        t_end,
        integrator=integrator,
        rtol=tol,
        atol=tol,
        coordinates=coordinates,
        q0=[0.0],
        qd0=[W0],
        output_dt=0.01,
    )


# each of these lost turns before (dopri5 1e-2: 55.1 rad of rotor for 95.3; dop853 1e-4: -16.2;
# dop853 1e-6: 84.2), the steps turning the rotor 2 to 7 rad
CASES = [("dopri5", 1e-2), ("dop853", 1e-4), ("dop853", 1e-5), ("dop853", 1e-6)]
TURN = W0 * 0.5  # the rotor's angle at the end [rad]


@pytest.mark.parametrize(("integrator", "tol"), CASES)
def test_a_free_gear_train_keeps_every_turn_of_its_rotor(integrator, tol):
    # both axes vertical: no torque about either, so the speeds stay constant (closed form)
    r = run(geared((0, 0, 1)), integrator, tol, "cartesian")
    rotor, link = r.q[:, 0], r.q[:, 1]
    assert TURN / r.stats["steps"] > 2.0  # long steps: 2 rad and more of rotor each
    # the rotor's 32 turns, each output row on its closed form to the integration error of the
    # Euler parameters (measured 0.1 to 0.3 tol of the angle)
    np.testing.assert_allclose(rotor, W0 * r.t, rtol=0, atol=tol * TURN)
    # the gear row holds on the unwrapped angles at every row: no turn lost or gained (a lost
    # turn is 2 pi / RATIO = 0.063 rad of link)
    np.testing.assert_allclose(link, -rotor / RATIO, rtol=0, atol=1e-9)


@pytest.mark.parametrize(("integrator", "tol"), CASES)
def test_a_geared_pendulum_follows_the_joint_space_run(integrator, tol):
    model = geared((0, 1, 0))  # the link swings under gravity, the rotor 100 times faster
    rc = run(model, integrator, tol, "cartesian")
    rj = run(model, "dop853", 1e-10, "joint")
    assert TURN / rc.stats["steps"] > 2.0
    np.testing.assert_allclose(rc.t, rj.t)
    # the link to the integration error (measured below 0.6 tol of the rotor's angle / RATIO)
    np.testing.assert_allclose(rc.q[:, 1], rj.q[:, 1], rtol=0, atol=tol * TURN / RATIO)
    np.testing.assert_allclose(rc.q[:, 0], -RATIO * rc.q[:, 1], rtol=0, atol=1e-7)


def driven(joint, accel):
    """The pendulum gear train driven through `joint`: its rotor at q = W0 t + accel t^2 / 2
    (the link at -q / RATIO)."""
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("rotor", 0.5, np.diag([2e-4, 2e-4, 4e-4]), position=(0, 0, 0))
    b.add_body("link", 2.0, np.diag([0.02, 0.02, 0.004]), position=(0.3, 0, 0.5))
    b.add_revolute("jm", "ground", "rotor", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_revolute("jl", "ground", "link", point=(0, 0, 0.5), axis=(0, 1, 0))
    b.add_gear("g", "jm", "jl", 1.0, RATIO)
    k = 1.0 if joint == "jm" else -1.0 / RATIO
    b.add_drive(
        joint, lambda t: (k * (W0 * t + accel * t * t / 2), k * (W0 + accel * t), k * accel)
    )
    return b.finalize()


@pytest.mark.parametrize("joint", ["jm", "jl"])
@pytest.mark.parametrize("accel", [0.0, 2000.0])
def test_driven_inverse_dynamics_on_a_coarse_time_grid_keeps_the_rotor_turns(joint, accel):
    # 20 ms between times: the rotor turns 8 to 16 rad from one to the next (before: the
    # rotor's table lost a turn at every time, 100 pi over 0.5 s at 10 ms)
    t = np.linspace(0.0, 0.5, 26)
    r = ad.driven_inverse_dynamics(driven(joint, accel), t)
    q = np.asarray(r.q)
    rotor = W0 * t + accel * t * t / 2
    np.testing.assert_allclose(q[:, 0], rotor, rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(q[:, 1], -rotor / RATIO, rtol=1e-13, atol=1e-12)
    # the effort in closed form: one degree of freedom q = rotor angle, the link at -q / RATIO
    # (about y, its centre of mass 0.3 m out: I = 0.02 + 2 * 0.3^2, gravity torque
    # -2 g 0.3 cos(q_link) about its axis), the rotor's 4e-4 about z
    i_rotor, i_link, g_link = 4e-4, 0.02 + 2.0 * 0.3**2, -2.0 * 9.81 * 0.3 * np.cos(-rotor / RATIO)
    tau_rotor = (i_rotor + i_link / RATIO**2) * accel - g_link / RATIO
    tau = tau_rotor if joint == "jm" else -RATIO * tau_rotor
    np.testing.assert_allclose(np.asarray(r.drive_forces)[:, 0], tau, rtol=1e-10, atol=1e-13)
