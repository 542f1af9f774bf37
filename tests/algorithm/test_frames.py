"""Named frames (issue 21): every URDF link stays a frame after fixed links are merged, the builder
adds frames (``ModelBuilder.add_frame``), and ``frame_pose`` / ``frame_jacobian`` give a frame's
world pose and its Jacobian (linear rows then angular rows, world axes, at the frame's origin:
Pinocchio's LOCAL_WORLD_ALIGNED).

References: Pinocchio's own URDF parser and ``framesForwardKinematics`` /
``computeFrameJacobian`` on example-robot-data robots (to 1e-12); on a hand-built model with
revolute, prismatic, cylindrical and fixed joints, central finite differences of ``frame_pose``
and the frame velocity from the bodies' velocities of ``state_from_joints`` (a different sweep).
"""

import re

import armdyn as ad
import numpy as np
import pytest
from armdyn.papers import five_dof
from armdyn.validation import end_effector_position
from conftest import quat_to_rot, random_quat, random_unit

from benchmarks import common

# example-robot-data robots with a fixed base and revolute/prismatic joints only, and the frames
# the issue names on them (merged fixed links: tool0, ee_link, panda_hand, gripper frames)
ROBOTS = {
    "ur5": (
        "ur_description/urdf/ur5_robot.urdf",
        ["tool0", "ee_link", "wrist_3_link", "base_link"],
    ),
    "panda": (
        "panda_description/urdf/panda.urdf",
        ["panda_hand", "panda_link8", "panda_leftfinger", "panda_rightfinger", "panda_link0"],
    ),
    "talos_left_arm": ("talos_data/robots/talos_left_arm.urdf", []),
    "kinova": ("kinova_description/robots/kinova.urdf", []),
    "ur10": ("ur_description/urdf/ur10_robot.urdf", ["tool0", "ee_link"]),
}


def robot_path(name):
    ur5 = common.robot_urdf("ur5")
    assert ur5 is not None, "example-robot-data is part of the test extra"
    robots = ur5.parents[2]  # .../example-robot-data/robots
    return robots / ROBOTS[name][0]


class Pair:
    """One URDF in armdyn and in Pinocchio. ``perm[k]``: the armdyn coordinate of Pinocchio's
    velocity k (``qd_armdyn[perm] = qd_pinocchio``); continuous joints take (cos, sin) in
    Pinocchio's configuration."""

    def __init__(self, name):
        pin = pytest.importorskip("pinocchio")
        path = robot_path(name)
        self.pin = pin
        self.pm = pin.buildModelFromUrdf(str(path))
        self.pd = self.pm.createData()
        self.am = ad.load_urdf(str(path), mimic=False)  # Pinocchio's default reading
        names = list(self.am.coord_names)
        joints = [self.pm.joints[i] for i in range(1, self.pm.njoints)]
        assert self.pm.nv == len(names) and all(j.nv == 1 for j in joints)
        self.perm = np.array([names.index(self.pm.names[i]) for i in range(1, self.pm.njoints)])
        self.joints = joints

    def to_pinocchio(self, qa):
        """Pinocchio's configuration for armdyn's joint coordinates qa."""
        q = np.empty(self.pm.nq)
        for j, k in zip(self.joints, self.perm, strict=True):
            if j.nq == 2:  # continuous: (cos, sin)
                q[j.idx_q : j.idx_q + 2] = np.cos(qa[k]), np.sin(qa[k])
            else:
                q[j.idx_q] = qa[k]
        return q

    def link_frames(self):
        """Pinocchio's link (BODY) frames by name."""
        pin = self.pin
        return {f.name: i for i, f in enumerate(self.pm.frames) if f.type == pin.FrameType.BODY}


