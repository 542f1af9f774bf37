"""armdyn.motion.time_optimal and shortest_cycle against independent references: the joint
torques of the output recomputed by armdyn.inverse_dynamics, a convex TOPP of the same
discretisation in cvxpy (Verscheure et al. 2009: minimise Σ 2Δ/(√x_i + √x_{i+1}), x = ṡ²,
u = s̈, linear constraints), bang-bang and trapezoid closed forms, the motor side recomputed by
armdyn.actuators.motor_side, and the shortest thermal cycle of a bang-bang motion in closed form
(RMS: a quartic; one-node winding temperature: the periodic steady state of a square loss).
"""

import armdyn as ad
import numpy as np
import pytest
from armdyn.actuators import motor_side
from armdyn.motion import Path, shortest_cycle, time_optimal
from armdyn.sizing.motor import motor_envelope
from armdyn.sizing.options import SizingOptions

from benchmarks import common

UR5_TORQUE = np.array([60.0, 60.0, 40.0, 10.0, 10.0, 10.0])
UR5_ACC = np.array([np.inf, np.inf, np.inf, 25.0, 25.0, 25.0])
UR5_WAYPOINTS = np.array(
    [
        [0.0, -1.2, 1.0, -1.4, -1.57, 0.0],
        [0.8, -1.5, 1.6, -1.0, -1.3, 0.3],
        [1.5, -0.6, 0.4, -0.8, -1.0, 1.0],
    ]
)

# the one-link arm: a link of 2 kg at 0.5 m (I_yy = I_zz = 0.05 about its centre)
MASS, ARM, I_C = 2.0, 0.5, 0.05
INERTIA = I_C + MASS * ARM**2


def arm(actuator=None, axis=(0, 0, 1)):
    """About z (vertical: gravity gives no torque) by default; about y it lifts the link."""
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("link", MASS, [0.01, I_C, I_C], position=(ARM, 0.0, 0.0))
    b.add_revolute("j", "ground", "link", point=(0, 0, 0), axis=axis)
    if actuator:
        b.add_actuator("j", **actuator)
    return b.finalize()


def segment(q_end, q_start=0.0):
    return Path([0.0, 1.0], [np.atleast_1d(q_start), np.atleast_1d(q_end)])


@pytest.fixture(scope="module")
def ur5():
    path = common.robot_urdf("ur5")
    if path is None:
        pytest.skip("example-robot-data is not installed")
    return ad.load_urdf(path)


@pytest.fixture(scope="module")
def ur5_path():
    return Path([0.0, 0.5, 1.0], UR5_WAYPOINTS)  # a natural cubic spline


def cvxpy_duration(model, path, s, tau_max, v_max, a_max):
    """The reference: the convex problem of the same collocation (rows at s_0 … s_{N-1} with
    (u_i, x_i); x_0 = x_N = 0), coefficients from armdyn.inverse_dynamics computed here."""
    cp = pytest.importorskip("cvxpy")
    q, d1, d2 = path.evaluate(s)
    z = np.zeros_like(q)
    c = ad.inverse_dynamics(model, q, z, z)
    a = ad.inverse_dynamics(model, q, z, d1) - c
    b = ad.inverse_dynamics(model, q, d1, d2) - c
    n, delta = len(s) - 1, np.diff(s)
    with np.errstate(divide="ignore"):
        x_max = np.min(np.where(d1 != 0.0, (v_max / np.abs(d1)) ** 2, np.inf), axis=1)
    x, u = cp.Variable(n + 1), cp.Variable(n)
    torque = cp.multiply(a[:-1], u[:, None]) + cp.multiply(b[:-1], x[:-1][:, None]) + c[:-1]
    acc = cp.multiply(d1[:-1], u[:, None]) + cp.multiply(d2[:-1], x[:-1][:, None])
    fin = np.isfinite(a_max)
    constraints = [
        x[0] == 0,
        x[n] == 0,
        x >= 0,
        x <= np.minimum(x_max, 1e12),
        x[1:] == x[:-1] + 2 * cp.multiply(delta, u),
        cp.abs(torque) <= tau_max,
        cp.abs(acc[:, fin]) <= a_max[fin],
    ]
    cost = cp.sum(cp.multiply(2 * delta, cp.inv_pos(cp.sqrt(x[:-1]) + cp.sqrt(x[1:]))))
    problem = cp.Problem(cp.Minimize(cost), constraints)
    problem.solve(solver="CLARABEL")
    assert problem.status == "optimal"
    # the duration of its x with the ends at rest exactly: the solver meets x_0 = x_N = 0 to
    # its tolerance (~1e-8), which the square root turns into a 1e-4 error at the ends
    xs = np.maximum(x.value, 0.0)
    xs[0] = xs[-1] = 0.0
    sd = np.sqrt(xs)
    return float(np.sum(2 * delta / (sd[1:] + sd[:-1])))


# --- the UR5: torque limits and the convex reference -------------------------------------------


@pytest.mark.filterwarnings("ignore::UserWarning")  # cvxpy: "CPP backend" notice
def test_ur5_torque_limits_respected_and_duration_matches_a_convex_topp(ur5, ur5_path):
    grid = 400
    traj = time_optimal(ur5, ur5_path, max_torque=UR5_TORQUE, max_acceleration=UR5_ACC, grid=grid)
    tau = ad.inverse_dynamics(ur5, traj.q, traj.qd, traj.qdd)
    ratio = np.abs(tau) / UR5_TORQUE
    assert np.max(ratio) <= 1.0 + 1e-6
    assert np.max(ratio) >= 1.0 - 1e-6  # a torque limit binds: the check is not idle
    v_max = ur5.coord_velocity_limit
    assert np.max(np.abs(traj.qd) / v_max) <= 1.0 + 1e-6
    fin = np.isfinite(UR5_ACC)
    assert np.max(np.abs(traj.qdd[:, fin]) / UR5_ACC[fin]) <= 1.0 + 1e-6
    assert np.any(["torque" in a for a in traj.info["active"]])
    assert np.any(["velocity" in a for a in traj.info["active"]])
    reference = cvxpy_duration(ur5, ur5_path, traj.info["s"], UR5_TORQUE, v_max, UR5_ACC)
    assert traj.duration == pytest.approx(reference, rel=1e-2)  # the target
    assert traj.duration == pytest.approx(reference, rel=1e-5)  # measured: 2e-7
    assert traj.duration >= reference * (1.0 - 1e-6)  # the reference is the optimum


