"""The joint-space path (``forward_dynamics``/``mass_matrix`` with method "joint", and
``_TreeDynamics``, the ODE of ``simulate(coordinates="joint")``) against independent
references: Pinocchio's CRBA and ABA on real URDF arms, the Pinocchio reference of the geared
arm, and armdyn's Cartesian constrained Newton–Euler path (the paper's method), which shares no
code with it beyond the force laws. Closed-form checks of the joint path on gears and PI motors
are in test_gears.py and test_drive_elements.py (parametrised over ``coordinates``)."""

import armdyn as ad
import numpy as np
import pytest
from armdyn import _core
from armdyn.papers.geared_arm import geared_arm_6dof

from benchmarks import common
from benchmarks.peers.pinocchio import PinPair


@pytest.mark.parametrize("robot", ["ur5", "panda"])
def test_mass_matrix_and_accelerations_equal_pinocchio(robot):
    pin = pytest.importorskip("pinocchio")
    pair = PinPair(common.robot_urdf(robot))
    td = _core._TreeDynamics(pair.am)
    assert td.dof == pair.pm.nq
    rng = np.random.default_rng(11)
    worst_m = worst_a = worst_kkt = 0.0
    for _ in range(20):
        q, v, tau = rng.uniform(-np.pi, np.pi, size=(3, pair.pm.nq))
        m_pin = pin.crba(pair.pm, pair.pd, q)
        m_pin = np.triu(m_pin) + np.triu(m_pin, 1).T  # Pinocchio fills the upper triangle
        qa, va, ta = (pair.to_armdyn(x) for x in (q, v, tau))
        m_ad = ad.mass_matrix(pair.am, qa)[np.ix_(pair.perm, pair.perm)]
        worst_m = max(worst_m, np.abs(m_ad - m_pin).max() / np.abs(m_pin).max())
        assert np.array_equal(td.mass_matrix(qa), ad.mass_matrix(pair.am, qa))
        a_ad = ad.forward_dynamics(pair.am, qa, va, ta, method="joint")
        a_pin = pair.aba(q, v, tau)  # with the URDF's joint damping
        worst_a = max(worst_a, np.abs(a_ad[pair.perm] - a_pin).max() / np.abs(a_pin).max())
        a_kkt = ad.forward_dynamics(pair.am, qa, va, ta, method="cartesian")
        worst_kkt = max(worst_kkt, np.abs(a_ad - a_kkt).max() / np.abs(a_ad).max())
        # the simulation's ODE and "auto" are this path
        assert np.array_equal(td(qa, va, ta), a_ad)
        assert np.array_equal(ad.forward_dynamics(pair.am, qa, va, ta), a_ad)
    # measured: M 1.0e-15, accelerations 1.7e-14 (Panda)
    assert worst_m <= 1e-12
    assert worst_a <= 1e-10
    assert worst_kkt <= 1e-10


def spatial_arm():
    """Revolute, cylindrical and prismatic joints about skew axes, bodies with full inertia
    tensors, and every force element: a point-to-point spring-damper, a body force with a time
    profile, a joint spring-damper, joint friction, a PD motor with a torque limit and a joint
    torque input."""
    b = ad.ModelBuilder(gravity=(0.3, -0.2, -9.81))
    inertia = np.array([[0.02, 0.003, -0.001], [0.003, 0.03, 0.002], [-0.001, 0.002, 0.025]])
    b.add_body("a", 2.0, inertia, position=(0.1, 0.05, 0.3))
    b.add_body("b", 1.5, 0.8 * inertia, position=(0.4, -0.1, 0.5))
    b.add_body("c", 0.7, 0.5 * inertia, position=(0.6, 0.1, 0.4))
    b.add_body("d", 0.4, 0.3 * inertia, position=(0.2, 0.3, 0.6))
    b.add_revolute("j1", "ground", "a", point=(0, 0, 0.2), axis=(0.1, 0.2, 1.0))
    b.add_cylindrical("j2", "a", "b", point=(0.25, 0.0, 0.4), axis=(1.0, -0.3, 0.2))
    b.add_prismatic("j3", "b", "c", point=(0.5, 0.0, 0.45), axis=(0.2, 1.0, -0.1))
    b.add_revolute("j4", "a", "d", point=(0.15, 0.2, 0.5), axis=(0.0, 1.0, 0.3))
    b.add_spring_damper("s", "ground", (0.5, 0.5, 1.0), "c", (0.6, 0.1, 0.4), 40.0, 1.5)
    b.add_body_force(
        "b",
        force=(1.0, -2.0, 0.5),
        torque=(0.1, 0.0, -0.2),
        point=(0.45, -0.1, 0.5),
        profile=ad.profiles.sine(1.0, 2.0, 0.0, 0.0),
    )
    b.add_joint_spring_damper("j3", stiffness=30.0, damping=0.8, rest=0.02)
    b.add_joint_friction("j2", viscous=0.05, coulomb=0.2, smoothing_velocity=1e-2, coord=0)
    b.add_motor("j1", ad.profiles.sine(0.4, 1.5, 0.0, 0.0), kp=20.0, kd=2.0, torque_limit=3.0)
    b.add_joint_torque("j4", ad.profiles.sine(0.3, 3.0, 0.0, 0.0))
    return b.finalize()


