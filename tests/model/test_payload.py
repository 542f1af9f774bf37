"""Model.with_payload / with_payloads (issue 33): a new finalized model with a rigid body welded to
a frame or a body, the original unchanged. References: the same body added through the builder
(armdyn.urdf_builder + add_body + add_fixed, as notebooks/sizing_ur5.ipynb does, with the
inertia rotated into world axes by the frame's pose), the static torques J^T m g with J by
central differences of the bare model's frame pose, and the builder on models with actuators,
couplings and a floating base."""

from __future__ import annotations

import pickle

import armdyn as ad
import numpy as np
import pytest
from armdyn import profiles

from benchmarks import common

UR5 = common.robot_urdf("ur5")
pytestmark = pytest.mark.skipif(UR5 is None, reason="example-robot-data is part of the test extra")

MASS = 3.0
COM = np.array([0.01, -0.02, 0.05])  # in tool0's axes, from its origin
# about the centre of mass in tool0's axes: not diagonal, physical (principal moments satisfy
# the triangle inequality)
INERTIA = np.array([[0.006, 0.001, -0.0005], [0.001, 0.008, 0.0007], [-0.0005, 0.0007, 0.005]])
Q = np.array([0.3, -1.0, 1.2, -0.5, 0.8, 0.1])


def _state(model) -> bytes:
    return bytes(model.__getstate__()[0])


def _builder_reference(mass, com, inertia, frame="tool0"):
    """The UR5 with the payload added through the builder: world placement from the bare model's
    frame pose at q = 0 (the build pose), the inertia rotated into world axes."""
    bare = ad.load_urdf(str(UR5))
    pose = ad.frame_pose(bare, np.zeros(6), frame)
    rot, origin = pose[:3, :3], pose[:3, 3]
    b = ad.urdf_builder(str(UR5))
    b.add_body("payload", mass, rot @ inertia @ rot.T, position=origin + rot @ com)
    b.add_fixed("payload_mount", bare.frame(frame)["body"], "payload")
    return b.finalize()


def _close(a, b, rtol=1e-12):
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape
    assert np.abs(a - b).max() <= rtol * max(np.abs(b).max(), 1.0), np.abs(a - b).max()


def test_ur5_payload_equals_the_builder_body():
    bare = ad.load_urdf(str(UR5))
    before = _state(bare)
    loaded = bare.with_payload("tool0", MASS, com=COM, inertia=INERTIA)
    ref = _builder_reference(MASS, COM, INERTIA)
    assert _state(bare) == before and bare.nb == 6  # the original unchanged
    assert loaded.nb == 7 and loaded.body_names[-1] == "payload"
    assert list(loaded.coord_names) == list(bare.coord_names)
    rng = np.random.default_rng(33)
    for _ in range(5):
        q, qd, qdd = rng.uniform(-2, 2, (3, 6))
        _close(ad.mass_matrix(loaded, q), ad.mass_matrix(ref, q))
        _close(ad.inverse_dynamics(loaded, q, qd, qdd), ad.inverse_dynamics(ref, q, qd, qdd))
    # the payload's frame sits at its centre of mass, with tool0's axes
    pose = ad.frame_pose(bare, Q, "tool0")
    at = ad.frame_pose(loaded, Q, "payload")
    _close(at[:3, 3], pose[:3, :3] @ COM + pose[:3, 3])
    _close(at[:3, :3], pose[:3, :3])
    # a simulation from the same state: the same motion
    qd0 = np.array([0.5, -0.3, 0.2, 0.1, -0.4, 0.6])
    run = ad.simulate(loaded, 0.2, q0=Q, qd0=qd0, output_dt=0.05, rtol=1e-10, atol=1e-12)
    ref_run = ad.simulate(ref, 0.2, q0=Q, qd0=qd0, output_dt=0.05, rtol=1e-10, atol=1e-12)
    assert run.q.shape == ref_run.q.shape == (5, 6)
    _close(run.q, ref_run.q, 1e-9)
    # the pickled result travels as any model
    again = pickle.loads(pickle.dumps(loaded))
    assert _state(again) == _state(loaded)
    _close(ad.mass_matrix(again, Q), ad.mass_matrix(loaded, Q), 0.0)


def test_static_torques_are_jt_m_g():
    """A point mass at the body's centre of mass: the extra holding torques are J_v^T m (-g),
    J_v by central differences of the bare model's frame pose of a point fixed in that body."""
    bare = ad.load_urdf(str(UR5))
    com = np.array([0.02, 0.03, -0.01])
    loaded = bare.with_payload("tool0", MASS, com=com)
    zero = np.zeros(6)
    extra = ad.inverse_dynamics(loaded, Q, zero, zero) - ad.inverse_dynamics(bare, Q, zero, zero)

    def point(q):
        return ad.frame_pose(bare, q, "tool0") @ np.append(com, 1.0)

    h = 1e-6
    jv = np.column_stack(
        [(point(Q + h * e)[:3] - point(Q - h * e)[:3]) / (2 * h) for e in np.eye(6)]
    )
    expected = jv.T @ (-MASS * np.array([0.0, 0.0, -9.81]))
    assert np.abs(expected).max() > 1.0
    assert np.abs(extra - expected).max() <= 1e-7 * np.abs(expected).max()


