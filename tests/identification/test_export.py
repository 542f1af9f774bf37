"""with_parameters / write_urdf: an identified parameter vector back into models (issue 35)."""

import difflib
import pickle
import re

import armdyn as ad
import numpy as np
import pytest
from armdyn.identification import with_parameters, write_urdf

from benchmarks import common

ROBOTS = common.robots_dir()
needs_robots = pytest.mark.skipif(ROBOTS is None, reason="example-robot-data not installed")
UR5 = str(ROBOTS / "ur_description/urdf/ur5_robot.urdf") if ROBOTS else ""
PANDA = str(ROBOTS / "panda_description/urdf/panda.urdf") if ROBOTS else ""
SOLO = str(ROBOTS / "solo_description/robots/solo12.urdf") if ROBOTS else ""

# a pendulum about y (link1) with a massive fixed child (tool, merged into link1's body), and a
# second link (link2) about y: every parameter of link1 is in closed form below
PENDULUM = """<?xml version="1.0"?>
<!-- a hand-written test robot -->
<robot name="pendulum">
  <link name="base"/>
  <joint name="j1" type="revolute">
    <parent link="base"/>
    <child link="link1"/>
    <origin xyz="0 0 1" rpy="0 0 0"/>
    <axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="10" velocity="5"/>
  </joint>
  <link name="link1">
    <inertial>
      <origin xyz="0.1 0.02 -0.3" rpy="0.1 0.2 0.3"/>
      <mass value="2.0"/>
      <inertia ixx="0.03" ixy="0.001" ixz="0.002" iyy="0.04" iyz="0.003" izz="0.02"/>
    </inertial>
  </link>
  <joint name="tool_mount" type="fixed">
    <parent link="link1"/>
    <child link="tool"/>
    <origin xyz="0.05 0 -0.5" rpy="0 0.4 0"/>
  </joint>
  <link name="tool">
    <inertial>
      <origin xyz="0 0.01 -0.05" rpy="0 0 0"/>
      <mass value="0.5"/>
      <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.003" iyz="0" izz="0.001"/>
    </inertial>
  </link>
  <joint name="j2" type="revolute">
    <parent link="link1"/>
    <child link="link2"/>
    <origin xyz="0 0.1 -0.6" rpy="0 0 0"/>
    <axis xyz="1 0 0"/>
    <limit lower="-3" upper="3" effort="10" velocity="5"/>
    <dynamics damping="0.2" friction="0.1"/>
  </joint>
  <link name="link2">
    <inertial>
      <origin xyz="0 0 -0.2" rpy="0 0 0"/>
      <mass value="1.0"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.002"/>
    </inertial>
  </link>
</robot>
"""


def _state(model, rng):
    q = rng.uniform(-1.0, 1.0, model.n_coords)
    if model.n_free:
        quat = rng.normal(size=4)
        q = np.concatenate([rng.normal(size=3), quat / np.linalg.norm(quat), q[7:]])
    return q, rng.normal(size=model.n_dofs), rng.normal(size=model.n_dofs)


def _names(model):
    return ad.dynamic_parameter_names(model)


def _n_bodies(model):
    return sum(n.endswith(".m") for n in _names(model))


def _point_mass(mass, c):
    """The 10 parameters of a point mass at c (about the frame origin)."""
    i = mass * (c @ c * np.eye(3) - np.outer(c, c))
    return np.r_[mass, mass * c, i[0, 0], i[0, 1], i[1, 1], i[0, 2], i[1, 2], i[2, 2]]


def _identified(model, seed=0):
    """A physically consistent pi far from the nominal one: a point mass added to every body
    (moving its centre of mass), random friction, offsets and rotor inertias."""
    rng = np.random.default_rng(seed)
    pi = ad.dynamic_parameters(model)
    nb = _n_bodies(model)
    for i in range(nb):
        pi[10 * i : 10 * i + 10] += _point_mass(rng.uniform(0.1, 1.0), rng.normal(size=3) * 0.1)
    for o in range(10 * nb, pi.size, 4):
        pi[o : o + 4] = (
            rng.uniform(0.0, 1.0),
            rng.uniform(0.0, 1.0),
            rng.normal(),
            0.1 * rng.random(),
        )
    return pi


def _without_offsets(model, pi):
    out = pi.copy()
    out[[i for i, n in enumerate(_names(model)) if n.endswith(".offset")]] = 0.0
    return out


