"""energy_regressor: the kinetic plus potential energy is h(q, qd) @ pi (issue 35).

Two independent references: the energy of the Cartesian state (``armdyn.energy`` of
``state_from_joints``: every body's and rotor's 0.5 m |v|^2 + 0.5 w^T J w, and -m g . c), and
``0.5 qd^T M qd`` from ``armdyn.mass_matrix`` with the potential at rest; and the energy theorem
along a closed-form motion: the work of the joint torques less friction equals the change of
h @ pi (Gauss-Legendre quadrature of the power, exact to round-off for this smooth motion).
"""

import armdyn as ad
import numpy as np
import pytest

from benchmarks import common

ROBOTS = common.robots_dir()
pytestmark = pytest.mark.skipif(ROBOTS is None, reason="example-robot-data not installed")
UR5 = "ur_description/urdf/ur5_robot.urdf"


def _urdf(path, **kw):
    return ad.load_urdf(str(ROBOTS / path), **kw)


def _actuated(gyroscopic, friction=True):
    """The UR5 with a gear-reduced or gyroscopic rotor on two joints, and joint friction."""
    b = ad.urdf_builder(str(ROBOTS / UR5))
    b.add_actuator("elbow_joint", 100.0, 1e-4, gyroscopic=gyroscopic)
    b.add_actuator("shoulder_lift_joint", -50.0, 2e-4, gyroscopic=gyroscopic)
    if friction:
        b.add_joint_friction("wrist_1_joint", 0.3, 0.5, 0.01)
    return b.finalize()


MODELS = {
    "ur5": lambda: _urdf(UR5),
    "panda-mimic": lambda: _urdf("panda_description/urdf/panda.urdf"),
    "solo12-floating": lambda: _urdf("solo_description/robots/solo12.urdf", fixed_base=False),
    "ur5-geared": lambda: _actuated(False),
    "ur5-gyroscopic": lambda: _actuated(True),
}


def _state(model, rng, scale=1.0):
    q = rng.uniform(-np.pi, np.pi, model.n_coords)
    if model.n_free:
        e = rng.normal(size=4)
        q = np.concatenate([rng.normal(size=3), e / np.linalg.norm(e), q[7:]])
    return q, scale * rng.normal(size=model.n_dofs)


def _cartesian_energy(model, q, qd):
    ke, pe = ad.energy(model, *ad.state_from_joints(model, q, qd))
    return ke, pe


@pytest.mark.parametrize("name", list(MODELS))
def test_h_pi_is_the_energy(name):
    model = MODELS[name]()
    pi = ad.dynamic_parameters(model)
    rng = np.random.default_rng(11)
    for k in range(5):
        q, qd = _state(model, rng, scale=0.0 if k == 0 else 1.0)  # the first at rest
        h = ad.energy_regressor(model, q, qd)
        assert h.shape == pi.shape
        ke, pe = _cartesian_energy(model, q, qd)
        scale = abs(ke) + abs(pe)
        assert h @ pi == pytest.approx(ke + pe, rel=0, abs=1e-12 * scale)
        # the kinetic part alone: 0.5 qd^T M qd (the CRBA's mass matrix), and the potential at rest
        h0 = ad.energy_regressor(model, q, np.zeros_like(qd))
        m = ad.mass_matrix(model, q)
        assert (h - h0) @ pi == pytest.approx(0.5 * qd @ m @ qd, rel=0, abs=1e-12 * scale)
        assert h0 @ pi == pytest.approx(pe, rel=0, abs=1e-12 * scale)


def test_friction_and_offset_entries_are_zero_and_rotors_count():
    model = _actuated(False)
    names = ad.dynamic_parameter_names(model)
    q, qd = _state(model, np.random.default_rng(3))
    h = ad.energy_regressor(model, q, qd)
    for k, n in enumerate(names):
        if n.endswith((".fv", ".fc", ".offset")):
            assert h[k] == 0.0, n
    # a gear-reduced rotor's energy 0.5 Ia qd^2 (and a coordinate without one: the same column)
    c = model.coord_names.index("elbow_joint")
    assert h[names.index("elbow_joint.Ia")] == pytest.approx(0.5 * qd[c] ** 2, rel=1e-15)
    gyro = _actuated(True)
    hg = ad.energy_regressor(gyro, q, qd)
    names_g = ad.dynamic_parameter_names(gyro)
    # a gyroscopic rotor turns with its carrier too: more than its own axis' share
    assert hg[names_g.index("elbow_joint.Ia")] != pytest.approx(0.5 * qd[c] ** 2, rel=1e-6)


