"""MJCF loops, couplings and ball joints through ``armdyn.load_mjcf``, checked against MuJoCo.

- A four-bar closed by ``<connect>`` and two coaxial pendulums held together by ``<weld>``: the
  loop joints are built (spherical, fixed), and the Cartesian path's accelerations at the
  assembled state (qpos0, at rest, gravity and a spring loading it) equal the rigid constrained
  dynamics of MuJoCo's own quantities: ``[M J'; J 0] [qacc; -f] = [qfrc_smooth; 0]`` with
  ``M = mj_fullM`` and ``J`` the equality rows of ``efc_J`` (MuJoCo itself solves them softly),
  mapped to bodies by MuJoCo's Jacobians (``mj_jacBodyCom``); and in motion (a velocity the
  loops allow), with the loops' rows and their ``Jdot qvel`` from ``mj_jac`` / ``mj_jacDot``.
- A ball joint (spherical pendulum with a hinged second link) at random states with velocity:
  ``body_accelerations`` equal MuJoCo's ``qacc`` mapped the same way (plus ``mj_jacDot``).
- A ``<joint>`` equality with a linear polycoef is a coupling: ``mass_matrix`` and
  ``inverse_dynamics`` equal MuJoCo's (``mj_fullM``, ``mj_inverse``) projected on the
  independent coordinates (``T' M T``, ``T' qfrc_inverse``).
"""

from __future__ import annotations

import warnings

import armdyn as ad
import numpy as np
import pytest
from armdyn.mjcf import mjcf_info

mujoco = pytest.importorskip("mujoco")

LOOPS = """
<mujoco model="loops">
  <option gravity="0 0 -9.81"/>
  <default><geom type="capsule" size="0.02" density="1000"/></default>
  <worldbody>
    <body name="crank">
      <joint name="a" type="hinge" axis="0 1 0" stiffness="3" springref="0.2"/>
      <geom fromto="0 0 0 0.2 0 0.3"/>
      <body name="coupler" pos="0.2 0 0.3">
        <joint name="b" type="hinge" axis="0 1 0"/>
        <geom fromto="0 0 0 0.6 0 0.1"/>
      </body>
    </body>
    <body name="rocker" pos="0.9 0 0">
      <joint name="d" type="hinge" axis="0 1 0"/>
      <geom fromto="0 0 0 -0.1 0 0.4"/>
    </body>
    <body name="left" pos="0 1 0">
      <joint name="l" type="hinge" axis="1 0 0"/>
      <geom fromto="0 0 0 0 0.3 0.2"/>
    </body>
    <body name="right" pos="0 1 0">
      <joint name="r" type="hinge" axis="1 0 0"/>
      <geom fromto="0 0 0 0 -0.2 0.3"/>
    </body>
  </worldbody>
  <equality>
    <connect name="close" body1="coupler" body2="rocker" anchor="0.6 0 0.1"/>
    <weld name="glue" body1="left" body2="right"/>
  </equality>
</mujoco>
"""

BALL = """
<mujoco model="ball">
  <option gravity="0 0 -9.81"/>
  <worldbody>
    <body name="upper" pos="0 0 1">
      <joint name="shoulder" type="ball"/>
      <geom type="capsule" fromto="0 0 0 0.3 0.1 -0.4" size="0.03"/>
      <body name="lower" pos="0.3 0.1 -0.4">
        <joint name="elbow" type="hinge" axis="0 1 0"/>
        <geom type="box" size="0.05 0.02 0.2" pos="0 0 -0.2" euler="10 20 30"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""

COUPLED = """
<mujoco model="coupled">
  <worldbody>
    <body name="l1">
      <joint name="j1" type="hinge" axis="0 0 1" damping="0.3" armature="0.05"/>
      <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.03"/>
      <body name="l2" pos="0.4 0 0">
        <joint name="j2" type="hinge" axis="0 1 0" ref="0.3"/>
        <geom type="capsule" fromto="0 0 0 0.3 0 0.1" size="0.03"/>
        <body name="l3" pos="0.3 0 0.1">
          <joint name="j3" type="slide" axis="1 0 0"/>
          <geom type="box" size="0.05 0.05 0.05"/>
        </body>
      </body>
    </body>
  </worldbody>
  <equality>
    <joint name="follow" joint1="j2" joint2="j1" polycoef="0.1 -0.5 0 0 0"/>
  </equality>
