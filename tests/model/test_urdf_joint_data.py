"""Joint data and zero-DOF models from URDF (issue 21).

* ``<dynamics damping friction>`` is joint friction, tau = -damping qd - friction tanh(qd / v_s)
  (v_s = armdyn._core.URDF_COULOMB_SMOOTHING): the accelerations of a URDF pendulum equal the
  closed form, a damped swing loses energy at the rate c qd^2 the damping predicts, and the URDF
  model runs exactly as the same pendulum built by hand with add_joint_friction.
* ``<limit>`` is ``model.coord_lower`` / ``coord_upper`` / ``coord_effort_limit`` /
  ``coord_velocity_limit``, equal to Pinocchio's reading of the UR5 and Panda URDFs.
* A URDF with no moving joint: with a fixed base a zero-DOF model (every function answers with
  empty arrays, a UserWarning suggests fixed_base=False); with a floating base one free body that
  falls as the closed form says.
"""

import armdyn as ad
import numpy as np
import pytest
from armdyn import _core
from scipy.integrate import simpson

from benchmarks import common

G = 9.81
MASS, L, IYY = 1.3, 0.5, 0.02  # pendulum: CoM at L below the joint, inertia about the CoM


def pendulum(damping=None, friction=None, joint_type="revolute", limit=None):
    dyn = ""
    if damping is not None or friction is not None:
        attrs = "".join(
            f' {k}="{v}"'
            for k, v in (("damping", damping), ("friction", friction))
            if v is not None
        )
        dyn = f"<dynamics{attrs}/>"
    if limit is None:
        limit = '<limit lower="-3" upper="3" effort="10" velocity="5"/>'
    return f"""<robot name="pendulum">
  <link name="base"/>
  <link name="bob">
    <inertial>
      <origin xyz="0 0 {-L}"/>
      <mass value="{MASS}"/>
      <inertia ixx="0.03" ixy="0" ixz="0" iyy="{IYY}" iyz="0" izz="0.015"/>
    </inertial>
  </link>
  <joint name="hinge" type="{joint_type}">
    <parent link="base"/>
    <child link="bob"/>
    <origin xyz="0 0 0"/>
    <axis xyz="0 1 0"/>
    {limit}
    {dyn}
  </joint>
</robot>"""


def closed_form_qdd(q, qd, tau, damping, friction):
    # about y, the CoM at R_y(q) (0, 0, -L) = (-L sin q, 0, -L cos q): V = -m g L cos q
    vs = _core.URDF_COULOMB_SMOOTHING
    j = IYY + MASS * L**2
    return (-MASS * G * L * np.sin(q) - damping * qd - friction * np.tanh(qd / vs) + tau) / j


@pytest.mark.parametrize(("damping", "friction"), [(0.05, 0.0), (0.0, 0.2), (0.07, 0.3)])
def test_dynamics_become_joint_friction(damping, friction):
    model = ad.load_urdf(pendulum(damping, friction))
    rng = np.random.default_rng(5)
    for q, qd, tau in rng.uniform(-2, 2, size=(20, 3)):
        # qd near v_s too, where tanh is not saturated
        for rate in (qd, 1e-3 * qd):
            expected = closed_form_qdd(q, rate, tau, damping, friction)
            for method in ("crba", "aba", "cartesian"):
                got = ad.forward_dynamics(model, [q], [rate], [tau], method=method)[0]
                assert got == pytest.approx(expected, rel=1e-12, abs=1e-12), method
            # inverse dynamics: the torque that realises the closed-form acceleration
            tau_id = ad.inverse_dynamics(model, [q], [rate], [expected])[0]
            assert tau_id == pytest.approx(tau, rel=1e-11, abs=1e-11)


def test_zero_dynamics_add_no_force_element():
    plain = ad.load_urdf(pendulum())
    zero = ad.load_urdf(pendulum(0.0, 0.0))
    q, qd = [0.4], [1.5]
    assert np.array_equal(
        ad.forward_dynamics(plain, q, qd, [0.0]), ad.forward_dynamics(zero, q, qd, [0.0])
    )
    assert ad.forward_dynamics(plain, q, qd, [0.0])[0] == pytest.approx(
        closed_form_qdd(0.4, 1.5, 0.0, 0.0, 0.0), rel=1e-12
    )


