"""Every argument of every ModelBuilder method (and its constructor, finalize and the
physical_inertia setter), of armdyn.Motor and armdyn.Data, of urdf_builder and of the
armdyn.profiles factories fed a wrong type, None, NaN, an infinity, a complex number or array, a
lone-surrogate string or a huge integer: a ModelError naming the argument, never pybind11's
"incompatible function arguments" signature dump nor "Unable to cast" (common.hpp's float_arg,
int_arg, bool_arg, str_arg in the bindings), and the builder unchanged. The baselines succeed, so
each failure is the bad argument's."""

from __future__ import annotations

import armdyn as ad
import numpy as np
import pytest
from armdyn.sizing import MOTOR_FIELDS

LEAKS = ("incompatible function arguments", "Unable to cast", "TypeError", "ComplexWarning")
SURROGATE = "bad\ud800name"
I3 = np.diag([1e-3, 1e-3, 1e-3])

# bad values by kind of argument; None is bad unless the argument takes it
BAD = {
    "name": [SURROGATE, 5, b"link", 1j, ["a"]],
    "text": [SURROGATE, 5, 1j, ["a"]],  # a str or bytes (urdf_builder's source)
    "float": ["1", 1j, np.nan, np.inf, -np.inf, True, np.bool_(True), 10**400, [1.0], object()],
    # a number where an infinity is meaningful (no limit): NaN and non-numbers refused
    "float_inf": ["1", 1j, np.nan, True, 10**400, [1.0]],
    "int": [1.5, 2**70, -(2**70), 2**40, "0", True, 1j, np.nan],
    "bool": ["yes", 2, 1j, 0],
    "vec": [np.array([0.1 + 1j, 0.0, 0.0]), "x", "abc", [[0.1], [0.2, 0.3]], [1.0, 2.0]],
    "inertia": [[[1j, 0, 0], [0, 1, 0], [0, 0, 1]], "abc", [1.0, 2.0]],
    "profile": ["abc", 1j, b"x"],
    "motor": [5, "maxon"],
    "model": [5, "model", ad.ModelBuilder()],
}


def _builder():
    """ground - hinge - a - slide - b, a free body c, an unattached body d."""
    b = ad.ModelBuilder()
    b.add_body("a", 1.0, I3, position=(0.0, 0.0, -0.5))
    b.add_body("b", 1.0, I3, position=(0.0, 0.0, -1.0))
    b.add_body("c", 1.0, I3, position=(1.0, 0.0, 0.0))
    b.add_body("d", 1.0, I3, position=(2.0, 0.0, 0.0))
    b.add_revolute("hinge", "ground", "a", (0, 0, 0), (0, 1, 0))
    b.add_revolute("hinge2", "ground", "c", (1, 0, 0), (0, 1, 0))
    b.add_prismatic("slide", "a", "b", (0, 0, -0.5), (0, 0, 1))
    return b


def _method(name, base):
    return lambda b, **o: getattr(b, name)(**{**base, **o})


JOINT = dict(name="j", parent="ground", child="d", point=(2.0, 0.0, 0.0), axis=(1.0, 0.0, 0.0))
JOINT_OPTS = {
    "name": ("name", False),
    "parent": ("name", False),
    "child": ("name", False),
    "point": ("vec", False),
    "axis": ("vec", False),
}
SPRING = dict(
    name="s", body_a="a", point_a=(0, 0, -0.5), body_b="c", point_b=(1, 0, 0), stiffness=10.0
)
GEAR = dict(name="g", joint_a="hinge", joint_b="hinge2", r_a=1.0, r_b=2.0)

