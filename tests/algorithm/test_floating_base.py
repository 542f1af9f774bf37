"""Floating bases in joint space (issue 21): ``load_urdf(path, fixed_base=False)`` and
``ModelBuilder.add_free`` give q = (x, y, z, e0, e1, e2, e3, joints…) and qd = (v, ω, rates…),
the base frame's velocity in its own axes -- Pinocchio's free-flyer convention with the
quaternion scalar first. Checked against Pinocchio's ``JointModelFreeFlyer`` model of the same
URDF (``crba``, ``rnea``, ``aba``), a closed form (one free rigid body: Euler's equations), and
the two formulations of ``simulate`` against each other and against the ballistic motion of the
centre of mass, and the Lagrange validator (the base in a local chart)."""

import armdyn
import numpy as np
import pytest

from benchmarks import common

pin = pytest.importorskip("pinocchio")

ROBOTS = {
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "panda": "panda_description/urdf/panda.urdf",
    "solo12": "solo_description/robots/solo12.urdf",
    "anymal_c": "anymal_c_simple_description/urdf/anymal.urdf",
    "talos_reduced": "talos_data/robots/talos_reduced.urdf",
}


def _robot_path(rel):
    ur5 = common.robot_urdf("ur5")
    assert ur5 is not None, "example-robot-data is part of the test extra"
    robots = next(p for p in ur5.parents if p.name == "robots")
    return str(robots / rel)


class FreeFlyerPair:
    """The same URDF as an armdyn floating-base model and a Pinocchio free-flyer model, with the
    maps between their q and v (joints matched by name; the quaternion reordered)."""

    def __init__(self, path):
        # each mimicking joint its own coordinate, as Pinocchio by default (aba has no mimic)
        self.am = armdyn.load_urdf(path, fixed_base=False, mimic=False)
        self.pm = pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer())
        self.pd = self.pm.createData()
        names = self.am.coord_names[7:]
        self.iq = np.array([self.pm.idx_qs[self.pm.getJointId(n)] for n in names], dtype=int)
        self.iv = np.array([self.pm.idx_vs[self.pm.getJointId(n)] for n in names], dtype=int)
        self.perm = np.concatenate([np.arange(6), self.iv])

    def q_pin(self, q):
        qp = np.zeros(self.pm.nq)
        qp[:3] = q[:3]
        qp[3:6] = q[4:7]  # Pinocchio: (x, y, z, w)
        qp[6] = q[3]
        qp[self.iq] = q[7:]
        return qp

    def v_pin(self, v):
        vp = np.zeros(self.pm.nv)
        vp[self.perm] = v
        return vp

    def friction(self, vp):
        """The URDF's <dynamics> torques (Pinocchio order), which armdyn imports as joint
        friction and Pinocchio's algorithms leave out (its model.damping, model.friction)."""
        vs = armdyn._core.URDF_COULOMB_SMOOTHING
        return -self.pm.damping * vp - self.pm.friction * np.tanh(vp / vs)

    def random_state(self, rng):
        e = rng.normal(size=4)
        e /= np.linalg.norm(e)
        q = np.concatenate([rng.normal(size=3), e, rng.uniform(-2.0, 2.0, self.am.n_coords - 7)])
        return q, rng.normal(size=self.am.n_dofs), rng.normal(size=self.am.n_dofs)


def _rel(a, b):
    return np.abs(a - b).max() / max(1.0, np.abs(b).max())


@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_free_flyer_dynamics_equal_pinocchio(robot):
    pair = FreeFlyerPair(_robot_path(ROBOTS[robot]))
    am, pm, pd = pair.am, pair.pm, pair.pd
    assert (am.n_coords, am.n_dofs, am.n_free) == (pm.nq, pm.nv, 1)
    assert am.coord_names[:7] == [f"root_free:{s}" for s in ("x", "y", "z", "e0", "e1", "e2", "e3")]
    rng = np.random.default_rng(21)
    for _ in range(5):
        q, v, a = pair.random_state(rng)
        qp, vp, ap = pair.q_pin(q), pair.v_pin(v), pair.v_pin(a)
        Mp = pin.crba(pm, pd, qp)
        Mp = np.triu(Mp) + np.triu(Mp, 1).T
        assert _rel(armdyn.mass_matrix(am, q), Mp[np.ix_(pair.perm, pair.perm)]) <= 1e-10
        tau = armdyn.inverse_dynamics(am, q, v, a)
        ref_tau = pin.rnea(pm, pd, qp, vp, ap) - pair.friction(vp)
        assert _rel(tau, ref_tau[pair.perm]) <= 1e-10
        ref = pin.aba(pm, pd, qp, vp, pair.v_pin(tau) + pair.friction(vp))[pair.perm]
        assert _rel(ref, a) <= 1e-9  # Pinocchio's own round trip
        for method in ("auto", "crba", "aba", "cartesian"):
            qdd = armdyn.forward_dynamics(am, q, v, tau, method=method)
            assert _rel(qdd, ref) <= 1e-10, method