@pytest.mark.parametrize("coordinates", ["cartesian", "joint"])
def test_damped_swing_loses_energy_at_the_damping_rate(coordinates):
    c = 0.05
    model = ad.load_urdf(pendulum(damping=c))
    r = ad.simulate(
        model,
        3.0,
        q0=[1.2],
        qd0=[0.0],
        rtol=1e-11,
        atol=1e-12,
        output_dt=1e-3,
        integrator="dop853",
        coordinates=coordinates,
    )
    e = r.total_energy
    # closed-form energy of the state, and dE/dt = -c qd^2 integrated along the run
    q, qd = r.q[:, 0], r.qd[:, 0]
    j = IYY + MASS * L**2
    e_closed = 0.5 * j * qd**2 - MASS * G * L * np.cos(q)
    assert np.max(np.abs((e - e[0]) - (e_closed - e_closed[0]))) < 1e-9
    dissipated = simpson(c * qd**2, x=r.t)
    assert dissipated > 0.05  # the swing loses a visible amount
    assert e[0] - e[-1] == pytest.approx(dissipated, rel=1e-9)  # measured 5e-13


def test_urdf_friction_runs_as_the_hand_built_pendulum():
    c, f = 0.04, 0.1
    model = ad.load_urdf(pendulum(c, f))
    b = ad.ModelBuilder()
    b.add_body("bob", MASS, np.diag([0.03, IYY, 0.015]), position=(0, 0, -L))
    b.add_revolute("hinge", "ground", "bob", point=(0, 0, 0), axis=(0, 1, 0))
    b.add_joint_friction("hinge", viscous=c, coulomb=f, smoothing_velocity=1e-3)
    hand = b.finalize()
    kw = dict(q0=[1.0], qd0=[0.0], rtol=1e-10, atol=1e-12, output_dt=0.05)
    a, h = ad.simulate(model, 2.0, **kw), ad.simulate(hand, 2.0, **kw)
    assert np.max(np.abs(a.q - h.q)) < 1e-9
    assert np.max(np.abs(a.qd - h.qd)) < 1e-9
    # and it does lose energy: the friction acts
    assert a.total_energy[-1] < a.total_energy[0] - 0.1


def test_negative_damping_is_refused():
    with pytest.raises(ad.UrdfError, match=r"joint 'hinge': <dynamics> damping and friction"):
        ad.load_urdf(pendulum(damping=-0.1))
    with pytest.raises(ad.UrdfError, match=r"joint 'hinge': <dynamics> damping and friction"):
        ad.load_urdf(pendulum(friction=-1.0))


# --- limits ----------------------------------------------------------------------------------


@pytest.mark.parametrize("robot", ["ur5", "panda"])
def test_limits_equal_pinocchios_reading(robot):
    pin = pytest.importorskip("pinocchio")
    path = common.robot_urdf(robot)
    assert path is not None, "example-robot-data is part of the test extra"
    model = ad.load_urdf(path, mimic=False)  # Pinocchio's default reading
    pm = pin.buildModelFromUrdf(str(path))
    assert pm.nq == pm.nv == model.n_coords
    for k, name in enumerate(model.coord_names):
        i = pm.joints[pm.getJointId(name)].idx_q
        assert model.coord_lower[k] == pm.lowerPositionLimit[i], name
        assert model.coord_upper[k] == pm.upperPositionLimit[i], name
        assert model.coord_effort_limit[k] == pm.effortLimit[i], name
        assert model.coord_velocity_limit[k] == pm.velocityLimit[i], name
    for arr in (model.coord_lower, model.coord_upper):
        assert arr.shape == (model.n_coords,) and np.all(np.isfinite(arr))


def test_limits_of_the_template_pendulum():
    model = ad.load_urdf(pendulum())
    assert model.coord_lower.tolist() == [-3.0]
    assert model.coord_upper.tolist() == [3.0]
    assert model.coord_effort_limit.tolist() == [10.0]
    assert model.coord_velocity_limit.tolist() == [5.0]


def test_continuous_joint_has_no_position_limits():
    model = ad.load_urdf(pendulum(joint_type="continuous", limit=""))
    assert model.coord_lower.tolist() == [-np.inf]
    assert model.coord_upper.tolist() == [np.inf]
    assert model.coord_effort_limit.tolist() == [np.inf]
    assert model.coord_velocity_limit.tolist() == [np.inf]
    # a continuous joint may carry effort and velocity limits; lower/upper stay unbounded
    model = ad.load_urdf(pendulum(joint_type="continuous"))
    assert model.coord_lower.tolist() == [-np.inf] and model.coord_upper.tolist() == [np.inf]
    assert model.coord_effort_limit.tolist() == [10.0]
    assert model.coord_velocity_limit.tolist() == [5.0]