def _check_model(model, new, pi, rng, frames=True):
    """new's parameters are pi, its inverse dynamics Y(model) pi, its geometry model's."""
    expected = _without_offsets(model, pi)
    scale = np.abs(expected).max()
    np.testing.assert_allclose(ad.dynamic_parameters(new), expected, rtol=0, atol=1e-12 * scale)
    for _ in range(4):
        q, qd, qdd = _state(model, rng)
        tau = ad.inverse_dynamics(new, q, qd, qdd)
        y = ad.joint_torque_regressor(model, q, qd, qdd)
        np.testing.assert_allclose(tau, y @ expected, rtol=0, atol=1e-12 * np.abs(tau).max())
        # forward dynamics of the new model (its mass matrix) inverts its inverse dynamics
        np.testing.assert_allclose(ad.forward_dynamics(new, q, qd, tau), qdd, atol=1e-9)
        if frames:  # the attachment points moved with the centres of mass: same geometry
            for f in model.frame_names:
                np.testing.assert_allclose(
                    ad.frame_pose(new, q, f), ad.frame_pose(model, q, f), rtol=0, atol=1e-13
                )


# ------------------------------------------------------------------------ with_parameters ---


@needs_robots
@pytest.mark.parametrize(
    "path, fixed", [(UR5, True), (PANDA, True), (SOLO, False)], ids=["ur5", "panda-mimic", "solo12"]
)
def test_with_parameters_gives_pi_and_its_dynamics(path, fixed):
    model = ad.load_urdf(path, fixed_base=fixed)
    before = ad.dynamic_parameters(model)
    pi = _identified(model)
    new = with_parameters(model, pi)
    _check_model(model, new, pi, np.random.default_rng(1))
    np.testing.assert_array_equal(ad.dynamic_parameters(model), before)  # nominal untouched
    # Ia on coordinates without actuator: a gear-ratio-1 armature each
    coords = [n[: -len(".Ia")] for n in _names(model) if n.endswith(".Ia")]
    assert [b for b in new.body_names if b.endswith("_armature")] == [
        f"{c}_armature" for c in coords
    ]
    # the copy is a model the builder could have made: it pickles (the bytes are re-checked)
    np.testing.assert_array_equal(
        ad.dynamic_parameters(pickle.loads(pickle.dumps(new))), ad.dynamic_parameters(new)
    )


@needs_robots
def test_with_parameters_cartesian_state_and_simulation():
    """The assembled Cartesian state has the new centres of mass (link frame pose at the build
    pose times pi's c = h / m) and the Cartesian simulation (welded model, KKT plans made
    afresh) follows the joint-space one."""
    model = ad.load_urdf(UR5)
    pi = _identified(model)
    new = with_parameters(model, pi)
    zero = np.zeros(model.n_coords)
    for i, body in enumerate(model.body_names):
        k = new.body_names.index(body)
        c = pi[10 * i + 1 : 10 * i + 4] / pi[10 * i]
        expected = ad.frame_pose(model, zero, body) @ np.r_[c, 1.0]
        np.testing.assert_allclose(new.u0[7 * k : 7 * k + 3], expected[:3], atol=1e-12)
    q0 = np.array([0.3, -1.0, 1.2, -0.5, 0.8, 0.2])
    runs = [
        ad.simulate(new, 0.2, q0=q0, coordinates=c, rtol=1e-9, atol=1e-11)
        for c in ("cartesian", "joint")
    ]
    np.testing.assert_allclose(runs[0].q[-1], runs[1].q[-1], atol=1e-6)
    assert np.abs(runs[0].q[-1][: q0.size] - q0).max() > 0.01  # it moved


