"""joint_torque_regressor / dynamic_parameters: Y pi equals inverse_dynamics (issue 35)."""

import armdyn as ad
import numpy as np
import pytest

from benchmarks import common

ROBOTS = common.robots_dir()
pytestmark = pytest.mark.skipif(ROBOTS is None, reason="example-robot-data not installed")


def _state(model, rng):
    q = rng.uniform(-1.0, 1.0, model.n_coords)
    if model.n_free:
        quat = rng.normal(size=4)
        q = np.concatenate([rng.normal(size=3), quat / np.linalg.norm(quat), q[7:]])
    return q, rng.normal(size=model.n_dofs), rng.normal(size=model.n_dofs)


def _ur5_builder():
    return ad.urdf_builder(str(ROBOTS / "ur_description/urdf/ur5_robot.urdf"))


@pytest.mark.parametrize(
    "make",
    [
        lambda: ad.load_urdf(str(ROBOTS / "ur_description/urdf/ur5_robot.urdf")),
        lambda: ad.load_urdf(str(ROBOTS / "panda_description/urdf/panda.urdf")),
        lambda: ad.load_urdf(str(ROBOTS / "solo_description/robots/solo12.urdf"), fixed_base=False),
    ],
    ids=["ur5", "panda-mimic", "solo12-floating"],
)
def test_y_pi_equals_inverse_dynamics(make):
    model = make()
    rng = np.random.default_rng(1)
    pi = ad.dynamic_parameters(model)
    assert len(ad.dynamic_parameter_names(model)) == pi.size
    for _ in range(5):
        q, qd, qdd = _state(model, rng)
        tau = ad.inverse_dynamics(model, q, qd, qdd)
        y = ad.joint_torque_regressor(model, q, qd, qdd)
        assert y.shape == (model.n_dofs, pi.size)
        np.testing.assert_allclose(y @ pi, tau, rtol=0, atol=1e-12 * np.abs(tau).max())


@pytest.mark.parametrize("gyroscopic", [False, True])
def test_y_pi_with_actuators_and_friction(gyroscopic):
    b = _ur5_builder()
    b.add_actuator(
        "elbow_joint",
        100.0,
        1e-4,
        friction_viscous=1e-4,
        friction_coulomb=0.01,
        gyroscopic=gyroscopic,
    )
    b.add_actuator("shoulder_lift_joint", -50.0, 2e-4, gyroscopic=gyroscopic)
    b.add_joint_friction("wrist_1_joint", 0.3, 0.5, 0.01)
    model = b.finalize()
    pi = ad.dynamic_parameters(model)
    names = ad.dynamic_parameter_names(model)
    assert pi[names.index("elbow_joint.Ia")] == pytest.approx(100.0**2 * 1e-4)
    assert pi[names.index("wrist_1_joint.fv")] == 0.3
    rng = np.random.default_rng(2)
    for _ in range(5):
        q, qd, qdd = _state(model, rng)
        tau = ad.inverse_dynamics(model, q, qd, qdd)
        y = ad.joint_torque_regressor(model, q, qd, qdd)
        np.testing.assert_allclose(y @ pi, tau, rtol=0, atol=1e-12 * np.abs(tau).max())


def _ur5():
    return ad.load_urdf(str(ROBOTS / "ur_description/urdf/ur5_robot.urdf"))


def _check(model, q, qd, qdd, tol=1e-12):
    """Y pi against inverse_dynamics, to tol relative to the largest term of Y pi, or to the
    arm's weight times a metre when that is larger: the size of the gravity terms that cancel
    in a column (upright, at qdd = 0, the UR5's torques are 1e-10 N m)."""
    pi = ad.dynamic_parameters(model)
    names = ad.dynamic_parameter_names(model)
    weight = 9.81 * sum(p for p, n in zip(pi, names, strict=True) if n.endswith(".m"))
    y = ad.joint_torque_regressor(model, q, qd, qdd)
    tau = ad.inverse_dynamics(model, q, qd, qdd)
    scale = max(np.abs(y * pi).max(), weight * 1.0)
    np.testing.assert_allclose(y @ pi, tau, rtol=0, atol=tol * scale)
    return y


