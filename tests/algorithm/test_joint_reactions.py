"""armdyn.joint_reactions: every joint's reaction along a given joint-space motion of a tree (on
the child at the joint point, in the child's joint frame; SimulationResult's convention), with
the inverse dynamics' joint torques. Checked against Pinocchio's RNEA joint forces ``data.f``
(moved to armdyn's joint frame and point; their axis component is the joint torque, which the
reaction leaves out), against a joint-space ``simulate`` run's own reactions at its output
samples, and through couplings, actuators, fixed joints and floating bases against models that
must give the same reactions."""

from __future__ import annotations

import armdyn as ad
import numpy as np
import pytest
from welded_scene import quat, welded_pendulums

from benchmarks import common


def ur5(**kw):
    path = common.robot_urdf("ur5")
    assert path is not None, "example-robot-data is part of the test extra"
    return path, ad.load_urdf(str(path), **kw)


def motion(n_coords, n=25, seed=3, q0=None):
    """A smooth motion q = q0 + a sin(w t + p) sampled at n times, with its exact rates and
    accelerations."""
    rng = np.random.default_rng(seed)
    a = rng.uniform(0.3, 1.0, n_coords)
    w = rng.uniform(1.0, 4.0, n_coords)
    p = rng.uniform(-np.pi, np.pi, n_coords)
    q0 = np.zeros(n_coords) if q0 is None else np.asarray(q0, dtype=float)
    t = np.linspace(0.0, 2.0, n)[:, None]
    q = q0 + a * np.sin(w * t + p)
    qd = a * w * np.cos(w * t + p)
    qdd = -a * w**2 * np.sin(w * t + p)
    return t[:, 0], q, qd, qdd


def rel_err(a, b):
    return float(np.abs(a - b).max() / np.abs(b).max())


