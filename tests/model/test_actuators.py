"""Actuators (issue 22): ``ModelBuilder.add_actuator`` puts a gearbox's motor rotor in the
dynamics as a body of its own coupled to the joint (q_rotor = N q). The gear-reduced rotor (on
ground) is exactly Pinocchio's ``model.armature = N^2 J``; the gyroscopic rotor (on the joint's
parent body) is checked against a rotor built by hand and against closed forms. Also: the
applied joint torques every run records (``result.joint_torques``), ``armdyn.Motor``, the
reflected friction and the bad inputs."""

from __future__ import annotations

import pickle

import armdyn as ad
import numpy as np
import pytest
from conftest import rel_err

from benchmarks import common

pin = pytest.importorskip("pinocchio")

# gear ratios and rotor inertias of the arms' actuators (a negative ratio reverses the rotor)
GEARS = {
    "ur5": ([100.0, -100.0, 80.0, 50.0, -50.0, 50.0], [6e-5, 6e-5, 4e-5, 1.5e-5, 1.5e-5, 1.5e-5]),
    "panda": ([100.0, 100.0, -100.0, 80.0, 60.0, 60.0, -60.0], [4e-5] * 4 + [1.5e-5] * 3),
}
# the Panda's fingers (prismatic): ball-screw rotors, ratio in rad/m
FINGER = (2 * np.pi / 2e-3, 1e-7)


def _pin_model(path):
    pm = pin.buildModelFromUrdf(str(path))
    return pm, pm.createData()


def _arm(robot, gyroscopic=False):
    """(armdyn model with actuators, pinocchio model with the armature, pinocchio data, perm,
    reflected armature in Pinocchio order) for an example-robot-data arm."""
    path = common.robot_urdf(robot)
    assert path is not None, "example-robot-data is part of the test extra"
    b = ad.urdf_builder(str(path), mimic=False)  # as Pinocchio's default
    pm, pd = _pin_model(path)
    pin_names = [pm.names[i] for i in range(1, pm.njoints) if pm.joints[i].nq > 0]
    ratios, inertias = GEARS[robot]
    armature = np.zeros(pm.nv)
    k = 0
    for i, name in enumerate(pin_names):
        if pm.joints[pm.getJointId(name)].shortname() == "JointModelPZ" or "finger" in name:
            n, j = FINGER
        else:
            n, j = ratios[k], inertias[k]
            k += 1
        b.add_actuator(name, n, j, gyroscopic=gyroscopic)
        armature[i] = n * n * j
    am = b.finalize()
    names = list(am.coord_names)
    perm = np.array([names.index(n) for n in pin_names])
    pm.armature = armature
    return am, pm, pd, perm, armature


def _to_armdyn(x, perm):
    x = np.asarray(x, dtype=float)
    out = np.empty_like(x)
    out[..., perm] = x
    return out


def _urdf_friction(pm, v):
    """The URDF's joint damping and friction, which armdyn imports and Pinocchio leaves out."""
    vs = ad._core.URDF_COULOMB_SMOOTHING
    return -pm.damping * v - pm.friction * np.tanh(v / vs)


# ----------------------------------------------------------------------------------------------
# the gear-reduced rotor is Pinocchio's armature
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("robot", ["ur5", "panda"])
def test_reduced_rotor_at_rest_equals_pinocchio_armature(robot):
    am, pm, pd, perm, armature = _arm(robot)
    assert np.array_equal(am.reflected_inertia, _to_armdyn(armature, perm))
    rng = np.random.default_rng(3)
    zero = np.zeros(pm.nv)
    worst = {}
    for _ in range(10):
        qp = pin.randomConfiguration(pm)
        tau = rng.normal(scale=20.0, size=pm.nv)
        qdd = rng.normal(size=pm.nv)
        q = _to_armdyn(qp, perm)
        ref_fd = pin.aba(pm, pd, qp, zero, tau)
        ref_id = pin.rnea(pm, pd, qp, zero, qdd)
        ref_m = pin.crba(pm, pd, qp)
        ref_m = np.triu(ref_m) + np.triu(ref_m, 1).T
        checks = {
            "fd_crba": (
                ad.forward_dynamics(am, q, zero, _to_armdyn(tau, perm), method="crba"),
                ref_fd,
            ),
            "fd_cartesian": (
                ad.forward_dynamics(am, q, zero, _to_armdyn(tau, perm), method="cartesian"),
                ref_fd,
            ),
            "fd_auto": (ad.forward_dynamics(am, q, zero, _to_armdyn(tau, perm)), ref_fd),
            "id_joint": (ad.inverse_dynamics(am, q, zero, _to_armdyn(qdd, perm)), ref_id),
            "id_cartesian": (
                ad.inverse_dynamics(am, q, zero, _to_armdyn(qdd, perm), method="cartesian"),
                ref_id,
            ),
        }
        for key, (a, r) in checks.items():
            worst[key] = max(worst.get(key, 0.0), rel_err(a, _to_armdyn(r, perm)))
        m = ad.mass_matrix(am, q)
        worst["mass_matrix"] = max(
            worst.get("mass_matrix", 0.0), rel_err(m[np.ix_(perm, perm)], ref_m)
        )
    assert max(worst.values()) <= 1e-12, worst