# (method id, call(builder, **options), {option: (kind, None accepted)})
METHODS = [
    (
        "add_body",
        _method("add_body", dict(name="e", mass=1.0, inertia=I3)),
        {
            "name": ("name", False),
            "mass": ("float", False),
            "inertia": ("inertia", False),
            "position": ("vec", False),
            "orientation": ("vec", False),
        },
    ),
    ("add_revolute", _method("add_revolute", JOINT), JOINT_OPTS),
    ("add_prismatic", _method("add_prismatic", JOINT), JOINT_OPTS),
    ("add_cylindrical", _method("add_cylindrical", JOINT), JOINT_OPTS),
    ("add_inline", _method("add_inline", JOINT), JOINT_OPTS),
    (
        "add_spherical",
        _method("add_spherical", {k: v for k, v in JOINT.items() if k != "axis"}),
        {k: v for k, v in JOINT_OPTS.items() if k != "axis"},
    ),
    (
        "add_fixed",
        _method("add_fixed", {k: v for k, v in JOINT.items() if k != "axis"}),
        {**{k: v for k, v in JOINT_OPTS.items() if k != "axis"}, "point": ("vec", True)},
    ),
    (
        "add_universal",
        _method(
            "add_universal",
            dict(name="u", parent="ground", child="d", point=(2, 0, 0), axis1=(1, 0, 0))
            | {"axis2": (0, 1, 0)},
        ),
        {
            **{k: v for k, v in JOINT_OPTS.items() if k != "axis"},
            "axis1": ("vec", False),
            "axis2": ("vec", False),
        },
    ),
    (
        "add_distance",
        _method(
            "add_distance",
            dict(name="r", body_a="a", point_a=(0, 0, -0.5), body_b="c", point_b=(1, 0, 0)),
        ),
        {
            "name": ("name", False),
            "body_a": ("name", False),
            "point_a": ("vec", False),
            "body_b": ("name", False),
            "point_b": ("vec", False),
        },
    ),
    (
        "add_free",
        _method("add_free", dict(name="f", child="d")),
        {"name": ("name", False), "child": ("name", False), "origin": ("vec", True)},
    ),
    (
        "add_frame",
        _method("add_frame", dict(name="tip", body="a")),
        {
            "name": ("name", False),
            "body": ("name", False),
            "position": ("vec", False),
            "orientation": ("vec", False),
        },
    ),
    (
        "set_joint_limits",
        _method("set_joint_limits", dict(joint="hinge", lower=-1.0, upper=1.0)),
        {
            "joint": ("name", False),
            "lower": ("float_inf", False),
            "upper": ("float_inf", False),
            "effort": ("float_inf", False),
            "velocity": ("float_inf", False),
        },
    ),
    (
        "add_drive",
        _method("add_drive", dict(joint="hinge", profile=0.1)),
        {
            "joint": ("name", False),
            "profile": ("profile", False),
            "coord": ("int", False),
            "name": ("name", True),
        },
    ),
    (
        "add_body_force",
        _method("add_body_force", dict(body="a")),
        {
            "body": ("name", False),
            "force": ("vec", False),
            "torque": ("vec", False),
            "point": ("vec", True),
            "profile": ("profile", True),
        },
    ),
    (
        "add_spring_damper",
        _method("add_spring_damper", SPRING),
        {
            "name": ("name", False),
            "body_a": ("name", False),
            "point_a": ("vec", False),
            "body_b": ("name", False),
            "point_b": ("vec", False),
            "stiffness": ("float", False),
            "damping": ("float", False),
            "rest_length": ("float", True),
        },
    ),
    (
        "add_joint_spring_damper",
        _method("add_joint_spring_damper", dict(joint="hinge")),
        {
            "joint": ("name", False),
            "stiffness": ("float", False),
            "damping": ("float", False),
            "rest": ("float", False),
            "coord": ("int", False),
        },
    ),
    (
        "add_joint_friction",
        _method("add_joint_friction", dict(joint="hinge")),
        {
            "joint": ("name", False),
            "viscous": ("float", False),
            "coulomb": ("float", False),
            "smoothing_velocity": ("float", False),
            "coord": ("int", False),
        },
    ),
    (
        "add_gear",
        _method("add_gear", GEAR),
        {
            "name": ("name", False),
            "joint_a": ("name", False),
            "joint_b": ("name", False),
            "r_a": ("float", False),
            "r_b": ("float", False),
        },
    ),
    (
        "add_gear_pair",
        _method("add_gear_pair", GEAR),
        {
            "name": ("name", False),
            "joint_a": ("name", False),
            "joint_b": ("name", False),
            "r_a": ("float", False),
            "r_b": ("float", False),
            "backlash": ("float", False),
            "stiffness": ("float", False),
            "exponent": ("float", False),
            "hc_damping": ("float", False),
        },
    ),
    (
        "add_coupling",
        _method("add_coupling", dict(name="k", follower="hinge2", leader="hinge", multiplier=2.0)),
        {
            "name": ("name", False),
            "follower": ("name", False),
            "leader": ("name", False),
            "multiplier": ("float", False),
            "offset": ("float", False),
        },
    ),
    (
        "add_actuator",
        _method("add_actuator", dict(joint="hinge", gear_ratio=50.0, rotor_inertia=1e-5)),
        {
            "joint": ("name", False),
            "gear_ratio": ("float", False),
            "rotor_inertia": ("float", False),
            "efficiency": ("float", False),
            "friction_viscous": ("float", False),
            "friction_coulomb": ("float", False),
            "motor": ("motor", True),
            "gyroscopic": ("bool", False),
            "friction_smoothing": ("float", True),
        },
    ),
    (
        "add_motor",
        _method("add_motor", dict(joint="hinge", reference=0.1, kp=10.0, kd=1.0)),
        {
            "joint": ("name", False),
            "reference": ("profile", False),
            "kp": ("float", False),
            "kd": ("float", False),
            "torque_limit": ("float_inf", False),
            "feedforward": ("profile", True),
            "coord": ("int", False),
            "ki": ("float", False),
        },
    ),
    (
        "add_joint_torque",
        _method("add_joint_torque", dict(joint="hinge", profile=0.5)),
        {"joint": ("name", False), "profile": ("profile", False), "coord": ("int", False)},
    ),
    (
        "finalize",
        _method("finalize", {}),
        {"mass_weighted_assembly": ("bool", False)},
    ),
]