@pytest.mark.parametrize("robot", list(ROBOTS))
def test_frames_match_pinocchio(robot, rng):
    pair = Pair(robot)
    pin, pm, pd, am = pair.pin, pair.pm, pair.pd, pair.am
    links = pair.link_frames()
    # every URDF link is a frame, whether it became a body, was merged into one or into ground
    assert sorted(am.frame_names) == sorted(links)
    assert len(am.frame_names) > am.nb  # some links were merged
    for name in ROBOTS[robot][1]:
        assert name in am.frame_names
    worst_pose = worst_jac = 0.0
    for _ in range(10):
        qa = rng.uniform(-np.pi, np.pi, am.n_coords)
        q = pair.to_pinocchio(qa)
        pin.framesForwardKinematics(pm, pd, q)
        pin.computeJointJacobians(pm, pd, q)
        for name, fid in links.items():
            T = ad.frame_pose(am, qa, name)
            J = ad.frame_jacobian(am, qa, name)
            assert T.shape == (4, 4) and J.shape == (6, am.n_coords)
            T_pin = pd.oMf[fid].homogeneous
            J_pin = pin.computeFrameJacobian(pm, pd, q, fid, pin.LOCAL_WORLD_ALIGNED)
            worst_pose = max(worst_pose, np.max(np.abs(T - T_pin)))
            worst_jac = max(worst_jac, np.max(np.abs(J[:, pair.perm] - J_pin)))
    assert worst_pose <= 1e-12
    assert worst_jac <= 1e-12


def test_ur5_frames_by_index_rows_and_placement(rng):
    pair = Pair("ur5")
    am = pair.am
    names = list(am.frame_names)
    # the fixed base and what is welded to it sit on ground; tool0 on the last moving link
    assert am.frame("base_link")["body"] == "ground"
    assert am.frame("world")["body"] == "ground"
    assert am.frame("tool0")["body"] == "wrist_3_link"
    assert am.frame("ee_link")["body"] == "wrist_3_link"
    assert am.frame("tool0")["index"] == names.index("tool0")
    # the link frame, not the centre of mass: upper_arm_link's <inertial> is at z = 0.28 in its
    # link frame; ee_link sits 0.0823 along wrist_3_link's y (ur5_robot.urdf)
    np.testing.assert_allclose(am.frame("upper_arm_link")["point"], [0, 0, -0.28], atol=1e-15)
    np.testing.assert_allclose(am.frame("ee_link")["point"], [0, 0.0823, 0], atol=1e-15)
    Q = rng.uniform(-np.pi, np.pi, (4, am.n_coords))
    k = names.index("tool0")
    T_rows, J_rows = ad.frame_pose(am, Q, "tool0"), ad.frame_jacobian(am, Q, np.int64(k))
    assert T_rows.shape == (4, 4, 4) and J_rows.shape == (4, 6, am.n_coords)
    data = ad.Data(am)
    for i in range(4):
        np.testing.assert_array_equal(T_rows[i], ad.frame_pose(am, Q[i], k, data=data))
        np.testing.assert_array_equal(J_rows[i], ad.frame_jacobian(am, Q[i], "tool0", data=data))
    # a frame on ground: constant pose, zero Jacobian
    np.testing.assert_array_equal(ad.frame_jacobian(am, Q[0], "base_link"), 0.0)


def test_floating_base_keeps_the_root_frames():
    """With fixed_base=False the root link's frames ride on the root body; the Cartesian
    frame_pose at the assembled state is the fixed-base pose at q = 0."""
    path = robot_path("ur5")
    fixed = ad.load_urdf(str(path))
    free = ad.load_urdf(str(path), fixed_base=False)
    assert sorted(free.frame_names) == sorted(fixed.frame_names)
    assert free.frame("base_link")["body"] == free.frame("world")["body"] != "ground"
    q0 = np.zeros(fixed.n_coords)
    for name in ("world", "base_link", "tool0", "shoulder_link"):
        T = ad.frame_pose_cartesian(free, free.u0, name)
        np.testing.assert_allclose(T, ad.frame_pose(fixed, q0, name), rtol=0, atol=1e-12)


# ----------------------------------------------------------------------------------------------
# a hand-built model: revolute, prismatic, cylindrical and fixed joints, frames on each body
# ----------------------------------------------------------------------------------------------