@pytest.mark.parametrize("robot", ["ur5", "panda"])
def test_reduced_rotor_cartesian_run_starts_with_pinocchio_accelerations(robot):
    # simulate(coordinates="cartesian") at t = 0 from rest: the bodies' constrained Newton-Euler
    # equations with the rotor bodies and their couplings' rows give Pinocchio's armature
    # accelerations (gravity alone acting), and each rotor turns at N qdd
    am, pm, pd, perm, _ = _arm(robot)
    qp = pin.neutral(pm) + 0.3 * np.arange(1, pm.nq + 1) / pm.nq
    qp = np.clip(qp, pm.lowerPositionLimit, pm.upperPositionLimit)
    zero = np.zeros(pm.nv)
    ref = _to_armdyn(pin.aba(pm, pd, qp, zero, zero), perm)
    cols = [list(am.joint_dof_names).index(n) for n in am.dof_names]
    for coords in ("cartesian", "joint"):
        # free dynamics, as Pinocchio's ABA (the clipped fingers sit on their stops)
        r = ad.simulate(
            am,
            1e-3,
            q0=_to_armdyn(qp, perm),
            qd0=zero,
            output_dt=1e-3,
            coordinates=coords,
            limits="ignore",
        )
        assert rel_err(r.qdd[0, cols], ref) <= 1e-12, coords
        for a in am.actuators:
            # the gear-reduced rotor's armature (N^2 J) turns with its joint
            k = list(am.joint_dof_names).index(a.rotor_joint)
            assert r.qdd[0, k] == pytest.approx(ref[a.dof], rel=1e-12, abs=1e-12)


@pytest.mark.parametrize("robot", ["ur5", "panda"])
def test_reduced_rotor_in_motion_equals_pinocchio_armature(robot):
    # the reduced rotor's kinetic energy is 1/2 N^2 J qdot^2 at any state: it is exactly the
    # armature model, velocity terms included
    am, pm, pd, perm, _ = _arm(robot)
    rng = np.random.default_rng(11)
    worst_fd = worst_id = 0.0
    for _ in range(10):
        qp = pin.randomConfiguration(pm)
        v = rng.normal(size=pm.nv)
        tau = rng.normal(scale=20.0, size=pm.nv)
        qdd = rng.normal(size=pm.nv)
        q, qd = _to_armdyn(qp, perm), _to_armdyn(v, perm)
        ref_fd = pin.aba(pm, pd, qp, v, tau + _urdf_friction(pm, v))
        ref_id = pin.rnea(pm, pd, qp, v, qdd) - _urdf_friction(pm, v)
        for method in ("crba", "cartesian"):
            fd = ad.forward_dynamics(am, q, qd, _to_armdyn(tau, perm), method=method)
            worst_fd = max(worst_fd, rel_err(fd, _to_armdyn(ref_fd, perm)))
        worst_id = max(
            worst_id,
            rel_err(
                ad.inverse_dynamics(am, q, qd, _to_armdyn(qdd, perm)), _to_armdyn(ref_id, perm)
            ),
        )
    assert worst_fd <= 1e-11 and worst_id <= 1e-11, (worst_fd, worst_id)


def _dofs(x, dof, n):
    """A Pinocchio free-flyer velocity-space vector in armdyn's order (base block first)."""
    out = np.zeros(n)
    out[:6], out[dof] = x[:6], x[6:]
    return out