def test_ur5_with_motors_respects_every_joint_and_motor_limit(ur5_path):
    """The UR5 with a geared motor on every joint (N = 100, η = 0.85, viscous friction): the
    joint torques (the URDF's efforts) and speeds by an independent inverse dynamics, and each
    motor's peak torque, envelope and speed by armdyn.actuators.motor_side; a motor binds."""
    path = common.robot_urdf("ur5")
    if path is None:
        pytest.skip("example-robot-data is not installed")
    b = ad.urdf_builder(str(path))
    big = dict(torque_constant=0.1, resistance=0.5, voltage=48.0, peak_torque=1.5)
    small = dict(torque_constant=0.05, resistance=1.0, voltage=24.0, peak_torque=0.4)
    for k, joint in enumerate(ad.load_urdf(path).dof_names):
        b.add_actuator(
            joint,
            gear_ratio=100.0,
            rotor_inertia=3e-5 if k < 3 else 1e-5,
            efficiency=0.85,
            friction_viscous=1e-5,
            motor=ad.Motor(no_load_speed=450.0, **(big if k < 3 else small)),
        )
    model = b.finalize()
    traj = time_optimal(model, ur5_path, grid=300)
    tau = ad.inverse_dynamics(model, traj.q, traj.qd, traj.qdd)
    assert np.max(np.abs(tau) / model.coord_effort_limit) <= 1 + 1e-6
    assert np.max(np.abs(traj.qd) / model.coord_velocity_limit) <= 1 + 1e-6
    worst = 0.0
    for act in model.actuators:
        k = act.dof
        side = motor_side(act, traj.t, traj.qd[:, k], traj.qdd[:, k], tau[:, k])
        t0, w0 = motor_envelope(act.motor)
        peak = np.max(np.abs(side.torque)) / act.motor.peak_torque
        envelope = np.max(np.abs(side.torque + t0 * side.speed / w0)) / t0
        assert max(peak, envelope) <= 1 + 1e-6, act.joint
        assert np.max(np.abs(side.speed)) <= 450.0 * (1 + 1e-9)
        worst = max(worst, peak, envelope)
    assert worst >= 1 - 1e-6
    assert any(a.startswith("motor") for a in traj.info["active"])


def test_samples_follow_the_timing_and_evaluate_is_exact(ur5, ur5_path):
    traj = time_optimal(ur5, ur5_path, max_torque=UR5_TORQUE, grid=200)
    s, sd, sdd = (traj.info[k] for k in ("s", "sd", "sdd"))
    # the time of each interval at constant s̈: 2Δs / (ṡ_i + ṡ_{i+1}), and ṡ² grows by 2 s̈ Δs
    np.testing.assert_allclose(np.diff(traj.t), 2 * np.diff(s) / (sd[1:] + sd[:-1]), rtol=1e-12)
    np.testing.assert_allclose(np.diff(sd**2), 2 * sdd[:-1] * np.diff(s), atol=1e-12)
    assert sd[0] == 0.0 and sd[-1] == 0.0 and traj.duration == traj.info["duration"]
    q, qd, qdd = traj._evaluate(traj.t[:-1])
    np.testing.assert_allclose(q, traj.q[:-1], atol=1e-12)
    np.testing.assert_allclose(qd, traj.qd[:-1], atol=1e-12)
    np.testing.assert_allclose(qdd, traj.qdd[:-1], atol=1e-9)
    # between samples: central differences of evaluate's q and q̇ give its q̇ and q̈
    mid = 0.5 * (traj.t[50:60] + traj.t[51:61])
    h = 1e-6
    qp, qdp, _ = traj._evaluate(mid + h)
    qm, qdm, _ = traj._evaluate(mid - h)
    _, qd0, qdd0 = traj._evaluate(mid)
    np.testing.assert_allclose((qp - qm) / (2 * h), qd0, rtol=1e-6, atol=1e-8)
    np.testing.assert_allclose((qdp - qdm) / (2 * h), qdd0, rtol=1e-5, atol=1e-6)
    np.testing.assert_array_equal(traj.qd[-1], 0.0)
    np.testing.assert_array_equal(traj.qdd[-1], 0.0)


# --- closed forms ----------------------------------------------------------------------------


@pytest.mark.parametrize("q_end", [1.5, 1e-12, 1e4])
def test_one_joint_constant_torque_limit_is_bang_bang(q_end):
    """I q̈ = ±τ_max over Q from rest to rest: T = 2 √(Q I / τ_max), exact on a grid with the
    switch (s = 1/2) on a grid point. A tiny move (ṡ² ~ 1e12, beyond the 1e8 where toppra's
    solver caps it) and a long one (ṡ² ~ 1e-5) too."""
    tau_max = 3.0
    traj = time_optimal(arm(), segment(q_end), max_torque=tau_max, max_velocity=np.inf, grid=500)
    assert traj.duration == pytest.approx(2 * np.sqrt(q_end * INERTIA / tau_max), rel=1e-12)
    tau = ad.inverse_dynamics(arm(), traj.q, traj.qd, traj.qdd)
    np.testing.assert_allclose(np.abs(tau[:-1, 0]), tau_max, rtol=1e-10)


