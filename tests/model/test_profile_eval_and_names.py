"""Profile.eval on arrays (against the scalar calls and closed forms) and the builder's body and
joint names in definition order (against the UR5 URDF read independently with xml.etree)."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import armdyn as ad
import numpy as np
import pytest

from benchmarks import common

PROFILES = {
    "cubic": ad.profiles.cubic(0.5, 2.0, 0.2, 1.2),
    "quintic": ad.profiles.quintic(-1.0, 1.0, 0.0, 2.0),
    "sine": ad.profiles.sine(0.3, 1.5, phase=0.4, offset=0.1),
    "spline": ad.profiles.spline([0.0, 0.5, 1.0, 2.0], [0.0, 1.0, 0.5, 0.25]),
    "constant": ad.profiles.constant(2.5),
}


@pytest.mark.parametrize("name", list(PROFILES))
@pytest.mark.parametrize("shape", [(7,), (3, 4), (0,)])
def test_eval_on_arrays_matches_the_scalar_calls(name, shape):
    p = PROFILES[name]
    rng = np.random.default_rng(3)
    t = rng.uniform(-0.5, 2.5, size=shape)
    y, yd, ydd = p.eval(t)
    for a in (y, yd, ydd):
        assert isinstance(a, np.ndarray) and a.dtype == np.float64 and a.shape == t.shape
    for idx in np.ndindex(*shape):
        assert (y[idx], yd[idx], ydd[idx]) == p.eval(float(t[idx]))  # bit for bit


def test_eval_closed_form_and_scalars():
    a, f, ph, off = 0.3, 1.5, 0.4, 0.1
    p = ad.profiles.sine(a, f, phase=ph, offset=off)
    t = np.linspace(0.0, 1.0, 11)
    y, yd, ydd = p.eval(t)
    w = 2 * math.pi * f
    np.testing.assert_allclose(y, off + a * np.sin(w * t + ph), rtol=0, atol=1e-15)
    np.testing.assert_allclose(yd, a * w * np.cos(w * t + ph), rtol=0, atol=1e-14)
    np.testing.assert_allclose(ydd, -a * w * w * np.sin(w * t + ph), rtol=0, atol=1e-13)
    # a scalar stays a tuple of floats (ints, numpy scalars too); lists are arrays
    for t0 in (0.25, 1, np.float64(0.25)):
        r = p.eval(t0)
        assert isinstance(r, tuple) and all(type(x) is float for x in r)
        assert r[0] == pytest.approx(off + a * math.sin(w * float(t0) + ph), abs=1e-15)
    y2, _, _ = p.eval([0.0, 0.5])
    assert y2.shape == (2,)
    assert y2[1] == p.eval(0.5)[0]
    # a 0-d array gives 0-d arrays
    y0, _, _ = p.eval(np.array(0.5))
    assert isinstance(y0, np.ndarray) and y0.shape == () and float(y0) == p.eval(0.5)[0]


def test_eval_cubic_closed_form_on_arrays():
    # y = 3 s^2 - 2 s^3 on [0, 1], constant outside; binary fractions make every value exact
    p = ad.profiles.cubic(0.0, 1.0, 0.0, 1.0)
    s = np.array([[-0.5, 0.25], [0.5, 0.75], [1.0, 2.0]])
    y, yd, ydd = p.eval(s)
    inside = (s > 0) & (s < 1)
    c = np.clip(s, 0.0, 1.0)
    np.testing.assert_array_equal(y, 3 * c**2 - 2 * c**3)
    np.testing.assert_array_equal(yd, np.where(inside, 6 * c - 6 * c**2, 0.0))
    np.testing.assert_array_equal(ydd, np.where(inside, 6 - 12 * c, 0.0))


def test_eval_refuses_non_numbers():
    for bad in ("soon", None, b"1", ["a", "b"], {"t": 1}):
        with pytest.raises(ad.ModelError, match=r"Profile\.eval: t"):
            PROFILES["cubic"].eval(bad)


def test_builder_lists_bodies_and_joints_in_definition_order():
    b = ad.ModelBuilder()
    assert b.joint_names == [] and b.body_names == []
    b.add_body("upper", 1.0, [0.1, 0.1, 0.01], position=[0, 0, -0.5])
    b.add_body("lower", 1.0, [0.1, 0.1, 0.01], position=[0, 0, -1.5])
    b.add_revolute("shoulder", "ground", "upper", [0, 0, 0], [0, 1, 0])
    b.add_revolute("elbow", "upper", "lower", [0, 0, -1.0], [0, 1, 0])
    b.add_frame("tip", "lower", [0, 0, -2.0])
    assert b.body_names == ["upper", "lower"]
    assert b.joint_names == ["shoulder", "elbow"]
    assert b.frame_names == ["tip"]
    # a refused joint leaves the list as it was
    with pytest.raises(ad.ModelError):
        b.add_revolute("shoulder", "ground", "lower", [0, 0, 0], [0, 1, 0])
    assert b.joint_names == ["shoulder", "elbow"]
    assert b.finalize().joint_names == ["shoulder", "elbow"]


def test_urdf_builder_lists_the_urdf_joints():
    path = common.robot_urdf("ur5")
    if path is None:
        pytest.skip("example-robot-data is not installed")
    root = ET.parse(path).getroot()
    urdf_joints = [j.get("name") for j in root.findall("joint")]
    moving = [j.get("name") for j in root.findall("joint") if j.get("type") != "fixed"]
    b = ad.urdf_builder(str(path))
    names = b.joint_names
    # every moving joint of the URDF, in the URDF's document order; nothing the URDF lacks
    assert [n for n in names if n in moving] == moving
    assert set(names) <= set(urdf_joints)
    assert b.finalize().joint_names == names
    # bodies: URDF links (fixed-joint chains merged into one body)
    links = {link.get("name") for link in root.findall("link")}
    assert b.body_names and set(b.body_names) <= links