def test_force_elements_equal_the_cartesian_path():
    model = spatial_arm()
    td = _core._TreeDynamics(model)
    rng = np.random.default_rng(5)
    n = model.n_coords
    worst = 0.0
    for t in np.linspace(0.0, 2.0, 9):
        q, qd, tau = rng.uniform(-1.0, 1.0, size=(3, n))
        a = td(q, qd, tau, t)
        assert np.array_equal(ad.forward_dynamics(model, q, qd, tau, t, method="joint"), a)
        kkt = ad.forward_dynamics(model, q, qd, tau, t, method="cartesian")
        worst = max(worst, np.abs(a - kkt).max() / np.abs(a).max())
    assert worst <= 1e-10


def test_spatial_arm_runs_equal_on_both_paths():
    model = spatial_arm()
    kw = dict(integrator="dop853", rtol=1e-12, atol=1e-12, output_dt=0.1)
    cart = ad.simulate(model, 2.0, **kw)
    joint = ad.simulate(model, 2.0, coordinates="joint", **kw)
    assert joint.stats["formulation"].startswith("joint space: 5 coordinates")
    # measured: q 2.0e-11, reactions 2.0e-12 relative, energy 1.9e-12 relative
    assert np.abs(joint.q - cart.q).max() <= 1e-9
    assert np.ptp(cart.q[:, 0]) > 0.3  # it moves
    scale = np.abs(cart.reaction_forces).max()
    assert np.abs(joint.reaction_forces - cart.reaction_forces).max() <= 1e-7 * scale
    energy = joint.total_energy - cart.total_energy
    assert np.abs(energy).max() <= 1e-8 * np.abs(cart.total_energy).max()
    assert joint.position_residual.max() <= 1e-13  # built by forward kinematics


# the geared arm's motion compressed into [0.1, 1.1] s (the default quintics run over
# [0.5, 4.5] s): the same scene and checks in a 0.8 s run, where a rotor passes 1.5 turns at 0.6 s
# (the default motion needed 2.5 s for it, and the Cartesian run 126 s of the suite)
QUICK_GEARED_ARM = {"t_start": 0.1, "t_end": 1.1}