def test_with_parameters_closed_form_pendulum():
    """link1's torque in closed form: tau1 = (Iyy + Ia) qdd + fv qd + fc tanh(qd / 1e-3) +
    g (-mx cos q - mz sin q) at q2 = qd2 = qdd2 = 0, link2's mass at its joint's point (mx, mz:
    the first moments of link1 and link2 about j1, in link1's frame; Iyy likewise)."""
    model = ad.load_urdf(PENDULUM)
    assert model.body_names == ["link1", "link2"]
    m1, c1 = 3.0, np.array([0.2, -0.05, -0.4])
    pi = _identified(model)
    pi[0:10] = _point_mass(m1, c1)
    pi[4:10] += [0.05, 0.001, 0.06, 0.002, 0.003, 0.04]  # + a physical inertia at the origin
    pi[10:20] = _point_mass(0.7, np.zeros(3))  # link2: mass at its frame (joint) origin
    pi[14:20] += [0.01, 0.0, 0.01, 0.0, 0.0, 0.01]  # ... and an inertia (link2 axes = link1's)
    fv, fc, ia = 0.3, 0.2, 0.05
    pi[20:24] = fv, fc, 9.0, ia
    new = with_parameters(model, pi)
    g, p2 = 9.81, np.array([0.0, 0.1, -0.6])  # link2's origin in link1's frame
    for q, qd, qdd in [(0.3, 0.5, -1.2), (-1.1, -0.2, 0.7)]:
        tau = ad.inverse_dynamics(new, [q, 0.0], [qd, 0.0], [qdd, 0.0])
        # link1 rotates about y: a point (x, y, z) of it is at height -x sin q + z cos q
        mx, mz = m1 * c1[0] + 0.7 * p2[0], m1 * c1[2] + 0.7 * p2[2]
        iyy = pi[6] + 0.7 * (p2[0] ** 2 + p2[2] ** 2) + 0.01
        expected = (iyy + ia) * qdd + fv * qd + fc * np.tanh(qd / 1e-3)
        expected += g * (-mx * np.cos(q) - mz * np.sin(q))
        assert tau[0] == pytest.approx(expected, rel=1e-12, abs=1e-12)


def test_with_parameters_actuators_friction_and_smoothing():
    """Actuators (gear-reduced and gyroscopic) and motor-side friction are scaled, not replaced:
    the regressor's columns (their smoothing) stay exact."""
    for gyroscopic in (False, True):
        b = ad.urdf_builder(PENDULUM)
        b.add_actuator(
            "j1", 50.0, 2e-4, friction_viscous=1e-3, friction_coulomb=0.01, gyroscopic=gyroscopic
        )
        b.add_joint_friction("j1", 0.1, 0.3, 0.05)
        model = b.finalize()
        pi = _identified(model, seed=3)
        new = with_parameters(model, pi)
        _check_model(model, new, pi, np.random.default_rng(2))
        # one actuator on j1 (its rotor scaled), one added on j2
        rotor = "j1_rotor" if gyroscopic else "j1_armature"
        assert rotor in new.body_names and "j2_armature" in new.body_names


def _quat(v):
    """A unit quaternion (scalar first) of rotation vector v."""
    angle = np.linalg.norm(v)
    return np.r_[np.cos(angle / 2), np.sin(angle / 2) * np.asarray(v) / angle]


def test_with_parameters_builder_model_body_frames():
    """Bodies without a frame of their name: the parameter frame is the body frame (the
    centre of mass, body axes, here rotated); its origin moves with pi's centre of mass, the
    named frame 'tip' and the joints stay where they were, and the old body frame becomes a
    frame of the body's name (pi's parameter frame)."""
    b = ad.ModelBuilder(gravity=(0.3, -0.2, -9.81))
    b.add_body(
        "upper",
        2.0,
        [[0.05, 0.004, -0.002], [0.004, 0.06, 0.003], [-0.002, 0.003, 0.03]],
        position=(0.0, 0.02, 0.2),
        orientation=_quat([0.1, -0.3, 0.2]),
    )
    b.add_body(
        "slide",
        0.8,
        [0.01, 0.02, 0.015],
        position=(0.3, 0.05, 0.4),
        orientation=_quat([-0.4, 0.2, 0.5]),
    )
    b.add_revolute("yaw", "ground", "upper", (0, 0, 0.1), (0.1, 0, 1))
    b.add_prismatic("reach", "upper", "slide", (0.2, 0.03, 0.4), (1, 0.1, 0))
    b.add_frame("tip", "slide", (0.5, 0.1, 0.45), _quat([0.2, 0.1, -0.3]))
    b.add_joint_friction("reach", 0.4, 0.6, 0.02)
    model = b.finalize()
    pi = _identified(model, seed=8)
    new = with_parameters(model, pi)
    _check_model(model, new, pi, np.random.default_rng(9))
    # pi's centre of mass of 'slide' is now its body frame's origin: in the old body frame
    # (the old centre of mass, body axes) it sits at h / m
    c_old = pi[11:14] / pi[10]
    frame = model.frame("tip")
    np.testing.assert_allclose(new.frame("tip")["point"], frame["point"] - c_old, atol=1e-15)
    # ... and pi's parameter frame, the old body frame, is now a frame of its name
    np.testing.assert_allclose(new.frame("slide")["point"], -c_old, atol=1e-15)
    np.testing.assert_allclose(new.frame("slide")["rotation"], np.eye(3), atol=1e-15)
    assert "slide" not in model.frame_names


