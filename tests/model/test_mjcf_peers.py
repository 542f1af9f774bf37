"""Every MJCF model that dm_control and gymnasium ship, loaded by ``armdyn.load_mjcf`` and checked
against MuJoCo itself (issue 36): the mass matrix equals ``mj_fullM`` and the forward dynamics
MuJoCo's ``qacc`` (constraints, contacts and actuation disabled) to 1e-10 relative at seeded
random states, with damping, stiffness and armature in both. MuJoCo's terms that armdyn does not
map (tendon springs and dampers, fluid forces, a free joint's damping or armature) are switched
off on MuJoCo's side, and the test checks that load_mjcf's warning lists each of them.

Coordinates: ``mjcf_info(model).q_from_qpos`` / ``qd_from_qvel`` / ``velocity_map`` /
``qacc_from`` (a free joint's linear velocity is in world axes in MuJoCo, in the body's axes in
armdyn: ``qvel = T qd``, ``M_armdyn = T' M T``, ``tau = T' qfrc``). The reference for
``forward_dynamics`` is MuJoCo's dynamics reduced to armdyn's coordinates,
``T' M T qdd = T' (qfrc_smooth - M Tdot qd)``, and, where ``T`` is square, MuJoCo's own
``qacc``. It covers a free joint welded by ``fixed_base=True`` (at qpos0 and at rest; no column
of ``T``: MuJoCo's model with that joint held) and a tendon equality coupling two joints
(manipulator's and stacker's fingers: a coupling, the follower's row of ``T`` its multiplier).
"""

from __future__ import annotations

import glob
import os
import warnings

import armdyn as ad
import numpy as np
import pytest
from armdyn.mjcf import mjcf_info

mujoco = pytest.importorskip("mujoco")
dm_control = pytest.importorskip("dm_control")
gymnasium = pytest.importorskip("gymnasium")

TOL = 1e-10


def shipped_files() -> list[str]:
    """Every .xml of dm_control's suite and third_party folders and gymnasium's MuJoCo assets."""
    dmc = os.path.dirname(dm_control.__file__)
    gym = os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets")
    return sorted(
        glob.glob(os.path.join(dmc, "suite", "*.xml"))
        + glob.glob(os.path.join(dmc, "third_party", "**", "*.xml"), recursive=True)
        + glob.glob(os.path.join(gym, "*.xml"))
    )


FILES = shipped_files()
IDS = [os.path.relpath(f, os.path.dirname(os.path.dirname(f))) for f in FILES]


def compiled(path: str) -> mujoco.MjModel:
    """MuJoCo's model of the file, its compiler warnings (settotalmass deprecated) dropped rather
    than written to MUJOCO_LOG.TXT in the working directory (load_mjcf lists them)."""
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda _msg: None)
    try:
        return mujoco.MjModel.from_xml_path(path)
    finally:
        mujoco.set_mju_user_warning(previous)


def _has_free(path: str) -> bool:
    return bool(np.any(compiled(path).jnt_type == 0))


# a file with a free joint twice: welded (fixed_base=True) and floating; else once
CASES = [
    pytest.param(f, base, id=f"{i}-{'fixed' if base else 'floating'}")
    for f, i in zip(FILES, IDS, strict=True)
    for base in ((True, False) if _has_free(f) else (True,))
]


def test_the_sweep_sees_every_shipped_file():
    assert len(FILES) >= 30  # dm_control 1.0.x: 19 suite + 4 third_party; gymnasium 1.x: 14
    names = {os.path.basename(f) for f in FILES}
    for arm in ("jaco_arm.xml", "manipulator.xml", "reacher.xml", "pusher.xml", "acrobot.xml"):
        assert arm in names