def hand_built(rng):
    b = ad.ModelBuilder()
    poses = {}
    for k, name in enumerate(["a", "b", "c", "d"]):
        pos = np.array([0.3 * k, 0.1 * k, 0.2]) + 0.05 * rng.normal(size=3)
        b.add_body(name, 1.0 + k, np.diag([0.1, 0.12, 0.15]), pos, random_quat(rng))
        poses[name] = pos
    b.add_revolute("r", "ground", "a", rng.normal(size=3) * 0.1, random_unit(rng))
    b.add_prismatic("p", "a", "b", poses["a"] + 0.1 * rng.normal(size=3), random_unit(rng))
    b.add_cylindrical("c", "b", "c", poses["b"] + 0.1 * rng.normal(size=3), random_unit(rng))
    b.add_fixed("f", "c", "d")
    frames = {}
    for name, body in (("on_a", "a"), ("on_c", "c"), ("tool", "d"), ("fixed", "ground")):
        pos = (poses[body] if body != "ground" else 0.0) + 0.2 * rng.normal(size=3)
        quat = random_quat(rng)
        b.add_frame(name, body, position=pos, orientation=quat)
        frames[name] = (pos, quat)
    return b, frames


def rotation_log(R):
    """The rotation vector of R (angle below pi)."""
    angle = np.arccos(np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0))
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    return w * (0.5 / np.sinc(angle / np.pi)) if angle > 1e-12 else 0.5 * w


def test_hand_built_frames_at_assembly(rng):
    b, frames = hand_built(rng)
    assert b.frame_names == ["on_a", "on_c", "tool", "fixed"]
    m = b.finalize()
    assert m.frame_names == ["on_a", "on_c", "tool", "fixed"]
    q0 = np.zeros(m.n_coords)
    for name, (pos, quat) in frames.items():
        T = ad.frame_pose(m, q0, name)
        np.testing.assert_allclose(T[:3, 3], pos, rtol=0, atol=1e-14)
        np.testing.assert_allclose(T[:3, :3], quat_to_rot(quat), rtol=0, atol=1e-14)
        np.testing.assert_array_equal(T[3], [0, 0, 0, 1])
        # and from the assembled Cartesian state
        np.testing.assert_allclose(ad.frame_pose_cartesian(m, m.u0, name), T, rtol=0, atol=1e-14)


def test_jacobian_matches_finite_differences_and_body_velocities(rng):
    b, _ = hand_built(rng)
    m = b.finalize()
    n = m.n_coords
    assert n == 4  # revolute, prismatic, cylindrical (angle, displacement)
    h = 1e-6
    for _ in range(5):
        q = rng.uniform(-1.5, 1.5, n)
        qd = rng.normal(size=n)
        u, v = ad.state_from_joints(m, q, qd)
        for name in m.frame_names:
            J = ad.frame_jacobian(m, q, name)
            fd = np.empty((6, n))
            for k in range(n):
                e = np.zeros(n)
                e[k] = h
                Tp, Tm = ad.frame_pose(m, q + e, name), ad.frame_pose(m, q - e, name)
                fd[:3, k] = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
                fd[3:, k] = rotation_log(Tp[:3, :3] @ Tm[:3, :3].T) / (2 * h)
            # central differences: O(h^2) truncation plus 1e-16/h round-off
            assert np.max(np.abs(J - fd)) <= 1e-8
            # the frame's velocity from its body's velocity (state_from_joints' sweep)
            body = m.frame(name)["body"]
            T = ad.frame_pose(m, q, name)
            if body == "ground":
                expect = np.zeros(6)
            else:
                k = list(m.body_names).index(body)
                x, e = u[7 * k : 7 * k + 3], u[7 * k + 3 : 7 * k + 7]
                xd, w_body = v[6 * k : 6 * k + 3], v[6 * k + 3 : 6 * k + 6]
                W = quat_to_rot(e) @ w_body
                expect = np.concatenate([xd + np.cross(W, T[:3, 3] - x), W])
            assert np.max(np.abs(J @ qd - expect)) <= 1e-13
            # the Cartesian Jacobian maps the bodies' velocities to the same frame velocity
            Jc = ad.frame_jacobian_cartesian(m, u, name)
            assert Jc.shape == (6, m.nv)
            assert np.max(np.abs(Jc @ v - expect)) <= 1e-13
            assert np.max(np.abs(ad.frame_pose_cartesian(m, u, name) - T)) <= 1e-14