def test_with_parameters_rotor_without_inertia_and_cylindrical():
    """An actuator whose rotor inertia is 0 takes all of Ia (J = Ia / N^2); a cylindrical
    joint's slide takes no actuator (ModelError naming the coordinate)."""
    b = ad.urdf_builder(PENDULUM)
    b.add_actuator("j2", 10.0, 0.0)
    model = b.finalize()
    pi = _identified(model, seed=6)
    new = with_parameters(model, pi)
    _check_model(model, new, pi, np.random.default_rng(7))
    assert "j2_armature" in new.body_names and len(new.body_names) == 4  # + j1_armature
    b = ad.ModelBuilder()
    b.add_body("slider", 1.0, np.diag([0.01, 0.02, 0.03]), position=(0.0, 0.0, -0.5))
    b.add_cylindrical("cyl", "ground", "slider", (0, 0, 0), (0, 0, 1))
    model = b.finalize()
    pi = ad.dynamic_parameters(model)
    names = _names(model)
    pi[names.index(names[-1])] = 0.1  # the slide's Ia
    with pytest.raises(ad.ModelError, match=rf"'{re.escape(names[-1])}' = 0\.1\d*: .*cylindrical"):
        with_parameters(model, pi)
    pi[names.index(names[-1])] = 0.0
    pi[names.index(names[-5])] = 0.1  # the angle's Ia: an actuator on a cylindrical joint
    with pytest.raises(ad.ModelError, match="joint 'cyl' needs an actuator"):
        with_parameters(model, pi)


def test_with_parameters_zero_friction_and_massless():
    model = ad.load_urdf(PENDULUM)
    pi = ad.dynamic_parameters(model)
    pi[20:] = 0.0  # j2's nominal friction removed
    pi[10:20] = [0.0, 0, 0, 0, 1e-3, 0, 1e-3, 0, 0, 1e-3]  # link2 massless (inertia kept)
    new = with_parameters(model, pi)
    _check_model(model, new, pi, np.random.default_rng(4))
    assert "j2_armature" not in new.body_names  # Ia 0: no actuator added


def test_with_parameters_physical_inertia_option():
    model = ad.load_urdf(PENDULUM)
    pi = ad.dynamic_parameters(model)
    # link2 with an inertia about its centre of mass violating the triangle inequality
    pi[10:20] = _point_mass(1.0, np.array([0, 0, -0.2]))
    pi[14:20] += [0.001, 0, 0.001, 0, 0, 0.01]  # Ixx + Iyy < Izz about the centre of mass
    with pytest.raises(ad.ModelError, match=r"body 'link2'.*triangle inequality"):
        with_parameters(model, pi)
    new = with_parameters(model, pi, physical_inertia=False)
    _check_model(model, new, pi, np.random.default_rng(5))
    copy = pickle.loads(pickle.dumps(new))  # the model bytes take such an inertia back
    np.testing.assert_array_equal(ad.dynamic_parameters(copy), ad.dynamic_parameters(new))


@needs_robots
def test_with_parameters_urdf_checked():
    model = ad.load_urdf(UR5)
    pi = _identified(model)
    new = with_parameters(model, pi, urdf=UR5)
    np.testing.assert_allclose(
        ad.dynamic_parameters(new), ad.dynamic_parameters(with_parameters(model, pi)), atol=0
    )
    with pytest.raises(ad.ModelError, match=r"with_parameters: urdf: .*no link 'shoulder_link'"):
        with_parameters(model, pi, urdf=PENDULUM)