@pytest.mark.parametrize("fixed_base", [True, False])
def test_ur5_reactions_equal_pinocchio_rnea_joint_forces(fixed_base):
    pin = pytest.importorskip("pinocchio")
    path, model = ur5(fixed_base=fixed_base)
    root = () if fixed_base else (pin.JointModelFreeFlyer(),)
    pm = pin.buildModelFromUrdf(str(path), *root)
    pd = pm.createData()
    names = [n for n in model.joint_names if n != "root_free"]
    base = 0 if fixed_base else 6  # the floating base's rates lead qd (7 entries of q)
    pin_joints = [pm.getJointId(n) for n in names]
    perm = [pm.joints[j].idx_q for j in pin_joints]  # armdyn coordinate k -> Pinocchio q index
    assert sorted(perm) == list(range(pm.nq - len(names), pm.nq))
    t, q, qd, qdd = motion(len(names), q0=common.UR5_Q0)
    if not fixed_base:
        # the base: a position, a unit quaternion (scalar first) and its rates in its own frame
        _, qb, qdb, qddb = motion(6, seed=5)
        q_base = np.stack([np.cos(qb[:, 3]), *(np.sin(qb[:, 3]) * np.c_[0.6, 0.0, 0.8].T)], axis=1)
        q = np.hstack([qb[:, :3], q_base, q])
        qd, qdd = np.hstack([qdb, qd]), np.hstack([qddb, qdd])
    forces, torques = ad.joint_reactions(model, q, qd, qdd, t)
    assert forces.shape == torques.shape == (len(t), len(model.joint_names), 3)
    tau = ad.inverse_dynamics(model, q, qd, qdd, t)
    if not fixed_base:
        # a free joint has no rows: no reaction (its wrench is the inverse dynamics' base entries)
        assert not forces[:, 0].any() and not torques[:, 0].any()
        forces, torques = forces[:, 1:], torques[:, 1:]
    # armdyn's joint frame (z the axis) in the URDF child link's frame, Pinocchio's joint frame
    place = []
    for name in names:
        jf = model.joint_frame(name)
        link = model.frame(jf["child"])
        rot = link["rotation"].T @ jf["frame_child"]
        off = link["rotation"].T @ (jf["point_child"] - link["point"])
        place.append((rot, off))
    worst_f = worst_t = worst_tau = 0.0
    fmax = tmax = taumax = 0.0
    for i in range(len(t)):
        qp, vp, ap = (np.empty(pm.nq) for _ in range(3))
        qp[perm], vp[perm], ap[perm] = q[i, base + base // 6 :], qd[i, base:], qdd[i, base:]
        if not fixed_base:
            qp[:3], qp[3:6], qp[6] = q[i, :3], q[i, 4:7], q[i, 3]  # Pinocchio: scalar last
        vp, ap = vp[pm.nq - pm.nv :], ap[pm.nq - pm.nv :]
        vp[:base], ap[:base] = qd[i, :base], qdd[i, :base]
        tau_pin = pin.rnea(pm, pd, qp, vp, ap)
        friction = -pm.damping * vp - pm.friction * np.tanh(vp / ad._core.URDF_COULOMB_SMOOTHING)
        for k, jid in enumerate(pin_joints):
            rot, off = place[k]
            f_pin = pd.f[jid].linear
            n_pin = pd.f[jid].angular  # about the link frame's origin
            f = rot @ forces[i, k]
            n = rot @ torques[i, k] + np.cross(off, f)  # moved to the link frame's origin
            axis = rot[:, 2]
            # the axis component of data.f is Pinocchio's joint torque; the reaction has none
            assert abs(axis @ (rot @ torques[i, k])) <= 1e-12 * max(1.0, np.abs(n_pin).max())
            worst_f = max(worst_f, np.abs(f - f_pin).max())
            worst_t = max(worst_t, np.abs(n + (axis @ n_pin) * axis - n_pin).max())
            worst_tau = max(worst_tau, abs(axis @ n_pin - tau_pin[pm.joints[jid].idx_v]))
            fmax, tmax = max(fmax, np.abs(f_pin).max()), max(tmax, np.abs(n_pin).max())
        # armdyn's inverse dynamics is Pinocchio's joint torque with the URDF's friction (and
        # the floating base's wrench, Pinocchio's first six)
        tau_ref = tau_pin - friction
        vperm = [pm.joints[j].idx_v for j in pin_joints]
        worst_tau = max(worst_tau, np.abs(tau[i, base:] - tau_ref[vperm]).max())
        if base:
            worst_tau = max(worst_tau, np.abs(tau[i, :base] - tau_ref[:base]).max())
        taumax = max(taumax, np.abs(tau_ref).max())
    # measured: forces 7.9e-16 (5.5e-16 floating), torques 6.5e-16 (7.3e-16), joint torques
    # 3.8e-16 (4.0e-16) relative
    assert worst_f <= 1e-9 * fmax
    assert worst_t <= 1e-9 * tmax
    assert worst_tau <= 1e-9 * taumax


def test_one_state_and_scalar_or_default_time():
    _, model = ur5()
    t, q, qd, qdd = motion(model.n_coords, n=3)
    rows = ad.joint_reactions(model, q, qd, qdd, t[1])
    f1, n1 = ad.joint_reactions(model, q[1], qd[1], qdd[1], t[1])
    assert f1.shape == n1.shape == (len(model.joint_names), 3)
    np.testing.assert_array_equal(f1, rows[0][1])
    np.testing.assert_array_equal(n1, rows[1][1])
    # t=None is t=0 (the UR5 has no time-dependent load)
    f0, n0 = ad.joint_reactions(model, q[1], qd[1], qdd[1])
    np.testing.assert_array_equal(f0, f1)
    np.testing.assert_array_equal(n0, n1)


def independent(model, res):
    """The run's independent coordinates (model.coord_names) and rates, the floating bases'
    entries first, from its columns over every joint."""
    nf = len(model.coord_names) - model.n_dofs  # floating bases: 7 entries of q, 6 of qd
    cols = list(model.joint_coord_names)[7 * nf :]
    k = [cols.index(c) for c in list(model.coord_names)[7 * nf :]]
    iq = list(range(7 * nf)) + [7 * nf + i for i in k]
    iv = list(range(6 * nf)) + [6 * nf + i for i in k]
    return res.q[:, iq], res.qd[:, iv], res.qdd[:, iv]


def assert_equal_to_run(model, res, rel):
    q, qd, qdd = independent(model, res)
    forces, torques = ad.joint_reactions(model, q, qd, qdd, res.t)
    assert forces.shape == res.reaction_forces.shape
    assert rel_err(forces, res.reaction_forces) <= rel
    assert rel_err(torques, res.reaction_torques) <= rel
    return forces, torques


@pytest.mark.parametrize("merge_welded", [True, False])
def test_fixed_joints_equal_a_joint_space_run(merge_welded):
    # measured: 1.1e-15 (merged) and 1.2e-15 (full) relative
    model = welded_pendulums()
    res = ad.simulate(
        model, 0.6, coordinates="joint", merge_welded=merge_welded, rtol=1e-10, output_dt=0.05
    )
    forces, _ = assert_equal_to_run(model, res, 1e-12)
    # the welds carry loads: the tip's weld its weight and inertia, never zero
    tip = list(model.joint_names).index("tip_mount")
    assert np.abs(forces[:, tip]).max() >= 0.2 * 9.81 * 0.9


@pytest.mark.parametrize("fixed_base", [True, False])
def test_ur5_equal_to_a_joint_space_run(fixed_base):
    # measured 2.4e-15 relative
    _, model = ur5(fixed_base=fixed_base)
    q0, qd0 = np.array(common.UR5_Q0), np.array([0.4, -0.3, 0.5, 0.2, -0.6, 0.3])
    if not fixed_base:  # a base thrown spinning
        q0 = np.r_[0.1, -0.2, 0.3, quat((1, 2, 3), 0.5), q0]
        qd0 = np.r_[0.5, 0.0, 1.0, 0.3, -0.2, 0.4, qd0]
    res = ad.simulate(
        model, 1.0, q0=q0, qd0=qd0, coordinates="joint", limits="ignore", output_dt=0.1
    )
    forces, _ = assert_equal_to_run(model, res, 1e-12)
    if not fixed_base:
        assert not forces[:, 0].any()


def test_fixed_joint_reaction_of_a_hanging_weight_is_its_weight():
    # at rest: the weld carries the weight's gravity (m g up on it, no torque about the weld
    # point above its centre of mass), the pivot both bodies'
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("rod", 1.0, [0.01, 0.01, 1e-4], position=(0, 0, -0.5))
    b.add_revolute("pivot", "ground", "rod", point=(0, 0, 0), axis=(0, 1, 0))
    b.add_body("weight", 2.5, [1e-3, 1e-3, 1e-3], position=(0, 0, -1.1))
    b.add_fixed("weld", "rod", "weight", point=(0, 0, -1.0))
    model = b.finalize()
    f, n = ad.joint_reactions(model, [0.0], [0.0], [0.0])
    j = list(model.joint_names).index("weld")
    np.testing.assert_allclose(f[j], [0.0, 0.0, 2.5 * 9.81], rtol=0, atol=1e-12)
    np.testing.assert_allclose(n[j], 0.0, atol=1e-12)
    # swinging through the bottom at rate w and no angular acceleration: the centripetal
    # force m w^2 r adds to the weight, still along the rod
    w = 1.7
    f, n = ad.joint_reactions(model, [0.0], [w], [0.0])
    np.testing.assert_allclose(f[j], [0.0, 0.0, 2.5 * (9.81 + w**2 * 1.1)], rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(n[j], 0.0, atol=1e-12)
    p = list(model.joint_names).index("pivot")
    assert np.linalg.norm(f[p]) == pytest.approx(3.5 * 9.81 + (0.5 + 2.5 * 1.1) * w**2, rel=1e-13)


def expand(model, q, qd, qdd, follower, leader, multiplier, offset):
    """A coupled motion over every coordinate of the uncoupled model."""
    names = list(model.coord_names)
    i, k = names.index(leader), [n for n in names if n != follower]
    full = []
    for x, shift in ((q, offset), (qd, 0.0), (qdd, 0.0)):
        y = np.empty((len(x), len(names)))
        y[:, [names.index(n) for n in k]] = x
        y[:, names.index(follower)] = multiplier * y[:, i] + shift
        full.append(y)
    return full


def test_coupling_gives_the_reactions_of_the_coupled_motion():
    # a coupling (URDF <mimic>) only ties the coordinates' axis torques: every joint's reaction
    # is the uncoupled arm's along the same motion, and a joint-space run's (measured 3.4e-16)
    path, plain = ur5()
    b = ad.urdf_builder(str(path))
    b.add_coupling("wrist_link", "wrist_3_joint", "wrist_2_joint", -1.5, 0.2)
    coupled = b.finalize()
    assert len(coupled.coord_names) == 5
    t, q, qd, qdd = motion(5, q0=np.delete(common.UR5_Q0, 5))
    forces, torques = ad.joint_reactions(coupled, q, qd, qdd, t)
    qf, qdf, qddf = expand(plain, q, qd, qdd, "wrist_3_joint", "wrist_2_joint", -1.5, 0.2)
    ref_f, ref_t = ad.joint_reactions(plain, qf, qdf, qddf, t)
    assert list(coupled.joint_names) == list(plain.joint_names)
    assert rel_err(forces, ref_f) <= 1e-12
    assert rel_err(torques, ref_t) <= 1e-12
    res = ad.simulate(
        coupled, 0.5, q0=q[0], qd0=qd[0], coordinates="joint", limits="ignore", output_dt=0.05
    )
    assert_equal_to_run(coupled, res, 1e-12)


@pytest.mark.parametrize("gyroscopic", [False, True])
def test_actuators(gyroscopic):
    # an armature on ground (gyroscopic=False) turns with its joint and loads no arm body: the
    # arm's reactions are the bare arm's; a rotor on the joint's parent body (gyroscopic=True)
    # adds its gyroscopic moments there: checked against a joint-space run (measured 1.5e-15)
    path, plain = ur5()
    b = ad.urdf_builder(str(path))
    for k, name in enumerate(plain.coord_names):
        b.add_actuator(name, 50.0 + 10 * k, 2e-5 * (k + 1), gyroscopic=gyroscopic)
    model = b.finalize()
    t, q, qd, qdd = motion(6, q0=common.UR5_Q0)
    forces, torques = ad.joint_reactions(model, q, qd, qdd, t)
    names = list(model.joint_names)
    arm = [names.index(n) for n in plain.joint_names]
    ref_f, ref_t = ad.joint_reactions(plain, q, qd, qdd, t)
    if gyroscopic:
        assert rel_err(torques[:, arm], ref_t) >= 1e-6  # the rotors' moments are there
        res = ad.simulate(
            model, 0.3, q0=q[0], qd0=qd[0], coordinates="joint", limits="ignore", output_dt=0.05
        )
        assert_equal_to_run(model, res, 1e-12)
        return
    assert rel_err(forces[:, arm], ref_f) <= 1e-12
    assert rel_err(torques[:, arm], ref_t) <= 1e-12
    rotors = [i for i in range(len(names)) if i not in arm]
    assert len(rotors) == 6
    assert np.abs(forces[:, rotors]).max() <= 1e-12
    assert np.abs(torques[:, rotors]).max() <= 1e-12 * np.abs(ref_t).max()
    # the joint torques are the inverse dynamics': the bare arm's and the reflected inertia
    tau = ad.inverse_dynamics(model, q, qd, qdd, t)
    reflected = np.array([(50.0 + 10 * k) ** 2 * 2e-5 * (k + 1) for k in range(6)]) * qdd
    tau_plain = ad.inverse_dynamics(plain, q, qd, qdd, t)
    assert rel_err(tau, tau_plain + reflected) <= 1e-12


def test_hostile_inputs_name_their_culprit():
    _, model = ur5()
    z, rows = np.zeros(6), np.zeros((3, 6))
    cases = [
        ((None, z, z, z), "model must be an armdyn.Model"),
        ((model, np.r_[np.nan, z[1:]], z, z), r"\bq contains NaN"),
        ((model, z, z, np.r_[z[1:], np.inf]), r"\bqdd contains NaN"),
        ((model, rows, rows, np.full((3, 6), np.nan)), r"row 0: .*\bqdd contains NaN"),
        ((model, z, z[:5], z), r"\bqd: expected shape \(6,\)"),
        ((model, rows, np.zeros((2, 6)), rows), r"\bqd must have shape \(3, 6\)"),
        ((model, rows, z, rows), r"\bqd must have shape \(3, 6\)"),
        ((model, z + 1j, z, z), r"\bq: must hold real numbers"),
        ((model, "abc", z, z), r"\bq: expected an array"),
        ((model, z, z, z, np.nan), r"\bt is not finite"),
        ((model, z, z, z, "x"), r"\bt must be a number"),
        ((model, rows, rows, rows, [0.0, 1.0]), r"\bt: expected shape \(3,\)"),
        # a loop model takes its independent coordinates (the four-bar: the crank angle alone)
        (
            (ad.scenes.four_bar(), np.zeros(4), np.zeros(4), np.zeros(4)),
            r"q: expected shape \(1,\)",
        ),
    ]
    for args, pattern in cases:
        with pytest.raises(ad.ModelError, match=pattern):
            ad.joint_reactions(*args)
    with pytest.raises(ad.ModelError, match="made for another model"):
        ad.joint_reactions(model, z, z, z, data=ad.Data(ad.scenes.four_bar()))
    _, floating = ur5(fixed_base=False)
    with pytest.raises(ad.ModelError, match=r"quaternion of free joint 'root_free'"):
        ad.joint_reactions(floating, np.zeros(13), np.zeros(12), np.zeros(12))
    # finite inputs whose products overflow: a SolverError naming the largest one, never NaN
    with pytest.raises(ad.SolverError, match=r"qdd\[0\] = 1.69.*overflow"):
        ad.joint_reactions(model, z, z, np.full(6, 1.7e308))
    # the workspace and the model stay usable: the same answer as before
    t, q, qd, qdd = motion(6, n=2)
    before = ad.joint_reactions(model, q, qd, qdd, t)
    with pytest.raises(ad.SolverError):
        ad.joint_reactions(model, z, np.full(6, 1e300), z)
    after = ad.joint_reactions(model, q, qd, qdd, t)
    for a, b in zip(before, after, strict=True):
        np.testing.assert_array_equal(a, b)
    # no rows: empty outputs of the right shape
    f, n = ad.joint_reactions(model, np.zeros((0, 6)), np.zeros((0, 6)), np.zeros((0, 6)))
    assert f.shape == n.shape == (0, 6, 3)


def test_trajectory_run_carries_the_reactions():
    # a planned motion (a joint-space run's samples) through trajectory_run: its reactions are
    # the run's own, for every joint (the welds too); its torques the inverse dynamics'
    model = welded_pendulums()
    res = ad.simulate(model, 0.4, coordinates="joint", rtol=1e-10, output_dt=0.05)
    plan = ad.trajectory_run(model, res.t, res.q, res.qd, res.qdd)
    n = (len(res.t), len(model.joint_names), 3)
    assert plan.reaction_forces.shape == plan.reaction_torques.shape == n
    assert rel_err(plan.reaction_forces, res.reaction_forces) <= 1e-12
    assert rel_err(plan.reaction_torques, res.reaction_torques) <= 1e-12
    np.testing.assert_array_equal(
        plan.joint_torques, ad.inverse_dynamics(model, res.q, res.qd, res.qdd, res.t)
    )
    # refused inputs leave no run (trajectory_run's own checks come first)
    with pytest.raises(ad.ModelError, match="trajectory_run"):
        ad.trajectory_run(model, res.t, res.q[:, :1], res.qd, res.qdd)


def test_driven_arm_equals_driven_inverse_dynamics():
    # every joint of the UR5 driven: driven_inverse_dynamics solves the constrained Newton-Euler
    # system (a KKT solve, the drives' multipliers) along the prescribed motion; joint_reactions
    # on the same model (its drives ignored) at that motion gives the same reactions, and its
    # torques are the drives' efforts
    path, plain = ur5()
    b = ad.urdf_builder(str(path))
    for k, name in enumerate(plain.coord_names):
        b.add_drive(name, ad.profiles.sine(0.4 + 0.1 * k, 0.3 + 0.2 * k, k, common.UR5_Q0[k]))
    model = b.finalize()
    times = np.linspace(0.0, 1.0, 11)
    ref = ad.driven_inverse_dynamics(model, times)
    forces, torques = ad.joint_reactions(model, ref.q, ref.qd, ref.qdd, times)
    assert rel_err(forces, ref.reaction_forces) <= 1e-12  # measured 2.8e-16
    assert rel_err(torques, ref.reaction_torques) <= 1e-12
    # the drives play no part: the model without them gives the same
    bare = ad.joint_reactions(plain, ref.q, ref.qd, ref.qdd, times)
    np.testing.assert_array_equal(bare[0], forces)
    np.testing.assert_array_equal(bare[1], torques)
    tau = ad.inverse_dynamics(model, ref.q, ref.qd, ref.qdd, times)
    assert rel_err(tau, ref.drive_forces) <= 1e-12