</mujoco>
"""


def load(xml: str, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return ad.load_mjcf(xml, **kw)


def cartesian_state(model, m, d, info):
    """armdyn's Cartesian (u, v) of MuJoCo's state: per body its centre of mass and the
    quaternion of its axes (MuJoCo's body frame), the centre of mass' world velocity and the
    angular velocity in the body's axes."""
    u, v = np.zeros(model.nq), np.zeros(model.nv)
    jacs = {}
    for i in range(1, m.nbody):
        k = model.body_names.index(info.bodies[i])
        jp, jr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
        mujoco.mj_jacBodyCom(m, d, jp, jr, i)
        rot = d.xmat[i].reshape(3, 3)
        jacs[k] = (i, jp, jr, rot)
        u[7 * k : 7 * k + 3], u[7 * k + 3 : 7 * k + 7] = d.xipos[i], d.xquat[i]
        v[6 * k : 6 * k + 3], v[6 * k + 3 : 6 * k + 6] = jp @ d.qvel, rot.T @ (jr @ d.qvel)
    return u, v, jacs


def body_accelerations_of(m, d, jacs, qacc, nv):
    out = np.zeros(nv)
    for k, (i, jp, jr, rot) in jacs.items():
        jpd, jrd = np.zeros((3, m.nv)), np.zeros((3, m.nv))
        mujoco.mj_jacDot(m, d, jpd, jrd, d.xipos[i], i)
        out[6 * k : 6 * k + 3] = jp @ qacc + jpd @ d.qvel
        out[6 * k + 3 : 6 * k + 6] = rot.T @ (jr @ qacc + jrd @ d.qvel)
    return out


def test_connect_and_weld_close_loops_as_mujoco_rigidly():
    model = load(LOOPS)
    types = dict(zip(model.joint_names, model.joint_types, strict=True))
    assert types["close"] == "spherical" and types["glue"] == "fixed"
    assert not model.is_tree
    m = mujoco.MjModel.from_xml_string(LOOPS)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)  # qpos0, at rest: both loops closed there
    rows = d.efc_type == int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)
    jac = d.efc_J.reshape(d.nefc, m.nv)[rows]
    assert np.abs(d.efc_pos[rows]).max() < 1e-12
    full = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, full)
    kkt = np.block([[full, jac.T], [jac, np.zeros((len(jac), len(jac)))]])
    rhs = np.r_[d.qfrc_smooth, np.zeros(len(jac))]
    qacc = np.linalg.lstsq(kkt, rhs, rcond=None)[0][: m.nv]  # redundant rows: qacc is unique
    info = mjcf_info(model)
    u, v, jacs = cartesian_state(model, m, d, info)
    assert np.allclose(u, model.u0, atol=1e-12) and not v.any()
    vdot, _ = ad.body_accelerations(model, u, v)
    expect = body_accelerations_of(m, d, jacs, qacc, model.nv)
    assert np.abs(expect).max() > 1.0  # gravity and the spring move it
    assert np.abs(vdot - expect).max() < 1e-10 * np.abs(expect).max()


def test_loop_model_simulates_and_keeps_the_loops_closed():
    model = load(LOOPS)
    run = ad.simulate(model, 0.2, output_dt=0.1)
    c = ad.evaluate_constraints(model, run.u[-1], run.v[-1])
    assert np.abs(c["f"]).max() < 1e-8


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_ball_joint_matches_mujoco_on_the_cartesian_path(seed):
    model = load(BALL)
    assert model.joint_types[model.joint_names.index("shoulder")] == "spherical"
    m = mujoco.MjModel.from_xml_string(BALL)
    d = mujoco.MjData(m)
    rng = np.random.default_rng(seed)
    quat = rng.normal(size=4)
    d.qpos[:4], d.qpos[4] = quat / np.linalg.norm(quat), rng.uniform(-1, 1)
    d.qvel[:] = rng.normal(size=m.nv)
    mujoco.mj_forward(m, d)
    u, v, jacs = cartesian_state(model, m, d, mjcf_info(model))
    vdot, _ = ad.body_accelerations(model, u, v)
    expect = body_accelerations_of(m, d, jacs, d.qacc, model.nv)
    assert np.abs(vdot - expect).max() < 1e-10 * np.abs(expect).max()


def test_joint_equality_is_a_coupling_as_mujoco_projected():
    model = load(COUPLED)
    assert [c["follower"] for c in model.couplings if c["name"] == "follow"] == ["j2"]
    coupling = next(c for c in model.couplings if c["name"] == "follow")
    assert coupling["leader"] == "j1" and coupling["multiplier"] == -0.5
    assert coupling["offset"] == 0.1
    assert model.coord_names == ["j1", "j3"]
    info = mjcf_info(model)
    m = mujoco.MjModel.from_xml_string(COUPLED)
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
    d = mujoco.MjData(m)
    rng = np.random.default_rng(7)
    for _ in range(3):
        q, qd, qdd = rng.uniform(-1, 1, 2), rng.normal(size=2), rng.normal(size=2)
        qpos = m.qpos0.copy()
        qpos[0], qpos[2] = q[0], q[1]
        qpos[1] = m.qpos0[1] + 0.1 - 0.5 * q[0]  # the equality, in MuJoCo's own terms
        assert np.allclose(info.q_from_qpos(qpos), q)
        t = info.velocity_map(qpos)
        d.qpos[:], d.qvel[:], d.qacc[:] = qpos, t @ qd, t @ qdd
        mujoco.mj_inverse(m, d)
        full = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, d, full)
        assert np.allclose(ad.mass_matrix(model, q), t.T @ full @ t, rtol=1e-12, atol=1e-14)
        tau = ad.inverse_dynamics(model, q, qd, qdd)
        expect = t.T @ d.qfrc_inverse
        assert np.abs(tau - expect).max() < 1e-10 * np.abs(expect).max()


