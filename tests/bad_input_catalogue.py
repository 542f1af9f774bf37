"""The catalogue of bad inputs armdyn rejects: one entry per case, each run by
tests/model/test_bad_input_catalogue.py, and rendered into docs/bad_inputs.md by

    python tests/bad_input_catalogue.py > docs/bad_inputs.md

Each entry: (id, area, input, function raising, expected exception, regex the message must
match: the culprit's name).
"""

from __future__ import annotations

import sys
from pathlib import Path

import armdyn as ad
import numpy as np
from armdyn import _core

DATA = Path(__file__).resolve().parent / "data" / "urdf"
I3 = np.diag([0.01, 0.02, 0.025])


def _b(name="link"):
    b = ad.ModelBuilder()
    b.add_body(name, 1.0, I3, position=(0.0, 0.0, -0.5))
    return b


def _mjcf(mass="1", pos="0 0 0", site="", world=""):
    """A one-hinge MJCF arm with the given body mass and position."""
    return (
        f'<mujoco><worldbody><body name="link" pos="{pos}"><joint name="hinge" type="hinge"/>'
        f'<inertial pos="0 0 0.5" mass="{mass}" diaginertia="0.1 0.1 0.1"/>{site}</body>'
        f"{world}</worldbody></mujoco>"
    )


def _hinged():
    b = _b("link")
    b.add_revolute("hinge", "ground", "link", (0, 0, 0), (0, 1, 0))
    return b


def _massless_leaf():
    b = ad.ModelBuilder()
    b.add_body("heavy", 0.0, np.zeros((3, 3)), position=(0.0, 0.0, -0.5))
    b.add_revolute("hinge", "ground", "heavy", (0, 0, 0), (0, 1, 0))
    return b.finalize()


def _hinged_with(mass=1.0, position=(0.0, 0.0, -0.5), point=(0.0, 0.0, 0.0)):
    b = ad.ModelBuilder()
    b.add_body("link", mass, I3, position=position)
    b.add_revolute("hinge", "ground", "link", point, (0, 1, 0))
    return b.finalize()


def _gear_train(independent=None):
    """Two wheels on ground joined by an ideal gear (q_b = -q_a / 2); `independent` given to
    set_independent_coordinates when not None."""
    b = ad.ModelBuilder()
    b.add_body("pinion", 1.0, [0.01, 0.01, 0.01], position=(0, 0, 0))
    b.add_body("wheel", 1.0, [0.01, 0.01, 0.01], position=(0.3, 0, 0))
    b.add_revolute("ja", "ground", "pinion", (0, 0, 0), (0, 0, 1))
    b.add_revolute("jb", "ground", "wheel", (0.3, 0, 0), (0, 0, 1))
    b.add_gear("mesh", "ja", "jb", 0.1, 0.2)
    if independent is not None:
        b.set_independent_coordinates(independent)
    return b.finalize()


def _four_bar_by_rocker(name="D"):
    """A crank-rocker four-bar whose independent coordinate is `name` (the rocker D)."""
    b = ad.ModelBuilder()
    for body, pos in (
        ("crank", (0.5, 0, 0)),
        ("coupler", (1.0, 1.0, 0)),
        ("rocker", (1.5, 1.0, 0)),
    ):
        b.add_body(body, 1.0, [0.01, 0.01, 0.01], position=pos)
    z = (0, 0, 1)
    b.add_revolute("A", "ground", "crank", (0, 0, 0), z)
    b.add_revolute("B", "crank", "coupler", (1, 0, 0), z)
    b.add_revolute("C", "coupler", "rocker", (1, 2, 0), z)
    b.add_revolute("D", "rocker", "ground", (2, 0, 0), z)
    b.set_independent_coordinates([name])
    return b.finalize()


def _pendulum():
    return _hinged().finalize()


def _coulomb_pendulum():
    b = _hinged()
    b.add_joint_friction("hinge", viscous=0.1, coulomb=0.5)
    return b.finalize()


def _sprung_pendulum():
    b = _hinged()
    b.add_joint_spring_damper("hinge", 10.0, 0.0)
    return b.finalize()


def _heavy_pendulum():
    """10 kg at 0.5 m: I = 2.52 kg m², so I q̈ overflows for q̈ = 1.7e308."""
    b = ad.ModelBuilder()
    b.add_body("link", 10.0, I3, position=(0.0, 0.0, -0.5))
    b.add_revolute("hinge", "ground", "link", (0, 0, 0), (0, 1, 0))
    return b.finalize()


def _two_links():
    """Two links on parallel hinges: the mass matrix depends on the elbow angle."""
    b = _hinged()
    b.add_body("forearm", 1.0, I3, position=(0.0, 0.0, -1.5))
    b.add_revolute("elbow", "link", "forearm", (0, 0, -1.0), (0, 1, 0))
    return b.finalize()


def _driven():
    b = _hinged()
    b.add_drive("hinge", _core.profiles.cubic(0.0, 1.0, 0.0, 1.0))
    return b.finalize()


URDF_LINKS = """<link name="base"/><link name="arm"><inertial><mass value="1"/>
  <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>"""


def _urdf(joint: str, links: str = URDF_LINKS) -> str:
    return f"<robot name='r'>{links}{joint}</robot>"


def _slider_crank_dead_centre():
    model = ad.scenes.slider_driven_to_dead_centre()
    return ad.driven_inverse_dynamics(model, np.linspace(0.0, 1.0, 11))


def _nan_force_run():
    b = _hinged()
    b.add_body_force("link", force=(1.0, 0, 0), profile=lambda t: (np.nan if t > 0.2 else 0, 0, 0))
    ad.simulate(b.finalize(), 1.0, integrator="rk4", dt=0.01)


def _state_of(model):
    return bytes(model.__getstate__()[0])


def _load_state(data):
    ad.Model.__new__(ad.Model).__setstate__((data,))


def _with_body_count(data, n):
    at = 13 + 24  # after the header (tag, format version, kind) and gravity
    return data[:at] + int(n).to_bytes(8, "little", signed=True) + data[at + 8 :]


def _with_format(data, version):
    return data[:8] + int(version).to_bytes(4, "little") + data[12:]


ME, UE, SE = ad.ModelError, ad.UrdfError, ad.SolverError

