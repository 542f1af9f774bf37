"""armdyn.motion.least_energy: the least-copper-loss (or least-squared-torque) rest-to-rest
motion in a given time under joint and motor limits.

References independent of the implementation: closed-form optima of a free inertia (the cubic
for ∫ τ² dt; with a lossy gear, the optimum whose k(t) T(t) is linear in t), the motor-side
values of armdyn.actuators.motor_side and armdyn.inverse_dynamics on fine grids of the returned
motion's exact evaluator, and central finite differences of the solver's own cost and limits
for its analytic gradient.
"""

import armdyn as ad
import numpy as np
import pytest
from armdyn.actuators import motor_side
from armdyn.motion import Trajectory, least_energy
from armdyn.motion import energy as en
from armdyn.sizing.motor import motor_envelope, speed_limit
from scipy.integrate import quad

from benchmarks.least_energy import PICK, PLACE

# --- models ------------------------------------------------------------------------------------


def _disc(actuator=None, gravity=(0.0, 0.0, -9.81)):
    """A free inertia: a disc of axial inertia 0.5 kg m² on a vertical hinge (gravity along
    the axis does no work), optionally geared."""
    b = ad.ModelBuilder(gravity=gravity)
    b.add_body("disc", 2.0, np.diag([0.3, 0.3, 0.5]), position=(0.0, 0.0, 0.2))
    b.add_revolute("spin", "ground", "disc", (0, 0, 0), (0, 0, 1))
    if actuator:
        b.add_actuator("spin", **actuator)
    return b.finalize()


def _ur5(friction=False):
    """The UR5 with a 3 kg payload and the example catalog's drivetrains on every joint
    (benchmarks.least_energy.ur5_actuated, the example's model)."""
    from benchmarks.least_energy import ur5_actuated

    model = ur5_actuated(friction=friction)
    if model is None:
        pytest.skip("example-robot-data is not installed")
    return model


@pytest.fixture(scope="module")
def ur5():
    return _ur5()


@pytest.fixture(scope="module")
def pick_and_place(ur5):
    """The pick-to-place swing (1.6 rad about the base, wrist following) in 1.45 s: the
    quintic of that time is within every joint and motor limit (its pan speed 2.07 rad/s, the
    motor's 210 rad/s through 100:1 allow 2.1)."""
    return least_energy(ur5, PICK, PLACE, 1.45)


# --- independent evaluation --------------------------------------------------------------------


def _motion(traj, t=None):
    """(q, qd, qdd) of a trajectory, at times ``t`` (its exact evaluator) or its samples."""
    out = traj if t is None else traj.sample(t)
    return out.q, out.qd, out.qdd


def _quintic(start, goal, duration, t):
    u = t / duration
    d = np.asarray(goal) - np.asarray(start)
    s = 10 * u**3 - 15 * u**4 + 6 * u**5
    sd = (30 * u**2 - 60 * u**3 + 30 * u**4) / duration
    sdd = (60 * u - 180 * u**2 + 120 * u**3) / duration**2
    return start + np.outer(s, d), np.outer(sd, d), np.outer(sdd, d)


def _motor_sides(model, t, q, qd, qdd):
    """{joint: MotorSide} by armdyn.actuators.motor_side from armdyn.inverse_dynamics."""
    tau = ad.inverse_dynamics(model, q, qd, qdd)
    return tau, {
        a.joint: motor_side(a, t, qd[:, a.dof], qdd[:, a.dof], tau[:, a.dof])
        for a in model.actuators
    }


def _copper(model, t, q, qd, qdd):
    _, sides = _motor_sides(model, t, q, qd, qdd)
    return sum(s.integral("loss_copper") for s in sides.values())