def test_geared_arm_joint_path_equals_the_reference_and_the_cartesian_run():
    """The 44-body geared arm (18 coordinates, 12 ideal gears: 6 independent) on its PD motors.
    At moving states its accelerations equal those of the Pinocchio reference of the
    geared_arm work-precision problem (CRBA/RNEA of the open tree, reduced by the gear ratios; no
    armdyn code) for the same scene, and a 0.8 s run, in which a rotor passes 1.5 turns, agrees
    with the Cartesian path."""
    from benchmarks.references import GearedArmReference

    model = geared_arm_6dof(backlash=0.0, **QUICK_GEARED_ARM)
    ref = GearedArmReference(**QUICK_GEARED_ARM)
    f, _ = ref.rhs()
    perm = [list(ref.tree.coord_names).index(c) for c in model.joint_coord_names]
    td = _core._TreeDynamics(model)
    assert td.dof == 6
    n = model.n_joint_coords
    rng = np.random.default_rng(2)
    worst = 0.0
    for t in (0.05, 0.4, 0.9):  # before the motion and during it (the references' terms)
        p, pd = rng.uniform(-1.0, 1.0, size=(2, 6))
        q, qd = (ref.T @ x for x in (p, pd))  # on the gear rows
        qdd_ref = (ref.T @ f(t, np.concatenate([p, pd]))[6:])[perm]
        qdd = td(q[perm], qd[perm], np.zeros(n), t)
        worst = max(worst, np.abs(qdd - qdd_ref).max() / np.abs(qdd_ref).max())
    assert worst <= 1e-10
    kw = dict(integrator="dop853", rtol=1e-10, atol=1e-10, output_dt=0.05)
    cart = ad.simulate(model, 0.8, **kw)
    joint = ad.simulate(model, 0.8, coordinates="joint", **kw)
    assert "18 coordinates, 12 ideal-gear rows (rank 12)" in joint.stats["formulation"]
    # measured: 1.8e-13 rad; gear forces 4.2e-11 relative
    assert np.abs(joint.q - cart.q).max() <= 1e-9
    assert np.abs(joint.q).max() > 3 * np.pi  # a rotor passes 1.5 turns
    gf = joint.gear_forces["force"] - cart.gear_forces["force"]
    assert np.abs(gf).max() <= 1e-6 * np.abs(cart.gear_forces["force"]).max()
    assert joint.position_residual.max() <= 1e-12  # gear rows held over the turns


def test_joint_path_bad_input():
    with pytest.raises(ad.ModelError, match=r"coordinates 'joint'.*closed loops"):
        ad.simulate(ad.scenes.four_bar(), 0.1, coordinates="joint")
    with pytest.raises(ad.ModelError, match=r"coordinates must be one of .* got 'minimal'"):
        ad.simulate(spatial_arm(), 0.1, coordinates="minimal")
    # a driven tree: the joint path has no driving rows; "auto" falls back and says why
    b = ad.ModelBuilder()
    b.add_body("bar", 1.0, [0.01, 0.01, 0.01], position=(0.5, 0, 0))
    b.add_body("tip", 0.5, [0.01, 0.01, 0.01], position=(1.0, 0, 0))
    b.add_revolute("pitch", "ground", "bar", point=(0, 0, 0), axis=(0, 1, 0))
    b.add_revolute("elbow", "bar", "tip", point=(0.8, 0, 0), axis=(0, 1, 0))
    b.add_drive("pitch", ad.profiles.sine(0.3, 1.0, 0.0, 0.0))
    driven = b.finalize()
    with pytest.raises(ad.ModelError, match=r"coordinates 'joint'.*drive 'pitch' prescribes"):
        ad.simulate(driven, 0.1, coordinates="joint", integrator="dopri5")
    res = ad.simulate(driven, 0.05, coordinates="auto", integrator="dopri5")
    assert "joint space does not apply: drive 'pitch' prescribes" in res.stats["formulation"]
    assert "not available (drive 'pitch'" in driven.summary()
    res = ad.simulate(ad.scenes.four_bar(), 0.05, coordinates="auto")
    assert "joint space does not apply: the model has closed loops" in res.stats["formulation"]
    model = spatial_arm()
    td = _core._TreeDynamics(model)
    z = np.zeros(model.n_coords)
    with pytest.raises(ad.ModelError, match="TreeDynamics: q contains NaN"):
        td(np.full(model.n_coords, np.nan), z, z)
    with pytest.raises(ad.ModelError, match=r"tau: expected shape \(5,\), got \(2,\)"):
        td(z, z, np.zeros(2))
    with pytest.raises(ad.ModelError, match="closed loops"):
        _core._TreeDynamics(ad.scenes.four_bar())
    with pytest.raises(
        ad.ModelError, match="method must be 'auto', 'joint', 'crba', 'aba' or 'cartesian'"
    ):
        ad.forward_dynamics(model, z, z, z, method="lu")
    # the model and a run after the errors are intact
    assert ad.simulate(model, 0.1, coordinates="auto").stats["formulation"].startswith("joint")