def test_reduced_rotor_on_a_floating_base_equals_pinocchio_armature():
    # the ground-fixed rotor of a floating robot: still 1/2 N^2 J qdot^2, Pinocchio's armature
    # on the joint dofs (the free-flyer's quaternion is scalar-last there)
    path = str(common.robot_urdf("ur5"))
    b = ad.urdf_builder(path, fixed_base=False)
    pm = pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer())
    pd = pm.createData()
    names = [pm.names[i] for i in range(2, pm.njoints)]
    ratios, inertias = GEARS["ur5"]
    for name, n, j in zip(names, ratios, inertias, strict=True):
        b.add_actuator(name, n, j)
    am = b.finalize()
    pm.armature = np.concatenate([np.zeros(6), np.square(ratios) * inertias])
    dof = np.array([list(am.dof_names).index(n) for n in names])
    rng = np.random.default_rng(4)
    worst = 0.0
    for _ in range(5):
        qp = pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq))
        qp[3:7] /= np.linalg.norm(qp[3:7])
        v, tau = rng.normal(size=pm.nv), rng.normal(scale=10.0, size=pm.nv)
        q = np.zeros(am.n_coords)
        q[:7] = [*qp[:3], qp[6], *qp[3:6]]
        q[dof + 1] = qp[7:]
        ref = pin.aba(pm, pd, qp, v, tau + _urdf_friction(pm, v))
        qd, t, ref = (_dofs(x, dof, am.n_dofs) for x in (v, tau, ref))
        worst = max(worst, rel_err(ad.forward_dynamics(am, q, qd, t), ref))
    assert worst <= 1e-11


def test_coupled_aba_is_refused_by_name():
    am, *_ = _arm("ur5")
    with pytest.raises(ad.ModelError, match="aba"):
        ad.forward_dynamics(am, np.zeros(6), np.zeros(6), np.zeros(6), method="aba")


# ----------------------------------------------------------------------------------------------
# the gyroscopic rotor
# ----------------------------------------------------------------------------------------------

I_A = np.diag([0.3, 0.4, 0.5])
I_B = np.diag([0.02, 0.05, 0.05])  # axisymmetric about x (the spin axis)