def _assert_within_limits(model, t, q, qd, qdd, max_velocity=None, max_torque=None):
    """Every limit least_energy enforces, checked on the given samples from the model, the
    datasheets and motor_side: |x| <= limit (no tolerance)."""
    lo, hi = np.asarray(model.coord_lower), np.asarray(model.coord_upper)
    assert np.all(q >= lo) and np.all(q <= hi)
    v = np.asarray(model.coord_velocity_limit if max_velocity is None else max_velocity)
    assert np.all(np.abs(qd) <= v), np.max(np.abs(qd) / v)
    tau, sides = _motor_sides(model, t, q, qd, qdd)
    e = np.asarray(model.coord_effort_limit if max_torque is None else max_torque)
    assert np.all(np.abs(tau) <= e), np.max(np.abs(tau) / e)
    for a in model.actuators:
        s, m = sides[a.joint], a.motor
        assert np.all(np.abs(s.speed) <= speed_limit(m.max_speed, m.no_load_speed)[0]), a.joint
        assert np.all(np.abs(s.torque) <= m.peak_torque), a.joint
        t0, w0 = motor_envelope(m)
        # motor_side takes the holding (motoring) branch at q̇ = 0; least_energy at the rest
        # ends takes the limit from inside the move: compare away from the two end samples
        inner = slice(1, -1)
        assert np.all(np.abs(s.torque + t0 * s.speed / w0)[inner] <= t0), a.joint


# --- the target --------------------------------------------------------------------------------


def test_ur5_pick_and_place_needs_at_least_20_percent_less_copper_than_the_quintic(
    ur5, pick_and_place
):
    """Copper loss ∫ Σ R i² dt of the least-energy motion and of the quintic move of the same
    1.45 s, both evaluated independently (motor_side on 20,001 samples of the exact motion):
    at least 20 % less, as the solver's own info reports; both within every limit."""
    traj = pick_and_place
    t = np.linspace(0.0, 1.45, 20001)
    q, qd, qdd = _motion(traj, t)
    quintic = _quintic(PICK, PLACE, 1.45, t)
    ours, theirs = _copper(ur5, t, q, qd, qdd), _copper(ur5, t, *quintic)
    assert ours <= 0.8 * theirs
    assert traj.info["saving_percent"] >= 20.0
    np.testing.assert_allclose(traj.info["value"], ours, rtol=1e-3)
    np.testing.assert_allclose(traj.info["baseline"], theirs, rtol=1e-3)
    _assert_within_limits(ur5, t, q, qd, qdd)
    _assert_within_limits(ur5, t, *quintic)
    assert traj.info["converged"] and traj.info["objective"] == "copper"


def test_the_result_is_a_rest_to_rest_trajectory_with_an_exact_evaluator(ur5, pick_and_place):
    traj = pick_and_place
    assert isinstance(traj, Trajectory) and traj.info["method"] == "least_energy"
    assert traj.t[0] == 0.0 and traj.t[-1] == pytest.approx(1.45, rel=1e-15)
    np.testing.assert_allclose(traj.q[0], PICK, atol=1e-14)
    np.testing.assert_allclose(traj.q[-1], PLACE, atol=1e-14)
    np.testing.assert_allclose(traj.qd[[0, -1]], 0.0, atol=1e-13)
    again = traj.sample(traj.t)
    for a, b in zip((again.q, again.qd, again.qdd), (traj.q, traj.qd, traj.qdd), strict=True):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)
    # the exact evaluator's rates are the derivatives of its positions
    t = np.linspace(0.1, 1.3, 7)
    h = 1e-6
    qp, qm = traj.sample(t + h).q, traj.sample(t - h).q
    np.testing.assert_allclose((qp - qm) / (2 * h), traj.sample(t).qd, atol=1e-7)
    # what the sizing takes: a run, and a duty cycle (it ends at rest: q̇ = 0, with the free
    # end acceleration's step in torque when the hold begins)
    cycle = ad.duty_cycle(ur5, tuple(traj), dwell=0.5)
    assert cycle.dwell == 0.5
    run = ad.trajectory_run(ur5, traj)
    np.testing.assert_allclose(
        run.joint_torques, ad.inverse_dynamics(ur5, *_motion(traj)), atol=1e-9
    )


# --- the limits --------------------------------------------------------------------------------