def test_a_given_uneven_grid_is_used_as_it_is():
    """A cosine-spaced grid (denser at the ends, s = 1/2 on it): the samples are at those
    path parameters and the bang-bang time is still exact."""
    grid = 0.5 - 0.5 * np.cos(np.pi * np.arange(81) / 80)
    grid[0], grid[-1] = 0.0, 1.0
    traj = time_optimal(arm(), segment(1.5), max_torque=3.0, max_velocity=np.inf, grid=grid)
    np.testing.assert_array_equal(traj.info["grid"], grid)
    assert traj.duration == pytest.approx(2 * np.sqrt(1.5 * INERTIA / 3.0), rel=1e-12)


def test_spring_torque_is_in_the_static_term_and_joint_coulomb_friction_is_refused():
    """A joint spring (k = 4 N m/rad) adds k q to the torque: the limit holds with it, checked
    by an independent inverse dynamics, and binds; a joint's smoothed Coulomb friction (not
    linear in the rates, not an actuator's) is refused."""
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("link", MASS, [0.01, I_C, I_C], position=(ARM, 0.0, 0.0))
    b.add_revolute("j", "ground", "link", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_joint_spring_damper("j", stiffness=4.0)
    model = b.finalize()
    traj = time_optimal(model, segment(0.5), max_torque=3.0, max_velocity=np.inf, grid=300)
    tau = ad.inverse_dynamics(model, traj.q, traj.qd, traj.qdd)
    assert np.max(np.abs(tau)) <= 3.0 * (1 + 1e-6)
    assert np.max(np.abs(tau)) >= 3.0 * (1 - 1e-6)
    np.testing.assert_allclose(tau[-1, 0], 4.0 * 0.5, rtol=1e-12)  # held by the motor at the end
    b.add_joint_friction("j", coulomb=0.5)
    with pytest.raises(ad.ModelError, match=r"velocity-dependent forces .* joint 'j'"):
        time_optimal(b.finalize(), segment(0.5), max_torque=3.0)


# --- dampers: torques a s̈ + b ṡ² + d ṡ + c --------------------------------------------------

TAU_D, C_D = 3.0, 1.5  # the damped arm's torque limit and its damping (N m s/rad)


def damped_arm():
    """The arm about z with a joint damper (1 N m s/rad) and viscous joint friction (0.5):
    I q̈ + C q̇ = τ, C = 1.5."""
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("link", MASS, [0.01, I_C, I_C], position=(ARM, 0.0, 0.0))
    b.add_revolute("j", "ground", "link", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_joint_spring_damper("j", damping=1.0)
    b.add_joint_friction("j", viscous=C_D - 1.0)
    return b.finalize()


def damped_bang_bang(q_end):
    """The time-optimal rest-to-rest move of I q̈ + C q̇ = τ, |τ| ≤ τ_max, by scipy's solve_ivp
    in the speed ω: accelerating dθ/dω = I ω/(τ − C ω), dt/dω = I/(τ − C ω) from rest;
    braking, integrated back from the end, dθ/dω = I ω/(τ + C ω), dt/dω = I/(τ + C ω); the
    switch where the two angles add up to the move. Returns (duration, switch speed)."""
    from scipy.integrate import solve_ivp

    def rhs(w, y):
        up, down = TAU_D - C_D * w, TAU_D + C_D * w
        return [INERTIA * w / up, INERTIA / up, INERTIA * w / down, INERTIA / down]

    def meet(w, y):
        return y[0] + y[2] - q_end

    meet.terminal = True
    sol = solve_ivp(
        rhs, [0.0, TAU_D / C_D * (1 - 1e-12)], [0.0] * 4, events=meet, rtol=1e-12, atol=1e-14
    )
    y = sol.y_events[0][0]
    return y[1] + y[3], sol.t_events[0][0]


def test_damped_inertia_bang_bang_converges_to_the_ode_solution():
    """I q̈ + C q̇ = ±τ_max (a joint damper and viscous joint friction): the duration against
    the bang-bang of :func:`damped_bang_bang` (solve_ivp): the collocation is first order in
    the grid step (the damper makes the phase curves bend: x_{i+1} = x_i + 2Δ u(x_i) is
    explicit Euler), so the error halves with the step (measured: −2.4e-3, −1.3e-3, −7.0e-4
    at 1000, 2000, 4000 intervals); every sample but the switch and the arrival at rest is at
    the torque limit to 1e-6 by an independent inverse dynamics (the damper's torque C q̇ there
    is up to C ω*/τ_max = 93 % of the limit: ignoring it would fail by that much)."""
    model = damped_arm()
    exact, switch_speed = damped_bang_bang(1.5)
    errors = []
    for grid in (1000, 2000, 4000):
        traj = time_optimal(model, segment(1.5), max_torque=TAU_D, max_velocity=np.inf, grid=grid)
        errors.append(traj.duration / exact - 1.0)
        tau = ad.inverse_dynamics(model, traj.q, traj.qd, traj.qdd)[:, 0]
        assert np.max(np.abs(tau)) <= TAU_D * (1 + 1e-6)
        off = np.flatnonzero(np.abs(np.abs(tau) / TAU_D - 1.0) > 1e-6)
        assert len(off) <= 2 and off[-1] == grid  # the switch's sample and the arrival
    assert abs(errors[-1]) < 1e-3
    assert 1.6 < errors[1] / errors[2] < 2.4 and 1.6 < errors[0] / errors[1] < 2.4
    assert np.max(traj.qd) == pytest.approx(switch_speed, rel=1e-4)
    assert C_D * switch_speed / TAU_D > 0.9


def test_damped_inertia_cruises_at_the_terminal_speed():
    """A long move (40 rad, no speed limit): the damped arm accelerates at τ_max towards its
    terminal speed τ_max / C, where the damper takes the whole torque: the samples reach it to
    1e-9 (the discrete speed has the same fixed point), at the torque limit there."""
    model = damped_arm()
    traj = time_optimal(model, segment(40.0), max_torque=TAU_D, max_velocity=np.inf, grid=2000)
    assert np.max(traj.qd) == pytest.approx(TAU_D / C_D, rel=1e-9)
    cruise = np.abs(traj.qd[:, 0] / (TAU_D / C_D) - 1.0) < 1e-9
    assert cruise.sum() > 500
    tau = ad.inverse_dynamics(model, traj.q, traj.qd, traj.qdd)[:, 0]
    switch = np.flatnonzero(cruise)[-1]  # the last sample at that speed begins the braking
    np.testing.assert_allclose(tau[cruise][:-1], TAU_D, rtol=1e-6)
    np.testing.assert_allclose(np.abs(np.delete(tau, [switch, 2000])), TAU_D, rtol=1e-6)
    assert np.max(np.abs(tau)) <= TAU_D * (1 + 1e-6)


PANDA_WAYPOINTS = np.array(
    [
        [0.0, -0.5, 0.0, -2.2, 0.0, 1.8, 0.8, 0.01],
        [0.7, 0.2, -0.4, -1.5, 0.5, 2.4, 1.4, 0.035],
        [1.4, -0.3, 0.3, -2.5, -0.4, 1.6, 2.2, 0.02],
    ]
)
PANDA_TORQUE = np.array([40.0, 40.0, 30.0, 30.0, 5.0, 5.0, 5.0, 20.0])


def cvxpy_damped_duration(model, path, s, tau_max, v_max, iterations=12):
    """The convex reference with dampers: torque rows a u + b x + c + d √x, a, b, c, d from
    armdyn.inverse_dynamics here (d √x, the damper, the odd part in the rates: d = (ID(q, q',
    0) − ID(q, −q', 0))/2; b the even part less c). On each side of |τ| ≤ τ_max the term is
    either −|d| √x (convex: kept exact, cvxpy's sqrt) or +|d| √x (concave: not DCP). The
    concave ones are replaced by their tangent at the previous solution, starting from the
    solution without them (a relaxation), and solved again until the duration settles: the
    convex–concave procedure, whose fixed point is a local optimum (KKT point) of the true
    problem on the same grid. Its own iteration, exact convex side and solver: independent of
    time_optimal's tangents and secants."""
    cp = pytest.importorskip("cvxpy")
    q, d1, d2 = path.evaluate(s)
    z = np.zeros_like(q)
    c = ad.inverse_dynamics(model, q, z, z)
    a = ad.inverse_dynamics(model, q, z, d1) - c
    d = 0.5 * (ad.inverse_dynamics(model, q, d1, z) - ad.inverse_dynamics(model, q, -d1, z))
    b = 0.5 * (ad.inverse_dynamics(model, q, d1, d2) + ad.inverse_dynamics(model, q, -d1, d2))
    b -= c
    n, delta = len(s) - 1, np.diff(s)
    with np.errstate(divide="ignore"):
        x_max = np.min(np.where(d1 != 0.0, (v_max / np.abs(d1)) ** 2, np.inf), axis=1)
    x, u = cp.Variable(n + 1), cp.Variable(n)
    # the concave terms' tangent r/2 + x/(2r) at x = r² (0 at first: left out, a relaxation)
    offset, slope = cp.Parameter(n, nonneg=True), cp.Parameter(n, nonneg=True)
    a, b, c, d = a[:-1], b[:-1], c[:-1], d[:-1]
    lin = cp.multiply(a, u[:, None]) + cp.multiply(b, x[:-1][:, None]) + c
    root = cp.sqrt(x[:-1])[:, None]
    tangent = (offset + cp.multiply(slope, x[:-1]))[:, None]
    dp, dm = np.maximum(d, 0.0), np.maximum(-d, 0.0)
    constraints = [
        x[0] == 0,
        x[n] == 0,
        x >= 0,
        x <= np.minimum(x_max, 1e12),
        x[1:] == x[:-1] + 2 * cp.multiply(delta, u),
        lin + cp.multiply(dp, tangent) - cp.multiply(dm, root) <= tau_max,
        -lin - cp.multiply(dp, root) + cp.multiply(dm, tangent) <= tau_max,
    ]
    cost = cp.sum(cp.multiply(2 * delta, cp.inv_pos(cp.sqrt(x[:-1]) + cp.sqrt(x[1:]))))
    problem = cp.Problem(cp.Minimize(cost), constraints)
    durations = []
    offset.value, slope.value = np.zeros(n), np.zeros(n)
    for _ in range(iterations):
        problem.solve(solver="CLARABEL")
        assert problem.status == "optimal"
        xs = np.maximum(x.value, 0.0)
        xs[0] = xs[-1] = 0.0
        sd = np.sqrt(xs)
        durations.append(float(np.sum(2 * delta / (sd[1:] + sd[:-1]))))
        if len(durations) > 2 and abs(durations[-1] / durations[-2] - 1.0) < 1e-7:
            break
        r = np.maximum(sd[:-1], 1e-6 * np.max(sd))
        offset.value, slope.value = r / 2, 1 / (2 * r)
    assert len(durations) < iterations  # settled
    return durations[-1], durations[0]


@pytest.fixture(scope="module")
def panda():
    path = common.robot_urdf("panda")
    if path is None:
        pytest.skip("example-robot-data is not installed")
    return ad.load_urdf(path)


@pytest.mark.filterwarnings("ignore::UserWarning")  # cvxpy: "CPP backend" notice
def test_panda_with_its_urdf_damping_respects_torques_and_matches_a_convex_reference(panda):
    """The Panda of example-robot-data with its URDF <dynamics damping> (0.003 N m s/rad on the
    arm, 0.3 N s/m on the fingers) on a path of all its joints: every torque within its limit to
    1e-6 by an independent inverse dynamics (which includes the dampers), the limits binding,
    and the dampers' torque at the binding samples far above 1e-6 of the limit (the check would
    see them left out); the duration within 1 % of the convex–concave reference of
    :func:`cvxpy_damped_duration` on the same grid (measured: 1.1e-8; without the dampers on
    the concave side, its first solve, 6.8e-5 shorter)."""
    path = Path([0.0, 0.5, 1.0], PANDA_WAYPOINTS)
    traj = time_optimal(panda, path, max_torque=PANDA_TORQUE, grid=300)
    tau = ad.inverse_dynamics(panda, traj.q, traj.qd, traj.qdd)
    ratio = np.abs(tau) / PANDA_TORQUE
    assert np.max(ratio) <= 1.0 + 1e-6
    binding = ratio >= 1.0 - 1e-6
    assert binding.sum() > 100
    assert np.max(np.abs(traj.qd) / panda.coord_velocity_limit) <= 1.0 + 1e-6
    zero = np.zeros_like(traj.qd)
    damper = 0.5 * (
        ad.inverse_dynamics(panda, traj.q, traj.qd, zero)
        - ad.inverse_dynamics(panda, traj.q, -traj.qd, zero)
    )
    assert (
        np.max(np.abs(damper)[binding] / np.broadcast_to(PANDA_TORQUE, tau.shape)[binding]) > 1e-4
    )
    reference, undamped = cvxpy_damped_duration(
        panda, path, traj.info["s"], PANDA_TORQUE, panda.coord_velocity_limit
    )
    assert traj.duration == pytest.approx(reference, rel=1e-2)  # the target
    assert traj.duration == pytest.approx(reference, rel=1e-5)
    assert reference > undamped  # the dampers matter to the reference too


def test_speed_and_acceleration_limits_give_the_trapezoid():
    """Two joints on a straight segment, the second moving half as far: the first's limits
    (v = 1, a = 1 over Q = 2) give T = Q/v + v/a = 3; its cruise starts at s = 1/4."""
    path = Path([0.0, 1.0], [[0.0, 0.0], [2.0, -1.0]])
    model = ad.ModelBuilder()
    for k in range(2):
        model.add_body(f"b{k}", 1.0, [0.1, 0.1, 0.1], position=(0.0, 0.0, 0.1 * k))
        model.add_revolute(f"j{k}", "ground" if k == 0 else "b0", f"b{k}", (0, 0, 0), (0, 0, 1))
    model = model.finalize()
    traj = time_optimal(
        model,
        path,
        max_velocity=[1.0, 1.0],
        max_acceleration=[1.0, 1.0],
        max_torque=np.inf,
        grid=1000,
    )
    assert traj.duration == pytest.approx(3.0, rel=1e-12)
    assert np.max(np.abs(traj.qd[:, 0])) == pytest.approx(1.0, rel=1e-12)
    assert traj.info["active"][500] == "velocity 'j0'"
    assert traj.info["active"][10].startswith("acceleration 'j0'")


def _geared(eta=0.8, j=2e-5, n=50.0, **motor):
    return arm(dict(gear_ratio=n, rotor_inertia=j, efficiency=eta, motor=ad.Motor(**motor)))


@pytest.mark.parametrize("n, direction", [(50.0, 1.0), (-50.0, 1.0), (50.0, -1.0)])
def test_gear_efficiency_branches_give_an_asymmetric_bang_bang(n, direction):
    """A motor of peak torque T_p behind a gear (N, η, rotor J): accelerating, T = (J N +
    I/(N η)) q̈; braking, the load drives the gear and T = (J N + I η/N) q̈. The fastest motion
    accelerates at a₁ = T_p/(J N + I/(N η)), brakes at a₂ = T_p/(J N + I η/N): T = v/a₁ + v/a₂
    with v = √(2 Q a₁ a₂/(a₁ + a₂)). The switch falls between grid points: the error is second
    order in the grid step."""
    j, eta, t_p, q_end = 2e-5, 0.8, 0.2, 1.5
    m = abs(n)  # a reversed gear (N < 0) or a move backwards: the same times
    a1, a2 = t_p / (j * m + INERTIA / (m * eta)), t_p / (j * m + INERTIA * eta / m)
    v = np.sqrt(2 * q_end * a1 * a2 / (a1 + a2))
    exact = v / a1 + v / a2
    model = _geared(eta, j, n, peak_torque=t_p)
    errors = []
    for grid in (100, 1000):
        traj = time_optimal(
            model, segment(direction * q_end), max_torque=np.inf, max_velocity=np.inf, grid=grid
        )
        errors.append(abs(traj.duration / exact - 1.0))
    assert errors[1] < 1e-6
    assert errors[1] < errors[0] / 20.0  # second order: 100× from 10× the grid
    speeding, braking = ("upper", "lower") if n * direction > 0 else ("lower", "upper")
    assert traj.info["active"][1] == f"motor peak torque 'j' {speeding}"
    assert traj.info["active"][-2] == f"motor peak torque 'j' {braking}"


def test_motor_envelope_speed_and_peak_respected_on_the_motor_side():
    """With friction (viscous and Coulomb) and the speed–torque envelope, the motor-side values
    recomputed by armdyn.actuators.motor_side from an independent inverse dynamics: |T| ≤
    T_peak, |T + T0 ω/ω0| ≤ T0, |ω| ≤ ω_max, and the envelope binds (its speed term is exact
    where it binds after the tangent updates)."""
    motor = ad.Motor(
        torque_constant=0.05,
        resistance=1.0,
        voltage=24.0,
        no_load_speed=400.0,
        peak_torque=0.5,
        max_speed=390.0,
    )
    model = arm(
        dict(
            gear_ratio=50.0,
            rotor_inertia=2e-5,
            efficiency=0.8,
            friction_viscous=1e-5,
            friction_coulomb=0.002,
            motor=motor,
        )
    )
    traj = time_optimal(model, segment(3.0), max_torque=np.inf, max_velocity=np.inf, grid=600)
    tau = ad.inverse_dynamics(model, traj.q, traj.qd, traj.qdd)
    side = motor_side(model.actuators[0], traj.t, traj.qd[:, 0], traj.qdd[:, 0], tau[:, 0])
    t0, w0 = motor_envelope(motor)
    envelope = np.abs(side.torque + t0 * side.speed / w0) / t0
    assert np.max(np.abs(side.torque)) <= 0.5 * (1 + 1e-6)
    assert np.max(envelope) <= 1 + 1e-6
    assert np.max(envelope) >= 1 - 1e-6
    assert np.max(np.abs(side.speed)) <= 390.0 * (1 + 1e-9)
    assert traj.info["envelope_iterations"] > 1
    assert any("envelope" in a for a in traj.info["active"])


# --- the shortest repeated cycle ---------------------------------------------------------------

N_GEAR, J_ROT, T_PEAK, Q_END, DWELL = 50.0, 2e-5, 0.2, 1.5, 0.5
ACC = T_PEAK / (J_ROT * N_GEAR + INERTIA / N_GEAR)  # η = 1: the bang-bang's |q̈|
T_FAST = 2 * np.sqrt(Q_END / ACC)


def test_shortest_cycle_rms_binds_as_in_closed_form():
    """Bang-bang at T_p/k² over k T*, nothing held in the dwell D (no gravity torque): the RMS
    torque is T_p √(T*/(k³ (k T* + D))); it meets T_c at the root k > 1 of
    T_c² T* k⁴ + T_c² D k³ − T_p² T* = 0."""
    t_c = 0.08
    model = _geared(1.0, J_ROT, N_GEAR, peak_torque=T_PEAK, continuous_torque=t_c)
    cycle = shortest_cycle(
        model,
        segment(Q_END),
        dwell=DWELL,
        max_torque=np.inf,
        max_velocity=np.inf,
        grid=500,
        tolerance=1e-7,
    )
    roots = np.roots([t_c**2 * T_FAST, t_c**2 * DWELL, 0.0, 0.0, -(T_PEAK**2) * T_FAST])
    k = max(r.real for r in roots if abs(r.imag) < 1e-12 and r.real > 0)
    assert cycle.info["time_optimal_duration"] == pytest.approx(T_FAST, rel=1e-12)
    assert cycle.info["slowdown"] == pytest.approx(k, rel=2e-7)
    assert cycle.info["binding"] == ("j", "continuous_torque")
    assert cycle.info["period"] == pytest.approx(k * T_FAST + DWELL, rel=2e-7)
    assert cycle.duration == pytest.approx(cycle.info["period"], rel=1e-12)
    np.testing.assert_array_equal(cycle.qd[-3:], 0.0)


def test_shortest_cycle_with_a_damper_binds_its_rms_by_an_independent_recomputation():
    """The geared arm of the RMS test with a joint damper (0.5 N m s/rad: up to 0.035 N m at
    the motor, against a continuous torque of 0.08): shortest_cycle accepts it, and the motor's
    RMS torque over the period, recomputed on a fine resampling of the cycle
    (Trajectory.sample, an independent inverse dynamics, armdyn.actuators.motor_side, the
    midpoint rule on 20001 points), meets the continuous torque to the grid's error: the
    sizing integrates the grid's samples, first order here (measured: +1.5e-3, +8.4e-4 at
    1000, 2000 intervals); without the damper's torque the same cycle's RMS is 2 % lower (the
    damper counts)."""
    t_c, damping = 0.08, 0.5
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("link", MASS, [0.01, I_C, I_C], position=(ARM, 0.0, 0.0))
    b.add_revolute("j", "ground", "link", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_joint_spring_damper("j", damping=damping)
    b.add_actuator(
        "j",
        gear_ratio=N_GEAR,
        rotor_inertia=J_ROT,
        efficiency=1.0,
        motor=ad.Motor(peak_torque=T_PEAK, continuous_torque=t_c),
    )
    model = b.finalize()
    errors = []
    for grid in (1000, 2000):
        cycle = shortest_cycle(
            model, segment(Q_END), dwell=DWELL, max_torque=np.inf, max_velocity=np.inf, grid=grid
        )
        assert cycle.info["binding"] == ("j", "continuous_torque")
        motion = cycle.info["motion_duration"]
        t = (np.arange(20001) + 0.5) * motion / 20001
        _, q, qd, qdd = cycle.sample(t)
        tau = ad.inverse_dynamics(model, q, qd, qdd)
        side = motor_side(model.actuators[0], t, qd[:, 0], qdd[:, 0], tau[:, 0])
        rms = np.sqrt(np.sum(side.torque**2) * (motion / 20001) / cycle.info["period"])
        errors.append(rms / t_c - 1.0)
    assert abs(errors[1]) < 1e-3
    assert 1.6 < errors[0] / errors[1] < 2.4
    # the same without the damper's torque: clearly below the limit
    bare = motor_side(model.actuators[0], t, qd[:, 0], qdd[:, 0], tau[:, 0] - damping * qd[:, 0])
    rms_bare = np.sqrt(np.sum(bare.torque**2) * (motion / 20001) / cycle.info["period"])
    assert rms_bare < t_c * (1 - 1e-2)


def test_shortest_cycle_winding_temperature_binds_as_in_closed_form():
    """One-node winding (R_th, τ_th), the copper's resistance constant (coefficient 0): the loss
    is P = R (T_p/(k² k_t))² during the motion (k T*), 0 in the dwell; the periodic peak rise
    R_th P (1 − e^{−k T*/τ_th}) / (1 − e^{−(k T* + D)/τ_th}) meets T_max − T_ambient."""
    from scipy.optimize import brentq

    k_t, r, r_th, tau_th, t_max = 0.05, 1.2, 3.0, 5.0, 60.0
    model = _geared(
        1.0,
        J_ROT,
        N_GEAR,
        peak_torque=T_PEAK,
        torque_constant=k_t,
        resistance=r,
        thermal_resistance=r_th,
        thermal_time_constant=tau_th,
        max_winding_temperature=t_max,
    )
    options = SizingOptions(ambient_temperature=40.0, copper_temperature_coefficient=0.0)

    def rise(k):
        p = r * (T_PEAK / (k * k * k_t)) ** 2
        tm = k * T_FAST
        return r_th * p * -np.expm1(-tm / tau_th) / -np.expm1(-(tm + DWELL) / tau_th)

    assert rise(1.0) > t_max - 40.0  # the time-optimal cycle overheats
    k = brentq(lambda k: rise(k) - (t_max - 40.0), 1.0, 10.0, xtol=1e-14)
    cycle = shortest_cycle(
        model,
        segment(Q_END),
        dwell=DWELL,
        max_torque=np.inf,
        max_velocity=np.inf,
        grid=500,
        options=options,
        tolerance=1e-7,
    )
    assert cycle.info["slowdown"] == pytest.approx(k, rel=2e-7)
    assert cycle.info["binding"] == ("j", "winding_temperature")


def test_shortest_cycle_is_the_time_optimal_one_when_the_thermal_limits_are_loose():
    """η = 0.8: the arrival brakes through the gear's regenerating branch; the cycle's samples
    keep it (a sample at rest with the braking torque would take the motoring branch and exceed
    the peak by 1/η²)."""
    model = _geared(0.8, J_ROT, N_GEAR, peak_torque=T_PEAK, continuous_torque=1.0)
    cycle = shortest_cycle(
        model, segment(Q_END), dwell=DWELL, max_torque=np.inf, max_velocity=np.inf, grid=200
    )
    assert cycle.info["slowdown"] == 1.0
    assert cycle.info["binding"] == ("j", "peak_torque")
    assert cycle.info["margins"][("j", "peak_torque")] == pytest.approx(1.0, rel=1e-9)


def test_shortest_cycle_limited_by_a_joint_limit_has_no_motor_binding():
    """A joint torque limit (0.5 N m) below what the motor gives: the time-optimal cycle is the
    shortest, no motor check binds (binding None), every motor margin above 1."""
    model = _geared(0.8, J_ROT, N_GEAR, peak_torque=T_PEAK, continuous_torque=1.0)
    cycle = shortest_cycle(
        model, segment(Q_END), dwell=DWELL, max_torque=0.5, max_velocity=np.inf, grid=200
    )
    assert cycle.info["slowdown"] == 1.0 and cycle.info["binding"] is None
    assert np.nanmin(list(cycle.info["margins"].values())) > 1.0 + 1e-6
    assert cycle.info["time_optimal_duration"] == pytest.approx(
        2 * np.sqrt(Q_END * (INERTIA + N_GEAR**2 * J_ROT) / 0.5), rel=1e-12
    )


def test_shortest_cycle_that_cannot_hold_in_the_dwell_names_the_check():
    """A lifted link held in the dwell: its holding current alone overheats the winding, so no
    slowdown helps: SolverError naming the check."""
    model = arm(
        dict(
            gear_ratio=20.0,
            rotor_inertia=1e-5,
            efficiency=1.0,
            motor=ad.Motor(
                peak_torque=5.0,
                torque_constant=0.05,
                resistance=2.0,
                thermal_resistance=5.0,
                thermal_time_constant=10.0,
                max_winding_temperature=60.0,
            ),
        ),
        axis=(0, 1, 0),
    )
    with pytest.raises(ad.SolverError, match="winding_temperature"):
        shortest_cycle(
            model, segment(-0.5), dwell=20.0, max_velocity=np.inf, grid=100, max_slowdown=8.0
        )


# --- infeasible paths and hostile inputs -----------------------------------------------------


def test_static_torque_above_the_limit_is_infeasible_and_named():
    """The link lifted about y, starting horizontal (holding torque m g L = 9.81 N m) with a
    limit of 8 N m: it cannot even start."""
    model = arm(axis=(0, 1, 0))
    with pytest.raises(ad.SolverError, match=r"s = 0 .*torque 'j' at rest is -?9\.81, .*±8"):
        time_optimal(model, segment(-1.0), max_torque=8.0, grid=100)


def test_an_end_pose_that_cannot_be_held_is_infeasible_and_named():
    """Swinging up through horizontal (9.81 N m to hold there, above the 8 N m limit) is
    possible with momentum, but the poses near the end cannot be held (m g L cos q: 8.61 N m
    at q = 0.5, 8.70 N m at the grid point before): named there."""
    model = arm(axis=(0, 1, 0))
    with pytest.raises(ad.SolverError, match=r"s = 0\.99 .*torque 'j' at rest is -?8\.70"):
        time_optimal(model, segment(0.5, -np.pi / 2 + 0.1), max_torque=8.0, grid=100)


def test_holding_at_the_end_takes_the_motoring_branch_of_the_gear():
    """Lifting the link to horizontal through a gear of η = 0.5: holding it there at rest takes
    m g L / (N η) = 0.3924 N m from the motor (the gear drives the load: motoring, whatever the
    sign), above the 0.9 × that peak torque, though the gear's other branch (m g L η / N) would
    fit: infeasible, named at the end."""
    n, eta = 50.0, 0.5
    hold = MASS * 9.81 * ARM / (n * eta)
    model = arm(
        dict(
            gear_ratio=n, rotor_inertia=1e-5, efficiency=eta, motor=ad.Motor(peak_torque=0.9 * hold)
        ),
        axis=(0, 1, 0),
    )
    with pytest.raises(ad.SolverError, match=r"s = 1 .*motor peak torque 'j' at rest is -?0\.3924"):
        time_optimal(model, segment(0.0, -1.2), max_velocity=np.inf, max_torque=np.inf, grid=100)
    # with the peak above the hold, the motion is feasible and the end sample holds within it
    model = arm(
        dict(
            gear_ratio=n, rotor_inertia=1e-5, efficiency=eta, motor=ad.Motor(peak_torque=1.1 * hold)
        ),
        axis=(0, 1, 0),
    )
    traj = time_optimal(model, segment(0.0, -1.2), max_velocity=np.inf, max_torque=np.inf, grid=100)
    tau = ad.inverse_dynamics(model, traj.q, traj.qd, traj.qdd)
    side = motor_side(model.actuators[0], traj.t, traj.qd[:, 0], traj.qdd[:, 0], tau[:, 0])
    assert np.max(np.abs(side.torque)) <= 1.1 * hold * (1 + 1e-6)
    assert abs(side.torque[-1]) == pytest.approx(hold, rel=1e-9)


def test_ur5_static_torque_above_the_limit_names_the_joint(ur5, ur5_path):
    q0 = UR5_WAYPOINTS[0]
    hold = ad.inverse_dynamics(ur5, q0, np.zeros(6), np.zeros(6))
    limit = UR5_TORQUE.copy()
    limit[1] = 0.5 * abs(hold[1])
    with pytest.raises(ad.SolverError, match=r"torque 'shoulder_lift_joint' at rest"):
        time_optimal(ur5, ur5_path, max_torque=limit, grid=100)


def _bad_evaluator(s):
    q = np.zeros((len(s), 1))
    return q, q + np.nan, q


BAD = [
    ("max_torque NaN", dict(max_torque=np.nan), r"max_torque\[0\]"),
    ("max_torque negative", dict(max_torque=-1.0), r"max_torque\[0\] \(joint 'j'\)"),
    ("max_torque zero", dict(max_torque=0.0), r"max_torque\[0\]"),
    ("max_velocity shape", dict(max_velocity=[1.0, 2.0]), r"max_velocity must be .* one per"),
    ("max_acceleration text", dict(max_acceleration="fast"), r"max_acceleration"),
    ("grid 1", dict(grid=1), r"grid must be"),
    ("grid bool", dict(grid=True), r"grid"),
    ("grid huge", dict(grid=10**9), r"grid must be"),
    ("grid not to 1", dict(grid=[0.0, 0.5, 0.9]), r"grid must be"),
    ("grid decreasing", dict(grid=[0.0, 0.6, 0.5, 1.0]), r"strictly increasing \(grid\[2\]\)"),
    ("grid NaN", dict(grid=[0.0, np.nan, 1.0]), r"grid\[1\]"),
    ("motors text", dict(motors="yes"), r"motors must be True or False"),
]


@pytest.mark.parametrize("case", BAD, ids=[c[0] for c in BAD])
def test_hostile_arguments(case):
    _, kwargs, pattern = case
    with pytest.raises(ad.ModelError, match=pattern):
        time_optimal(arm(), segment(1.0), **{"max_torque": 3.0, **kwargs})


def test_hostile_paths_and_models(ur5_path):
    model = arm()
    with pytest.raises(ad.ModelError, match=r"path must be an armdyn\.motion\.Path"):
        time_optimal(model, np.zeros((2, 1)))
    with pytest.raises(ad.ModelError, match="the path has 6 joints, the model 1"):
        time_optimal(model, ur5_path)
    with pytest.raises(ad.ModelError, match=r"the path's joints \['k'\] are not the model's"):
        time_optimal(model, Path([0.0, 1.0], [[0.0], [1.0]], names=["k"]))
    with pytest.raises(ad.ModelError, match="does not move"):
        time_optimal(model, Path([0.0, 1.0], [[0.2], [0.2]]), max_torque=1.0)
    with pytest.raises(ad.ModelError, match=r"the path's dq/ds\[0, 0\]"):
        time_optimal(model, Path([0.0, 1.0], [[0.0], [1.0]], evaluate=_bad_evaluator))
    with pytest.raises(ad.ModelError, match="overflows at s = 0"):
        time_optimal(model, Path([0.0, 1.0], [[0.0], [1e200]]), max_torque=1.0)
    with pytest.raises(ad.ModelError, match="nothing limits the path speed"):
        time_optimal(model, segment(1.0), max_torque=np.inf, max_velocity=np.inf)
    floating = ad.ModelBuilder()
    floating.add_body("b", 1.0, [0.1, 0.1, 0.1])
    floating.add_free("f", "b")
    with pytest.raises(ad.ModelError, match="fixed-base"):
        time_optimal(floating.finalize(), segment(1.0))


@pytest.mark.parametrize(
    "kwargs, pattern",
    [
        (dict(dwell=-1.0), "dwell"),
        (dict(dwell=np.nan), "dwell"),
        (dict(dwell=1.0, tolerance=0.0), "tolerance"),
        (dict(dwell=1.0, max_slowdown=1.0), "max_slowdown"),
    ],
)
def test_shortest_cycle_hostile_arguments(kwargs, pattern):
    model = _geared(1.0, J_ROT, N_GEAR, peak_torque=T_PEAK, continuous_torque=0.1)
    with pytest.raises(ad.ModelError, match=pattern):
        shortest_cycle(model, segment(1.0), **kwargs)


def test_shortest_cycle_needs_a_motor():
    with pytest.raises(ad.ModelError, match="no actuator with a motor"):
        shortest_cycle(arm(), segment(1.0), dwell=1.0, max_torque=1.0)