def _builder_model():
    b = _builder()
    b.add_free("fd", "d")
    return b.finalize()


URDF = """<robot name="r"><link name="base"/><link name="arm"><inertial><mass value="1"/>
  <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="j" type="continuous"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>
  <origin xyz="0 0 -0.5"/></joint></robot>"""

# (function id, call(**options), {option: (kind, None accepted)})
FUNCTIONS = [
    (
        "ModelBuilder",
        lambda **o: ad.ModelBuilder(**o),
        {"gravity": ("vec", False), "physical_inertia": ("bool", False)},
    ),
    (
        "urdf_builder",
        lambda **o: ad.urdf_builder(**{"path_or_xml": URDF, **o}),
        {
            "path_or_xml": ("text", False),
            "fixed_base": ("bool", False),
            "gravity": ("vec", False),
            "physical_inertia": ("bool", False),
            "mimic": ("bool", False),
        },
    ),
    (
        "Motor",
        lambda **o: ad.Motor(**o),
        {"name": ("name", False)} | {f: ("float", True) for f in MOTOR_FIELDS if f != "name"},
    ),
    (
        "Data",
        lambda **o: ad.Data(**{"model": _builder_model(), **o}),
        {"model": ("model", False)},
    ),
    ("profiles.constant", lambda **o: ad.profiles.constant(**{"value": 1.0, **o}), {"value": 0}),
    (
        "profiles.cubic",
        lambda **o: ad.profiles.cubic(**{"y0": 0.0, "y1": 1.0, "t0": 0.0, "t1": 1.0, **o}),
        {"y0": 0, "y1": 0, "t0": 0, "t1": 0},
    ),
    (
        "profiles.quintic",
        lambda **o: ad.profiles.quintic(**{"y0": 0.0, "y1": 1.0, "t0": 0.0, "t1": 1.0, **o}),
        {"y0": 0, "y1": 0, "t0": 0, "t1": 0},
    ),
    (
        "profiles.sine",
        lambda **o: ad.profiles.sine(**{"amplitude": 1.0, "frequency": 2.0, **o}),
        {"amplitude": 0, "frequency": 0, "phase": 0, "offset": 0},
    ),
    (
        "profiles.spline",
        lambda **o: ad.profiles.spline(**{"t": [0.0, 1.0, 2.0], "y": [0.0, 1.0, 0.0], **o}),
        {"t": ("vec", False), "y": ("vec", False)},
    ),
]
# the profile factories take real numbers only
FUNCTIONS = [
    (fid, call, {k: ("float", False) if v == 0 else v for k, v in opts.items()})
    for fid, call, opts in FUNCTIONS
]


def _values(kind, none_ok):
    return BAD[kind] + ([] if none_ok else [None])


