"""Sites and bodies as named frames, joint data and actuator gears of ``armdyn.load_mjcf``
against MuJoCo: ``frame_pose`` equals ``site_xpos``/``site_xmat`` and ``xpos``/``xmat``, and
``frame_jacobian`` equals ``mj_jacSite`` (times ``velocity_map``) at random states; ranges, a
spring with ``ref`` and ``springref``, armature (``model.reflected_inertia``) and the actuators'
gears as MuJoCo compiled them."""

from __future__ import annotations

import os
import warnings

import armdyn as ad
import numpy as np
import pytest
from armdyn.mjcf import mjcf_info

mujoco = pytest.importorskip("mujoco")
dm_control = pytest.importorskip("dm_control")

SUITE = os.path.join(os.path.dirname(dm_control.__file__), "suite")
JACO = os.path.join(os.path.dirname(dm_control.__file__), "third_party", "kinova", "jaco_arm.xml")


def load(path, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return ad.load_mjcf(path, **kw)


@pytest.mark.parametrize("path", [os.path.join(SUITE, "manipulator.xml"), JACO])
def test_sites_and_bodies_are_frames_as_in_mujoco(path):
    model = load(path)
    info = mjcf_info(model)
    m = mujoco.MjModel.from_xml_path(path)
    d = mujoco.MjData(m)
    rng = np.random.default_rng(3)
    assert set(info.body_frames.values()) <= set(model.frame_names)
    assert len(info.sites) == m.nsite and len(info.body_frames) == m.nbody
    for _ in range(3):
        d.qpos[:] = info.qpos_from_q(rng.uniform(-1, 1, model.n_coords))  # fingers coupled
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        q = info.q_from_qpos(d.qpos)
        t = info.velocity_map(d.qpos)
        for s in range(m.nsite):
            frame = info.sites[m.site(s).name]
            pose = ad.frame_pose(model, q, frame)
            assert np.allclose(pose[:3, 3], d.site_xpos[s], rtol=0, atol=1e-12)
            assert np.allclose(pose[:3, :3], d.site_xmat[s].reshape(3, 3), rtol=0, atol=1e-12)
            jp, jr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
            mujoco.mj_jacSite(m, d, jp, jr, s)
            jac = ad.frame_jacobian(model, q, frame)
            assert np.allclose(jac, np.vstack([jp, jr]) @ t, rtol=0, atol=1e-12)
        for i in range(1, m.nbody):
            pose = ad.frame_pose(model, q, info.body_frames[m.body(i).name])
            assert np.allclose(pose[:3, 3], d.xpos[i], rtol=0, atol=1e-12)
            assert np.allclose(pose[:3, :3], d.xmat[i].reshape(3, 3), rtol=0, atol=1e-12)


def test_ranges_armature_and_actuator_gears_as_compiled():
    path = os.path.join(SUITE, "manipulator.xml")
    model = load(path)
    info = mjcf_info(model)
    m = mujoco.MjModel.from_xml_path(path)
    for j in range(m.njnt):
        name = info.joints[m.joint(j).name]
        if name not in model.coord_names:  # the finger, coupled to the thumb
            assert name == "finger" and any(c["follower"] == name for c in model.couplings)
            continue
        k = model.coord_names.index(name)
        q0 = m.qpos0[m.jnt_qposadr[j]]
        lo, hi = (m.jnt_range[j] - q0) if m.jnt_limited[j] else (-np.inf, np.inf)
        assert model.coord_lower[k] == lo and model.coord_upper[k] == hi
    assert len(info.actuators) == m.nu
    for a, act in enumerate(info.actuators):
        assert act.name == m.actuator(a).name
        assert act.gear == tuple(m.actuator_gear[a])
        if act.transmission == "joint":
            assert act.target == info.joints[m.joint(m.actuator_trnid[a, 0]).name]
    jaco = load(JACO)
    mj = mujoco.MjModel.from_xml_path(JACO)
    assert np.array_equal(jaco.reflected_inertia, mj.dof_armature)
    # frictionloss (MuJoCo's dry friction, a constraint) is listed with every joint's value
    (item,) = [u for u in mjcf_info(jaco).unmapped if u.startswith("frictionloss")]
    for j in range(mj.njnt):
        assert f"'{mj.joint(j).name}' {mj.dof_frictionloss[mj.jnt_dofadr[j]]:g}" in item


@pytest.mark.parametrize(
    "flags", ["", '<option><flag spring="disable" damper="disable"/></option>']
)
def test_spring_with_ref_and_springref_matches_mujoco(flags):
    xml = f"""<mujoco>{flags}<compiler angle="radian"/><worldbody><body name="a">
      <geom type="capsule" fromto="0 0 0 0.4 0 0"
      size="0.05"/><joint name="h" type="hinge" axis="0 1 0" ref="0.3" springref="0.5"
      stiffness="2" damping="0.4" armature="0.02" range="-1 2"/>
      <body name="b" pos="0.4 0 0"><joint name="s" type="slide" axis="1 0 1" ref="0.1"
      springref="-0.2" stiffness="30"/><geom type="box" size="0.05 0.05 0.05"/></body>
      </body></worldbody></mujoco>"""
    model = load(xml)
    info = mjcf_info(model)
    if flags:
        assert "joint stiffness: the MJCF disables it (option flag), as MuJoCo" in info.unmapped
    assert model.coord_lower[0] == -1 - 0.3 and model.coord_upper[0] == 2 - 0.3
    m = mujoco.MjModel.from_xml_string(xml)
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
    d = mujoco.MjData(m)
    rng = np.random.default_rng(5)
    for _ in range(3):
        d.qpos[:], d.qvel[:] = m.qpos0 + rng.uniform(-1, 1, 2), rng.normal(size=2)
        mujoco.mj_forward(m, d)
        q, qd = info.q_from_qpos(d.qpos), info.qd_from_qvel(d.qpos, d.qvel)
        qdd = ad.forward_dynamics(model, q, qd, np.zeros(2))
        assert np.abs(qdd - d.qacc).max() < 1e-10 * np.abs(d.qacc).max()


def test_gravcomp_is_a_body_force_as_in_mujoco():
    xml = """<mujoco><worldbody><body name="a" gravcomp="0.7"><joint type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0.4 0 0.1" size="0.05"/>
      <body name="b" pos="0.4 0 0.1" gravcomp="1"><joint type="hinge" axis="1 0 0"/>
      <geom type="box" size="0.05 0.1 0.02" pos="0 0.1 0"/></body></body></worldbody></mujoco>"""
    model = load(xml)
    info = mjcf_info(model)
    assert not any("gravcomp" in u for u in info.unmapped)
    m = mujoco.MjModel.from_xml_string(xml)
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
    d = mujoco.MjData(m)
    rng = np.random.default_rng(9)
    for _ in range(3):
        d.qpos[:], d.qvel[:] = rng.uniform(-1, 1, 2), rng.normal(size=2)
        mujoco.mj_forward(m, d)
        assert np.abs(d.qfrc_gravcomp).max() > 0.1
        qdd = ad.forward_dynamics(model, d.qpos.copy(), d.qvel.copy(), np.zeros(2))
        assert np.abs(qdd - d.qacc).max() < 1e-10 * np.abs(d.qacc).max()


def test_unnamed_and_clashing_names_get_the_documented_names():
    xml = """<mujoco><worldbody><site name="world"/>
      <body name="ground" pos="0 0 1"><joint type="hinge" axis="0 1 0"/>
        <geom type="sphere" size="0.1" pos="0.3 0 0"/><site name="ground" pos="0.3 0 0"/>
        <body pos="0.3 0 0"><joint name="j" type="hinge" axis="0 0 1"/>
          <joint type="slide" axis="1 0 0"/><geom type="sphere" size="0.05" pos="0.2 0 0"/>
          <site name="body2"/><site/>
        </body>
      </body></worldbody>
      <equality><weld body1="ground" active="false"/></equality></mujoco>"""
    model = load(xml)
    info = mjcf_info(model)
    # a body named 'ground' (armdyn's world) and an unnamed body get body<id>
    assert info.bodies == ("ground", "body1", "body2")
    assert model.body_names == ["body1", "body2", "body2__j"]  # massless, between 2 joints
    assert model.joint_names[:3] == ["joint0", "j", "joint2"]
    assert info.joints == {"joint0": "joint0", "j": "j", "joint2": "joint2"}
    assert info.body_frames == {"world": "world", "ground": "body1", "body2": "body2"}
    # a site keeps its name unless a frame has it already: then site:<name>
    assert info.sites == {
        "world": "site:world",
        "ground": "ground",
        "body2": "site:body2",
        "site3": "site3",
    }
    assert "equality weld 0 (unnamed): inactive at the start (eq active='false')" in info.unmapped