def test_speed_and_torque_limits_bind_and_hold_where_the_quintic_exceeds_them(ur5):
    """With the pan joint limited to 1.45 rad/s (the quintic needs 2.07) and to 85 % of the
    quintic's peak pan torque, the least-energy motion keeps every limit, checked on 8,001
    samples by inverse_dynamics and motor_side, and reports both limits active."""
    v = np.asarray(ur5.coord_velocity_limit, dtype=float).copy()
    e = np.asarray(ur5.coord_effort_limit, dtype=float).copy()
    t = np.linspace(0.0, 1.45, 8001)
    tau_quintic = ad.inverse_dynamics(ur5, *_quintic(PICK, PLACE, 1.45, t))
    v[0], e[0] = 1.45, 0.85 * np.max(np.abs(tau_quintic[:, 0]))
    traj = least_energy(ur5, PICK, PLACE, 1.45, max_velocity=v, max_torque=e, samples=51)
    _assert_within_limits(ur5, t, *_motion(traj, t), max_velocity=v, max_torque=e)
    base = traj.info["baseline_limit_usage"]
    assert base["speed"]["shoulder_pan_joint"] > 1.4 and base["torque"]["shoulder_pan_joint"] > 1.1
    active = {(k, j) for k, j, _ in traj.info["active_limits"]}
    assert {("speed", "shoulder_pan_joint"), ("torque", "shoulder_pan_joint")} <= active
    for limit in ("speed", "torque"):
        assert 0.99 <= traj.info["limit_usage"][limit]["shoulder_pan_joint"] <= 1.0
    assert traj.info["saving_percent"] > 20.0


def test_a_robot_without_motor_data_minimises_its_squared_joint_torques():
    """The bare UR5 (no actuators): rms_torque's ∫ Σ τ² dt, evaluated independently by
    Gauss–Legendre on inverse_dynamics of the exact motion, below the quintic's, and each
    joint's RMS torque as info reports it; the URDF's position, speed and effort limits kept
    (several bind: the elbow folds and swings at its speed limit)."""
    from benchmarks import common

    path = common.robot_urdf("ur5")
    if path is None:
        pytest.skip("example-robot-data is not installed")
    model = ad.load_urdf(path)
    traj = least_energy(model, PICK, PLACE, 1.45, objective="rms_torque")
    x, w = np.polynomial.legendre.leggauss(80)
    t = (x + 1.0) * 1.45 / 2
    squares = w * 1.45 / 2 @ ad.inverse_dynamics(model, *_motion(traj, t)) ** 2
    quintic = w * 1.45 / 2 @ ad.inverse_dynamics(model, *_quintic(PICK, PLACE, 1.45, t)) ** 2
    assert squares.sum() < 0.8 * quintic.sum()
    np.testing.assert_allclose(traj.info["value"], squares.sum(), rtol=1e-6)
    np.testing.assert_allclose(traj.info["baseline"], quintic.sum(), rtol=1e-6)
    # per joint, Simpson's rule on the 801-sample check grid (the end steps in torque cost it
    # the fourth order there)
    rms = np.array(list(traj.info["per_joint"].values()))
    np.testing.assert_allclose(rms, np.sqrt(squares / 1.45), rtol=1e-5)
    _assert_within_limits(
        model, np.linspace(0.0, 1.45, 4001), *_motion(traj, np.linspace(0.0, 1.45, 4001))
    )
    assert np.isnan(traj.info["limit_usage"]["motor_peak_torque"]["elbow_joint"])


def test_an_infeasible_time_is_a_solver_error_naming_the_limit():
    """A free inertia I = 0.5 kg m² moved 1.2 rad with |τ| <= 1 N m needs at least the
    bang-bang time 2 sqrt(D I / τ) = 1.55 s: in 1 s no motion exists."""
    model = _disc()
    with pytest.raises(ad.SolverError, match=r"least_energy: no motion within the limits.*"):
        least_energy(model, [0.0], [1.2], 1.0, objective="rms_torque", max_torque=1.0)
    # above the bang-bang time it is found, within the limit
    traj = least_energy(model, [0.0], [1.2], 1.8, objective="rms_torque", max_torque=1.0)
    t = np.linspace(0.0, 1.8, 4001)
    tau = ad.inverse_dynamics(model, *_motion(traj, t))
    assert np.max(np.abs(tau)) <= 1.0


# --- closed forms ------------------------------------------------------------------------------