def mujoco_peer(path: str, info) -> mujoco.MjModel:
    """MuJoCo's model of the file with what armdyn does not map switched off (each checked to be
    listed in the warning), and constraints, contacts and actuation disabled."""
    m = compiled(path)
    listed = " ".join(info.unmapped)
    if np.any(m.tendon_stiffness) or np.any(m.tendon_damping):
        assert "tendons" in listed
    if m.opt.density or m.opt.viscosity:
        assert "fluid forces" in listed
    if m.nu:
        assert f"{m.nu} actuators apply no force" in listed
    m.tendon_stiffness[:] = 0
    m.tendon_damping[:] = 0
    m.opt.density = m.opt.viscosity = 0.0
    for j in np.flatnonzero(m.jnt_type <= 1):  # free and ball joints
        a, n = m.jnt_dofadr[j], 6 if m.jnt_type[j] == 0 else 3
        for arr in (m.dof_damping, m.dof_armature):
            if np.any(arr[a : a + n]):
                assert f"joint '{m.joint(j).name}'" in listed
            arr[a : a + n] = 0
        m.jnt_stiffness[j] = 0
    off = mujoco.mjtDisableBit
    m.opt.disableflags |= (
        int(off.mjDSBL_CONSTRAINT) | int(off.mjDSBL_CONTACT) | int(off.mjDSBL_ACTUATION)
    )
    return m


def random_qpos(m, rng, free_at_qpos0: bool) -> np.ndarray:
    qpos = m.qpos0.copy()
    for j in range(m.njnt):
        a = m.jnt_qposadr[j]
        if m.jnt_type[j] == 0 and not free_at_qpos0:
            qpos[a : a + 3] += rng.normal(size=3)
            quat = rng.normal(size=4)
            qpos[a + 3 : a + 7] = quat / np.linalg.norm(quat)
        elif m.jnt_type[j] >= 2:
            qpos[a] += rng.uniform(-1.0, 1.0)
    return qpos


def rel(a, b) -> float:
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300))


@pytest.mark.parametrize(("path", "fixed_base"), CASES)
def test_shipped_mjcf_matches_mujoco(path, fixed_base):
    has_free = _has_free(path)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        model = ad.load_mjcf(path, fixed_base=fixed_base)
    info = mjcf_info(model)
    mine = [w for w in caught if "armdyn.load_mjcf" in str(w.message)]
    assert len(mine) == (1 if info.unmapped else 0)  # one warning listing everything
    for item in info.unmapped:
        assert item in str(mine[0].message)
    m = mujoco_peer(path, info)
    welded = fixed_base and has_free
    dofs = [i for i in range(m.nv) if not (welded and m.jnt_type[m.dof_jntid[i]] == 0)]
    assert model.n_dofs == len(dofs) - len(info._followers)  # tendon/joint equalities: couplings
    if m.nv == 0:
        assert model.n_coords == 0
        return
    d = mujoco.MjData(m)
    rng = np.random.default_rng(36)
    for _ in range(3):
        # a state armdyn can hold: welded free joints at qpos0, coupling followers on their leaders
        q = info.q_from_qpos(random_qpos(m, rng, free_at_qpos0=welded))
        qpos, qd = info.qpos_from_q(q), rng.normal(size=model.n_dofs)
        assert np.allclose(info.q_from_qpos(qpos), q, rtol=0, atol=1e-15)
        t = info.velocity_map(qpos)
        d.qpos[:], d.qvel[:], d.qfrc_applied[:] = qpos, t @ qd, rng.normal(size=m.nv)
        mujoco.mj_forward(m, d)
        full = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, d, full)
        assert np.allclose(info.qd_from_qvel(qpos, d.qvel), qd, rtol=0, atol=1e-12)
        mass = ad.mass_matrix(model, q)
        assert rel(mass, t.T @ full @ t) < TOL
        qdd = ad.forward_dynamics(model, q, qd, t.T @ d.qfrc_applied)
        # MuJoCo's quantities reduced to armdyn's coordinates: qacc = T qdd + c (c: Tdot qd)
        c = info.qacc_from(qpos, qd, np.zeros(model.n_dofs))
        expect = np.linalg.solve(t.T @ full @ t, t.T @ (d.qfrc_smooth - full @ c))
        assert rel(qdd, expect) < TOL
        if t.shape[0] == t.shape[1]:  # nothing welded or coupled: MuJoCo's own qacc
            assert rel(info.qacc_from(qpos, qd, qdd), d.qacc) < TOL