CASES = [
    # ---- bodies
    ("mass-negative", "body", "mass −1", lambda: _b().add_body("heavy", -1.0, I3), ME, "heavy"),
    (
        "mass-str",
        "body",
        "mass '1' (a str, not a number)",
        lambda: _b().add_body("heavy", "1", I3),
        ME,
        r"ModelBuilder\.add_body: mass must be a real number, got '1'",
    ),
    (
        "body-name-surrogate",
        "body",
        "a name holding a lone surrogate",
        lambda: _b().add_body("\ud800", 1.0, I3),
        ME,
        "add_body: name must be valid Unicode text",
    ),
    (
        "mass-zero-leaf",
        "model",
        "a massless leaf body on a hinge (its motion carries no inertia)",
        _massless_leaf,
        ME,
        "hinge.*heavy",
    ),
    ("mass-nan", "body", "mass NaN", lambda: _b().add_body("heavy", np.nan, I3), ME, "heavy"),
    (
        "mass-overflow",
        "model",
        "mass 1e300 (finalize: the dynamics' products overflow)",
        lambda: _hinged_with(mass=1e300),
        ME,
        "body 'link': mass = 1e\\+300",
    ),
    (
        "mass-underflow",
        "model",
        "mass 1e-300 (finalize: its reciprocal's products overflow; massless is mass 0)",
        lambda: _hinged_with(mass=1e-300),
        ME,
        "body 'link': mass = 1e-300",
    ),
    (
        "position-overflow",
        "model",
        "a body at 1e300 m (finalize)",
        lambda: _hinged_with(position=(1e300, 0.0, 0.0)),
        ME,
        "body 'link': squared distance",
    ),
    (
        "joint-point-overflow",
        "model",
        "a joint point at 1e100 m (finalize)",
        lambda: _hinged_with(point=(1e100, 0.0, 0.0)),
        ME,
        "joint 'hinge': squared distance",
    ),
    (
        "inertia-nonsym",
        "body",
        "inertia not symmetric",
        lambda: _b().add_body("skew", 1.0, [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]),
        ME,
        "skew",
    ),
    (
        "inertia-not-psd",
        "body",
        "inertia with a negative principal value",
        lambda: _b().add_body("flat", 1.0, [1.0, 1.0, -1.0]),
        ME,
        "flat",
    ),
    (
        "inertia-triangle",
        "body",
        "principal inertias violate I1 + I2 ≥ I3",
        lambda: _b().add_body("weird", 1.0, [0.01, 0.01, 0.05]),
        ME,
        "weird",
    ),
    (
        "inertia-shape",
        "body",
        "inertia of shape (2, 2)",
        lambda: _b().add_body("shaped", 1.0, np.eye(2)),
        ME,
        "inertia",
    ),
    (
        "position-nan",
        "body",
        "position with NaN",
        lambda: _b().add_body("lost", 1.0, I3, position=(np.nan, 0, 0)),
        ME,
        "lost",
    ),
    (
        "position-shape",
        "body",
        "position of length 2",
        lambda: _b().add_body("lost", 1.0, I3, position=(0, 0)),
        ME,
        "position",
    ),
    (
        "quat-not-unit",
        "body",
        "orientation (1, 1, 0, 0)",
        lambda: _b().add_body("spun", 1.0, I3, orientation=(1, 1, 0, 0)),
        ME,
        "spun",
    ),
    (
        "quat-nan",
        "body",
        "orientation with NaN",
        lambda: _b().add_body("spun", 1.0, I3, orientation=(np.nan, 0, 0, 1)),
        ME,
        "spun",
    ),
    (
        "body-duplicate",
        "body",
        "second body of the same name",
        lambda: _b("dup").add_body("dup", 1.0, I3),
        ME,
        "dup",
    ),
    (
        "body-ground",
        "body",
        "a body named 'ground'",
        lambda: _b().add_body("ground", 1.0, I3),
        ME,
        "ground",
    ),
    # ---- joints
    (
        "coord-huge",
        "joint",
        "coord 2**70 (beyond a C int)",
        lambda: _hinged().add_joint_torque("hinge", 1.0, coord=2**70),
        ME,
        r"add_joint_torque: coord must be an integer in \[",
    ),
    (
        "axis-zero-revolute",
        "joint",
        "revolute with axis (0, 0, 0)",
        lambda: _b().add_revolute("axisless", "ground", "link", (0, 0, 0), (0, 0, 0)),
        ME,
        "axisless",
    ),
    (
        "axis-zero-prismatic",
        "joint",
        "prismatic with axis (0, 0, 0)",
        lambda: _b().add_prismatic("axisless", "ground", "link", (0, 0, 0), (0, 0, 0)),
        ME,
        "axisless",
    ),
    (
        "axis-nan",
        "joint",
        "revolute with a NaN axis",
        lambda: _b().add_revolute("axisnan", "ground", "link", (0, 0, 0), (np.nan, 1, 0)),
        ME,
        "axisnan",
    ),
    (
        "universal-not-perp",
        "joint",
        "universal joint with parallel axes",
        lambda: _b().add_universal("cardan", "ground", "link", (0, 0, 0), (0, 0, 1), (0, 0, 1)),
        ME,
        "cardan",
    ),
    (
        "joint-unknown-body",
        "joint",
        "joint to an unknown body",
        lambda: _b().add_revolute("j", "ground", "no_such_body", (0, 0, 0), (0, 1, 0)),
        ME,
        "no_such_body",
    ),
    (
        "joint-duplicate",
        "joint",
        "second joint of the same name",
        lambda: _hinged().add_revolute("hinge", "ground", "link", (0, 0, 0), (0, 1, 0)),
        ME,
        "hinge",
    ),
    (
        "joint-self",
        "joint",
        "joint from a body to itself",
        lambda: _b().add_revolute("self_joint", "link", "link", (0, 0, 0), (0, 1, 0)),
        ME,
        "self_joint",
    ),
    (
        "joint-point-nan",
        "joint",
        "joint point with inf",
        lambda: _b().add_spherical("ball", "ground", "link", (np.inf, 0, 0)),
        ME,
        "ball",
    ),
    # ---- drives and force elements
    (
        "drive-spherical",
        "drive",
        "drive on a spherical joint",
        lambda: (
            lambda b: (
                b.add_spherical("ball", "ground", "link", (0, 0, 0)),
                b.add_drive("ball", 0.0),
            )
        )(_b()),
        ME,
        "ball",
    ),
    (
        "drive-unknown-joint",
        "drive",
        "drive on an unknown joint",
        lambda: _hinged().add_drive("no_such_joint", 0.0),
        ME,
        "no_such_joint",
    ),
    (
        "drive-coord-range",
        "drive",
        "drive on coordinate 1 of a revolute",
        lambda: _hinged().add_drive("hinge", 0.0, coord=1),
        ME,
        "hinge",
    ),
    (
        "drive-bad-profile",
        "drive",
        "profile that is neither a number, Profile nor callable",
        lambda: _hinged().add_drive("hinge", "fast"),
        ME,
        "hinge",
    ),
    (
        "spline-not-increasing",
        "drive",
        "spline samples with decreasing times",
        lambda: _core.profiles.spline([0.0, 1.0, 0.5], [0.0, 1.0, 2.0]),
        ME,
        "increas",
    ),
    (
        "spring-negative",
        "force",
        "spring-damper with stiffness −1",
        lambda: _hinged().add_spring_damper("sp", "ground", (0, 0, 0), "link", (0, 0, 0), -1.0),
        ME,
        "sp",
    ),
    (
        "friction-negative",
        "force",
        "joint friction with viscous −1",
        lambda: _hinged().add_joint_friction("hinge", viscous=-1.0),
        ME,
        "hinge",
    ),
    (
        "force-unknown-body",
        "force",
        "body force on an unknown body",
        lambda: _hinged().add_body_force("nobody", force=(1, 0, 0)),
        ME,
        "nobody",
    ),
    # ---- topology and assembly
    (
        "not-connected",
        "model",
        "a body with no joint path to ground",
        lambda: (lambda b: (b.add_body("floating", 1.0, I3), b.finalize()))(_hinged()),
        ME,
        "floating",
    ),
    (
        "assembly-impossible",
        "model",
        "joints that cannot all hold (revolute 1 m from its body, and fixed at its CoM)",
        lambda: (
            lambda b: (
                b.add_revolute("far", "ground", "link", (0, 0, 0.5), (0, 1, 0)),
                b.add_fixed("weld", "ground", "link", (5, 0, 0)),
                b.add_drive("far", 3.0),
                b.finalize(),
            )
        )(_b()),
        ME,
        "assembl",
    ),
    # ---- model bytes (pickles)
    (
        "bytes-truncated",
        "pickle",
        "a model's pickled state cut short by one byte",
        lambda: _load_state(_state_of(_hinged().finalize())[:-1]),
        ME,
        r"model data: .*truncated",
    ),
    (
        "bytes-count",
        "pickle",
        "a model's pickled state with its body count set to 2**62",
        lambda: _load_state(_with_body_count(_state_of(_hinged().finalize()), 2**62)),
        ME,
        r"model data: bodies: count 4611686018427387904 exceeds",
    ),
    (
        "bytes-version",
        "pickle",
        "a model's pickled state of another format version",
        lambda: _load_state(_with_format(_state_of(_hinged().finalize()), 1)),
        ME,
        r"format version 1",
    ),
    # ---- motor datasheet and payloads (issue 33)
    (
        "motor-brake-negative",
        "motor",
        "a motor's brake_torque −1",
        lambda: ad.Motor(brake_torque=-1.0),
        ME,
        r"Motor: brake_torque must be finite and > 0",
    ),
    (
        "motor-row-bad-value",
        "motor",
        "a catalog row with mass 'heavy'",
        lambda: ad.Motor.from_row({"name": "M1", "mass": "heavy"}),
        ME,
        r"Motor.from_row 'M1': mass must be a real number",
    ),
    (
        "motor-row-not-mapping",
        "motor",
        "a list as a catalog row",
        lambda: ad.Motor.from_row([1.0]),
        ME,
        r"Motor.from_row: row must be a mapping",
    ),
    (
        "payload-mass-negative",
        "payload",
        "with_payload mass −1",
        lambda: _pendulum().with_payload("link", -1.0),
        ME,
        r"with_payload: mass must be finite and >= 0, got -1",
    ),
    (
        "payload-inertia-unphysical",
        "payload",
        "with_payload inertia (1, 1, 3): triangle inequality",
        lambda: _pendulum().with_payload("link", 1.0, inertia=[1.0, 1.0, 3.0]),
        ME,
        r"with_payload: inertia violates the triangle inequality",
    ),
    (
        "payload-at-unknown",
        "payload",
        "with_payload at a name that is no frame or body",
        lambda: _pendulum().with_payload("nowhere", 1.0),
        ME,
        r"with_payload: at 'nowhere' is neither a frame, a body nor a joint",
    ),
    (
        "payload-name-taken",
        "payload",
        "with_payload named as a body of the model",
        lambda: _pendulum().with_payload("link", 1.0, name="link"),
        ME,
        r"with_payload: name 'link' is taken by a body",
    ),
    # ---- URDF
    (
        "urdf-mass-overflow",
        "urdf",
        "a link mass of 1e300 (finalize)",
        lambda: ad.load_urdf(
            _urdf(
                "<joint name='j' type='continuous'><parent link='base'/><child link='arm'/>"
                "<axis xyz='0 1 0'/></joint>",
                URDF_LINKS.replace('<mass value="1"/>', '<mass value="1e300"/>'),
            )
        ),
        ME,
        "body 'arm': mass = 1e\\+300",
    ),
    (
        "urdf-unterminated",
        "urdf",
        "unterminated XML",
        lambda: ad.load_urdf("<robot name='x'>"),
        UE,
        "(?i)xml|pars|urdf",
    ),
    (
        "urdf-not-xml",
        "urdf",
        "text that is not XML",
        lambda: ad.load_urdf("not xml"),
        UE,
        "(?i)xml|pars|urdf",
    ),
    (
        "urdf-missing-file",
        "urdf",
        "a path that does not exist",
        lambda: ad.load_urdf(DATA / "no_such_robot.urdf"),
        UE,
        "no_such_robot",
    ),
    (
        "urdf-floating",
        "urdf",
        "a floating joint",
        lambda: ad.load_urdf(DATA / "bad_floating.urdf"),
        UE,
        "(?i)floating",
    ),
    (
        "urdf-massless-moving",
        "urdf",
        "a massless leaf link on a moving joint",
        lambda: ad.load_urdf(DATA / "bad_massless_moving.urdf"),
        ME,
        "wrist.*hand",
    ),
    (
        "urdf-unknown-parent",
        "urdf",
        "a joint whose parent link does not exist",
        lambda: ad.load_urdf(
            _urdf(
                "<joint name='j' type='revolute'><parent link='nolink'/>"
                "<child link='arm'/><axis xyz='0 0 1'/>"
                "<limit lower='0' upper='1' effort='1' velocity='1'/></joint>"
            )
        ),
        UE,
        "nolink",
    ),
    (
        "urdf-zero-axis",
        "urdf",
        "a revolute joint with axis 0 0 0",
        lambda: ad.load_urdf(
            _urdf(
                "<joint name='za' type='continuous'><parent link='base'/>"
                "<child link='arm'/><axis xyz='0 0 0'/></joint>"
            )
        ),
        UE,
        "za",
    ),
    (
        "urdf-negative-mass",
        "urdf",
        "a link with mass −1",
        lambda: ad.load_urdf(
            _urdf(
                "<joint name='j' type='continuous'><parent link='base'/>"
                "<child link='arm'/><axis xyz='0 0 1'/></joint>",
                URDF_LINKS.replace('value="1"', 'value="-1"'),
            )
        ),
        UE,
        "arm",
    ),
    (
        "urdf-inertia-triangle",
        "urdf",
        "published PUMA 560 inertias violating I1 + I2 ≥ I3 on two links",
        lambda: ad.load_urdf(DATA / "puma560_published_inertia.urdf"),
        UE,
        "'link1'.*'link3'.*physical_inertia=False",
    ),
    (
        "urdf-planar",
        "urdf",
        "a planar joint (unsupported)",
        lambda: ad.load_urdf(
            _urdf(
                "<joint name='pl' type='planar'><parent link='base'/>"
                "<child link='arm'/><axis xyz='0 0 1'/></joint>"
            )
        ),
        UE,
        "pl",
    ),
    (
        "urdf-nan-inertia",
        "urdf",
        "an inertia ixx of nan (urdfdom would read 0)",
        lambda: ad.load_urdf(
            _urdf(
                "<joint name='j' type='continuous'><parent link='base'/>"
                "<child link='arm'/><axis xyz='0 0 1'/></joint>",
                URDF_LINKS.replace('ixx="0.01"', 'ixx="nan"'),
            )
        ),
        UE,
        r"link 'arm'.*<inertia> attribute 'ixx'",
    ),
    (
        "urdf-overflow-origin",
        "urdf",
        "a joint origin component 1e400",
        lambda: ad.load_urdf(
            _urdf(
                "<joint name='j' type='continuous'><parent link='base'/>"
                "<child link='arm'/><origin xyz='0 1e400 0'/><axis xyz='0 0 1'/></joint>"
            )
        ),
        UE,
        r"joint 'j'.*<origin> attribute 'xyz'",
    ),
    (
        "urdf-device",
        "urdf",
        "a path to a device (/dev/zero)",
        lambda: ad.load_urdf("/dev/zero"),
        UE,
        "character device",
    ),
    (
        "urdf-bad-utf8-name",
        "urdf",
        "a link name that is not valid UTF-8",
        lambda: ad.urdf_builder(
            _urdf(
                "<joint name='j' type='continuous'><parent link='base'/>"
                "<child link='arm'/><axis xyz='0 0 1'/></joint>"
            )
            .encode()
            .replace(b'name="base"', b'name="ba\xffse"')
        ),
        UE,
        r"not valid UTF-8 \(byte offset 2\)",
    ),
    (
        "urdf-many-attributes",
        "urdf",
        "an element with 40000 attributes",
        lambda: ad.load_urdf(
            _urdf(
                "<joint name='j' type='continuous'><parent link='base'/>"
                "<child link='arm'/><axis xyz='0 0 1'/></joint>",
                URDF_LINKS.replace(
                    '<link name="base"/>',
                    '<link name="base" ' + " ".join(f'a{i}="1"' for i in range(40000)) + "/>",
                ),
            )
        ),
        UE,
        "40001 attributes, more than the limit of 1000",
    ),
    # ---- MJCF (issue 36; armdyn.load_mjcf through MuJoCo's parser, docs/mjcf.md)
    (
        "mjcf-missing-file",
        "mjcf",
        "a path that does not exist",
        lambda: ad.load_mjcf(DATA / "no_such_robot.xml"),
        ME,
        r"MJCF file '.*no_such_robot\.xml' does not exist",
    ),
    (
        "mjcf-device",
        "mjcf",
        "/dev/zero as the file",
        lambda: ad.load_mjcf("/dev/zero"),
        ME,
        r"'/dev/zero' is a character device, not a regular file",
    ),
    (
        "mjcf-truncated",
        "mjcf",
        "truncated XML",
        lambda: ad.load_mjcf("<mujoco><worldbody><body><joint type='hin"),
        ME,
        r"MJCF string: not well-formed XML: unclosed token",
    ),
    (
        "mjcf-urdf-root",
        "mjcf",
        "a URDF given to load_mjcf",
        lambda: ad.load_mjcf("<robot name='r'/>"),
        ME,
        r"root element is <robot>, not <mujoco>",
    ),
    (
        "mjcf-nan-position",
        "mjcf",
        "a body position of NaN (MuJoCo accepts it)",
        lambda: ad.load_mjcf(_mjcf(pos="nan 0 0"), warn=False),
        ME,
        r"body 'link': position at qpos0 is not finite",
    ),
    (
        "mjcf-mass-overflow",
        "mjcf",
        "a body mass of 1e300 (finalize)",
        lambda: ad.load_mjcf(_mjcf(mass="1e300"), warn=False),
        ME,
        r"body 'link': mass = 1e\+300",
    ),
    (
        "mjcf-open-loop",
        "mjcf",
        "a connect between sites apart at qpos0",
        lambda: ad.load_mjcf(
            _mjcf(
                site='<site name="s1" pos="0.5 0 0"/>', world='<site name="s2" pos="0.7 0 0"/>'
            ).replace(
                "</mujoco>",
                '<equality><connect name="hold" site1="s1" site2="s2"/></equality></mujoco>',
            ),
            warn=False,
        ),
        ME,
        r"equality connect 'hold': not satisfied at qpos0",
    ),
    (
        "mjcf-fixed-base-type",
        "mjcf",
        "fixed_base='yes'",
        lambda: ad.load_mjcf(_mjcf(), fixed_base="yes"),
        ME,
        r"load_mjcf: fixed_base must be True or False, got 'yes'",
    ),
    # ---- arrays and joint-space calls
    (
        "fd-q-length",
        "arrays",
        "forward_dynamics with q of length 2 for 1 coordinate",
        lambda: ad.forward_dynamics(_pendulum(), [0, 0], [0], [0]),
        ME,
        r"\bq\b",
    ),
    (
        "fd-tau-nan",
        "arrays",
        "forward_dynamics with tau NaN",
        lambda: ad.forward_dynamics(_pendulum(), [0], [0], [np.nan]),
        ME,
        "tau",
    ),
    (
        "sfj-q-shape",
        "arrays",
        "state_from_joints with q of length 3",
        lambda: ad.state_from_joints(_pendulum(), np.zeros(3), np.zeros(1)),
        ME,
        r"\bq\b",
    ),
    (
        "acc-u-length",
        "arrays",
        "accelerations with u of length 5",
        lambda: ad.body_accelerations(_pendulum(), np.zeros(5), np.zeros(6)),
        ME,
        r"\bu\b",
    ),
    (
        "fd-on-loop",
        "arrays",
        "forward_dynamics on a closed loop given every joint's coordinate (it takes the "
        "independent ones, model.coord_names)",
        lambda: ad.forward_dynamics(ad.scenes.four_bar(), np.zeros(4), np.zeros(4), np.zeros(4)),
        ME,
        r"q: expected shape \(1,\)",
    ),
    (
        "loop-beyond-reach",
        "arrays",
        "inverse_dynamics of a four-bar whose rocker (its independent coordinate) is turned "
        "beyond the linkage's reach",
        lambda: ad.inverse_dynamics(_four_bar_by_rocker(), [1.5], [0.0], [0.0]),
        SE,
        r"no configuration at the independent coordinates \(D = 1\.5\)",
    ),
    (
        "loop-coordinate-unknown",
        "arrays",
        "set_independent_coordinates naming no joint coordinate",
        lambda: _four_bar_by_rocker("E"),
        ME,
        r"unknown joint coordinate 'E'",
    ),
    (
        "gear-train-every-coordinate",
        "arrays",
        "inverse_dynamics of a geared tree given every joint's coordinate (it takes the "
        "independent ones, model.coord_names)",
        lambda: ad.inverse_dynamics(_gear_train(), np.zeros(2), np.zeros(2), np.zeros(2)),
        ME,
        r"q: expected shape \(1,\)",
    ),
    (
        "gear-train-both-independent",
        "arrays",
        "set_independent_coordinates naming both coordinates a gear ties (mobility 1)",
        lambda: _gear_train(["ja", "jb"]),
        ME,
        r"2 coordinate\(s\) given, the model's mobility is 1",
    ),
    # ---- solver options
    (
        "sim-t-end",
        "solver",
        "simulate with t_end = −1",
        lambda: ad.simulate(_pendulum(), -1.0),
        ME,
        "t_end",
    ),
    (
        "sim-rtol",
        "solver",
        "simulate with rtol = −1e-6",
        lambda: ad.simulate(_pendulum(), 1.0, rtol=-1e-6),
        ME,
        "rtol",
    ),
    (
        "sim-integrator",
        "solver",
        "simulate with integrator 'euler_bogus'",
        lambda: ad.simulate(_pendulum(), 1.0, integrator="euler_bogus"),
        ME,
        "euler_bogus",
    ),
    (
        "sim-projection",
        "solver",
        "simulate with projection 'sideways'",
        lambda: ad.simulate(_pendulum(), 1.0, projection="sideways"),
        ME,
        "sideways",
    ),
    (
        "sim-rk4-dt",
        "solver",
        "rk4 without dt",
        lambda: ad.simulate(_pendulum(), 1.0, integrator="rk4"),
        ME,
        "dt",
    ),
    (
        "sim-dt-tiny",
        "solver",
        "dt = 1e-300 (t + dt == t)",
        lambda: ad.simulate(_pendulum(), 1.0, integrator="rk4", dt=1e-300),
        ME,
        "dt=1e-300 does not advance time",
    ),
    (
        "sim-rk4-memory",
        "solver",
        "rk4, dt = 1e-9 over 1 s without output_dt (1e9 output rows)",
        lambda: ad.simulate(_pendulum(), 1.0, integrator="rk4", dt=1e-9),
        ME,
        "dt=1e-09 .* GiB of outputs",
    ),
    (
        "sim-coordinates-none",
        "solver",
        "coordinates=None",
        lambda: ad.simulate(_pendulum(), 1.0, coordinates=None),
        ME,
        "coordinates must be one of 'cartesian', 'joint', 'auto'",
    ),
    (
        "sim-integrator-int",
        "solver",
        "integrator=123",
        lambda: ad.simulate(_pendulum(), 1.0, integrator=123),
        ME,
        "integrator must be one of",
    ),
    (
        "sim-max-steps-float",
        "solver",
        "max_steps=1.5",
        lambda: ad.simulate(_pendulum(), 1.0, max_steps=1.5),
        ME,
        "max_steps must be a positive integer",
    ),
    (
        "sim-t-end-str",
        "solver",
        "t_end='1'",
        lambda: ad.simulate(_pendulum(), "1"),
        ME,
        "t_end must be a positive number",
    ),
    (
        "rollout-threads-float",
        "solver",
        "rollout with threads=2.5",
        lambda: ad.rollout(_pendulum(), [[0.1]], t_end=1.0, threads=2.5),
        ME,
        "threads must be a positive integer",
    ),
    (
        "fd-complex",
        "arrays",
        "forward_dynamics with a complex tau array",
        lambda: ad.forward_dynamics(_pendulum(), [0.0], [0.0], np.array([1j])),
        ME,
        "tau: must hold real numbers, got a complex array",
    ),
    (
        "fd-overflow",
        "arrays",
        "forward_dynamics with tau = 1.7e308 (finite; the accelerations overflow)",
        lambda: ad.forward_dynamics(_pendulum(), [0.0], [0.0], [1.7e308]),
        SE,
        r"overflow.*tau\[0\]",
    ),
    (
        "id-overflow",
        "arrays",
        "inverse_dynamics with qdd = 1.7e308 (finite; the torques overflow)",
        lambda: ad.inverse_dynamics(_heavy_pendulum(), [0.0], [0.0], [1.7e308]),
        SE,
        r"overflow.*qdd\[0\]",
    ),
    (
        "frame-index-huge",
        "arrays",
        "frame index 2**63",
        lambda: ad.frame_pose(_pendulum(), [0.0], 2**63),
        ME,
        "frame index 9223372036854775808 out of range",
    ),
    (
        "frame-name-surrogate",
        "arrays",
        "frame name with a lone surrogate",
        lambda: ad.frame_pose(_pendulum(), [0.0], "tip\ud800"),
        ME,
        "frame must be valid Unicode",
    ),
    (
        "sim-max-step",
        "solver",
        "simulate with max_step = −1",
        lambda: ad.simulate(_pendulum(), 1.0, max_step=-1.0),
        ME,
        "max_step",
    ),
    (
        "sim-u0-nan",
        "solver",
        "initial state with NaN",
        lambda: ad.simulate(_pendulum(), 1.0, u0=np.full(7, np.nan), v0=np.zeros(6)),
        ME,
        "NaN",
    ),
    (
        "sim-nan-force",
        "solver",
        "a user force that becomes NaN mid-run",
        _nan_force_run,
        SE,
        "body 'link'",
    ),
    (
        "sim-max-steps",
        "solver",
        "more steps needed than max_steps",
        lambda: ad.simulate(_pendulum(), 10.0, max_steps=5),
        SE,
        "steps",
    ),
    # ---- inverse dynamics and validators
    (
        "id-under-driven",
        "inverse dynamics",
        "driven inverse dynamics of an undriven model",
        lambda: ad.driven_inverse_dynamics(_pendulum(), [0.0, 1.0]),
        ME,
        "hinge",
    ),
    (
        "id-times",
        "inverse dynamics",
        "times not increasing",
        lambda: ad.driven_inverse_dynamics(_driven(), [0.0, 0.5, 0.5]),
        ME,
        "increase",
    ),
    (
        "id-singular",
        "inverse dynamics",
        "a slider driven to the dead centre of a slider-crank",
        _slider_crank_dead_centre,
        SE,
        "singular.*drive 'guide'",
    ),
    (
        "id-qdd-nan",
        "inverse dynamics",
        "joint-space inverse dynamics with qdd NaN",
        lambda: ad.inverse_dynamics(_pendulum(), [0.0], [0.0], [np.nan]),
        ME,
        "qdd",
    ),
    (
        "jr-qdd-nan",
        "inverse dynamics",
        "joint_reactions with qdd NaN",
        lambda: ad.joint_reactions(_pendulum(), [0.0], [0.0], [np.nan]),
        ME,
        "qdd",
    ),
    (
        "jr-on-loop",
        "inverse dynamics",
        "joint_reactions on a closed loop given every joint's coordinate (it takes the "
        "independent ones)",
        lambda: ad.joint_reactions(ad.scenes.four_bar(), np.zeros(4), np.zeros(4), np.zeros(4)),
        ME,
        r"q: expected shape \(1,\)",
    ),
    (
        "jr-overflow",
        "inverse dynamics",
        "joint_reactions with qdd = 1.7e308 (finite; the forces overflow)",
        lambda: ad.joint_reactions(_heavy_pendulum(), [0.0], [0.0], [1.7e308]),
        SE,
        r"qdd\[0\].*overflow",
    ),
    # ---- derivatives of the dynamics (issue 34)
    (
        "idd-q-length",
        "derivatives",
        "inverse_dynamics_derivatives with q of length 2 for 1 coordinate",
        lambda: ad.inverse_dynamics_derivatives(_pendulum(), [0.0, 0.0], [0.0], [0.0]),
        ME,
        r"\bq\b",
    ),
    (
        "idd-qdd-nan",
        "derivatives",
        "inverse_dynamics_derivatives with qdd NaN",
        lambda: ad.inverse_dynamics_derivatives(_pendulum(), [0.0], [0.0], [np.nan]),
        ME,
        "qdd",
    ),
    (
        "idd-rows",
        "derivatives",
        "inverse_dynamics_derivatives with 3 rows of q and 2 of qd",
        lambda: ad.inverse_dynamics_derivatives(
            _pendulum(), np.zeros((3, 1)), np.zeros((2, 1)), np.zeros((3, 1))
        ),
        ME,
        r"\bqd\b",
    ),
    (
        "idd-t-rows",
        "derivatives",
        "inverse_dynamics_derivatives with 2 times for 3 rows",
        lambda: ad.inverse_dynamics_derivatives(
            _pendulum(), np.zeros((3, 1)), np.zeros((3, 1)), np.zeros((3, 1)), t=[0.0, 1.0]
        ),
        ME,
        r"\bt\b",
    ),
    (
        "idd-model",
        "derivatives",
        "inverse_dynamics_derivatives of a ModelBuilder (not finalized)",
        lambda: ad.inverse_dynamics_derivatives(_hinged(), [0.0], [0.0], [0.0]),
        ME,
        "model must be an armdyn.Model",
    ),
    (
        "idd-data-other-model",
        "derivatives",
        "inverse_dynamics_derivatives with data made for another model",
        lambda: ad.inverse_dynamics_derivatives(
            _pendulum(), [0.0], [0.0], [0.0], data=ad.Data(_heavy_pendulum())
        ),
        ME,
        "data.*another model",
    ),
    (
        "idd-overflow",
        "derivatives",
        "inverse_dynamics_derivatives with qdd = 1e308 on a two-link arm (finite; overflows)",
        lambda: ad.inverse_dynamics_derivatives(_two_links(), [0.0, 0.5], [0.0, 0.0], [1e308] * 2),
        SE,
        r"overflow.*qdd\[0\]",
    ),
    # ---- dynamic-parameter regressors (issue 35)
    (
        "reg-qdd-nan",
        "identification",
        "joint_torque_regressor with qdd NaN",
        lambda: ad.joint_torque_regressor(_pendulum(), [0.0], [0.0], [np.nan]),
        ME,
        r"joint_torque_regressor: qdd contains NaN",
    ),
    (
        "reg-rows",
        "identification",
        "joint_torque_regressor with 3 rows of q and 2 of qdd",
        lambda: ad.joint_torque_regressor(
            _pendulum(), np.zeros((3, 1)), np.zeros((3, 1)), np.zeros((2, 1))
        ),
        ME,
        r"\bqdd\b must have shape \(3, 1\)",
    ),
    (
        "reg-spring",
        "identification",
        "joint_torque_regressor of a model with a joint spring (not a dynamic parameter)",
        lambda: ad.joint_torque_regressor(_sprung_pendulum(), [0.0], [0.0], [0.0]),
        ME,
        r"joint coordinate 'hinge' has a spring",
    ),
    (
        "reg-overflow",
        "identification",
        "joint_torque_regressor with qd = 1e200 (finite; its square overflows)",
        lambda: ad.joint_torque_regressor(_pendulum(), [0.3], [1e200], [0.0]),
        SE,
        r"overflow.*qd\[0\]",
    ),
    (
        "ereg-qd-inf",
        "identification",
        "energy_regressor with qd inf",
        lambda: ad.energy_regressor(_pendulum(), [0.0], [np.inf]),
        ME,
        r"energy_regressor: qd contains NaN or inf",
    ),
    (
        "ereg-overflow",
        "identification",
        "energy_regressor with qd = 1e200 (finite; the kinetic energy overflows)",
        lambda: ad.energy_regressor(_pendulum(), [0.3], [1e200]),
        SE,
        r"overflow.*qd\[0\]",
    ),
    (
        "fdd-tau-nan",
        "derivatives",
        "forward_dynamics_derivatives with tau NaN",
        lambda: ad.forward_dynamics_derivatives(_pendulum(), [0.0], [0.0], [np.nan]),
        ME,
        "tau",
    ),
    (
        "fdd-qd-inf",
        "derivatives",
        "forward_dynamics_derivatives with qd inf",
        lambda: ad.forward_dynamics_derivatives(_pendulum(), [0.0], [np.inf], [0.0]),
        ME,
        r"\bqd\b",
    ),
    (
        "fdd-q-3d",
        "derivatives",
        "forward_dynamics_derivatives with a 3-D q",
        lambda: ad.forward_dynamics_derivatives(_pendulum(), np.zeros((2, 2, 1)), [0.0], [0.0]),
        ME,
        r"\bq\b",
    ),
    (
        "fdd-model",
        "derivatives",
        "forward_dynamics_derivatives with model None",
        lambda: ad.forward_dynamics_derivatives(None, [0.0], [0.0], [0.0]),
        ME,
        "model must be an armdyn.Model",
    ),
    (
        "fdd-data-type",
        "derivatives",
        "forward_dynamics_derivatives with data a Model (not a Data)",
        lambda: ad.forward_dynamics_derivatives(_pendulum(), [0.0], [0.0], [0.0], data=_pendulum()),
        ME,
        r"data must be an armdyn\.Data",
    ),
    (
        "fdd-data-other-model",
        "derivatives",
        "forward_dynamics_derivatives with data made for another model",
        lambda: ad.forward_dynamics_derivatives(
            _pendulum(), [0.0], [0.0], [0.0], data=ad.Data(_two_links())
        ),
        ME,
        "data.*another model",
    ),
    (
        "fdd-on-loop",
        "derivatives",
        "forward_dynamics_derivatives on a closed loop",
        lambda: ad.forward_dynamics_derivatives(
            ad.scenes.four_bar(), np.zeros(1), np.zeros(1), np.zeros(1)
        ),
        ME,
        "loop",
    ),
    (
        "fdd-overflow",
        "derivatives",
        "forward_dynamics_derivatives with tau = 1.7e308 on a two-link arm (finite; overflows)",
        lambda: ad.forward_dynamics_derivatives(_two_links(), [0.0, 0.5], [0.0, 0.0], [1.7e308, 0]),
        SE,
        r"overflow.*tau\[0\]",
    ),
    (
        "lagrange-loop",
        "validators",
        "Lagrange validator of a closed loop",
        lambda: ad.LagrangeValidator(ad.scenes.four_bar()),
        ME,
        "LagrangeValidator",
    ),
    (
        "metrics-zero-ref",
        "validators",
        "error metric against an identically zero reference",
        lambda: ad.validation.torque_error_metrics(np.ones((3, 1)), np.zeros((3, 1))),
        ME,
        "identically zero",
    ),
    (
        "sizing-no-model",
        "sizing",
        "sizing_report of a result that holds no model, none passed",
        lambda: ad.sizing_report(_modelless_result()),
        ME,
        "model is required",
    ),
    (
        "cli-payload-count",
        "sizing",
        "`--payload 1,2` (neither MASS nor MASS,X,Y,Z)",
        lambda: _cli().parse_payload("1,2"),
        ME,
        r"--payload '1,2'.*MASS,X,Y,Z",
    ),
    (
        "cli-payload-mass",
        "sizing",
        "`--payload -1` (a negative mass)",
        lambda: _cli().parse_payload("-1"),
        ME,
        r"--payload '-1'.*> 0 kg",
    ),
    (
        "cli-payload-com-nan",
        "sizing",
        "`--payload 3,0,nan,0` (a NaN centre of mass)",
        lambda: _cli().parse_payload("3,0,nan,0"),
        ME,
        r"--payload '3,0,nan,0'.*centre of mass' y",
    ),
    (
        "cli-payload-frame",
        "sizing",
        "`--payload-frame` naming no frame of the robot",
        lambda: _cli().payload_frame(_pendulum(), "tool0"),
        ME,
        r"--payload-frame 'tool0'.*no such frame",
    ),
    (
        "cli-cycle",
        "sizing",
        "`--cycle 0` (not a positive count nor forever)",
        lambda: _cli().parse_repeat("0"),
        ME,
        r"--cycle '0'",
    ),
    (
        "cli-dwell",
        "sizing",
        "`--dwell -1` (a negative duration)",
        lambda: _cli().parse_seconds("-1"),
        ME,
        r"--dwell '-1'",
    ),
    (
        "cli-option",
        "sizing",
        "`--life 0` (a check option out of its range)",
        lambda: _cli().sizing_options_from_strings({"required_life": "0"}),
        ME,
        r"--required-life.*required_life",
    ),
    (
        "cli-catalog-device",
        "sizing",
        "`--catalog /dev/zero` (a device, not a folder or a file)",
        lambda: _cli().catalog_paths(["/dev/zero"]),
        ME,
        r"--catalog '/dev/zero' is a character device",
    ),
    (
        "select-objective",
        "sizing",
        "select_drivetrain with an unknown objective",
        lambda: ad.select_drivetrain(_pendulum(), None, None, objective="weight"),
        ME,
        "objective",
    ),
    (
        "select-no-drives",
        "sizing",
        "select_drivetrain with drives=True and a catalog without drives",
        lambda: ad.select_drivetrain(_pendulum(), None, _catalog_without_drives()),
        ME,
        "drives=True but the catalog has no drives",
    ),
    (
        "gearbox-ratio-zero",
        "sizing",
        "gearbox_cycle_values with a zero gear ratio",
        lambda: _gearbox().gearbox_cycle_values(_joint_load(), [0.0], {}),
        ME,
        r"ratio\[0\] must be non-zero",
    ),
    (
        "gearbox-column-negative",
        "sizing",
        "a gearbox catalog column below zero (rated_torque −1)",
        lambda: _gearbox().gearbox_cycle_values(_joint_load(), [50.0], {"rated_torque": [-1.0]}),
        ME,
        r"gearboxes\['rated_torque'\]\[0\] must be > 0",
    ),
    (
        "gearbox-empty-cycle",
        "sizing",
        "a joint load of one sample (no cycle to average over)",
        lambda: _gearbox().gearbox_cycle_values(_joint_load(1), [50.0], {}),
        ME,
        "load.t must hold at least two samples",
    ),
    (
        "bearing-axis-zero",
        "sizing",
        "bearing_cycle_values of a load whose joint axis is zero",
        lambda: _gearbox().bearing_cycle_values(
            _joint_load(axis=(0, 0, 0)), {"bearing_offset": [0]}
        ),
        ME,
        "load.axis must be a non-zero vector",
    ),
    (
        "bus-voltage-max-below",
        "sizing",
        "bus_values with the chopper voltage below the nominal bus voltage",
        lambda: _drive().bus_values(
            [0.0, 1.0], [[1.0, -1.0]], drives={"bus_voltage": 48.0, "max_bus_voltage": 40.0}
        ),
        ME,
        r"drives\['max_bus_voltage'\]\[0\] is below",
    ),
    (
        "catalog-mass-negative",
        "catalogs",
        "a motor of mass −1 kg (also read from motors.csv: named by file:line)",
        lambda: ad.Catalog(_motors(mass=[-1.0])),
        ME,
        "part 'M1': column 'mass'",
    ),
    (
        "catalog-duplicate",
        "catalogs",
        "two motors of one name",
        lambda: ad.Catalog(_motors(name=["M1", "M1"])),
        ME,
        "motor 'M1' is already at",
    ),
    (
        "catalog-peak-below-continuous",
        "catalogs",
        "a motor whose peak torque is below its continuous torque",
        lambda: ad.Catalog(_motors(peak_torque=[0.4])),
        ME,
        "column 'peak_torque': 0.4 is less than continuous_torque",
    ),
    (
        "cycle-dwell-nan",
        "sizing",
        "duty cycle with a NaN dwell",
        lambda: ad.duty_cycle(_pendulum(), _rest_motion(), dwell=np.nan),
        ME,
        "dwell",
    ),
    (
        "cycle-repeat-fraction",
        "sizing",
        "duty cycle repeated 1.5 times",
        lambda: ad.duty_cycle(_pendulum(), _rest_motion(), repeat=1.5),
        ME,
        "repeat",
    ),
    (
        "cycle-not-at-rest",
        "sizing",
        "duty cycle of a motion that ends moving",
        lambda: ad.duty_cycle(_pendulum(), _rest_motion(end_rate=0.5), dwell=1.0),
        ME,
        "hinge",
    ),
    (
        "least-energy-duration-nan",
        "motion",
        "least_energy with a NaN duration",
        lambda: _least_energy(duration=np.nan),
        ME,
        "least_energy: duration must be a positive number",
    ),
    (
        "least-energy-start-shape",
        "motion",
        "least_energy from a start of two coordinates on a one-joint model",
        lambda: _least_energy(start=[0.0, 0.0]),
        ME,
        r"least_energy: start must have shape \(1,\)",
    ),
    (
        "least-energy-copper-no-motor",
        "motion",
        "least_energy's copper loss on a joint without a motor's torque constant and resistance",
        lambda: _least_energy(objective="copper"),
        ME,
        "joint 'hinge' has none",
    ),
    (
        "least-energy-infeasible",
        "motion",
        "least_energy in less time than any motion within the torque limit takes",
        lambda: _least_energy(duration=0.2, max_torque=0.5),
        SE,
        "most exceeded limit is torque of joint 'hinge'",
    ),
    # ---- example machines (issue 36)
    (
        "palletizer-closure",
        "scenes",
        "palletizer with closure='weld'",
        lambda: ad.scenes.palletizer(closure="weld"),
        ME,
        "closure",
    ),
    (
        "palletizer-payload",
        "scenes",
        "palletizer with a negative payload",
        lambda: ad.scenes.palletizer(payload=-1.0),
        ME,
        "payload",
    ),
    (
        "delta-rod-short",
        "scenes",
        "delta robot whose rods cannot reach the plate",
        lambda: ad.scenes.delta_robot(geometry=ad.scenes.machines.DeltaGeometry(rod=0.3)),
        ME,
        r"geometry\.rod",
    ),
    (
        "machine-drive-passive",
        "scenes",
        "delta robot driven on a rod",
        lambda: ad.scenes.delta_robot(drives={"rod1a": 0.0}),
        ME,
        "rod1a",
    ),
    (
        "cycle-machine",
        "scenes",
        "pick_and_place of an unknown machine",
        lambda: ad.scenes.pick_and_place("scara"),
        ME,
        "machine",
    ),
    (
        "delta-ik-reach",
        "scenes",
        "delta_ik of a plate position out of reach",
        lambda: ad.scenes.machines.delta_ik([[0.0, 0.0, -0.8], [0.0, 0.0, -3.0]]),
        SE,
        "position 1",
    ),
    # ---- motion: joint trajectories
    (
        "p2p-start-nan",
        "motion",
        "point-to-point move from a NaN joint position",
        lambda: _motion().point_to_point([0.0, np.nan], [1.0, 1.0], **_LIMITS),
        ME,
        r"point_to_point: start\[1\] = .*nan.* is not finite",
    ),
    (
        "p2p-velocity-limit-zero",
        "motion",
        "a zero velocity limit",
        lambda: _motion().point_to_point(0.0, 1.0, **{**_LIMITS, "max_velocity": 0.0}),
        ME,
        r"max_velocity\[0\] = 0\.0 must be positive",
    ),
    (
        "p2p-limit-shape",
        "motion",
        "three velocity limits for two joints",
        lambda: _motion().point_to_point([0, 0], [1, 1], **{**_LIMITS, "max_velocity": [1, 2, 3]}),
        ME,
        r"max_velocity must be a scalar or have shape \(2,\)",
    ),
    (
        "p2p-jerk-missing",
        "motion",
        "a jerk-limited profile without a jerk limit",
        lambda: _motion().point_to_point(0.0, 1.0, max_velocity=1.0, max_acceleration=1.0),
        ME,
        "profile='double_s' needs max_jerk",
    ),
    (
        "p2p-too-many-samples",
        "motion",
        "a 10 000 s move sampled every microsecond",
        lambda: _motion().point_to_point(0.0, 1e4, **_LIMITS, dt=1e-6),
        ME,
        r"dt = 1e-06 s over .* samples \(> 10000000\)",
    ),
    (
        "p2p-scales",
        "motion",
        "a move of 1e300 rad at 1 rad/s (ruckig finds no profile)",
        lambda: _motion().point_to_point(0.0, 1e300, **_LIMITS),
        SE,
        r"segment 0 \(waypoint 0 to 1\) of joint 0",
    ),
    (
        "via-one-waypoint",
        "motion",
        "a move through a single waypoint",
        lambda: _motion().through_waypoints([[0.0, 1.0]], **_LIMITS),
        ME,
        "waypoints must hold at least two points, got 1",
    ),
    (
        "spline-times-repeat",
        "motion",
        "a spline whose times repeat",
        lambda: _motion().spline([0.0, 1.0, 1.0], [0.0, 1.0, 2.0]),
        ME,
        r"times must be strictly increasing \(times\[2\]",
    ),
    (
        "spline-over-limit",
        "motion",
        "a spline too fast for its velocity limit",
        lambda: _motion().spline([0.0, 0.5], [[0.0, 0.0], [0.1, 2.0]], max_velocity=[1.0, 3.0]),
        SE,
        r"joint 1 reaches velocity 7\.5 at t = 0\.25 s",
    ),
    (
        "path-repeated-waypoint",
        "motion",
        "a waypoint path through the same point twice in a row",
        lambda: _motion().waypoint_path([[0.0, 1.0], [0.0, 1.0], [1.0, 1.0]]),
        ME,
        r"waypoints\[0\] and waypoints\[1\] are equal",
    ),
    (
        "topp-torque-negative",
        "motion",
        "time_optimal with a negative torque limit",
        lambda: ad.motion.time_optimal(_pendulum(), _swing(), max_torque=-1.0),
        ME,
        r"max_torque\[0\] \(joint 'hinge'\)",
    ),
    (
        "topp-grid-one",
        "motion",
        "time_optimal on a grid of one interval",
        lambda: ad.motion.time_optimal(_pendulum(), _swing(), max_torque=5.0, grid=1),
        ME,
        "grid must be",
    ),
    (
        "topp-path-array",
        "motion",
        "time_optimal of an array instead of a Path",
        lambda: ad.motion.time_optimal(_pendulum(), np.zeros((2, 1))),
        ME,
        "path must be an armdyn.motion.Path",
    ),
    (
        "topp-unbounded",
        "motion",
        "time_optimal with no limit on the moving joint",
        lambda: ad.motion.time_optimal(_pendulum(), _swing(), max_torque=np.inf),
        ME,
        "nothing limits the path speed",
    ),
    (
        "topp-static-torque",
        "motion",
        "time_optimal from a pose whose holding torque exceeds the limit",
        lambda: ad.motion.time_optimal(_pendulum(), _swing(np.pi / 2, 2.5), max_torque=2.0),
        SE,
        r"s = 0 .*torque 'hinge' at rest is 4\.905",
    ),
    (
        "topp-joint-coulomb",
        "motion",
        "time_optimal of a model with a joint's Coulomb friction (dampers are accepted)",
        lambda: ad.motion.time_optimal(_coulomb_pendulum(), _swing(), max_torque=5.0),
        ME,
        r"velocity-dependent forces .*joint 'hinge'",
    ),
    (
        "cycle-time-no-motor",
        "motion",
        "shortest_cycle of a model without a motor",
        lambda: ad.motion.shortest_cycle(_pendulum(), _swing(), dwell=1.0, max_torque=5.0),
        ME,
        "no actuator with a motor",
    ),
    (
        "cycle-time-dwell-negative",
        "motion",
        "shortest_cycle with a negative dwell",
        lambda: ad.motion.shortest_cycle(_pendulum(), _swing(), dwell=-1.0),
        ME,
        "dwell",
    ),
    (
        "ik-target-nan",
        "motion",
        "inverse_kinematics with NaN in the target pose",
        lambda: _motion().inverse_kinematics(_arm2(), "tip", _tip_pose(y=np.nan), [0.3, 0.5]),
        ME,
        r"target\[1, 3\] = .*nan",
    ),
    (
        "ik-target-not-rotation",
        "motion",
        "inverse_kinematics with a scaled rotation (|R^T R - I| = 0.02)",
        lambda: _motion().inverse_kinematics(_arm2(), "tip", _tip_pose(scale=1.01), [0.3, 0.5]),
        ME,
        r"target\[:3, :3\] is not a rotation matrix",
    ),
    (
        "ik-unknown-frame",
        "motion",
        "inverse_kinematics of a frame the model does not have",
        lambda: _motion().inverse_kinematics(_arm2(), "hand", _tip_pose(), [0.3, 0.5]),
        ME,
        "unknown frame 'hand'",
    ),
    (
        "ik-unreachable",
        "motion",
        "inverse_kinematics of a target beyond the arm's reach",
        lambda: _motion().inverse_kinematics(
            _arm2(), "tip", _tip_pose(x=5.0), [0.3, 0.5], mask=_XY
        ),
        SE,
        r"no solution for frame 'tip' at position \[5\.0",
    ),
    (
        "move-start-outside-limits",
        "motion",
        "linear_move from a start outside a joint's limits",
        lambda: _motion().linear_move(
            _arm2(limit=1.0), "tip", [0.0, 1.5], [1.0, 0.5, 0.0], mask=_XY
        ),
        ME,
        r"q_start\[1\] = 1\.5 is outside joint 'j1'",
    ),
    (
        "move-rows-not-joints",
        "motion",
        "linear_move of a 2-joint arm along all six rows (q(s) not unique)",
        lambda: _motion().linear_move(_arm2(), "tip", [0.3, 0.5], [1.0, 0.5, 0.0]),
        ME,
        r"moved by 2 joints but the move keeps 6 rows",
    ),
    (
        "arc-collinear",
        "motion",
        "arc_move through three points on a line",
        lambda: _motion().arc_move(
            _arm2(), "tip", [0.0, 0.0], [1.4, 0.0, 0.0], [1.2, 0.0, 0.0], mask=_XY
        ),
        ME,
        "collinear",
    ),
    (
        "move-singular",
        "motion",
        "linear_move beyond the stretched arm (manipulability falls below its minimum)",
        lambda: _motion().linear_move(_arm2(), "tip", [0.0, 1.0], [2.5, 0.0, 0.0], mask=_XY),
        SE,
        r"singularity at s = [0-9.]+ \(position \[",
    ),
    (
        "base-parameters-samples-zero",
        "identification",
        "base_parameters with samples = 0",
        lambda: _identification().base_parameters(_pendulum(), samples=0),
        ME,
        r"samples must be an integer in \[1, 1000000\], got 0",
    ),
    (
        "excitation-floating-base",
        "identification",
        "fourier_excitation of a floating base",
        lambda: _identification().fourier_excitation(_floating_box()),
        ME,
        "floating base",
    ),
    (
        "excitation-period-nan",
        "identification",
        "fourier_excitation with period NaN",
        lambda: _identification().fourier_excitation(
            _pendulum(), period=float("nan"), max_velocity=1.0
        ),
        ME,
        "period must be a positive number",
    ),
    (
        "excitation-unknown-criterion",
        "identification",
        "fourier_excitation with a criterion it does not know",
        lambda: _identification().fourier_excitation(
            _pendulum(), max_velocity=1.0, criterion="log-det"
        ),
        ME,
        "criterion",
    ),
    (
        "excitation-torque-infeasible",
        "identification",
        "fourier_excitation whose torque limit is below the gravity torque at q0",
        lambda: _identification().fourier_excitation(
            _pendulum(), q0=[1.0], max_velocity=1.0, max_torque=0.1, harmonics=2, samples=10
        ),
        SE,
        "torque limit of joint 'hinge'",
    ),
    (
        "log-unknown-column",
        "identification",
        "load_log with a column that is no coordinate of the model",
        lambda: _load_log({**_log_columns(), "wrist": [0.0] * 6}),
        ME,
        r"unknown column 'wrist'",
    ),
    (
        "log-missing-torque",
        "identification",
        "load_log with neither `<joint>.tau` nor `<joint>.current` for a joint",
        lambda: _load_log({k: v for k, v in _log_columns().items() if k != "hinge.tau"}),
        ME,
        r"joint 'hinge' needs one of the columns 'hinge.tau' or 'hinge.current'",
    ),
    (
        "log-nan-cell",
        "identification",
        "load_log with a NaN cell",
        lambda: _load_log({**_log_columns(), "hinge": [0.0, 0.1, np.nan, 0.3, 0.4, 0.5]}),
        ME,
        r"column 'hinge', row 2 is 'nan', not finite",
    ),
    (
        "log-time-order",
        "identification",
        "load_log with t not strictly increasing",
        lambda: _load_log({**_log_columns(), "t": [0.0, 0.1, 0.1, 0.3, 0.4, 0.5]}),
        ME,
        r"t must be strictly increasing, but row 2",
    ),
    (
        "log-current-constants",
        "identification",
        "load_log with a current column but no torque constants",
        lambda: _load_log(
            {("hinge.current" if k == "hinge.tau" else k): v for k, v in _log_columns().items()}
        ),
        ME,
        r"torque_constants is required",
    ),
    (
        "log-cutoff-nyquist",
        "identification",
        "log_from_arrays with a cutoff above the Nyquist frequency",
        lambda: _identification().log_from_arrays(
            _pendulum(), np.arange(40) * 0.1, np.zeros((40, 1)), np.zeros((40, 1)), cutoff=6.0
        ),
        ME,
        r"cutoff 6.0 Hz is not below the Nyquist frequency 5 Hz",
    ),
    (
        "log-device",
        "identification",
        "load_log of a device (/dev/zero)",
        lambda: _identification().load_log("/dev/zero", _pendulum()),
        ME,
        r"'/dev/zero' is a character device, not a regular file",
    ),
    (
        "log-directory",
        "identification",
        "load_log of a directory",
        lambda: _identification().load_log(DATA, _pendulum()),
        ME,
        r"is a directory, not a regular file",
    ),
    (
        "log-floating-base",
        "identification",
        "load_log with a floating-base model",
        lambda: _identification().load_log(
            _log_columns(), ad.urdf_builder(str(DATA / "arm6.urdf"), fixed_base=False).finalize()
        ),
        ME,
        r"floating base",
    ),
    (
        "with-parameters-length",
        "identification",
        "with_parameters with a pi one entry short",
        lambda: _ident().with_parameters(_pendulum(), np.zeros(13)),
        ME,
        r"pi must have shape \(14,\)",
    ),
    (
        "with-parameters-nan",
        "identification",
        "with_parameters with a NaN entry in pi",
        lambda: _ident().with_parameters(_pendulum(), _pi_with(4, np.nan)),
        ME,
        r"pi\[4\] \('link.Ixx'\) must be finite",
    ),
    (
        "with-parameters-negative-mass",
        "identification",
        "with_parameters with a negative body mass",
        lambda: _ident().with_parameters(_pendulum(), _pi_with(0, -1.0)),
        ME,
        r"body 'link': mass \('link.m'\) must be >= 0",
    ),
    (
        "with-parameters-not-psd",
        "identification",
        "with_parameters with a body inertia that is not positive semidefinite",
        lambda: _ident().with_parameters(_pendulum(), _pi_with(4, -1.0)),
        ME,
        r"body 'link'.*not positive semidefinite",
    ),
    (
        "write-urdf-missing-link",
        "identification",
        "write_urdf onto a URDF without one of the model's bodies",
        lambda: _ident().write_urdf(
            '<robot name="r"><link name="other"/></robot>', _pendulum(), _pi_with(0, 1.0)
        ),
        ME,
        "the URDF has no link 'link'",
    ),
    (
        "identify-log-of-another-model",
        "identification",
        "identify with a log whose joint names are not the model's coordinates",
        lambda: _ident().identify(_pendulum(), _swing_log(names=["elbow"])),
        ME,
        r"log.joint_names \['elbow'\] do not match the model's coord_names \['hinge'\]",
    ),
    (
        "identify-too-few-samples",
        "identification",
        "identify with four samples (fewer rows than base parameters)",
        lambda: _ident().identify(_pendulum(), _swing_log(n=4)),
        SE,
        r"rank deficient: the log excites only",
    ),
    (
        "identify-outlier-threshold",
        "identification",
        "identify with outlier_threshold 0",
        lambda: _ident().identify(_pendulum(), _swing_log(), outlier_threshold=0.0),
        ME,
        r"outlier_threshold must be a number > 0",
    ),
    (
        "validate-log-joints",
        "identification",
        "validate with a log of other joints than the model's",
        lambda: _validate(joint_names=["other"]),
        ME,
        r"the log's joints \['other'\] are not the model's \['hinge'\]",
    ),
    (
        "validate-pi-length",
        "identification",
        "validate with a pi of the wrong length",
        lambda: _validate(pi=np.ones(3)),
        ME,
        r"pi has 3 entries, the model 14",
    ),
    (
        "identify-cli-per-joint",
        "identification",
        "`armdyn identify --gear-ratios elbow=2,3` (named and unnamed entries mixed)",
        lambda: _identify_cli().per_joint("--gear-ratios", "elbow=2,3"),
        ME,
        r"--gear-ratios 'elbow=2,3': either every entry is JOINT=VALUE or none is",
    ),
    (
        "identify-cli-cutoff",
        "identification",
        "`armdyn identify --cutoff -1` (not a positive frequency)",
        lambda: _identify_cli()._cutoff("-1"),
        ME,
        r"--cutoff '-1': the cutoff must be > 0 Hz",
    ),
]