def _gauss_cost(model, traj, duration, torque=lambda tau, qd, qdd: tau, nodes=60):
    """∫ x² dt of the returned motion by Gauss–Legendre on its exact evaluator (x a function of
    the joint torque, rate and acceleration)."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    t = (x + 1.0) * duration / 2
    q, qd, qdd = _motion(traj, t)
    tau = ad.inverse_dynamics(model, q, qd, qdd)
    return float(w * duration / 2 @ torque(tau, qd, qdd)[:, 0] ** 2)


def test_a_free_inertia_takes_the_cubic_for_least_squared_torque():
    """min ∫ τ² dt, τ = I q̈, rest to rest over D in T: the Euler–Lagrange equation q'''' = 0
    with q, q̇ given at both ends: the cubic q = D (3u² − 2u³), τ linear in t, ∫ τ² dt =
    12 I² D² / T³ (the quintic's 120/7 instead of 12: 30 % more)."""
    model = _disc()
    d, duration, inertia = 1.2, 0.8, 0.5
    traj = least_energy(model, [0.0], [d], duration, objective="rms_torque")
    t = np.linspace(0.0, duration, 1001)
    u = t / duration
    q, qd, qdd = _motion(traj, t)
    np.testing.assert_allclose(q[:, 0], d * (3 * u**2 - 2 * u**3), rtol=0, atol=1e-6 * d)
    np.testing.assert_allclose(qd[:, 0], d * (6 * u - 6 * u**2) / duration, atol=1e-5)
    np.testing.assert_allclose(qdd[:, 0], d * (6 - 12 * u) / duration**2, atol=1e-4 * qdd[0, 0])
    closed = 12 * inertia**2 * d**2 / duration**3
    cost = _gauss_cost(model, traj, duration)
    assert closed * (1 - 1e-12) <= cost <= closed * (1 + 1e-7)
    np.testing.assert_allclose(traj.info["value"], closed, rtol=1e-7)
    np.testing.assert_allclose(traj.info["baseline"], inertia**2 * d**2 * 120 / 7 / duration**3)
    assert traj.info["saving_percent"] == pytest.approx(30.0, abs=1e-4)


def _lossy_optimum(inertia, n, j, eta, k_t, r, d, duration):
    """min ∫ R (T / k_t)² dt of the geared free inertia: T = k q̈ with k₁ = J N + I / (N η)
    while accelerating (the motor drives the load) and k₂ = J N + I η / N while braking. The
    cost is convex in q̈ (two parabolas k² q̈² meeting at 0), so its optimum makes
    d(k² q̈²)/dq̈ = 2 k T affine in t: k T = β (t_s − t), q̈ = β (t_s − t) / k²; rest at T gives
    t_s / k₁ = (T − t_s) / k₂, q(T) = D gives β; cost R/k_t² β² (t_s³/k₁² + (T−t_s)³/k₂²) / 3."""
    k1, k2 = j * n + inertia / (n * eta), j * n + inertia * eta / n
    ts = duration * k1 / (k1 + k2)
    unit = quad(
        lambda t: (duration - t) * (ts - t) / (k1**2 if t < ts else k2**2),
        0.0,
        duration,
        points=[ts],
    )[0]
    beta = d / unit
    return r / k_t**2 * beta**2 * (ts**3 / k1**2 + (duration - ts) ** 3 / k2**2) / 3


@pytest.mark.parametrize("eta", [1.0, 0.7])
def test_a_geared_free_inertia_reaches_the_closed_form_least_copper_loss(eta):
    """Copper loss through a 50:1 gear of efficiency η (motor k_t 0.05 N m/A, R 1.2 Ω, rotor
    2e-5 kg m²), evaluated independently by motor_side on 40,001 samples: at η = 1 the cubic
    (k₁ = k₂), to 1e-7; at η = 0.7 the optimum's q̈ has a slope jump at t_s that a quintic
    spline without a knot there approaches from above (within 5e-4 with 12 knots)."""
    n, j, k_t, r, d, duration = 50.0, 2e-5, 0.05, 1.2, 1.2, 0.8
    motor = ad.Motor(torque_constant=k_t, resistance=r)
    model = _disc(dict(gear_ratio=n, rotor_inertia=j, efficiency=eta, motor=motor))
    traj = least_energy(model, [0.0], [d], duration, knots=12)
    closed = _lossy_optimum(0.5, n, j, eta, k_t, r, d, duration)
    t = np.linspace(0.0, duration, 40001)
    cost = _copper(model, t, *_motion(traj, t))
    if eta == 1.0:
        np.testing.assert_allclose(cost, closed, rtol=1e-7)
        np.testing.assert_allclose(traj.info["value"], closed, rtol=1e-7)
    else:
        assert closed <= cost <= closed * (1 + 5e-4)
        assert closed <= traj.info["value"] <= closed * (1 + 5e-4)


def test_zero_end_acceleration_starts_and_ends_smoothly_at_a_cost():
    """end_acceleration="zero": q̈ = 0 at both ends; a subset of the free motions, so its cost
    lies between the free optimum (the cubic's 12) and the quintic's (120/7)."""
    model = _disc()
    free = least_energy(model, [0.0], [1.2], 0.8, objective="rms_torque")
    zero = least_energy(model, [0.0], [1.2], 0.8, objective="rms_torque", end_acceleration="zero")
    np.testing.assert_allclose(zero.qdd[[0, -1]], 0.0, atol=1e-12)
    assert abs(free.qdd[0, 0]) > 1.0
    assert free.info["value"] < zero.info["value"] < zero.info["baseline"]


# --- the gradient ------------------------------------------------------------------------------


def _problem(model, start, goal, duration, samples=21, **kw):
    options = dict(
        objective="copper",
        knots=4,
        samples=samples,
        end_acceleration="free",
        max_velocity=None,
        max_torque=None,
        motors=True,
        weights=None,
        margin=1e-3,
        check_factor=8,
        max_iterations=100,
        tol=1e-8,
    )
    options.update(kw)
    problem, _ = en._setup(model, start, goal, duration, **options)
    u = np.linspace(0.0, 1.0, samples)
    problem.set_grid(u, en._simpson(u, duration))
    return problem


@pytest.mark.parametrize("friction", [False, True], ids=["frictionless", "rotor friction"])
@pytest.mark.parametrize("objective", ["copper", "rms_torque"])
def test_the_cost_and_limit_gradients_equal_finite_differences(objective, friction):
    """The analytic gradient (chain rule through inverse_dynamics_derivatives and the mass
    matrix, the gear's branch and the rotor's viscous and Coulomb friction) against central
    differences of the cost and of the limits, on the actuated UR5 at a random correction."""
    model = _ur5(friction=friction)
    problem = _problem(model, PICK, PLACE, 1.45, objective=objective)
    if friction:
        try:
            problem.state(np.zeros(problem.n * problem.k))
        except ad.ModelError as err:
            if "force elements have no derivatives yet" not in str(err):
                raise
            pytest.skip("the rotor friction's derivatives come with i34-forcederiv")
    rng = np.random.default_rng(3)
    p = 0.05 * rng.standard_normal(problem.n * problem.k)
    grad = problem.gradient(p)
    jac = problem.constraints(p, 1e-3, jacobian=True)
    h = 1e-6
    fd = np.empty_like(grad)
    fd_jac = np.empty_like(jac)
    for i in range(p.size):
        e = np.zeros_like(p)
        e[i] = h
        fd[i] = (problem.value(p + e) - problem.value(p - e)) / (2 * h)
        fd_jac[:, i] = (problem.constraints(p + e, 1e-3) - problem.constraints(p - e, 1e-3)) / (
            2 * h
        )
    # central differences of step 1e-6: truncation ~1e-12, round-off ~1e-10 of the largest
    np.testing.assert_allclose(grad, fd, rtol=1e-7, atol=1e-8 * np.max(np.abs(fd)))
    np.testing.assert_allclose(fd_jac, jac, rtol=1e-7, atol=1e-8 * np.max(np.abs(jac)))


# --- hostile inputs ----------------------------------------------------------------------------


def _copper_disc():
    motor = ad.Motor(torque_constant=0.05, resistance=1.2)
    return _disc(dict(gear_ratio=50.0, rotor_inertia=2e-5, efficiency=0.8, motor=motor))


BAD = [
    (dict(start=[np.nan]), r"start\[0\] = .*nan.* is not finite"),
    (dict(start=[0.0, 1.0]), r"start must have shape \(1,\)"),
    (dict(goal=[[1.0]]), r"goal must have shape \(1,\)"),
    (dict(goal=["a"]), "goal must hold real numbers"),
    (dict(duration=0.0), "duration must be a positive number"),
    (dict(duration=-1.0), "duration must be a positive number"),
    (dict(duration=np.inf), "duration must be a positive number"),
    (dict(duration=np.nan), "duration must be a positive number"),
    (dict(duration="1"), "duration must be a positive number"),
    (dict(objective="energy"), "objective must be 'copper' or 'rms_torque'"),
    (dict(knots=-1), "knots must be an integer in"),
    (dict(knots=2.5), "knots must be an integer in"),
    (dict(knots=10**9), "knots must be an integer in"),
    (dict(samples=5), "samples must be an integer in"),
    (dict(samples=100), "samples must be odd"),
    (dict(samples=10**12), "samples must be an integer in"),
    (dict(samples=20001, check_factor=100), "samples \\* check_factor = .* exceeds"),
    (
        dict(samples=9999, knots=200, check_factor=2),
        r"samples \* joints \* unknowns = 9999 \* 1 \* 202 exceeds",
    ),
    (dict(duration=1e-200), "the quintic move's cost is not finite"),
    (dict(goal=[1e300]), "the quintic move's cost is not finite"),
    (dict(end_acceleration="jerk"), "end_acceleration must be 'free' or 'zero'"),
    (dict(end_acceleration="zero", knots=0), "knots must be >= 1"),
    (dict(max_velocity=0.0), r"max_velocity\[0\] = 0 \(joint 'spin'\) must be > 0"),
    (dict(max_velocity=[np.nan]), r"max_velocity\[0\] = nan \(joint 'spin'\)"),
    (dict(max_torque=[1.0, 2.0]), r"max_torque must be a number or shape \(1,\)"),
    (dict(max_torque=-3.0), r"max_torque\[0\] = -3 \(joint 'spin'\) must be > 0"),
    (dict(weights=[0.0]), r"weights\[0\] = 0 \(joint 'spin'\) must be > 0"),
    (dict(motors=1), "motors must be True or False"),
    (dict(margin=0.5), r"margin must be a number in \[0, 0.49\]"),
    (dict(check_factor=1), "check_factor must be an integer in"),
    (dict(max_iterations=0), "max_iterations must be an integer in"),
    (dict(tol=0.0), "tol must be a number in"),
]


@pytest.mark.parametrize(("change", "message"), BAD, ids=[m for _, m in BAD])
def test_bad_arguments_are_model_errors_naming_them(change, message):
    args = dict(model=_copper_disc(), start=[0.0], goal=[1.0], duration=1.0)
    args.update(change)
    with pytest.raises(ad.ModelError, match=message):
        least_energy(**args)


def test_bad_models_and_configurations_are_named():
    with pytest.raises(ad.ModelError, match=r"model must be an armdyn\.Model"):
        least_energy("ur5", [0.0], [1.0], 1.0)
    # copper needs motor data on every joint
    with pytest.raises(ad.ModelError, match=r"joint 'spin' has none.*rms_torque"):
        least_energy(_disc(), [0.0], [1.0], 1.0)
    no_resistance = _disc(
        dict(gear_ratio=50.0, rotor_inertia=2e-5, motor=ad.Motor(torque_constant=0.05))
    )
    with pytest.raises(ad.ModelError, match="joint 'spin' has none"):
        least_energy(no_resistance, [0.0], [1.0], 1.0)
    # a floating base
    b = ad.ModelBuilder()
    b.add_body("box", 1.0, np.eye(3) * 0.01)
    b.add_free("float", "box")
    with pytest.raises(ad.ModelError, match="as many coordinates as rates"):
        least_energy(b.finalize(), np.zeros(7), np.zeros(7), 1.0, objective="rms_torque")
    # outside the position limits
    b = ad.ModelBuilder()
    b.add_body("link", 1.0, np.eye(3) * 0.01, position=(0.3, 0, 0))
    b.add_revolute("hinge", "ground", "link", (0, 0, 0), (0, 0, 1))
    b.set_joint_limits("hinge", -1.0, 1.0)
    limited = b.finalize()
    with pytest.raises(ad.ModelError, match=r"goal\[0\] = 2 is outside joint 'hinge'"):
        least_energy(limited, [0.0], [2.0], 1.0, objective="rms_torque")