def test_cartesian_frames_on_a_closed_loop():
    """frame_pose_cartesian on a four-bar loop, and frame_pose in its independent coordinate."""
    b = ad.ModelBuilder()
    b.add_body("crank", 1.0, [0.01, 0.01, 0.01], (0.5, 0, 0))
    b.add_body("coupler", 1.0, [0.01, 0.01, 0.01], (1.0, 1.0, 0))
    b.add_body("rocker", 1.0, [0.01, 0.01, 0.01], (2.0, 0.5, 0))
    z = (0, 0, 1)
    b.add_revolute("j0", "ground", "crank", (0, 0, 0), z)
    b.add_revolute("j1", "crank", "coupler", (1, 0, 0), z)
    b.add_revolute("j2", "coupler", "rocker", (1.0, 2.0, 0), z)
    b.add_inline("j3", "rocker", "ground", (2.0, 0, 0), z)
    quat = np.array([np.cos(0.2), 0, 0, np.sin(0.2)])
    b.add_frame("pin", "coupler", position=(1.0, 2.0, 0), orientation=quat)
    m = b.finalize()
    assert not m.joint_space
    T = ad.frame_pose_cartesian(m, m.u0, "pin")
    np.testing.assert_allclose(T[:3, 3], [1.0, 2.0, 0.0], rtol=0, atol=1e-14)
    np.testing.assert_allclose(T[:3, :3], quat_to_rot(quat), rtol=0, atol=1e-14)
    # the joint-level call takes the loop's independent coordinate (j0): at its assembled
    # value, the assembled pose
    assert list(m.coord_names) == ["j0"]
    np.testing.assert_allclose(ad.frame_pose(m, np.zeros(m.n_coords), "pin"), T, rtol=0, atol=1e-14)


# ----------------------------------------------------------------------------------------------
# the geometric validator names a frame
# ----------------------------------------------------------------------------------------------


def test_geometric_validator_by_frame(rng):
    model = five_dof.five_dof_arm(hold=np.zeros(5))
    body, point = five_dof.five_dof_tip()
    Q = np.column_stack([rng.uniform(-1.2, 1.2, (6, 4)), rng.uniform(0, five_dof.ARM5.stroke, 6)])
    by_body = end_effector_position(model, body, point, Q)
    by_frame = end_effector_position(model, q=Q, frame="tip")
    assert by_frame.shape == (6, 3)
    assert np.max(np.abs(by_frame - by_body)) <= 1e-14
    # an offset in the frame's axes
    R = ad.frame_pose(model, Q[0], "tip")[:3, :3]
    off = np.array([0.01, -0.02, 0.03])
    np.testing.assert_allclose(
        end_effector_position(model, q=Q[0], point=off, frame="tip"),
        by_body[0] + R @ off,
        rtol=0,
        atol=1e-14,
    )
    with pytest.raises(ad.ModelError, match="not both"):
        end_effector_position(model, body, point, Q[0], frame="tip")
    with pytest.raises(ad.ModelError, match="unknown frame 'tool0'"):
        end_effector_position(model, q=Q[0], frame="tool0")


def test_geometric_validator_tool0_matches_pinocchio(rng):
    pair = Pair("ur5")
    pin, pm, pd = pair.pin, pair.pm, pair.pd
    fid = pm.getFrameId("tool0", pin.FrameType.BODY)
    qa = rng.uniform(-np.pi, np.pi, pair.am.n_coords)
    pin.framesForwardKinematics(pm, pd, pair.to_pinocchio(qa))
    p = end_effector_position(pair.am, q=qa, frame="tool0")
    assert np.max(np.abs(p - pd.oMf[fid].translation)) <= 1e-12


# ----------------------------------------------------------------------------------------------
# bad input
# ----------------------------------------------------------------------------------------------