def _bad_pi(model):
    names = _names(model)
    pi = ad.dynamic_parameters(model)

    def at(name, value):
        p = pi.copy()
        p[names.index(name)] = value
        return p

    point = pi.copy()
    point[10:20] = [0.0, 0.1, 0, 0, 0.01, 0, 0.01, 0, 0, 0.01]
    not_psd = pi.copy()
    not_psd[14] = -1.0  # link2.Ixx about its frame: the inertia about the centre not PSD
    return [
        (pi[:-1], r"pi must have shape \(28,\)"),
        (np.c_[pi, pi], r"pi must have shape \(28,\)"),
        (["a"] * pi.size, "pi must be an array of numbers"),
        (at("link1.mcx", np.nan), r"pi\[1\] \('link1.mcx'\) must be finite"),
        (at("j2.Ia", np.inf), r"'j2.Ia'\) must be finite"),
        (at("link2.m", -1.0), "body 'link2'.*mass"),
        (point, "body 'link2': zero mass with a nonzero first moment"),
        (not_psd, "body 'link2'.*not positive semidefinite"),
        (at("j1.fv", -0.1), "'j1.fv' must be >= 0"),
        (at("j2.fc", -0.1), "'j2.fc' must be >= 0"),
        (at("j1.Ia", -0.1), "'j1.Ia' must be >= 0"),
    ]


def test_hostile_pi_refused_model_intact():
    model = ad.load_urdf(PENDULUM)
    before = ad.dynamic_parameters(model)
    for pi, match in _bad_pi(model):
        with pytest.raises(ad.ModelError, match=match):
            with_parameters(model, pi)
        np.testing.assert_array_equal(ad.dynamic_parameters(model), before)
    with pytest.raises(ad.ModelError, match=r"model must be an armdyn\.Model"):
        with_parameters("pendulum.urdf", before)


def test_with_parameters_refuses_non_parameter_elements():
    b = ad.urdf_builder(PENDULUM)
    b.add_joint_spring_damper("j2", 1.0, 0.0, 0.0)
    model = b.finalize()
    with pytest.raises(ad.ModelError, match="'j2' has a spring"):
        with_parameters(model, np.zeros(28))


# ----------------------------------------------------------------------------- write_urdf ---


def _body_and_friction(model):
    return [i for i, n in enumerate(_names(model)) if not n.endswith((".offset", ".Ia"))]


def _check_round_trip(source, model, pi, text, **load):
    again = ad.load_urdf(text, **load)
    assert _names(again) == _names(model)
    keep = _body_and_friction(model)
    np.testing.assert_allclose(
        ad.dynamic_parameters(again)[keep], pi[keep], rtol=0, atol=1e-12 * np.abs(pi).max()
    )
    # with_parameters of the re-loaded model (its Ia as actuators) is the whole identified one
    full = with_parameters(again, pi)
    expected = _without_offsets(model, pi)
    np.testing.assert_allclose(ad.dynamic_parameters(full), expected, atol=1e-12 * np.abs(pi).max())


def _changed_lines(original, text):
    """The original's lines the export removed or changed."""
    diff = difflib.ndiff(original.splitlines(), text.splitlines())
    return [line[2:] for line in diff if line.startswith("- ")]


INERTIAL_LINE = re.compile(r"^\s*(<inertial>|</inertial>|<mass |<origin |<inertia |<dynamics )")


@needs_robots
@pytest.mark.parametrize(
    "path, fixed",
    [(UR5, True), (PANDA, True), (SOLO, False)],
    ids=["ur5-merged-tool0", "panda-mimic", "solo12-floating"],
)
def test_write_urdf_round_trip(path, fixed, tmp_path):
    model = ad.load_urdf(path, fixed_base=fixed)
    pi = _identified(model)
    out = tmp_path / "identified.urdf"
    text = write_urdf(path, model, pi, path=out)
    assert out.read_text() == text
    _check_round_trip(path, model, pi, str(out), fixed_base=fixed)
    original = open(path).read()
    # everything but the inertials and the joints' <dynamics> kept byte for byte
    assert text.startswith(original[: original.index("<robot")])
    assert all(INERTIAL_LINE.match(line) for line in _changed_lines(original, text))
    n_ia = text.count("armdyn: rotor inertia Ia")
    assert n_ia == sum(n.endswith(".Ia") for n in _names(model))
    # a second export of the same pi changes nothing (its comments replaced, not added)
    assert write_urdf(text, model, pi) == text