def test_a_name_both_frame_and_body_is_the_frame():
    """A URDF link is a body (its centre of mass) and a frame (the link frame): `at` takes the
    frame. upper_arm_link's centre of mass lies 0.28 m from its link frame's origin."""
    bare = ad.load_urdf(str(UR5))
    assert np.linalg.norm(bare.frame("upper_arm_link")["point"]) == pytest.approx(0.28)
    loaded = bare.with_payload("upper_arm_link", 1.0, com=(0.0, 0.0, 0.1))
    link = ad.frame_pose(bare, Q, "upper_arm_link")
    _close(ad.frame_pose(loaded, Q, "payload")[:3, 3], link[:3, :3] @ [0.0, 0.0, 0.1] + link[:3, 3])


def test_at_a_joint_is_its_point_and_frame_on_the_parent():
    """The selection's housing mass at a joint: ``at=joint`` welds to the joint's parent at the
    joint point, in the joint frame (z the axis). Reference: the builder's body placed from the
    bare model's link-frame pose and joint_frame (upper_arm_link's link frame lies 0.28 m from
    its centre of mass, the joint point is given relative to the centre of mass)."""
    bare = ad.load_urdf(str(UR5))
    jf, link = bare.joint_frame("elbow_joint"), bare.frame("upper_arm_link")
    loaded = bare.with_payload("elbow_joint", 2.0, com=COM, inertia=INERTIA, name="housing")
    # the joint point and frame in the link frame's coordinates, then in world at q = 0
    pose = ad.frame_pose(bare, np.zeros(6), "upper_arm_link")
    rf = link["rotation"]
    origin = pose[:3, :3] @ rf.T @ (jf["point_parent"] - link["point"]) + pose[:3, 3]
    axes = pose[:3, :3] @ rf.T @ jf["frame_parent"]
    b = ad.urdf_builder(str(UR5))
    b.add_body("housing", 2.0, axes @ INERTIA @ axes.T, position=origin + axes @ COM)
    b.add_fixed("housing_mount", "upper_arm_link", "housing")
    ref = b.finalize()
    rng = np.random.default_rng(5)
    for _ in range(3):
        q, qd, qdd = rng.uniform(-2, 2, (3, 6))
        _close(ad.mass_matrix(loaded, q), ad.mass_matrix(ref, q))
        _close(ad.inverse_dynamics(loaded, q, qd, qdd), ad.inverse_dynamics(ref, q, qd, qdd))
    # a point mass on the elbow's axis: no holding torque on the elbow itself, but on the
    # shoulder lift
    on_axis = bare.with_payload("elbow_joint", 2.0, com=(0.0, 0.0, 0.03))
    zero = np.zeros(6)
    extra = ad.inverse_dynamics(on_axis, Q, zero, zero) - ad.inverse_dynamics(bare, Q, zero, zero)
    assert abs(extra[2]) <= 1e-12 * abs(extra[1]) and abs(extra[1]) > 1.0


def _arm(actuators=False, coupling=False, floating=False):
    """A three-link arm with a tilted body, optionally actuated, coupled or on a floating base."""
    b = ad.ModelBuilder()
    box = np.diag([0.02, 0.03, 0.01])
    tilt = (np.cos(0.3), np.sin(0.3), 0.0, 0.0)  # about x
    b.add_body("base", 4.0, 2 * box, (0.0, 0.0, 0.1))
    if floating:
        b.add_free("float", "base")
    else:
        b.add_fixed("mount", "ground", "base", (0.0, 0.0, 0.0))
    b.add_body("l1", 2.0, box, (0.0, 0.1, 0.35), tilt)
    b.add_revolute("j1", "base", "l1", (0.0, 0.0, 0.2), (0.0, 0.0, 1.0))
    b.add_body("l2", 1.5, box, (0.1, 0.1, 0.7))
    b.add_revolute("j2", "l1", "l2", (0.0, 0.0, 0.5), (0.0, 1.0, 0.0))
    b.add_body("l3", 1.0, box, (0.3, 0.1, 0.8))
    b.add_revolute("j3", "l2", "l3", (0.2, 0.0, 0.75), (0.0, 1.0, 0.0))
    b.add_frame("flange", "l3", (0.4, 0.1, 0.8), (np.cos(0.2), 0.0, np.sin(0.2), 0.0))
    if actuators:
        b.add_actuator("j1", 80.0, 2e-5, motor=ad.Motor(mass=0.5, brake_torque=0.3))
        b.add_actuator("j2", 50.0, 1e-5, gyroscopic=True)
    if coupling:
        b.add_coupling("c", "j3", "j2", -0.5, 0.1)
    return b