@pytest.mark.parametrize("robot", ["ur5", "solo12"])
def test_lagrange_validator_takes_floating_bases(robot):
    # an independent derivation: Euler-Lagrange by automatic differentiation of the composed
    # joint transforms, the base in a local chart (cpp/src/validate/joint_fk.hpp)
    m = armdyn.load_urdf(_robot_path(ROBOTS[robot]), fixed_base=False)
    lv = armdyn.LagrangeValidator(m)
    rng = np.random.default_rng(8)
    for _ in range(3):
        e = rng.normal(size=4)
        e /= np.linalg.norm(e)
        q = np.concatenate([rng.normal(size=3), e, rng.uniform(-2.0, 2.0, m.n_coords - 7)])
        v, a = rng.normal(size=m.n_dofs), rng.normal(size=m.n_dofs)
        assert _rel(lv.torques(q, v, a), armdyn.inverse_dynamics(m, q, v, a)) <= 1e-12
        np.testing.assert_allclose(lv.mass_matrix(q), armdyn.mass_matrix(m, q), atol=1e-12)


@pytest.mark.parametrize("robot", ["ur5", "solo12"])
def test_floating_base_frames_equal_pinocchio(robot):
    pair = FreeFlyerPair(_robot_path(ROBOTS[robot]))
    am, pm, pd = pair.am, pair.pm, pair.pd
    rng = np.random.default_rng(9)
    frames = [f for f in am.frame_names if pm.existFrame(f)]
    assert len(frames) >= 8
    for _ in range(3):
        q, _, _ = pair.random_state(rng)
        qp = pair.q_pin(q)
        pin.framesForwardKinematics(pm, pd, qp)
        pin.computeJointJacobians(pm, pd, qp)
        for f in frames:
            fid = pm.getFrameId(f)
            np.testing.assert_allclose(
                armdyn.frame_pose(am, q, f), pd.oMf[fid].homogeneous, rtol=0, atol=1e-12
            )
            Jp = pin.getFrameJacobian(pm, pd, fid, pin.LOCAL_WORLD_ALIGNED)
            np.testing.assert_allclose(
                armdyn.frame_jacobian(am, q, f), Jp[:, pair.perm], rtol=0, atol=1e-12
            )


def _free_brick(origin=None):
    b = armdyn.ModelBuilder(gravity=[0.0, 0.0, -9.81])
    inertia = np.diag([0.02, 0.05, 0.06])
    b.add_body("brick", 2.0, inertia, [0.3, -0.1, 0.5], [1.0, 0.0, 0.0, 0.0])
    b.add_free("float", "brick", origin=origin)
    return b.finalize(), inertia


def test_one_free_body_follows_euler_and_newton():
    m, inertia = _free_brick()
    assert (m.n_coords, m.n_dofs, m.n_free) == (7, 6, 1)
    rng = np.random.default_rng(3)
    e = rng.normal(size=4)
    e /= np.linalg.norm(e)
    q = np.concatenate([[0.1, 0.2, 0.3], e])
    v, w = rng.normal(size=3), rng.normal(size=3)
    f_local, n_local = rng.normal(size=3), rng.normal(size=3)
    qdd = armdyn.forward_dynamics(m, q, np.concatenate([v, w]), np.concatenate([f_local, n_local]))
    # closed form, frame at the centre of mass: m (v' + w x v) = R^T m g + f, I w' + w x I w = n
    R = _quat_to_rot(e)
    vdot = R.T @ np.array([0.0, 0.0, -9.81]) + f_local / 2.0 - np.cross(w, v)
    wdot = np.linalg.solve(inertia, n_local - np.cross(w, inertia @ w))
    np.testing.assert_allclose(qdd, np.concatenate([vdot, wdot]), rtol=0, atol=1e-13)
    M = armdyn.mass_matrix(m, q)
    np.testing.assert_allclose(
        M, np.block([[2.0 * np.eye(3), np.zeros((3, 3))], [np.zeros((3, 3)), inertia]]), atol=1e-15
    )