TENDON = """
<mujoco model="tendon">
  <compiler angle="radian"/>
  <worldbody>
    <body name="l1">
      <joint name="j1" type="hinge" axis="0 0 1" ref="0.2"/>
      <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.03"/>
      <body name="l2" pos="0.4 0 0">
        <joint name="j2" type="hinge" axis="0 1 0" ref="-0.1"/>
        <geom type="capsule" fromto="0 0 0 0.3 0 0.1" size="0.03"/>
      </body>
    </body>
  </worldbody>
  <tendon><fixed name="tie"><joint joint="j1" coef="0.7"/><joint joint="j2" coef="-0.4"/></fixed>
  </tendon>
  <equality><tendon name="tied" tendon1="tie" polycoef="0.05 0 0 0 0"/></equality>
</mujoco>
"""


@pytest.mark.parametrize(("xml", "name"), [(COUPLED, "follow"), (TENDON, "tied")])
def test_equality_couplings_hold_mujocos_own_constraint(xml, name):
    """At qpos_from_q(q) for any q, MuJoCo's residual of the equality (efc_pos) is zero: the
    coupling's multiplier and offset are MuJoCo's definition (ref, a0, the tendon's coefs)."""
    model = load(xml)
    assert any(c["name"] == name for c in model.couplings)
    info = mjcf_info(model)
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    rng = np.random.default_rng(11)
    for _ in range(3):
        d.qpos[:] = info.qpos_from_q(rng.uniform(-1, 1, model.n_coords))
        mujoco.mj_forward(m, d)
        rows = d.efc_type == int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)
        assert rows.sum() == 1 and abs(d.efc_pos[rows][0]) < 1e-14
        # and off the coupling, MuJoCo sees the violation
        d.qpos[1] += 0.01
        mujoco.mj_forward(m, d)
        rows = d.efc_type == int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)
        assert abs(d.efc_pos[rows][0]) > 1e-3


def loop_rows(m, d):
    """The loops' velocity rows J and their J' qvel terms, from MuJoCo's point Jacobians and
    mj_jacDot: the connect's anchor on the coupler and on the rocker move together; the weld's
    two bodies share a point's velocity and their angular velocity."""
    rows, dots = [], []

    def jac(body, point):
        jp, jr, jpd, jrd = (np.zeros((3, m.nv)) for _ in range(4))
        mujoco.mj_jac(m, d, jp, jr, point, body)
        mujoco.mj_jacDot(m, d, jpd, jrd, point, body)
        return jp, jr, jpd, jrd

    ids = {n: m.body(n).id for n in ("coupler", "rocker", "left", "right")}
    anchor = d.xpos[ids["coupler"]] + d.xmat[ids["coupler"]].reshape(3, 3) @ [0.6, 0, 0.1]
    a, b = jac(ids["coupler"], anchor), jac(ids["rocker"], anchor)
    rows.append(a[0] - b[0])
    dots.append((a[2] - b[2]) @ d.qvel)
    point = d.xpos[ids["right"]].copy()
    a, b = jac(ids["left"], point), jac(ids["right"], point)
    rows += [a[0] - b[0], a[1] - b[1]]
    dots += [(a[2] - b[2]) @ d.qvel, (a[3] - b[3]) @ d.qvel]
    return np.vstack(rows), np.concatenate(dots)


@pytest.mark.parametrize("seed", [0, 1])
def test_loops_in_motion_match_mujocos_rigid_dynamics(seed):
    """At qpos0 with a random velocity that the loops allow (the null space of their rows):
    ``[M J'; J 0] [qacc; -f] = [qfrc_smooth; -Jdot qvel]`` from MuJoCo's quantities."""
    model = load(LOOPS)
    m = mujoco.MjModel.from_xml_string(LOOPS)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    jac, _ = loop_rows(m, d)
    _, sing, vt = np.linalg.svd(jac)
    null = vt[np.sum(sing > 1e-10 * sing[0]) :].T
    assert null.shape[1] == 2  # the four-bar's and the welded pair's one dof each
    d.qvel[:] = null @ np.random.default_rng(seed).normal(scale=5.0, size=2)
    mujoco.mj_forward(m, d)
    jac, dot = loop_rows(m, d)
    assert np.abs(jac @ d.qvel).max() < 1e-13
    full = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, full)
    kkt = np.block([[full, jac.T], [jac, np.zeros((len(jac), len(jac)))]])
    qacc = np.linalg.lstsq(kkt, np.r_[d.qfrc_smooth, -dot], rcond=None)[0][: m.nv]
    u, v, jacs = cartesian_state(model, m, d, mjcf_info(model))
    vdot, _ = ad.body_accelerations(model, u, v)
    expect = body_accelerations_of(m, d, jacs, qacc, model.nv)
    assert np.abs(vdot - expect).max() < 1e-10 * np.abs(expect).max()