def test_unknown_frame_names_the_known_ones():
    pair = Pair("ur5")
    am = pair.am
    q = np.zeros(am.n_coords)
    for fn in (ad.frame_pose, ad.frame_jacobian):
        with pytest.raises(ad.ModelError, match=r"unknown frame 'tool1' \(known: 'world', ") as e:
            fn(am, q, "tool1")
        # a long list is cut short
        assert len(am.frame_names) > 10
        assert re.search(r"\.\.\. \(\d+ more\)\)$", str(e.value))
    with pytest.raises(ad.ModelError, match="unknown frame 'nope'"):
        am.frame("nope")
    with pytest.raises(ad.ModelError, match="frame index 99 out of range"):
        ad.frame_pose(am, q, 99)
    with pytest.raises(ad.ModelError, match="frame index -1 out of range"):
        ad.frame_jacobian(am, q, -1)
    with pytest.raises(ad.ModelError, match="frame must be a frame name"):
        ad.frame_pose(am, q, 1.5)
    with pytest.raises(ad.ModelError, match="frame must be a frame name"):
        ad.frame_pose(am, q, True)
    with pytest.raises(ad.ModelError, match=r"frame_pose_cartesian: frame index 99"):
        ad.frame_pose_cartesian(am, am.u0, 99)


def test_unknown_frame_on_a_model_without_frames():
    b = ad.ModelBuilder()
    b.add_body("a", 1.0, [0.1, 0.1, 0.1])
    b.add_revolute("r", "ground", "a", (0, 0, 0), (0, 0, 1))
    m = b.finalize()
    assert m.frame_names == []
    with pytest.raises(ad.ModelError, match=r"unknown frame 'x' \(known: none\)"):
        ad.frame_pose(m, [0.0], "x")


def test_wrong_q():
    b, _ = hand_built(np.random.default_rng(3))
    m = b.finalize()
    with pytest.raises(ad.ModelError, match=r"q: expected shape \(4,\), got \(3,\)"):
        ad.frame_pose(m, np.zeros(3), "tool")
    with pytest.raises(ad.ModelError, match=r"q: expected shape \(4,\), got \(5,\)"):
        ad.frame_jacobian(m, np.zeros(5), "tool")
    with pytest.raises(ad.ModelError, match="frame_jacobian: q contains NaN or inf"):
        ad.frame_jacobian(m, [0.0, np.nan, 0.0, 0.0], "tool")
    with pytest.raises(ad.ModelError, match=r"frame_pose: q must have shape \(2, 4\)"):
        ad.frame_pose(m, np.zeros((2, 3)), "tool")
    with pytest.raises(ad.ModelError, match="row 1: frame_pose: q contains NaN or inf"):
        ad.frame_pose(m, [[0.0] * 4, [np.inf, 0, 0, 0]], "tool")
    with pytest.raises(ad.ModelError, match=r"u: expected shape \(28,\)"):
        ad.frame_pose_cartesian(m, np.zeros(27), "tool")
    other = ad.Data(hand_built(np.random.default_rng(3))[0].finalize())
    with pytest.raises(ad.ModelError, match="data was made for another model"):
        ad.frame_pose(m, np.zeros(4), "tool", data=other)


def test_add_frame_refuses_bad_input_and_leaves_the_builder_intact():
    b, _ = hand_built(np.random.default_rng(5))
    before = list(b.frame_names)
    cases = [
        (("tool", "a", (0, 0, 0)), {}, "frame 'tool': duplicate frame name"),
        (("", "a", (0, 0, 0)), {}, "frame name must not be empty"),
        (("x", "nobody", (0, 0, 0)), {}, "frame 'x': unknown body 'nobody'"),
        (("x", "a", (0, np.nan, 0)), {}, "frame 'x': position contains NaN or inf"),
        (("x", "a", (0, np.inf, 0)), {}, "frame 'x': position contains NaN or inf"),
        (("x", "a", (0, 0, 0)), {"orientation": (1, 0, np.nan, 0)}, "orientation contains NaN"),
        (("x", "a", (0, 0, 0)), {"orientation": (1, 1, 0, 0)}, "unit quaternion .* norm 1.414"),
        (("x", "a", (0, 0)), {}, r"frame 'x': position: expected shape \(3,\)"),
    ]
    for args, kw, match in cases:
        with pytest.raises(ad.ModelError, match=match):
            b.add_frame(*args, **kw)
    assert b.frame_names == before
    # a frame may share a body's name (URDF links do), not another frame's
    b.add_frame("a", "a")
    assert b.finalize().frame_names == [*before, "a"]
