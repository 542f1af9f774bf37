"""Bad MJCF input for ``armdyn.load_mjcf``: each refused with a ModelError (or TypeError for a
source of the wrong type) that names the culprit, never a hang, a crash or a model with NaN;
MuJoCo's global warning handler is left as it was; mutated files never crash."""

from __future__ import annotations

import os
import subprocess
import sys
import warnings

import armdyn as ad
import numpy as np
import pytest
from armdyn import mjcf

mujoco = pytest.importorskip("mujoco")

BODY = '<inertial pos="0 0 0" mass="{mass}" diaginertia="0.1 0.1 0.1"/>'


def arm(mass="1", pos="0 0 0", axis="0 1 0", damping="0", extra=""):
    return (
        f'<mujoco><worldbody><body name="link" pos="{pos}">'
        f'<joint name="hinge" type="hinge" axis="{axis}" damping="{damping}"/>'
        + BODY.format(mass=mass)
        + f"</body>{extra}</worldbody></mujoco>"
    )


def refused(source, pattern, exc=ad.ModelError, **kw):
    before = mujoco.get_mju_user_warning()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(exc, match=pattern):
            ad.load_mjcf(source, **kw)
    assert mujoco.get_mju_user_warning() is before


def test_a_good_arm_loads_from_text_bytes_and_paths(tmp_path, monkeypatch):
    model = ad.load_mjcf(arm(), warn=False)
    assert model.coord_names == ["hinge"]
    assert mjcf.mjcf_info(model).unmapped == ()
    assert mjcf.mjcf_info(model).source == arm()
    (tmp_path / "arm.xml").write_text(arm())
    monkeypatch.chdir(tmp_path)
    for source in (arm().encode(), "arm.xml", tmp_path / "arm.xml"):
        again = ad.load_mjcf(source, warn=False)
        assert np.array_equal(again.u0, model.u0) and again.coord_names == ["hinge"]
    assert mjcf.mjcf_info(again).source == str(tmp_path / "arm.xml")


def test_malformed_and_truncated_xml():
    refused(
        "<mujoco><worldbody><body><joint type='hin",
        r"MJCF string: not well-formed XML: unclosed token \(line 1, column 26\)",
    )
    refused("<mujoco><worldbody><body></mujoco>", r"not well-formed XML: mismatched tag")
    refused(
        "<mujoco><worldbody><body><joint type='bad'/></body></worldbody></mujoco>",
        r"MuJoCo refused it: XML Error: invalid keyword: 'bad' \| Element 'joint', line 1",
    )
    refused("<robot name='urdf'/>", r"root element is <robot>, not <mujoco>.*load_urdf")
    refused("<?xml version='1.0'?><!-- c --><mujocox/>", r"root element is <mujocox>")
    refused("<mujoco>\x00</mujoco>", r"NUL byte at offset 8")


def test_missing_file_directory_device_fifo(tmp_path):
    refused(tmp_path / "none.xml", r"MJCF file '.*none\.xml' does not exist")
    refused("not xml and not a file", r"'not xml and not a file' does not exist")
    refused(str(tmp_path), r"is a directory, not a regular file")
    refused("/dev/zero", r"'/dev/zero' is a character device, not a regular file")
    fifo = tmp_path / "pipe.xml"
    os.mkfifo(fifo)
    refused(fifo, r"is a FIFO \(named pipe\), not a regular file")
    # MuJoCo itself would block reading an included FIFO: refused before it opens it
    refused(f'<mujoco><include file="{fifo}"/></mujoco>', r"referenced file .*pipe\.xml.* FIFO")
    main = tmp_path / "main.xml"
    main.write_text('<mujoco><include file="pipe.xml"/></mujoco>')
    refused(main, r"referenced file .*pipe\.xml.* FIFO")


def test_huge_file_and_string(tmp_path):
    big = tmp_path / "huge.xml"
    with open(big, "wb") as f:
        f.write(b"<mujoco>")
        f.truncate(mjcf.MJCF_MAX_BYTES + 1)  # sparse: nothing is written
    refused(big, r"67108865 bytes, more than the limit of 67108864 bytes")
    refused("<" + " " * mjcf.MJCF_MAX_BYTES, r"MJCF string is 67108865 bytes")


def test_not_utf8_and_wrong_types():
    refused(b"<mujoco>\xff</mujoco>", r"not valid UTF-8 \(byte offset 8\)")
    refused(b"no xml", r"MJCF bytes must hold XML")
    refused(3, r"expected a path .* got int", exc=TypeError)
    refused(arm(), r"load_mjcf: fixed_base must be True or False, got 'yes'", fixed_base="yes")
    refused(arm(), r"load_mjcf: fixed_base must be True or False, got None", fixed_base=None)
    refused(arm(), r"physical_inertia must be True or False", physical_inertia=1)
    refused(arm(), r"warn must be True or False", warn="no")
    refused(arm(), r"gravity must be 3 numbers", gravity=(0, 9.81))
    refused(arm(), r"gravity\[1\] = .*nan.* is not finite", gravity=(0, float("nan"), 1))