def _motion(t, n, seed):
    """A closed-form joint motion (q, qd, qdd) at times t: three harmonics per joint."""
    rng = np.random.default_rng(seed)
    a = rng.uniform(-0.6, 0.6, (3, n))
    w = np.array([1.3, 2.9, 4.1])[:, None] * rng.uniform(0.8, 1.2, (3, n))
    ph = rng.uniform(0, 2 * np.pi, (3, n))
    q0 = rng.uniform(-1.0, 1.0, n)
    arg = w[None] * t[:, None, None] + ph[None]
    q = q0 + (a * np.sin(arg)).sum(axis=1)
    qd = (a * w * np.cos(arg)).sum(axis=1)
    qdd = -(a * w * w * np.sin(arg)).sum(axis=1)
    return q, qd, qdd


@pytest.mark.parametrize("gyroscopic", [False, True])
def test_energy_theorem_along_a_motion(gyroscopic):
    """The work of (tau - friction) from 0 to T equals (h(T) - h(0)) @ pi."""
    model = _actuated(gyroscopic)
    pi = ad.dynamic_parameters(model)
    big_t = 1.5
    nodes, weights = np.polynomial.legendre.leggauss(80)
    t = 0.5 * big_t * (nodes + 1.0)
    q, qd, qdd = _motion(t, model.n_dofs, seed=5)
    tau = ad.inverse_dynamics(model, q, qd, qdd)
    # the joint friction given to the builder: tau_f = 0.3 qd + 0.5 tanh(qd / 0.01)
    w1 = model.coord_names.index("wrist_1_joint")
    friction = np.zeros_like(tau)
    friction[:, w1] = 0.3 * qd[:, w1] + 0.5 * np.tanh(qd[:, w1] / 0.01)
    work = 0.5 * big_t * weights @ np.einsum("ij,ij->i", tau - friction, qd)
    ends = np.array([0.0, big_t])
    qe, qde, _ = _motion(ends, model.n_dofs, seed=5)
    h = ad.energy_regressor(model, qe, qde)
    delta = (h[1] - h[0]) @ pi
    scale = np.abs(h @ pi).max()
    assert abs(work) > 1e-3 * scale  # the motion does work
    # measured: <= 8.2e-16 relative (80 Gauss-Legendre nodes integrate this motion's power)
    assert delta == pytest.approx(work, rel=0, abs=1e-12 * scale)


def test_batch_equals_single_calls():
    model = MODELS["solo12-floating"]()
    rng = np.random.default_rng(4)
    states = [_state(model, rng) for _ in range(4)]
    q = np.array([s[0] for s in states])
    qd = np.array([s[1] for s in states])
    h = ad.energy_regressor(model, q, qd)
    assert h.shape == (4, len(ad.dynamic_parameters(model)))
    for i in range(4):
        np.testing.assert_array_equal(h[i], ad.energy_regressor(model, q[i], qd[i]))
    data = ad.Data(model)
    np.testing.assert_array_equal(ad.energy_regressor(model, q, qd, data=data), h)


def _pendulum():
    b = ad.ModelBuilder()
    b.add_body("link", 1.0, np.diag([0.01, 0.02, 0.03]), position=(0.0, 0.0, -0.5))
    b.add_revolute("hinge", "ground", "link", (0, 0, 0), (0, 1, 0))
    return b.finalize()


@pytest.mark.parametrize(
    ("args", "pattern"),
    [
        (([np.nan], [0.0]), r"energy_regressor: q contains NaN"),
        (([0.0], [np.inf]), r"energy_regressor: qd contains NaN or inf"),
        (([0.0, 0.0], [0.0]), r"^q: expected shape \(1,\), got \(2,\)"),
        ((np.zeros((3, 1)), np.zeros((2, 1))), r"qd must have shape \(3, 1\)"),
        ((np.zeros((2, 1)), np.array([[0.0], [np.nan]])), r"row 1: .*qd"),
    ],
)
def test_bad_inputs_are_refused(args, pattern):
    with pytest.raises(ad.ModelError, match=pattern):
        ad.energy_regressor(_pendulum(), *args)


def test_overflowing_rates_are_a_solver_error_never_nan():
    with pytest.raises(
        ad.SolverError, match=r"energy_regressor: .*overflow.*h\[0\] = inf.*qd\[0\]"
    ):
        ad.energy_regressor(_pendulum(), [0.3], [1e200])
    h = ad.energy_regressor(_pendulum(), [1e200], [1e100])  # finite: cos/sin of 1e200, 1e200^1
    assert np.isfinite(h).all()


def test_floating_base_quaternion_checked():
    model = MODELS["solo12-floating"]()
    q, qd = _state(model, np.random.default_rng(1))
    q[3:7] *= 2.0
    with pytest.raises(ad.ModelError, match=r"energy_regressor: q\[3:7\].*unit quaternion"):
        ad.energy_regressor(model, q, qd)