def _quat_rot(e):
    e0, e1, e2, e3 = e
    return np.array(
        [
            [1 - 2 * (e2 * e2 + e3 * e3), 2 * (e1 * e2 - e0 * e3), 2 * (e1 * e3 + e0 * e2)],
            [2 * (e1 * e2 + e0 * e3), 1 - 2 * (e1 * e1 + e3 * e3), 2 * (e2 * e3 - e0 * e1)],
            [2 * (e1 * e3 - e0 * e2), 2 * (e2 * e3 + e0 * e1), 1 - 2 * (e1 * e1 + e2 * e2)],
        ]
    )


@pytest.mark.parametrize(
    "kind", ["plain", "actuators", "coupling", "floating", "all"], ids=lambda k: k
)
@pytest.mark.parametrize("at", ["flange", "l2"])
def test_payload_on_builder_models(kind, at):
    opts = {
        "plain": {},
        "actuators": {"actuators": True},
        "coupling": {"coupling": True},
        "floating": {"floating": True},
        "all": {"actuators": True, "coupling": True, "floating": True},
    }[kind]
    model = _arm(**opts).finalize()
    before = _state(model)
    loaded = model.with_payload(at, 2.5, com=COM, inertia=INERTIA, name="tool")
    assert _state(model) == before
    # the builder's reference: at's pose at the build pose (flange: quaternion (cos .2, 0,
    # sin .2, 0) at (.4, .1, .8); l2: its centre of mass and axes, identity at (.1, .1, .7))
    if at == "flange":
        rot, origin = _quat_rot((np.cos(0.2), 0.0, np.sin(0.2), 0.0)), np.array([0.4, 0.1, 0.8])
        body = "l3"
    else:
        rot, origin, body = np.eye(3), np.array([0.1, 0.1, 0.7]), "l2"
    b = _arm(**opts)
    b.add_body("tool", 2.5, rot @ INERTIA @ rot.T, origin + rot @ COM)
    b.add_fixed("tool_mount", body, "tool", origin)
    ref = b.finalize()
    assert loaded.n_dofs == ref.n_dofs == model.n_dofs
    rng = np.random.default_rng(7)
    for _ in range(3):
        q = rng.uniform(-1, 1, model.n_coords)
        if opts.get("floating"):
            q[3:7] /= np.linalg.norm(q[3:7])
        qd, qdd = rng.uniform(-1, 1, (2, model.n_dofs))
        _close(ad.mass_matrix(loaded, q), ad.mass_matrix(ref, q))
        _close(ad.inverse_dynamics(loaded, q, qd, qdd), ad.inverse_dynamics(ref, q, qd, qdd))
    assert [a.joint for a in loaded.actuators] == [a.joint for a in model.actuators]
    assert loaded.couplings == model.couplings
    assert _state(pickle.loads(pickle.dumps(loaded))) == _state(loaded)


def test_a_body_that_is_not_a_frame_is_its_centre_of_mass_and_axes():
    """l1 is tilted 0.6 rad about x: the payload's com and inertia are in l1's axes."""
    model = _arm().finalize()
    loaded = model.with_payload("l1", 1.2, com=(0.0, 0.1, 0.0), inertia=[0.01, 0.02, 0.015])
    rot = _quat_rot((np.cos(0.3), np.sin(0.3), 0.0, 0.0))
    b = _arm()
    b.add_body(
        "payload",
        1.2,
        rot @ np.diag([0.01, 0.02, 0.015]) @ rot.T,
        np.array([0.0, 0.1, 0.35]) + rot @ [0.0, 0.1, 0.0],
    )
    b.add_fixed("m", "l1", "payload")
    ref = b.finalize()
    q = np.array([0.4, -0.7, 0.9])
    _close(ad.mass_matrix(loaded, q), ad.mass_matrix(ref, q))
    _close(ad.inverse_dynamics(loaded, q, q, q), ad.inverse_dynamics(ref, q, q, q))


