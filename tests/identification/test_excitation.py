"""Excitation design: finite Fourier series within the limits, minimising the base regressor's
condition number (issue 35)."""

import armdyn as ad
import numpy as np
import pytest
from armdyn.identification import (
    Excitation,
    base_parameters,
    fourier_excitation,
    fourier_series,
    random_fourier,
)

from benchmarks import common

ROBOTS = common.robots_dir()
needs_robots = pytest.mark.skipif(ROBOTS is None, reason="example-robot-data not installed")

# small designs keep each test in seconds: 3 harmonics, 40 samples a period, one start
SMALL = {"harmonics": 3, "samples": 40}
TORQUES = np.array([150.0, 80.0, 40.0, 12.0, 12.0, 12.0])  # tighter than the UR5's: binding


def _ur5():
    return ad.load_urdf(str(ROBOTS / "ur_description/urdf/ur5_robot.urdf"))


@pytest.fixture(scope="module")
def ur5_design():
    model = _ur5()
    base = base_parameters(model)
    design = fourier_excitation(
        model, base=base, max_torque=TORQUES, maxiter=40, starts=1, seed=0, **SMALL
    )
    return model, base, design


def test_fourier_series_closed_form_and_derivatives():
    rng = np.random.default_rng(0)
    period, q0 = 4.0, rng.normal(size=2)
    a, b = rng.normal(size=(2, 3)), rng.normal(size=(2, 3))
    t = np.linspace(0.0, 2 * period, 401)
    q, qd, qdd = fourier_series(t, q0, a, b, period)
    # the series written out term by term (w = 2 pi / period)
    w = 2 * np.pi / period
    ref = np.tile(q0, (t.size, 1))
    for j in range(2):
        for k in range(3):
            lw = w * (k + 1)
            ref[:, j] += a[j, k] / lw * np.sin(lw * t) - b[j, k] / lw * np.cos(lw * t)
    np.testing.assert_allclose(q, ref, rtol=0, atol=1e-13)
    # derivatives: central differences of q and qd (error ~ h^2 |q'''| / 6)
    h = 1e-5
    qp, qdp, _ = fourier_series(t + h, q0, a, b, period)
    qm, qdm, _ = fourier_series(t - h, q0, a, b, period)
    np.testing.assert_allclose(qd, (qp - qm) / (2 * h), rtol=0, atol=1e-8)
    np.testing.assert_allclose(qdd, (qdp - qdm) / (2 * h), rtol=0, atol=1e-8)
    # periodic
    np.testing.assert_allclose(q[:201], q[200:], rtol=0, atol=1e-12)


@needs_robots
def test_design_beats_random_fourier(ur5_design):
    """The designed motion's condition number against 20 random Fourier motions within the
    same limits per scaling (seeds 10-29): 1.5x below every one, 2.5x below the per-joint median
    and 10x below the common-scaled median (margins: a 40-iteration design is not converged,
    other round-off ends elsewhere). Measured (this small design: 3 harmonics, 40 samples,
    one start of 40 iterations, tighter torques): cond 16.9 against 36-338 per joint (2.2x
    below the best, 3.4x below the median) and 69-1457 common (4.1x, 16.8x): the issue's 10x
    is not met on the UR5 against the per-joint baseline (docs/identification.md says why)."""
    model, base, design = ur5_design
    assert design.info["optimised"]
    assert design.cond < design.info["start_conds"][0]
    for scaling, median in (("joint", 2.5), ("common", 10.0)):
        rand = np.array(
            [
                random_fourier(
                    model, base=base, max_torque=TORQUES, seed=s, scaling=scaling, **SMALL
                ).cond
                for s in range(10, 30)
            ]
        )
        assert design.cond * 1.5 < rand.min()
        assert design.cond * median < np.median(rand)
    # the cond is the documented one: an independent recomputation
    t = design.period * np.arange(40) / 40
    y = base.regressor(ad.joint_torque_regressor(model, *design.evaluate(t))).reshape(-1, base.rank)
    scaled = y / _limit_scale(model, base, 0.05)
    assert design.cond == pytest.approx(np.linalg.cond(scaled), rel=1e-9)