def _identification():
    import armdyn.identification

    return armdyn.identification


def _floating_box():
    b = ad.ModelBuilder()
    b.add_body("box", 1.0, I3)
    b.add_free("float", "box")
    return b.finalize()


def _log_columns():
    """A six-sample log of the pendulum (coordinate 'hinge') as a dict of columns."""
    t = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5]
    return {"t": t, "hinge": [0.1 * x for x in t], "hinge.tau": [1.0] * 6}


def _load_log(columns):
    return _identification().load_log(columns, _pendulum())


def _ident():
    from armdyn import identification

    return identification


def _swing_log(n=50, names=("hinge",)):
    """A log of the pendulum swinging (torques by its inverse dynamics)."""
    model = _pendulum()
    t = np.linspace(0.0, 2.0, n)
    q, qd, qdd = np.sin(3 * t)[:, None], 3 * np.cos(3 * t)[:, None], -9 * np.sin(3 * t)[:, None]
    tau = np.array([ad.inverse_dynamics(model, *x) for x in zip(q, qd, qdd, strict=True)])
    return _ident().MotionLog(t, q, qd, qdd, tau, list(names), "synthetic")


def _pi_with(i, value):
    """The pendulum's dynamic parameters with entry i set to value."""
    pi = ad.dynamic_parameters(_pendulum())
    pi[i] = value
    return pi