def _method_cases():
    for fid, call, options in METHODS:
        for name, (kind, none_ok) in options.items():
            for k, value in enumerate(_values(kind, none_ok)):
                yield pytest.param(call, name, value, id=f"{fid}-{name}-{k}")


def _function_cases():
    for fid, call, options in FUNCTIONS:
        for name, (kind, none_ok) in options.items():
            for k, value in enumerate(_values(kind, none_ok)):
                yield pytest.param(call, name, value, id=f"{fid}-{name}-{k}")


def _state(b):
    return (b.body_names, b.joint_names, b.frame_names, b.physical_inertia)


def test_the_baselines_are_valid():
    """Each call succeeds with its baseline arguments (a fresh builder each), and accepts numpy
    scalars and ints where it takes numbers."""
    for fid, call, _options in METHODS:
        b = _builder()
        if fid == "finalize":
            b.add_free("fd", "d")  # every body connected
        call(b)
    for _fid, call, _options in FUNCTIONS:
        call()
    p = ad.profiles.cubic(np.float32(0.0), np.int64(1), 0, np.float64(2.0))
    assert p.eval(1.0) == pytest.approx((0.5, 0.75, 0.0))  # 3s^2 - 2s^3 at s = 1/2
    b = _builder()
    b.add_joint_spring_damper("slide", stiffness=np.float32(2.0), coord=np.int32(0))
    b.set_joint_limits("hinge", -np.inf, np.inf, effort=np.inf)
    b.add_actuator("hinge", 50, 1e-5, gyroscopic=np.bool_(True))
    assert ad.Motor(resistance=np.float32(2.0)).resistance == 2.0


@pytest.mark.parametrize("call, name, value", list(_method_cases()))
def test_a_bad_builder_argument_is_a_model_error_naming_it(call, name, value):
    b = _builder()
    before = _state(b)
    with pytest.raises(ad.ModelError) as err:
        call(b, **{name: value})
    message = str(err.value)
    assert name in message, message
    assert not any(leak in message for leak in LEAKS), message
    assert _state(b) == before


@pytest.mark.parametrize("call, name, value", list(_function_cases()))
def test_a_bad_argument_of_a_factory_is_a_model_error_naming_it(call, name, value):
    with pytest.raises(ad.ModelError) as err:
        call(**{name: value})
    message = str(err.value)
    assert name in message, message
    assert not any(leak in message for leak in LEAKS), message


def test_the_message_names_the_method_and_what_it_allows():
    b = _builder()
    with pytest.raises(
        ad.ModelError, match=r"ModelBuilder\.add_body: mass must be a real number, got '1'"
    ):
        b.add_body("e", "1", I3)
    with pytest.raises(ad.ModelError, match=r"add_revolute: name must be valid Unicode text"):
        b.add_revolute(SURROGATE, "ground", "d", (0, 0, 0), (1, 0, 0))
    with pytest.raises(ad.ModelError, match=r"add_drive: coord must be an integer in \["):
        b.add_drive("hinge", 0.1, coord=2**70)
    with pytest.raises(ad.ModelError, match=r"add_actuator: gyroscopic must be True or False"):
        b.add_actuator("hinge", 50.0, 1e-5, gyroscopic="yes")
    with pytest.raises(
        ad.ModelError, match=r"ModelBuilder: physical_inertia must be True or False"
    ):
        b.physical_inertia = None
    with pytest.raises(
        ad.ModelError, match=r"profiles\.sine: frequency must be a real number, got 1j"
    ):
        ad.profiles.sine(1.0, 1j)
    with pytest.raises(
        ad.ModelError, match=r"Motor: resistance must be a finite real number or None, got '2'"
    ):
        ad.Motor(resistance="2")


def test_big_and_small_numbers_that_fit_are_taken_exactly():
    """An int beyond 2**53 converts to the nearest double (as float() does); the largest C int
    is a valid coord value type (refused by the builder as an unknown coordinate, not a cast)."""
    p = ad.profiles.constant(2**70)
    assert p.eval(0.0) == (float(2**70), 0.0, 0.0)
    b = _builder()
    with pytest.raises(ad.ModelError, match=r"coord") as err:
        b.add_drive("hinge", 0.1, coord=2**31 - 1)
    assert "must be an integer" not in str(err.value)