@pytest.mark.parametrize(
    ("q", "qd_scale", "qdd_scale"),
    [
        (np.zeros(6), 0.0, 0.0),  # stretched, at rest: gravity alone (a singular configuration)
        (np.zeros(6), 1.0, 1.0),  # stretched and moving: the wrist axes 4 and 6 aligned
        (np.array([0.3, -np.pi / 2, 0.0, -np.pi / 2, 0.0, 0.0]), 1.0, 0.0),  # upright, qdd 0
        (np.array([1e3, -2e3, 5e2, 7e2, -9e2, 3e3]), 1.0, 1.0),  # angles of many turns
        (np.array([0.2, -0.4, 0.6, 0.1, -0.3, 0.5]), 1e3, 1e5),  # fast
        (np.array([0.2, -0.4, 0.6, 0.1, -0.3, 0.5]), 1e-9, 1e-9),  # nearly at rest
    ],
    ids=["rest-stretched", "stretched", "upright", "many-turns", "fast", "slow"],
)
def test_y_pi_at_special_states(q, qd_scale, qdd_scale):
    model = _ur5()
    rng = np.random.default_rng(7)
    y = _check(model, q, qd_scale * rng.normal(size=6), qdd_scale * rng.normal(size=6))
    if qd_scale == 0.0:
        # at rest only gravity acts: no inertia column
        names = ad.dynamic_parameter_names(model)
        inertia = [k for k, n in enumerate(names) if n.split(".")[-1].startswith("I")]
        assert not y[:, inertia].any()


def test_rows_of_a_body_are_zero_off_its_path():
    """Y's entry (joint row, body column) is zero unless the joint moves the body."""
    model = _ur5()
    names = ad.dynamic_parameter_names(model)
    y = ad.joint_torque_regressor(model, *_state(model, np.random.default_rng(3)))
    links = ["shoulder_link", "upper_arm_link", "forearm_link"]
    links += ["wrist_1_link", "wrist_2_link", "wrist_3_link"]
    for k, link in enumerate(links):
        cols = [names.index(f"{link}.{p}") for p in ("m", "mcx", "Izz")]
        assert not y[k + 1 :, cols].any()  # the joints below the body do not move it
        assert np.abs(y[k, cols]).max() > 0.0


def test_batch_equals_single_calls_and_data():
    model = ad.load_urdf(str(ROBOTS / "panda_description/urdf/panda.urdf"))
    rng = np.random.default_rng(5)
    states = [_state(model, rng) for _ in range(4)]
    q, qd, qdd = (np.array([s[i] for s in states]) for i in range(3))
    y = ad.joint_torque_regressor(model, q, qd, qdd)
    assert y.shape == (4, model.n_dofs, len(ad.dynamic_parameters(model)))
    assert y.flags["C_CONTIGUOUS"]
    for i in range(4):
        np.testing.assert_array_equal(y[i], ad.joint_torque_regressor(model, q[i], qd[i], qdd[i]))
    data = ad.Data(model)
    np.testing.assert_array_equal(ad.joint_torque_regressor(model, q, qd, qdd, data=data), y)
    # lists and non-contiguous arrays are read the same way
    np.testing.assert_array_equal(
        ad.joint_torque_regressor(model, list(q[1]), qd[1].tolist(), qdd[:, ::-1][1, ::-1]), y[1]
    )


def _pendulum():
    b = ad.ModelBuilder()
    b.add_body("link", 1.0, np.diag([0.01, 0.02, 0.03]), position=(0.0, 0.0, -0.5))
    b.add_revolute("hinge", "ground", "link", (0, 0, 0), (0, 1, 0))
    return b


@pytest.mark.parametrize(
    ("args", "pattern"),
    [
        (([np.nan], [0.0], [0.0]), r"joint_torque_regressor: q contains NaN"),
        (([0.0], [np.inf], [0.0]), r"joint_torque_regressor: qd contains NaN or inf"),
        (([0.0], [0.0], [-np.inf]), r"joint_torque_regressor: qdd contains NaN or inf"),
        (([0.0], [0.0], [0.0, 1.0]), r"^qdd: expected shape \(1,\), got \(2,\)"),
        ((np.zeros((3, 1)), np.zeros((3, 1)), np.zeros((2, 1))), r"qdd must have shape \(3, 1\)"),
        ((np.zeros((2, 1)), np.zeros((2, 1)), np.array([[0.0], [np.nan]])), r"^row 1: .*qdd"),
        ((np.zeros((2, 2, 1)), [0.0], [0.0]), r"\bq\b"),
    ],
    ids=["q-nan", "qd-inf", "qdd-inf", "qdd-length", "rows", "row-nan", "q-3d"],
)
def test_bad_inputs_are_refused(args, pattern):
    with pytest.raises(ad.ModelError, match=pattern):
        ad.joint_torque_regressor(_pendulum().finalize(), *args)