_LIMITS = {"max_velocity": 1.0, "max_acceleration": 2.0, "max_jerk": 10.0}


def _motion():
    import armdyn.motion

    return armdyn.motion


def _swing(q0=0.0, q1=1.0):
    """A straight joint-space path of the pendulum's hinge from q0 to q1."""
    return ad.motion.Path([0.0, 1.0], [[q0], [q1]])


def _motion():
    from armdyn import motion

    return motion


_XY = [1, 1, 0, 0, 0, 0]


def _arm2(limit=None):
    """A planar 2R arm (links 1 m and 0.8 m, axes z) with the frame 'tip' at its end; joint
    'j1' limited to [-limit, limit] when given."""
    b = ad.ModelBuilder()
    b.add_body("l0", 1.0, I3, position=(0.5, 0.0, 0.0))
    b.add_revolute("j0", "ground", "l0", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    b.add_body("l1", 1.0, I3, position=(1.4, 0.0, 0.0))
    b.add_revolute("j1", "l0", "l1", (1.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    b.add_frame("tip", "l1", position=(1.8, 0.0, 0.0))
    if limit is not None:
        b.set_joint_limits("j1", -limit, limit)
    return b.finalize()


def _tip_pose(x=1.2, y=0.5, scale=1.0):
    t = np.eye(4)
    t[:3, :3] *= scale
    t[:2, 3] = (x, y)
    return t


def _least_energy(**change):
    from armdyn.motion import least_energy

    args = dict(start=[0.0], goal=[1.0], duration=1.0, objective="rms_torque")
    args.update(change)
    return least_energy(_pendulum(), **args)


def _validate(pi=None, **log_fields):
    """validate(pendulum, a three-sample log of it, pi=pi), the log's fields overridden."""
    from types import SimpleNamespace

    from armdyn.identification import validate

    z = np.zeros((3, 1))
    fields = dict(t=np.arange(3.0), q=z, qd=z, qdd=z, tau=z, joint_names=["hinge"])
    fields.update(log_fields)
    return validate(_pendulum(), SimpleNamespace(**fields), pi=pi)


def _identify_cli():
    from armdyn.identification import cli

    return cli


def _cli():
    from armdyn.sizing import cli

    return cli


def _catalog_without_drives():
    """A catalog of one motor and one gearbox (the attributes select_drivetrain reads)."""
    from types import SimpleNamespace

    import pandas as pd

    motors = pd.DataFrame({"mass": [0.5], "rotor_inertia": [1e-5]}, index=["M"])
    gearboxes = pd.DataFrame(
        {"mass": [0.4], "ratio": [100.0], "efficiency": [0.8], "input_inertia": [1e-6]},
        index=["G"],
    )
    return SimpleNamespace(motors=motors, gearboxes=gearboxes, drives=None)


def _gearbox():
    from armdyn.sizing import gearbox

    return gearbox


def _drive():
    from armdyn.sizing import drive

    return drive


def _joint_load(n=5, axis=(0.0, 0.0, 1.0)):
    """JointLoad's fields (a stand-in) for a small cycle of n samples."""
    from types import SimpleNamespace

    t = np.linspace(0.0, 1.0, n)
    z = np.zeros((n, 3))
    return SimpleNamespace(t=t, speed=np.sin(t), torque=np.cos(t), force=z, moment=z, axis=axis)


def _motors(**change):
    """A one-motor table (two rows when ``name`` has two), with ``change`` applied."""
    n = len(change.get("name", ["M1"]))
    row = dict(name=["M1"], torque_constant=[0.1], resistance=[0.5], rotor_inertia=[1e-5])
    row.update(mass=[0.3], continuous_torque=[0.5], peak_torque=[1.5])
    row.update(change)
    return {k: (v * n if len(v) == 1 else v) for k, v in row.items()}


def _rest_motion(end_rate=0.0):
    """(t, q, qd, qdd) of the hinge: at rest at both ends (its last rate ``end_rate``)."""
    t = np.linspace(0.0, 1.0, 11)
    qd = np.sin(np.pi * t)[:, None]
    qd[-1] = end_rate
    return t, np.zeros((11, 1)), qd, np.zeros((11, 1))


def _modelless_result():
    """A run's arrays without its model (a result built by hand)."""
    from types import SimpleNamespace

    r = ad.simulate(_pendulum(), 0.1, output_dt=0.05)
    return SimpleNamespace(t=r.t, q=r.q, qd=r.qd, qdd=r.qdd, joint_torques=r.joint_torques)


def render() -> str:
    """The Markdown table of docs/bad_inputs.md, with the actual messages."""
    import re

    lines = [
        "# Bad inputs armdyn rejects",
        "",
        "Generated by `python tests/bad_input_catalogue.py > docs/bad_inputs.md`; every row is a",
        "test in `tests/model/test_bad_input_catalogue.py` (exception type and the culprit named",
        "in the message). Model and builder state are left unchanged by a failed call (tested in",
        "`tests/model/test_bad_input.py`).",
        "",
        f"{len(CASES)} cases.",
        "",
        "| id | area | input | exception | message |",
        "|---|---|---|---|---|",
    ]
    for cid, area, what, fn, exc, _pattern in CASES:
        try:
            fn()
            message = "(no exception!)"
        except exc as e:
            message = str(e).splitlines()[0]
        message = re.sub(r" at 0x[0-9a-f]+", "", message)
        message = re.sub(r"<function \S+>", "<function>", message)
        message = message.replace(str(DATA), "tests/data/urdf")
        if len(message) > 160:
            message = message[:157] + "..."
        message = message.replace("|", "\\|")
        lines.append(f"| {cid} | {area} | {what} | `{exc.__name__}` | {message} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.stdout.write(render())