def test_non_finite_numbers_name_the_body_or_joint():
    refused(arm(mass="nan"), r"MuJoCo refused it: .*mass and inertia.*'link'")
    refused(arm(mass="1e400"), r"MuJoCo refused it: .*too large.*'mass'")
    # MuJoCo accepts these (with a warning); armdyn refuses, naming the element
    refused(arm(pos="nan 0 0"), r"body 'link': position at qpos0 is not finite")
    refused(arm(axis="nan 0 1"), r"joint 'hinge': axis at qpos0 is not finite")
    refused(arm(damping="nan"), r"joint 'hinge': damping is not finite")


def test_scales_beyond_finalize_name_the_body():
    refused(arm(mass="1e300"), r"link")


def test_open_loop_at_qpos0_names_the_equality():
    xml = (
        '<mujoco><worldbody><body name="a"><joint name="h" type="hinge" axis="0 1 0"/>'
        '<geom type="sphere" size="0.1"/><site name="s1" pos="0.5 0 0"/></body>'
        '<site name="s2" pos="0.7 0 0"/></worldbody>'
        '<equality><connect name="hold" site1="s1" site2="s2"/></equality></mujoco>'
    )
    refused(xml, r"equality connect 'hold': not satisfied at qpos0 \(MuJoCo's residual 0\.2")


def test_warn_false_keeps_the_list():
    xml = arm(extra='<geom type="plane" size="1 1 1"/>')
    with pytest.warns(UserWarning, match=r"(?s)not mapped.*contacts: 1 colliding geoms"):
        ad.load_mjcf(xml)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        model = ad.load_mjcf(xml, warn=False)
    assert mjcf.mjcf_info(model).unmapped == (
        "contacts: 1 colliding geoms, 0 explicit contact pairs",
    )
    other = ad.ModelBuilder()
    other.add_body("b", 1.0, [1, 1, 1])
    other.add_revolute("h", "ground", "b", (0, 0, 0), (0, 0, 1))
    assert mjcf.mjcf_info(other.finalize()) is None


def test_mutated_files_never_crash():
    """Random character edits of a two-link arm: each loads (finite dynamics) or is a ModelError."""
    text = (
        '<mujoco><option gravity="0 0 -9.81"/><worldbody><body name="a" pos="0 0 1">'
        '<joint name="h1" type="hinge" axis="0 1 0" damping="0.1" range="-1 1"/>'
        '<geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.05"/>'
        '<body name="b" pos="0.5 0 0"><joint name="h2" type="hinge" axis="0 1 0" armature="0.01"/>'
        '<geom type="capsule" fromto="0 0 0 0.4 0 0.1" size="0.04" density="800"/>'
        "</body></body></worldbody></mujoco>"
    )
    rng = np.random.default_rng(36)
    numeric = [i for i, c in enumerate(text) if c in "0123456789.-"]  # half the edits: numbers
    loaded = 0
    for _ in range(80):
        chars = list(text)
        for _ in range(1):
            i = int(rng.choice(numeric) if rng.random() < 0.5 else rng.integers(len(chars)))
            chars[i] = str(rng.choice(list('0123456789.-e<>/=" nNaI')))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                model = ad.load_mjcf("".join(chars))
            except ad.ModelError:
                continue
        loaded += 1
        q = np.zeros(model.n_coords)
        assert np.all(np.isfinite(ad.forward_dynamics(model, q, q, q)))
    assert loaded >= 20


def test_without_mujoco_the_import_error_says_how_to_install_it():
    code = (
        "import sys; sys.modules['mujoco'] = None\n"
        "import armdyn\n"
        "try:\n    armdyn.load_mjcf('<mujoco/>')\n"
        "except ImportError as e:\n    print(e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert "needs the 'mujoco' package (pip install mujoco, or armdyn[mjcf])" in out.stdout


def test_many_attributes_doctype_and_ill_formed_xml_are_refused_before_mujoco():
    many = " ".join(f'a{i}="1"' for i in range(40_000))
    refused(
        f"<mujoco><worldbody><body {many}/></worldbody></mujoco>",
        r"element <body> on line 1 has 40000 attributes, more than the limit of 1000",
    )
    lol = '<!DOCTYPE m [<!ENTITY a "aaaaaaaa"><!ENTITY b "&a;&a;&a;&a;">]><mujoco model="&b;"/>'
    refused(lol, r"has a DOCTYPE \(<!DOCTYPE m>, line 1\)")
    refused('<mujoco model="&x;"/>', r"not well-formed XML: undefined entity \(line 1, column 1\)")