def test_models_with_non_parameter_forces_are_refused_by_name():
    b = _pendulum()
    b.add_joint_spring_damper("hinge", 10.0, 0.0)
    model = b.finalize()
    for fn in (
        lambda: ad.joint_torque_regressor(model, [0.0], [0.0], [0.0]),
        lambda: ad.energy_regressor(model, [0.0], [0.0]),
        lambda: ad.dynamic_parameters(model),
        lambda: ad.dynamic_parameter_names(model),
    ):
        with pytest.raises(ad.ModelError, match=r"'hinge' has a spring"):
            fn()
    with pytest.raises(ad.ModelError, match=r"model must be an armdyn\.Model"):
        ad.joint_torque_regressor(_pendulum(), [0.0], [0.0], [0.0])


@pytest.mark.parametrize("value", [1e-300, 1e100, 1e150, 1e200, 1.7e308])
@pytest.mark.parametrize("which", [0, 1, 2])
def test_huge_inputs_give_finite_rows_or_a_solver_error(value, which):
    """Never NaN or inf from finite input: a finite Y, or a SolverError naming the input."""
    model = _ur5()
    args = [np.full(6, 0.3), np.full(6, 0.2), np.full(6, 0.1)]
    args[which] = np.full(6, value)
    try:
        y = ad.joint_torque_regressor(model, *args)
    except ad.SolverError as e:
        assert "overflow" in str(e) and ["q", "qd", "qdd"][which] + "[" in str(e)
    else:
        assert np.isfinite(y).all()
    try:
        h = ad.energy_regressor(model, *args[:2])
    except ad.SolverError as e:
        assert "overflow" in str(e)
    else:
        assert np.isfinite(h).all()


def test_a_floating_base_needs_a_unit_quaternion():
    model = ad.load_urdf(str(ROBOTS / "solo_description/robots/solo12.urdf"), fixed_base=False)
    q, qd, qdd = _state(model, np.random.default_rng(2))
    q[3:7] = 0.0
    with pytest.raises(ad.ModelError, match=r"joint_torque_regressor: q\[3:7\].*has norm 0"):
        ad.joint_torque_regressor(model, q, qd, qdd)


def test_refused_call_leaves_later_results_intact():
    model = _ur5()
    q, qd, qdd = _state(model, np.random.default_rng(9))
    data = ad.Data(model)
    y = ad.joint_torque_regressor(model, q, qd, qdd, data=data)
    with pytest.raises(ad.ModelError):
        ad.joint_torque_regressor(model, q, qd, [np.nan] * 6, data=data)
    np.testing.assert_array_equal(ad.joint_torque_regressor(model, q, qd, qdd, data=data), y)


@pytest.mark.parametrize("gyroscopic", [False, True])
def test_actuator_on_a_coupling_follower_of_scale_two(gyroscopic):
    """A rotor on a follower q_b = 2 q_a: its reflected inertia on the independent coordinate is
    s^2 N^2 J for a gear-reduced rotor (tau_a = s tau_b, qdd_b = s qdd_a); the model rebuilt by
    with_parameters from a changed Ia has that Ia and the regressor's torques."""
    b = ad.ModelBuilder(gravity=(0, 0, -9.81))
    b.add_body("a", mass=1.0, inertia=[0.01, 0.02, 0.03], position=(0.3, 0, 0))
    b.add_body("b", mass=0.5, inertia=[0.01, 0.01, 0.02], position=(0.3, 0.2, 0.1))
    b.add_revolute("ja", "ground", "a", point=(0, 0, 0), axis=(0, 1, 0))
    b.add_revolute("jb", "a", "b", point=(0.3, 0.1, 0), axis=(1, 0, 0))
    b.add_coupling("jb", "jb", "ja", 2.0)
    b.add_actuator("jb", 10.0, 1e-3, gyroscopic=gyroscopic)
    model = b.finalize()
    names = ad.dynamic_parameter_names(model)
    pi = ad.dynamic_parameters(model)
    if not gyroscopic:
        assert pi[names.index("ja.Ia")] == pytest.approx(2.0**2 * 10.0**2 * 1e-3)
    rng = np.random.default_rng(3)
    pi2 = pi.copy()
    pi2[names.index("ja.Ia")] *= 3.0
    changed = ad.identification.with_parameters(model, pi2)
    np.testing.assert_allclose(ad.dynamic_parameters(changed), pi2, rtol=1e-13, atol=1e-15)
    for _ in range(3):
        q, qd, qdd = _state(model, rng)
        y = ad.joint_torque_regressor(model, q, qd, qdd)
        tau = ad.inverse_dynamics(model, q, qd, qdd)
        np.testing.assert_allclose(y @ pi, tau, rtol=0, atol=1e-12 * np.abs(tau).max())
        tau2 = ad.inverse_dynamics(changed, q, qd, qdd)
        np.testing.assert_allclose(y @ pi2, tau2, rtol=0, atol=1e-12 * np.abs(tau2).max())