def _turntable(actuator=None, explicit=False, N=40.0, J=2e-4, axis2=(1.0, 0.0, 0.0)):
    """A turntable A (joint 'turn' about world z) carrying, on joint 'spin' about `axis2` at
    (0.2, 0, 0.5), a body B axisymmetric about that axis; no gravity. actuator: the keyword
    arguments of add_actuator on 'spin'; explicit: the same rotor built by hand on A."""
    b = ad.ModelBuilder(gravity=(0.0, 0.0, 0.0))
    b.add_body("A", 2.0, I_A, (0.0, 0.0, 0.25), (1.0, 0.0, 0.0, 0.0))
    b.add_revolute("turn", "ground", "A", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    a2 = np.asarray(axis2, dtype=float) / np.linalg.norm(axis2)
    # B's inertia about its own axis a2: I_B in a frame whose x axis is a2
    e = np.cross(a2, [0.0, 1.0, 0.0]) if abs(a2[1]) < 0.9 else np.cross(a2, [1.0, 0.0, 0.0])
    e /= np.linalg.norm(e)
    R = np.column_stack([a2, np.cross(e, a2), e])
    R[:, 1] = np.cross(R[:, 2], R[:, 0])
    b.add_body("B", 1.0, R @ I_B @ R.T, (0.2, 0.0, 0.5), (1.0, 0.0, 0.0, 0.0))
    b.add_revolute("spin", "A", "B", (0.2, 0.0, 0.5), a2)
    if actuator is not None:
        b.add_actuator("spin", N, J, **actuator)
    if explicit:
        disc = 0.5 * J * (np.eye(3) + np.outer(a2, a2))
        b.add_body("rotor", 0.0, disc, (0.2, 0.0, 0.5), (1.0, 0.0, 0.0, 0.0))
        b.add_revolute("rotor", "A", "rotor", (0.2, 0.0, 0.5), a2)
        b.add_coupling("rotor", "rotor", "spin", N)
    return b.finalize()


def test_gyroscopic_rotor_equals_a_rotor_built_by_hand():
    rng = np.random.default_rng(5)
    for axis2 in ((1.0, 0.0, 0.0), (0.3, -0.4, 0.866)):
        m = _turntable({"gyroscopic": True}, axis2=axis2)
        h = _turntable(explicit=True, axis2=axis2)
        assert m.joint_coord_names == ["turn", "spin", "spin_rotor"]
        assert h.joint_coord_names == ["turn", "spin", "rotor"]
        for _ in range(5):
            q, qd, tau = rng.normal(size=2), rng.normal(size=2), rng.normal(size=2)
            assert rel_err(ad.mass_matrix(m, q), ad.mass_matrix(h, q)) <= 1e-14
            for method in ("crba", "cartesian"):
                a = ad.forward_dynamics(m, q, qd, tau, method=method)
                assert rel_err(a, ad.forward_dynamics(h, q, qd, tau, method=method)) <= 1e-13
            qdd = rng.normal(size=2)
            assert (
                rel_err(ad.inverse_dynamics(m, q, qd, qdd), ad.inverse_dynamics(h, q, qd, qdd))
                <= 1e-13
            )


def test_gyroscopic_rotor_coaxial_carrier_mass_matrix_closed_form():
    # spin parallel to turn: the rotor on A turns at (qd_turn + N qd_spin) about z, kinetic
    # energy 1/2 J (qd_turn + N qd_spin)^2, so M_gyro - M_bare = J [[1, N], [N, N^2]] while the
    # reduced rotor adds only N^2 J at (spin, spin)
    N, J = -30.0, 3e-4
    kw = {"N": N, "J": J, "axis2": (0.0, 0.0, 1.0)}
    bare = _turntable(**kw)
    gyro = _turntable({"gyroscopic": True}, **kw)
    red = _turntable({}, **kw)
    q = np.array([0.4, -1.1])
    d_gyro = ad.mass_matrix(gyro, q) - ad.mass_matrix(bare, q)
    d_red = ad.mass_matrix(red, q) - ad.mass_matrix(bare, q)
    assert np.allclose(d_gyro, J * np.array([[1.0, N], [N, N * N]]), rtol=0, atol=1e-15)
    assert np.allclose(d_red, np.diag([0.0, N * N * J]), rtol=0, atol=1e-15)
    assert np.array_equal(gyro.reflected_inertia, [0.0, N * N * J])


def test_gyroscopic_torque_on_the_turntable_bearing_closed_form():
    # turntable at Omega, B and rotor spinning about A's x axis: every inertia is constant along
    # the motion (B and the rotor axisymmetric about x, centres on the axes), so qdd = 0 and the
    # ground's torque on A through 'turn' is the rate of the angular momentum. The gyroscopic
    # rotor adds Omega z x (J N qd_spin x) = J N Omega qd_spin y to it; the reduced rotor nothing.
    N, J, omega, qd2 = 40.0, 2e-4, 3.0, 5.0
    runs = {}
    for key, act in (("bare", None), ("reduced", {}), ("gyro", {"gyroscopic": True})):
        m = _turntable(act, N=N, J=J)
        for coords in ("cartesian", "joint"):
            r = ad.simulate(
                m, 1e-3, q0=[0.0, 0.0], qd0=[omega, qd2], output_dt=1e-3, coordinates=coords
            )
            cols = [list(m.joint_dof_names).index(n) for n in ("turn", "spin")]
            assert np.max(np.abs(r.qdd[0, cols])) <= 1e-9
            jf = m.joint_frame("turn")
            tq = jf["frame_child"] @ r.reaction_torques[0, 0]  # in A's axes = world at t = 0
            runs[key, coords] = tq
    for coords in ("cartesian", "joint"):
        extra = runs["gyro", coords] - runs["bare", coords]
        assert np.allclose(extra, [0.0, J * N * omega * qd2, 0.0], rtol=0, atol=1e-9), extra
        assert np.allclose(runs["reduced", coords], runs["bare", coords], rtol=0, atol=1e-9)


# ----------------------------------------------------------------------------------------------
# friction, prismatic rotors, energy
# ----------------------------------------------------------------------------------------------


def _wheel(**actuator):
    """A wheel on joint 'w' about world z (inertia 0.1 about it), no gravity."""
    b = ad.ModelBuilder(gravity=(0.0, 0.0, 0.0))
    b.add_body("wheel", 1.0, np.diag([0.05, 0.05, 0.1]), (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))
    b.add_revolute("w", "ground", "wheel", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    b.add_actuator("w", **actuator)
    return b.finalize()


def test_motor_side_friction_reflects_as_n2_b_and_n_c():
    N, J, bv, c = -50.0, 1e-4, 2e-4, 0.03
    m = _wheel(gear_ratio=N, rotor_inertia=J, friction_viscous=bv, friction_coulomb=c)
    (a,) = m.actuators
    assert a.friction_smoothing == pytest.approx(1e-3 * abs(N))
    for qd in (-2.0, -1e-4, 0.0, 3e-5, 0.7):
        tau = ad.inverse_dynamics(m, [0.0], [qd], [0.0])[0]
        # the rotor's friction -b w - c tanh(w / v_s) at w = N qd, reflected by N
        expected = N * N * bv * qd + N * c * np.tanh(N * qd / a.friction_smoothing)
        assert tau == pytest.approx(expected, rel=1e-13, abs=1e-18)
        qdd = ad.forward_dynamics(m, [0.0], [qd], [0.0], method="cartesian")[0]
        assert qdd == pytest.approx(-expected / (0.1 + N * N * J), rel=1e-12, abs=1e-18)


def test_ball_screw_rotor_on_a_prismatic_joint():
    # a slider of mass m along x driven by a screw of lead p: the rotor turns at 2 pi / p rad/m,
    # the slider's effective mass is m + N^2 J in both formulations
    lead, J, mass = 5e-3, 2e-5, 3.0
    N = 2 * np.pi / lead
    b = ad.ModelBuilder(gravity=(0.0, 0.0, 0.0))
    b.add_body("slider", mass, 0.01 * np.eye(3), (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))
    b.add_prismatic("x", "ground", "slider", (0.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    b.add_actuator("x", N, J, gyroscopic=True)
    m = b.finalize()
    F = 7.0
    for method in ("crba", "cartesian"):
        a = ad.forward_dynamics(m, [0.01], [0.2], [F], method=method)[0]
        assert a == pytest.approx(F / (mass + N * N * J), rel=1e-12)
    for coords in ("cartesian", "joint"):
        r = ad.simulate(
            m, 0.5, q0=[0.0], qd0=[0.1], rtol=1e-10, atol=1e-12, output_dt=0.1, coordinates=coords
        )
        # free slider: constant speed; the rotor angle N x (multi-turn)
        assert np.allclose(r.q[:, 0], 0.1 * r.t, rtol=0, atol=1e-9)
        assert np.allclose(r.q[:, 1], N * 0.1 * r.t, rtol=0, atol=1e-6)


@pytest.mark.parametrize("gyroscopic", [False, True])
@pytest.mark.parametrize("coords", ["cartesian", "joint"])
def test_passive_actuated_double_pendulum_conserves_energy(gyroscopic, coords):
    # rotor kinetic energy included (the reduced rotor's sits on ground: it is a body too)
    b = ad.ModelBuilder()
    b.add_body("l1", 1.0, np.diag([0.01, 0.02, 0.02]), (0.25, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))
    b.add_revolute("j1", "ground", "l1", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    b.add_body("l2", 0.5, np.diag([0.005, 0.01, 0.01]), (0.75, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))
    b.add_revolute("j2", "l1", "l2", (0.5, 0.0, 0.0), (0.0, 1.0, 0.0))
    b.add_actuator("j1", 20.0, 1e-4, gyroscopic=gyroscopic)
    b.add_actuator("j2", -15.0, 5e-5, gyroscopic=gyroscopic)
    m = b.finalize()
    r = ad.simulate(
        m,
        2.0,
        rtol=1e-10,
        atol=1e-12,
        output_dt=0.05,
        coordinates=coords,
        q0=[0.3, -0.5],
        qd0=[1.0, 2.0],
    )
    e = r.total_energy
    # the rotors carry a visible share of the kinetic energy
    ke_rotor = 0.5 * (20.0**2 * 1e-4 * r.qd[0, 0] ** 2)
    assert r.kinetic_energy[0] > ke_rotor > 0.01 * r.kinetic_energy[0]
    assert np.max(np.abs(e - e[0])) <= 1e-8 * max(1.0, np.max(np.abs(r.kinetic_energy)))


@pytest.mark.parametrize("gyroscopic", [False, True])
def test_rotor_on_a_welded_carrier_runs_the_same_merged_or_not(gyroscopic):
    # the pitch rotor's carrier 'bracket' is welded to 'base': merge_welded integrates them as
    # one composite (the rotor joint then sits on it); the joint-space run agrees too
    b = ad.ModelBuilder()
    b.add_body("base", 2.0, np.diag([0.02, 0.02, 0.03]), (0.0, 0.0, 0.1), (1.0, 0.0, 0.0, 0.0))
    b.add_revolute("yaw", "ground", "base", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    b.add_body("bracket", 0.5, np.diag([1e-3, 1e-3, 1e-3]), (0.1, 0.0, 0.2), (1.0, 0.0, 0.0, 0.0))
    b.add_fixed("weld", "base", "bracket", (0.1, 0.0, 0.2))
    b.add_body("arm", 1.0, np.diag([0.002, 0.03, 0.03]), (0.4, 0.0, 0.2), (1.0, 0.0, 0.0, 0.0))
    b.add_revolute("pitch", "bracket", "arm", (0.1, 0.0, 0.2), (0.0, 1.0, 0.0))
    b.add_actuator("pitch", 50.0, 1e-4, gyroscopic=gyroscopic)
    b.add_actuator("yaw", 80.0, 1e-4, gyroscopic=gyroscopic)
    m = b.finalize()
    kw = {"q0": [0.2, 0.3], "qd0": [2.0, -1.0], "rtol": 1e-10, "atol": 1e-12, "output_dt": 0.1}
    merged = ad.simulate(m, 0.5, merge_welded=True, **kw)
    full = ad.simulate(m, 0.5, merge_welded=False, **kw)
    joint = ad.simulate(m, 0.5, coordinates="joint", **kw)
    assert merged.stats["solver_bodies"] == full.stats["solver_bodies"] - 1
    assert np.allclose(merged.q, full.q, rtol=0, atol=1e-7)
    assert np.allclose(joint.q, full.q, rtol=0, atol=1e-7)
    # the gyroscopic rotors turn at N qdot (motor side) in the results, relative to their
    # carriers; the gear-reduced armatures (N^2 J) with their joints
    n_pitch, n_yaw = (50.0, 80.0) if gyroscopic else (1.0, 1.0)
    assert np.allclose(full.qd[:, 2], n_pitch * full.qd[:, 1], rtol=1e-9, atol=1e-9)
    assert np.allclose(full.qd[:, 3], n_yaw * full.qd[:, 0], rtol=1e-9, atol=1e-9)
    e = full.total_energy
    assert np.max(np.abs(e - e[0])) <= 1e-8 * np.max(full.kinetic_energy)


# ----------------------------------------------------------------------------------------------
# the model's view of its actuators
# ----------------------------------------------------------------------------------------------


def test_model_lists_its_actuators_and_keeps_the_users_coordinates():
    path = common.robot_urdf("ur5")
    plain = ad.load_urdf(str(path))
    am, _, _, _, _ = _arm("ur5")
    assert am.coord_names == plain.coord_names
    assert am.dof_names == plain.dof_names
    assert list(am.joint_coord_names) == list(plain.coord_names) + [
        f"{n}_armature" for n in plain.coord_names
    ]
    ratios, inertias = GEARS["ur5"]
    assert [a.joint for a in am.actuators] == list(plain.coord_names)
    for k, a in enumerate(am.actuators):
        assert a.rotor_joint == a.joint + "_armature"
        assert am.dof_names[a.dof] == a.joint
        assert (a.gear_ratio, a.rotor_inertia, a.efficiency) == (ratios[k], inertias[k], 1.0)
        assert (a.friction_viscous, a.friction_coulomb, a.gyroscopic, a.motor) == (
            0.0,
            0.0,
            False,
            None,
        )
    # positions and frames are the robot's: the rotors add no coordinate of the user's
    rng = np.random.default_rng(2)
    q = rng.uniform(-2, 2, size=6)
    tool = am.frame_names[-1]
    p1, p0 = ad.frame_pose(am, q, tool), ad.frame_pose(plain, q, tool)
    for x, y in zip(p1, p0, strict=True):
        assert np.allclose(x, y, rtol=0, atol=1e-14)
    j1, j0 = ad.frame_jacobian(am, q, tool), ad.frame_jacobian(plain, q, tool)
    assert np.allclose(j1, j0, rtol=0, atol=1e-14)
    # the run welds nothing of the rotors away and reports them: same motion either way
    r1 = ad.simulate(am, 0.2, q0=q, qd0=np.zeros(6), output_dt=0.05, merge_welded=True)
    r0 = ad.simulate(am, 0.2, q0=q, qd0=np.zeros(6), output_dt=0.05, merge_welded=False)
    assert np.allclose(r1.q, r0.q, rtol=0, atol=1e-6)


def test_lagrange_validator_with_actuators():
    am, pm, pd, perm, _ = _arm("ur5")
    val = ad.LagrangeValidator(am)
    rng = np.random.default_rng(8)
    qp = pin.randomConfiguration(pm)
    v, a = rng.normal(size=6), rng.normal(size=6)
    ref = pin.rnea(pm, pd, qp, v, a) - _urdf_friction(pm, v)
    tau = val.torques(_to_armdyn(qp, perm), _to_armdyn(v, perm), _to_armdyn(a, perm))
    assert rel_err(tau, _to_armdyn(ref, perm)) <= 1e-9


# ----------------------------------------------------------------------------------------------
# applied joint torques in results
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("coords", ["cartesian", "joint"])
def test_add_motor_torques_are_recorded_and_equal_inverse_dynamics(coords):
    path = common.robot_urdf("ur5")
    b = ad.urdf_builder(str(path))
    pm, pd = _pin_model(path)
    pin_names = [pm.names[i] for i in range(1, pm.njoints) if pm.joints[i].nq > 0]
    ratios, inertias = GEARS["ur5"]
    for k, name in enumerate(pin_names):
        b.add_actuator(name, ratios[k], inertias[k])
        ref = ad.profiles.quintic(0.0, 0.4 * (-1) ** k, 0.0, 0.5)
        b.add_motor(name, ref, kp=800.0, kd=60.0, torque_limit=60.0)
    am = b.finalize()
    names = list(am.coord_names)
    perm = np.array([names.index(n) for n in pin_names])
    pm.armature = np.array([n * n * j for n, j in zip(ratios, inertias, strict=True)])
    r = ad.simulate(am, 0.6, output_dt=0.02, rtol=1e-9, atol=1e-11, coordinates=coords)
    cols = [list(am.joint_dof_names).index(n) for n in am.dof_names]
    rot = [list(am.joint_dof_names).index(a.rotor_joint) for a in am.actuators]
    assert r.joint_torques.shape == r.qd.shape
    assert np.all(r.joint_torques[:, rot] == 0.0)
    tq = r.joint_torques[:, cols]
    assert np.max(np.abs(tq)) == 60.0  # the limit saturates
    worst = 0.0
    for i in range(len(r.t)):
        qp, v, a = r.q[i, cols][perm], r.qd[i, cols][perm], r.qdd[i, cols][perm]
        ref = pin.rnea(pm, pd, qp, v, a) - _urdf_friction(pm, v)
        worst = max(worst, rel_err(tq[i][perm], ref, floor=1.0))
    assert worst <= 1e-9


def test_joint_torque_inputs_and_drives_are_recorded():
    b = ad.ModelBuilder()
    b.add_body("l1", 1.0, np.diag([0.01, 0.02, 0.02]), (0.25, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))
    b.add_revolute("j1", "ground", "l1", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    b.add_body("l2", 0.5, np.diag([0.005, 0.01, 0.01]), (0.75, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))
    b.add_revolute("j2", "l1", "l2", (0.5, 0.0, 0.0), (0.0, 1.0, 0.0))
    b.add_actuator("j2", 30.0, 1e-4)
    b.add_joint_torque("j1", ad.profiles.sine(2.0, 1.5, offset=0.5))
    b.add_joint_spring_damper("j1", 10.0, 0.5, 0.0)  # not an applied torque
    free = b.finalize()
    b.add_drive("j2", ad.profiles.sine(0.3, 1.0))
    driven = b.finalize()
    for m in (free, driven):
        for coords in ("cartesian", "joint") if m is free else ("cartesian",):
            r = ad.simulate(m, 1.0, output_dt=0.1, coordinates=coords)
            prof = 0.5 + 2.0 * np.sin(2 * np.pi * 1.5 * r.t)
            assert np.allclose(r.joint_torques[:, 0], prof, rtol=0, atol=1e-12)
            assert np.all(r.joint_torques[:, 2] == 0.0)  # the rotor
            if m is driven:
                assert np.array_equal(r.joint_torques[:, 1], r.drive_forces[:, 0])
                assert np.max(np.abs(r.drive_forces)) > 0.1
            else:
                assert np.all(r.joint_torques[:, 1] == 0.0)


# ----------------------------------------------------------------------------------------------
# Motor and bad inputs
# ----------------------------------------------------------------------------------------------


def test_motor_fields_repr_equality_and_pickle():
    m = ad.Motor(
        name="EC 45", torque_constant=0.0369, resistance=0.608, voltage=24.0, peak_torque=2.1
    )
    assert m.name == "EC 45" and m.torque_constant == 0.0369 and m.voltage == 24.0
    assert m.no_load_speed is None and m.thermal_time_constant is None
    assert eval(repr(m), {"armdyn": ad}) == m
    assert pickle.loads(pickle.dumps(m)) == m
    assert m != ad.Motor(name="EC 45", torque_constant=0.0369)
    assert ad.Motor() == ad.Motor() and ad.Motor() != 1
    with pytest.raises(TypeError):
        ad.Motor(0.03)  # keyword-only
    for bad in (0.0, -1.0, float("inf"), float("nan")):
        with pytest.raises(ad.ModelError, match="voltage"):
            ad.Motor(voltage=bad)
    b = ad.ModelBuilder()
    b.add_body("a", 1.0, 0.1 * np.eye(3), (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))
    b.add_revolute("j", "ground", "a", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    b.add_actuator("j", 10.0, 1e-4, efficiency=0.8, motor=m)
    (a,) = b.finalize().actuators
    assert a.motor == m and a.efficiency == 0.8


def _bad_builder():
    b = ad.ModelBuilder()
    b.add_body("a", 1.0, 0.1 * np.eye(3), (0.0, 0.0, -0.5), (1.0, 0.0, 0.0, 0.0))
    b.add_revolute("j", "ground", "a", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    b.add_body("c", 1.0, 0.1 * np.eye(3), (0.0, 0.0, -1.0), (1.0, 0.0, 0.0, 0.0))
    b.add_spherical("ball", "a", "c", (0.0, 0.0, -1.0))
    b.add_body("d", 1.0, 0.1 * np.eye(3), (0.0, 0.0, -1.5), (1.0, 0.0, 0.0, 0.0))
    b.add_revolute("k", "c", "d", (0.0, 0.0, -1.5), (1.0, 0.0, 0.0))
    b.add_body("k_armature", 0.0, np.zeros((3, 3)), (0.0, 0.0, -1.5), (1.0, 0.0, 0.0, 0.0))
    b.add_fixed("fix", "d", "k_armature", (0.0, 0.0, -1.5))
    b.add_actuator("j", 10.0, 1e-4)
    return b


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"joint": "nope"}, "unknown joint"),
        ({"joint": "ball"}, "spherical"),
        ({"joint": "fix"}, "fixed"),
        ({"joint": "j"}, "already has an actuator"),
        ({"joint": "k"}, "'k_armature' exists"),
        ({"gear_ratio": 0.0}, "gear_ratio"),
        ({"gear_ratio": float("inf")}, "gear_ratio"),
        ({"gear_ratio": float("nan")}, "gear_ratio"),
        ({"rotor_inertia": -1e-6}, "rotor_inertia"),
        ({"rotor_inertia": float("nan")}, "rotor_inertia"),
        ({"efficiency": 0.0}, "efficiency"),
        ({"efficiency": 1.01}, "efficiency"),
        ({"efficiency": float("nan")}, "efficiency"),
        ({"friction_viscous": -1.0}, "friction_viscous"),
        ({"friction_coulomb": -0.1}, "friction_coulomb"),
        ({"friction_coulomb": float("inf")}, "friction_coulomb"),
        ({"friction_smoothing": 0.0}, "friction_smoothing"),
        ({"motor": "maxon"}, "armdyn.Motor"),
    ],
)
def test_bad_actuator_inputs_raise_and_leave_the_builder_intact(kwargs, match):
    b = _bad_builder()
    # a revolute joint without an actuator, and the bad value
    b.add_body("e", 1.0, 0.1 * np.eye(3), (0.0, 0.0, -2.0), (1.0, 0.0, 0.0, 0.0))
    b.add_revolute("k2", "d", "e", (0.0, 0.0, -2.0), (1.0, 0.0, 0.0))
    before = b.finalize()
    args = {"joint": "k2", "gear_ratio": 10.0, "rotor_inertia": 1e-4, **kwargs}
    with pytest.raises(ad.ModelError, match=match) as err:
        b.add_actuator(**args)
    assert args["joint"] in str(err.value)
    after = b.finalize()
    assert after.body_names == before.body_names
    assert after.joint_names == before.joint_names
    assert after.joint_coord_names == before.joint_coord_names
    assert [a.joint for a in after.actuators] == [a.joint for a in before.actuators]
    assert np.array_equal(after.masses, before.masses)
    assert np.array_equal(after.inertias, before.inertias)
    assert np.array_equal(after.u0, before.u0)
    assert after.couplings == before.couplings


def test_docstrings_name_the_rotor_joint_the_builder_makes():
    """add_actuator's and Actuator.rotor_joint's docstrings say what the code does: by default
    '<joint>_armature' turning with the joint (axial inertia N² J), '<joint>_rotor' turning at
    N q̇ with gyroscopic=True (it once said '<joint>_rotor' at N q̇ for both)."""
    reduced, gyro = _turntable({}), _turntable({"gyroscopic": True})
    assert reduced.actuators[0].rotor_joint == "spin_armature"
    assert gyro.actuators[0].rotor_joint == "spin_rotor"
    # the armature turns with the joint, the gyroscopic rotor N times faster (relative to A)
    (arm,) = [c for c in reduced.couplings if c["follower"] == "spin_armature"]
    (rot,) = [c for c in gyro.couplings if c["follower"] == "spin_rotor"]
    assert arm["multiplier"] == 1.0 and rot["multiplier"] == 40.0  # N of _turntable
    doc = " ".join(ad.ModelBuilder.add_actuator.__doc__.split())
    assert (
        "by default (gyroscopic=False) '<joint>_armature' on ground, axial inertia N^2 J, "
        "turning with the joint" in doc
    )
    assert (
        "with gyroscopic=True '<joint>_rotor' on the joint's parent body, axial inertia J, "
        "turning at N qdot" in doc
    )
    field = " ".join(ad.Actuator.rotor_joint.__doc__.split())
    assert "'<joint>_armature' (gyroscopic=False, the default)" in field
    assert "'<joint>_rotor' (gyroscopic=True)" in field