def test_several_payloads_at_once_equal_one_at_a_time():
    bare = ad.load_urdf(str(UR5))
    housings = [
        {"at": link, "mass": 0.5 + k, "com": (0.0, 0.0, 0.01 * k), "name": f"housing_{k}"}
        for k, link in enumerate(bare.body_names)
    ]
    housings[2]["inertia"] = INERTIA
    at_once = bare.with_payloads(housings)
    in_turn = bare
    for h in housings:
        in_turn = in_turn.with_payload(**h)
    assert _state(at_once) == _state(in_turn)
    assert at_once.nb == 12
    _close(
        ad.inverse_dynamics(at_once, Q, Q, Q),
        ad.inverse_dynamics(in_turn, Q, Q, Q),
        0.0,
    )
    # total mass: the payloads' masses added
    assert sum(at_once.masses) == pytest.approx(sum(bare.masses) + sum(h["mass"] for h in housings))
    assert _state(bare.with_payloads([])) == _state(bare)
    # the model's KKT path and notes are kept
    dense = bare.with_kkt_path("dense")
    assert dense.with_payloads(housings).kkt_path == "dense" == dense.kkt_path
    assert at_once.kkt_path == bare.kkt_path


BAD = [
    (dict(mass=float("nan")), r"with_payload: mass must be finite and >= 0, got nan"),
    (dict(mass=-1.0), r"with_payload: mass must be finite and >= 0, got -1"),
    (dict(mass="3"), r"with_payload: mass must be a real number"),
    (dict(com=(0.0, float("inf"), 0.0)), r"with_payload: com must be finite"),
    (dict(com=(0.0, 0.0)), r"with_payload: com: "),
    (dict(inertia=[1.0, 1.0, float("nan")]), r"with_payload: inertia must be finite"),
    (dict(inertia=[1.0, 1.0, 3.0]), r"with_payload: inertia violates the triangle inequality"),
    (dict(inertia=[1.0, 1.0, -0.1]), r"with_payload: inertia is not positive semidefinite"),
    (dict(inertia=[[1.0, 0.5, 0], [0, 1.0, 0], [0, 0, 1.0]]), r"inertia is not symmetric"),
    (dict(inertia=np.eye(2)), r"with_payload: inertia: expected shape"),
    (dict(at="nowhere"), r"with_payload: at 'nowhere' is neither a frame, a body nor a joint"),
    (dict(at=3), r"with_payload: at must be a str"),
    (dict(name="wrist_3_link"), r"name 'wrist_3_link' is taken by a body of the model"),
    (dict(name="tool0"), r"name 'tool0' is taken by a frame of the model"),
    (dict(name=""), r"with_payload: name must not be empty"),
    (dict(name="ground"), r"name 'ground' is reserved"),
    (dict(mass=1e200), r"with_payload: the model with the payload does not finalize: "),
]


@pytest.mark.parametrize("kw,match", BAD, ids=[m for _, m in BAD])
def test_bad_payloads_name_the_culprit_and_leave_the_model(kw, match):
    bare = ad.load_urdf(str(UR5))
    before = _state(bare)
    args = {"at": "tool0", "mass": MASS, **kw}
    with pytest.raises(ad.ModelError, match=match):
        bare.with_payload(**args)
    assert _state(bare) == before
    # the same through with_payloads, naming the entry
    entry = r"with_payloads: (payloads\[0\]|.* does not finalize: .*body 'payload')"
    with pytest.raises(ad.ModelError, match=entry):
        bare.with_payloads([args])
    assert _state(bare) == before


def test_bad_payload_lists():
    bare = ad.load_urdf(str(UR5))
    before = _state(bare)
    loaded = bare.with_payload("tool0", 1.0)
    with pytest.raises(ad.ModelError, match=r"name 'payload' is taken by a body of the model"):
        loaded.with_payload("tool0", 1.0)  # a second payload needs its own name
    cases = [
        ({"at": "tool0", "mass": 1.0}, r"payloads must be a list of dicts"),
        ("tool0", r"payloads must be a list of dicts"),
        ([("tool0", 1.0)], r"payloads\[0\] must be a dict"),
        ([{"at": "tool0"}], r"payloads\[0\]: needs 'mass'"),
        ([{"mass": 1.0}], r"payloads\[0\]: needs 'at'"),
        ([{"at": "tool0", "mass": 1.0, "mas": 2.0}], r"payloads\[0\]: unknown key 'mas'"),
        (
            [{"at": "tool0", "mass": 1.0}, {"at": "base_link", "mass": 2.0}],
            r"payloads\[1\] 'payload': name 'payload' is taken by a body",
        ),
    ]
    for payloads, match in cases:
        with pytest.raises(ad.ModelError, match=match):
            bare.with_payloads(payloads)
        assert _state(bare) == before


def test_a_model_that_cannot_be_copied_says_so():
    b = _arm()
    b.add_joint_torque("j1", lambda t: (0.1 * t, 0.1, 0.0))
    model = b.finalize()
    with pytest.raises(ad.ModelError, match=r"with_payload: the model cannot be copied \("):
        model.with_payload("flange", 1.0)
    # a built-in profile travels
    b = _arm()
    b.add_joint_torque("j1", profiles.cubic(0.0, 1.0, 0.0, 1.0))
    assert b.finalize().with_payload("flange", 1.0).nb == 5