def test_base_frame_away_from_the_centre_of_mass_round_trips():
    m, _ = _free_brick(origin=[0.3, 0.1, 0.5])  # the frame 0.2 m from the centre of mass
    rng = np.random.default_rng(4)
    e = rng.normal(size=4)
    e /= np.linalg.norm(e)
    q = np.concatenate([[0.1, 0.2, 0.3], e])
    qd = rng.normal(size=6)
    u, v = armdyn.state_from_joints(m, q, qd)
    q2, qd2 = armdyn.joint_coordinates(m, u, v)
    np.testing.assert_allclose(q2[:3], q[:3], atol=1e-15)
    assert min(np.abs(q2[3:] - e).max(), np.abs(q2[3:] + e).max()) <= 1e-15
    np.testing.assert_allclose(qd2, qd, atol=1e-14)
    # the frame's origin: the centre of mass (u[:3]) plus the body-fixed offset (0, 0.2, 0)
    np.testing.assert_allclose(u[:3] + _quat_to_rot(u[3:7]) @ [0.0, 0.2, 0.0], q[:3], atol=1e-15)
    # forward dynamics and inverse dynamics invert each other, every method
    tau = rng.normal(size=6)
    for method in ("crba", "aba", "cartesian"):
        qdd = armdyn.forward_dynamics(m, q, qd, tau, method=method)
        np.testing.assert_allclose(armdyn.inverse_dynamics(m, q, qd, qdd), tau, atol=1e-12)


def _quat_to_rot(e):
    w, x, y, z = e / np.linalg.norm(e)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def test_floating_ur5_runs_agree_and_the_centre_of_mass_is_ballistic():
    m = armdyn.load_urdf(_robot_path(ROBOTS["ur5"]), fixed_base=False)
    rng = np.random.default_rng(5)
    e = rng.normal(size=4)
    e /= np.linalg.norm(e)
    q0 = np.concatenate([[0.1, 0.2, 0.3], e, rng.uniform(-2.0, 2.0, 6)])
    q0[7 + 4] = 3.5  # multi-turn: reported as given, not wrapped to -2.78
    qd0 = rng.normal(size=12)
    runs = {
        c: armdyn.simulate(
            m, 0.5, q0=q0, qd0=qd0, rtol=1e-10, atol=1e-12, output_dt=0.05, coordinates=c
        )
        for c in ("cartesian", "joint")
    }
    for c, r in runs.items():
        assert r.q.shape == (11, 13) and r.qd.shape == (11, 12) and r.qdd.shape == (11, 12), c
        np.testing.assert_allclose(r.q[0], q0, atol=1e-13, err_msg=c)
        np.testing.assert_allclose(r.qd[0], qd0, atol=1e-12, err_msg=c)
        energy = r.kinetic_energy + r.potential_energy
        assert np.abs(energy - energy[0]).max() <= 1e-8 * max(1.0, abs(energy[0])), c
        # the centre of mass of the whole robot falls freely
        masses = m.masses
        com = (r.u.reshape(len(r.t), -1, 7)[:, :, :3] * masses[None, :, None]).sum(1) / masses.sum()
        vcom0 = _com_velocity(m, r.v[0])
        expect = com[0] + np.outer(r.t, vcom0) + 0.5 * np.outer(r.t**2, [0.0, 0.0, -9.81])
        np.testing.assert_allclose(com, expect, atol=1e-9, err_msg=c)
        # qdd reported equals forward dynamics at the reported state
        for k in (0, 5, 10):
            f = armdyn.forward_dynamics(m, r.q[k], r.qd[k], np.zeros(12))
            np.testing.assert_allclose(r.qdd[k], f, atol=1e-9, err_msg=c)
    a, b = runs["cartesian"], runs["joint"]
    np.testing.assert_allclose(a.q, b.q, atol=1e-9)
    np.testing.assert_allclose(a.qd, b.qd, atol=1e-8)


def _com_velocity(m, v):
    masses = m.masses
    vel = v.reshape(-1, 6)[:, :3]
    return (vel * masses[:, None]).sum(0) / masses.sum()