@needs_robots
def test_write_urdf_ur5_merged_links():
    model = ad.load_urdf(UR5)
    text = write_urdf(UR5, model, _identified(model))
    for link in ("ee_link", "tool0"):
        block = re.search(rf'<link name="{link}">.*?</link>', text, re.S).group(0)
        assert "<inertial>" not in block
        assert "inertial merged into link 'wrist_3_link'" in block


@needs_robots
def test_write_urdf_panda_mimic_friction():
    """The fingers' damping (leader and mimic follower, 0.3 each) scaled so that the
    independent coordinate's reflected viscous friction is pi's."""
    model = ad.load_urdf(PANDA)
    pi = ad.dynamic_parameters(model)
    k = _names(model).index("panda_finger_joint1.fv")
    assert pi[k] == pytest.approx(0.6)  # 0.3 + 1^2 0.3
    pi[k] = 0.9
    text = write_urdf(PANDA, model, pi)
    assert text.count('<dynamics damping="0.45"/>') == 2
    _check_round_trip(PANDA, model, pi, text)


def test_write_urdf_fixed_child_with_mass(tmp_path):
    model = ad.load_urdf(PENDULUM)
    # the merged body's nominal parameters: link1's and the tool's, about link1's frame
    assert ad.dynamic_parameters(model)[0] == pytest.approx(2.5)
    pi = _identified(model)
    text = write_urdf(PENDULUM, model, pi)
    assert write_urdf(PENDULUM.encode(), model, pi) == text  # XML as bytes
    (tmp_path / "p.urdf").write_text(PENDULUM)
    assert write_urdf(tmp_path / "p.urdf", model, pi) == text  # a PathLike
    tool = re.search(r'<link name="tool">.*?</link>', text, re.S).group(0)
    assert "<inertial>" not in tool and "merged into link 'link1'" in tool
    assert text.startswith('<?xml version="1.0"?>\n<!-- a hand-written test robot -->\n')
    _check_round_trip(PENDULUM, model, pi, text)
    # link1 had no <dynamics>: added, with pi's values
    j1 = re.search(r'<joint name="j1".*?</joint>', text, re.S).group(0)
    assert f'<dynamics damping="{float(pi[20])!r}" friction="{float(pi[21])!r}"/>' in j1


@pytest.mark.parametrize("empty", [False, True], ids=["open", "self-closing"])
def test_write_urdf_adds_inertial_to_link_without_one(empty):
    model = ad.load_urdf(PENDULUM)
    link2 = '<link name="link2"/>' if empty else '<link name="link2">\n  </link>'
    urdf = re.sub(r'<link name="link2">.*?</link>', link2, PENDULUM, flags=re.S)
    assert urdf.count("<inertial>") == 2
    pi = _identified(model)
    text = write_urdf(urdf, model, pi)
    assert text.count("<inertial>") == 2  # link1's replaced, the tool's dropped, link2's added
    _check_round_trip(urdf, model, pi, text)


def test_write_urdf_hostile(tmp_path):
    model = ad.load_urdf(PENDULUM)
    pi = ad.dynamic_parameters(model)
    for bad, match in _bad_pi(model):
        if "positive semidefinite" in match:
            continue  # a URDF can hold any tensor: load_urdf judges it
        with pytest.raises(ad.ModelError, match=match):
            write_urdf(PENDULUM, model, bad)
    with pytest.raises(ad.ModelError, match="no link 'link2'"):
        write_urdf(PENDULUM.replace('"link2"', '"other"'), model, pi)
    with pytest.raises(ad.ModelError, match="no joint 'j2'"):
        write_urdf(PENDULUM.replace('name="j2"', 'name="jx"'), model, pi)
    with pytest.raises(ad.UrdfError, match="cannot read the URDF file"):
        write_urdf("/nonexistent/robot.urdf", model, pi)
    with pytest.raises(ad.UrdfError, match="not a regular file"):
        write_urdf(tmp_path, model, pi)
    with pytest.raises(ad.UrdfError, match="urdf must be a path or the XML text"):
        write_urdf(3, model, pi)
    with pytest.raises(ad.UrdfError, match="not well-formed"):
        write_urdf("<robot name='x'><link></robot>", model, pi)
    with pytest.raises(ad.UrdfError, match="root element is <sdf>"):
        write_urdf("<sdf/>", model, pi)
    np.testing.assert_array_equal(ad.dynamic_parameters(model), pi)