def test_built_models_have_unbounded_limits_unless_set():
    b = ad.ModelBuilder()
    b.add_body("a", 1.0, [0.1, 0.1, 0.1], position=(0.5, 0, 0))
    b.add_body("c", 1.0, [0.1, 0.1, 0.1], position=(1.5, 0, 0))
    b.add_revolute("j1", "ground", "a", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_prismatic("j2", "a", "c", point=(1, 0, 0), axis=(1, 0, 0))
    b.set_joint_limits("j2", -0.1, 0.2, effort=50.0)
    m = b.finalize()
    assert m.coord_lower.tolist() == [-np.inf, -0.1]
    assert m.coord_upper.tolist() == [np.inf, 0.2]
    assert m.coord_effort_limit.tolist() == [np.inf, 50.0]
    assert m.coord_velocity_limit.tolist() == [np.inf, np.inf]


# --- zero-DOF models -------------------------------------------------------------------------

STRUCTURES = [
    "hector_description/robots/quadrotor_base.urdf",
    "iris_description/robots/iris_simple.urdf",
]


def erd_path(relative):
    ur5 = common.robot_urdf("ur5")
    assert ur5 is not None, "example-robot-data is part of the test extra"
    path = ur5.parents[2] / relative
    assert path.is_file(), path
    return path


@pytest.mark.parametrize("relative", STRUCTURES)
def test_structure_with_a_fixed_base_is_a_zero_dof_model(relative):
    with pytest.warns(UserWarning, match=r"no moving joint.*fixed_base=False"):
        model = ad.load_urdf(erd_path(relative))
    assert model.nb == 0 and model.n_coords == 0 and model.nq == 0 and model.nv == 0
    assert model.mobility == 0 and model.body_names == []
    assert ad.mass_matrix(model, np.zeros(0)).shape == (0, 0)
    assert ad.forward_dynamics(model, [], [], []).shape == (0,)
    assert ad.forward_dynamics(model, [], [], [], method="cartesian").shape == (0,)
    assert ad.inverse_dynamics(model, [], [], []).shape == (0,)
    assert model.coord_lower.shape == (0,) and model.coord_velocity_limit.shape == (0,)
    assert "0 bodies" in model.summary()
    r = ad.simulate(model, 1.0, output_dt=0.25)
    assert r.t.tolist() == [0.0, 0.25, 0.5, 0.75, 1.0]
    assert r.q.shape == (5, 0) and r.u.shape == (5, 0) and r.qd.shape == (5, 0)
    assert r.stats["integrator"] == "none"
    r = ad.simulate(model, 0.7, output_dt=0.3)
    assert np.allclose(r.t, [0.0, 0.3, 0.6, 0.7], rtol=0, atol=1e-15)
    assert ad.simulate(model, 2.0).t.tolist() == [0.0, 2.0]
    with pytest.raises(ad.ModelError, match="t_end"):
        ad.simulate(model, -1.0)


@pytest.mark.parametrize("relative", STRUCTURES)
def test_structure_with_a_floating_base_falls_freely(relative):
    pin = pytest.importorskip("pinocchio")
    path = erd_path(relative)
    model = ad.load_urdf(path, fixed_base=False)
    # one free body: q is its frame's pose (7), qd its velocity (6)
    assert model.nb == 1 and (model.n_coords, model.n_dofs) == (7, 6)
    # one body with every link's mass: Pinocchio's total (the universe's composite inertia)
    pm = pin.buildModelFromUrdf(str(path))
    assert pm.nq == 0
    assert model.masses[0] == pytest.approx(pm.inertias[0].mass, rel=1e-14)
    t_end = 1.0
    r = ad.simulate(model, t_end, output_dt=0.25, rtol=1e-10, atol=1e-12)
    x0 = model.u0[:3]
    for t, u in zip(r.t, r.u, strict=True):
        expected = x0 + 0.5 * np.array([0.0, 0.0, -G]) * t**2
        assert np.allclose(u[:3], expected, rtol=0, atol=1e-9)
        assert np.allclose(u[3:], model.u0[3:], rtol=0, atol=1e-12)  # no rotation
    # the base frame (the root link's) falls with its velocity in its own axes
    np.testing.assert_allclose(r.q[:, 2] - r.q[0, 2], -0.5 * G * r.t**2, rtol=0, atol=1e-9)
    np.testing.assert_allclose(r.qd[:, 2], -G * r.t, rtol=0, atol=1e-9)


def test_empty_builder_finalizes_to_an_empty_model():
    m = ad.ModelBuilder().finalize()
    assert m.nb == 0 and m.n_coords == 0 and m.nc == 0
    assert ad.mass_matrix(m, []).shape == (0, 0)