def test_fixed_base_q0_keeps_its_turns():
    m = armdyn.load_urdf(_robot_path(ROBOTS["panda"]))
    q0 = np.zeros(m.n_coords)
    q0[m.coord_names.index("panda_joint6")] = 3.5  # limits -0.0175 .. 3.75
    q0[m.coord_names.index("panda_joint4")] = -2.0
    for c in ("cartesian", "joint"):
        r = armdyn.simulate(m, 0.05, q0=q0, output_dt=0.01, coordinates=c)
        assert r.q[0, m.coord_names.index("panda_joint6")] == pytest.approx(3.5, abs=1e-12), c
        assert np.all(r.q[:, m.coord_names.index("panda_joint6")] > 3.0), c


def test_floating_base_bad_inputs_name_the_culprit():
    m = armdyn.load_urdf(_robot_path(ROBOTS["ur5"]), fixed_base=False)
    q = np.zeros(13)
    q[3] = 1.0
    v = np.zeros(12)
    bad = q.copy()
    bad[3] = 2.0
    for fn, args in (
        (armdyn.forward_dynamics, (m, bad, v, v)),
        (armdyn.inverse_dynamics, (m, bad, v, v)),
        (armdyn.mass_matrix, (m, bad)),
        (armdyn.state_from_joints, (m, bad, v)),
    ):
        with pytest.raises(armdyn.ModelError, match="quaternion of free joint 'root_free'"):
            fn(*args)
    with pytest.raises(armdyn.ModelError, match=r"expected shape \(13,\)"):
        armdyn.forward_dynamics(m, q[:12], v, v)
    with pytest.raises(armdyn.ModelError, match="fixed-base models only"):
        armdyn.inverse_dynamics(m, q, v, v, method="cartesian")
    with pytest.raises(armdyn.ModelError, match="quaternion of free joint 'root_free'"):
        armdyn.LagrangeValidator(m).torques(bad, v, v)
    with pytest.raises(armdyn.ModelError, match=r"expected shape \(13,\), got \(12,\)"):
        armdyn.simulate(m, 0.1, q0=np.zeros(12))


def test_floating_base_with_a_welded_body_runs_alike_in_every_formulation():
    # a builder model: a free base (its frame 0.1 m below the centre of mass), a plate welded to
    # it (simulate merges the pair into one composite body) and an arm on a hinge started at
    # 7 rad (multi-turn)
    b = armdyn.ModelBuilder()
    b.add_body("base", 2.0, np.diag([0.02, 0.05, 0.06]), [0.3, -0.1, 0.5], [1.0, 0.0, 0.0, 0.0])
    b.add_body("plate", 0.5, np.diag([0.01, 0.01, 0.02]), [0.3, 0.2, 0.5], [1.0, 0.0, 0.0, 0.0])
    b.add_body("arm", 1.0, np.diag([0.01, 0.01, 0.002]), [0.6, -0.1, 0.5], [1.0, 0.0, 0.0, 0.0])
    b.add_free("float", "base", origin=[0.3, -0.1, 0.4])
    b.add_fixed("weld", "base", "plate", [0.3, 0.1, 0.5])
    b.add_revolute("hinge", "base", "arm", [0.45, -0.1, 0.5], [0.0, 0.0, 1.0])
    m = b.finalize()
    assert m.coord_names[-1] == "hinge" and (m.n_coords, m.n_dofs) == (8, 7)
    rng = np.random.default_rng(0)
    e = rng.normal(size=4)
    e /= np.linalg.norm(e)
    q0 = np.concatenate([[0.0, 0.0, 1.0], e, [7.0]])
    qd0 = rng.normal(size=7)
    runs = {
        (c, merge): armdyn.simulate(
            m,
            0.3,
            q0=q0,
            qd0=qd0,
            rtol=1e-10,
            atol=1e-12,
            output_dt=0.1,
            coordinates=c,
            merge_welded=merge,
        )
        for c in ("cartesian", "joint")
        for merge in (True, False)
    }
    ref = runs[("cartesian", False)]
    assert ref.stats["solver_bodies"] == 3 and runs[("cartesian", True)].stats["solver_bodies"] == 2
    for key, r in runs.items():
        np.testing.assert_allclose(r.q[0], q0, atol=1e-14, err_msg=str(key))
        assert r.q[-1, -1] > 6.0, key  # the hinge keeps its turns
        np.testing.assert_allclose(r.q, ref.q, atol=1e-10, err_msg=str(key))
        np.testing.assert_allclose(r.qd, ref.qd, atol=1e-9, err_msg=str(key))
        np.testing.assert_allclose(
            r.reaction_forces, ref.reaction_forces, atol=1e-9, err_msg=str(key)
        )