def _check_limits(model, exc, max_torque, margin=0.05, acc_per_vel=5.0):
    """Every limit on an independent fine grid (not the design's grids), torques from batch
    inverse_dynamics."""
    t = np.linspace(0.0, exc.period, 3001)
    q, qd, qdd = fourier_series(t, exc.q0, exc.a, exc.b, exc.period)
    lower = np.asarray(model.coord_lower) + margin
    upper = np.asarray(model.coord_upper) - margin
    assert np.all(q >= lower) and np.all(q <= upper)
    vel = np.asarray(model.coord_velocity_limit)
    assert np.all(np.abs(qd) <= vel)
    assert np.all(np.abs(qdd) <= acc_per_vel * vel)
    tau = ad.inverse_dynamics(model, q, qd, qdd)
    assert np.all(np.abs(tau) <= max_torque)
    return np.abs(tau).max(axis=0) / max_torque


@needs_robots
def test_limits_hold_on_a_fine_grid(ur5_design):
    model, base, design = ur5_design
    use = _check_limits(model, design, TORQUES)
    assert use.max() > 0.5  # the torque limits matter: the design uses them
    for scaling in ("joint", "common"):
        r = random_fourier(model, base=base, max_torque=TORQUES, seed=3, scaling=scaling, **SMALL)
        _check_limits(model, r, TORQUES)


@needs_robots
def test_starts_and_ends_at_rest_and_csv(ur5_design, tmp_path):
    model, _, design = ur5_design
    q, qd, qdd = design.evaluate([0.0, design.period])
    np.testing.assert_allclose(qd, 0.0, atol=1e-12)
    np.testing.assert_allclose(qdd, 0.0, atol=1e-12)
    np.testing.assert_allclose(q[0], q[1], atol=1e-12)
    traj = design.trajectory(dt=0.05, periods=2)
    assert isinstance(traj, ad.motion.Trajectory)
    assert traj.names == tuple(model.coord_names)
    assert traj.t[-1] == pytest.approx(2 * design.period) and len(traj) == 401
    np.testing.assert_allclose(traj.q[200], traj.q[0], atol=1e-12)
    path = tmp_path / "excitation.csv"
    design.to_csv(path, dt=0.1)
    data = np.genfromtxt(path, delimiter=",", names=True)
    cols = data.dtype.names
    assert cols[0] == "t" and list(cols[1:7]) == list(model.coord_names)
    assert cols[7] == "shoulder_pan_jointqd"  # genfromtxt drops the '.': the header is <joint>.qd
    header = path.read_text().splitlines()[0].split(",")
    assert header[7:9] == ["shoulder_pan_joint.qd", "shoulder_lift_joint.qd"]
    assert header[13] == "shoulder_pan_joint.qdd" and len(header) == 19
    raw = np.loadtxt(path, delimiter=",", skiprows=1)
    q, qd, qdd = design.evaluate(raw[:, 0])
    np.testing.assert_array_equal(raw[:, 1:], np.hstack([q, qd, qdd]))


@needs_robots
@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"period": float("nan")}, ad.ModelError, "period"),
        ({"period": -1.0}, ad.ModelError, "period"),
        ({"harmonics": 0}, ad.ModelError, "harmonics"),
        ({"harmonics": 1}, ad.ModelError, "harmonics"),  # at rest needs two
        ({"harmonics": 10_000}, ad.ModelError, "harmonics"),
        ({"samples": 5}, ad.ModelError, "samples"),
        ({"max_velocity": -1.0}, ad.ModelError, r"max_velocity\[0\]"),
        ({"max_velocity": [1.0, 2.0]}, ad.ModelError, "max_velocity must"),
        ({"max_acceleration": np.inf}, ad.ModelError, "max_acceleration"),
        ({"position_margin": 4.0}, ad.SolverError, "position limits of joint 'elbow_joint'"),
        ({"position_margin": -0.1}, ad.ModelError, "position_margin must be"),
        ({"position_margin": [0.1, 0.1]}, ad.ModelError, "position_margin must be"),
        ({"q0": [0, 0, 3.2, 0, 0, 0]}, ad.SolverError, "q0.*'elbow_joint'"),
        ({"criterion": "log-det"}, ad.ModelError, "criterion"),
        (
            {"max_torque": [150, 10, 150, 28, 28, 28]},
            ad.SolverError,
            "torque limit of joint 'shoulder_lift_joint'",
        ),
    ],
)
def test_hostile_arguments(kwargs, error, match):
    model = _ur5()
    with pytest.raises(error, match=match):
        random_fourier(model, **(SMALL | kwargs))
    with pytest.raises(error, match=match):
        fourier_excitation(model, maxiter=1, starts=1, **(SMALL | kwargs))


