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