def test_hostile_models():
    b = ad.ModelBuilder()
    b.add_body("lone", 1.0, (1.0, 1.0, 1.0))
    b.add_fixed("weld", "ground", "lone")
    with pytest.raises(ad.ModelError, match="no joint"):
        fourier_excitation(b.finalize())
    b = ad.ModelBuilder()
    b.add_body("box", 1.0, (1.0, 1.0, 1.0))
    b.add_free("float", "box")
    with pytest.raises(ad.ModelError, match="floating base"):
        fourier_excitation(b.finalize())
    with pytest.raises(ad.ModelError, match="no velocity limit for joint 'j'"):
        b = ad.ModelBuilder()
        b.add_body("l", 1.0, (1.0, 1.0, 1.0), (0.1, 0.0, 0.0))
        b.add_revolute("j", "ground", "l", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
        random_fourier(b.finalize())
    with pytest.raises(ad.ModelError, match="model must be"):
        fourier_excitation(None)


def test_fourier_series_bad_inputs():
    with pytest.raises(ad.ModelError, match="period"):
        fourier_series([0.0], [0.0], [[1.0]], [[1.0]], 0.0)
    with pytest.raises(ad.ModelError, match="shape"):
        fourier_series([0.0], [0.0, 1.0], [[1.0]], [[1.0]], 1.0)
    with pytest.raises(ad.ModelError, match=r"t\[1\]"):
        fourier_series([0.0, np.nan], [0.0], [[1.0]], [[1.0]], 1.0)


def test_unlimited_joint_with_given_velocity_and_excitation_type():
    """Joints without position limits: the velocity bound alone bounds the motion; q0 given."""
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("l1", 1.0, (0.01, 0.01, 0.01), (0.2, 0.0, 0.0))
    b.add_revolute("j1", "ground", "l1", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    b.add_body("l2", 0.5, (0.005, 0.005, 0.005), (0.5, 0.0, 0.0))
    b.add_revolute("j2", "l1", "l2", (0.4, 0.0, 0.0), (0.0, 1.0, 0.0))
    model = b.finalize()
    exc = fourier_excitation(
        model, max_velocity=2.0, period=3.0, q0=[0.3, -0.2], maxiter=20, starts=1, **SMALL
    )
    assert isinstance(exc, Excitation)
    np.testing.assert_array_equal(exc.q0, [0.3, -0.2])  # a given q0 stays fixed
    t = np.linspace(0.0, 3.0, 2001)
    _, qd, qdd = exc.evaluate(t)
    assert np.abs(qd).max() <= 2.0 and np.abs(qdd).max() <= 10.0


@needs_robots
def test_panda_with_a_coupled_finger():
    """The Panda (the second finger mimics the first): a per-joint margin for the finger's 4 cm;
    the design improves on its start and keeps every limit."""
    model = ad.load_urdf(str(ROBOTS / "panda_description/urdf/panda.urdf"))
    margin = [0.05] * 7 + [0.002]
    with pytest.raises(ad.SolverError, match="'panda_finger_joint1'"):
        random_fourier(model, **SMALL)
    exc = fourier_excitation(model, position_margin=margin, maxiter=15, starts=1, **SMALL)
    assert exc.info["optimised"] and exc.cond < exc.info["start_conds"][0]
    _check_limits(model, exc, np.asarray(model.coord_effort_limit), margin=np.array(margin))


@needs_robots
def test_objective_and_constraint_gradients_match_finite_differences():
    """The optimiser's gradients (chain rule through the regressor's state derivatives and the
    series' exact maps; the constraints' through inverse_dynamics_derivatives) against central
    differences of the objective and the constraints themselves, along random directions, at a
    random feasible start whose samples avoid t = 0 (where qd = 0 up to round-off would put
    the smoothed Coulomb column's steep slope into the differences)."""
    from armdyn.identification import excitation as ex

    model = _ur5()
    limits = {
        "max_velocity": None,
        "max_acceleration": None,
        "max_torque": TORQUES,
        "position_margin": 0.05,
    }
    problem = ex._setup("t", model, 10.0, 3, None, limits, None, 40, True, "scaled")
    problem.times = problem.times + 0.05
    x = problem.pack(*ex._random_start(problem, np.random.default_rng(1)))
    f, grad = problem.surrogate(x)
    # the surrogate bounds log cond from above, within 2 log(rank) / SMOOTHING
    log_cond = problem.log_cond(x)
    assert log_cond <= f <= log_cond + 2 * np.log(problem.base.rank) / ex.SMOOTHING
    jac = problem.constraints_jacobian(x)
    rng = np.random.default_rng(2)
    h = 1e-6
    for _ in range(3):
        d = rng.normal(size=x.size)
        fd = (problem.surrogate(x + h * d)[0] - problem.surrogate(x - h * d)[0]) / (2 * h)
        assert grad @ d == pytest.approx(fd, rel=1e-5, abs=1e-6)
        cfd = (problem.constraints(x + h * d) - problem.constraints(x - h * d)) / (2 * h)
        np.testing.assert_allclose(jac @ d, cfd, rtol=0, atol=1e-6 * np.abs(cfd).max())


@needs_robots
def test_panda_design_ten_times_below_random_fourier():
    """Issue 35's target on the Panda: the designed motion's condition number (the default
    scaled criterion) at least 10x below the median of 20 random Fourier motions with the same
    limits, period, harmonics and samples (per-joint scaling, the stronger baseline; seeds
    10-29), and 5x below the best of them, each recomputed independently. A small design (5
    harmonics, 50 samples, one start of 50 iterations, ~3.5 s CPU) measured cond 60.1 against
    483-3062 (8.0x below the best, 17x below the median); the full one (the defaults, python
    -m benchmarks.identification_excitation --seeds 20) 13.7x and 24.9x."""
    model = ad.load_urdf(str(ROBOTS / "panda_description/urdf/panda.urdf"))
    base = base_parameters(model)
    kw = {"position_margin": [0.05] * 7 + [0.002], "harmonics": 5, "samples": 50}
    design = fourier_excitation(model, base=base, maxiter=50, starts=1, seed=0, **kw)
    rand = [random_fourier(model, base=base, seed=s, **kw) for s in range(10, 30)]
    # the same column scale for all: the criterion's (one fixed scale per model and limits)
    t = design.period * np.arange(50) / 50

    def cond(motion):
        y = base.regressor(ad.joint_torque_regressor(model, *motion.evaluate(t)))
        s = np.linalg.svd(y.reshape(-1, base.rank) / scale, compute_uv=False)
        return s[0] / s[-1]

    scale = _limit_scale(model, base, np.array(kw["position_margin"]))
    assert cond(design) == pytest.approx(design.cond, rel=1e-8)
    ratios = np.array([cond(r) for r in rand]) / design.cond
    assert np.median(ratios) >= 10.0
    assert ratios.min() >= 5.0
    _check_limits(
        model, design, np.asarray(model.coord_effort_limit), margin=np.array(kw["position_margin"])
    )


def _limit_scale(model, base, margin):
    """The scaled criterion's column scale, recomputed: the RMS over 200 random states (seed 0)
    uniform within the position limits minus the margin, +-velocity and +-5/s x velocity."""
    rng = np.random.default_rng(0)
    lower = np.asarray(model.coord_lower) + margin
    upper = np.asarray(model.coord_upper) - margin
    vel = np.asarray(model.coord_velocity_limit)
    q = rng.uniform(lower, upper, size=(200, model.n_dofs))
    qd = rng.uniform(-1.0, 1.0, size=(200, model.n_dofs)) * vel
    qdd = rng.uniform(-1.0, 1.0, size=(200, model.n_dofs)) * 5.0 * vel
    y = base.regressor(ad.joint_torque_regressor(model, q, qd, qdd))
    return np.sqrt((y.reshape(-1, base.rank) ** 2).mean(axis=0))
