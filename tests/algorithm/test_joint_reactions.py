"""armdyn.joint_reactions: every joint's reaction along a given joint-space motion of a tree (on
the child at the joint point, in the child's joint frame; SimulationResult's convention), with
the inverse dynamics' joint torques. Checked against Pinocchio's RNEA joint forces ``data.f``
(moved to armdyn's joint frame and point; their axis component is the joint torque, which the
reaction leaves out), against a joint-space ``simulate`` run's own reactions at its output
samples, and through couplings, actuators, fixed joints and floating bases against models that
must give the same reactions."""

from __future__ import annotations

import armdyn as ad
import numpy as np
import pytest

from benchmarks import common


def ur5(**kw):
    path = common.robot_urdf("ur5")
    assert path is not None, "example-robot-data is part of the test extra"
    return path, ad.load_urdf(str(path), **kw)


def motion(n_coords, n=25, seed=3, q0=None):
    """A smooth motion q = q0 + a sin(w t + p) sampled at n times, with its exact rates and
    accelerations."""
    rng = np.random.default_rng(seed)
    a = rng.uniform(0.3, 1.0, n_coords)
    w = rng.uniform(1.0, 4.0, n_coords)
    p = rng.uniform(-np.pi, np.pi, n_coords)
    q0 = np.zeros(n_coords) if q0 is None else np.asarray(q0, dtype=float)
    t = np.linspace(0.0, 2.0, n)[:, None]
    q = q0 + a * np.sin(w * t + p)
    qd = a * w * np.cos(w * t + p)
    qdd = -a * w**2 * np.sin(w * t + p)
    return t[:, 0], q, qd, qdd


def rel_err(a, b):
    return float(np.abs(a - b).max() / np.abs(b).max())


def test_ur5_reactions_equal_pinocchio_rnea_joint_forces():
    pin = pytest.importorskip("pinocchio")
    path, model = ur5()
    pm = pin.buildModelFromUrdf(str(path))
    pd = pm.createData()
    names = list(model.joint_names)
    pin_joints = [pm.getJointId(n) for n in names]
    perm = [pm.joints[j].idx_q for j in pin_joints]  # armdyn coordinate k -> Pinocchio q index
    assert sorted(perm) == list(range(pm.nq))
    t, q, qd, qdd = motion(model.n_coords, q0=common.UR5_Q0)
    forces, torques = ad.joint_reactions(model, q, qd, qdd, t)
    assert forces.shape == torques.shape == (len(t), len(names), 3)
    tau = ad.inverse_dynamics(model, q, qd, qdd, t)
    # armdyn's joint frame (z the axis) in the URDF child link's frame, Pinocchio's joint frame
    place = []
    for name in names:
        jf = model.joint_frame(name)
        link = model.frame(jf["child"])
        rot = link["rotation"].T @ jf["frame_child"]
        off = link["rotation"].T @ (jf["point_child"] - link["point"])
        place.append((rot, off))
    worst_f = worst_t = worst_tau = 0.0
    fmax = tmax = taumax = 0.0
    for i in range(len(t)):
        qp, vp, ap = (np.empty(pm.nq) for _ in range(3))
        qp[perm], vp[perm], ap[perm] = q[i], qd[i], qdd[i]
        tau_pin = pin.rnea(pm, pd, qp, vp, ap)
        friction = -pm.damping * vp - pm.friction * np.tanh(vp / ad._core.URDF_COULOMB_SMOOTHING)
        for k, jid in enumerate(pin_joints):
            rot, off = place[k]
            f_pin = pd.f[jid].linear
            n_pin = pd.f[jid].angular  # about the link frame's origin
            f = rot @ forces[i, k]
            n = rot @ torques[i, k] + np.cross(off, f)  # moved to the link frame's origin
            axis = rot[:, 2]
            # the axis component of data.f is Pinocchio's joint torque; the reaction has none
            assert abs(axis @ (rot @ torques[i, k])) <= 1e-12 * max(1.0, np.abs(n_pin).max())
            worst_f = max(worst_f, np.abs(f - f_pin).max())
            worst_t = max(worst_t, np.abs(n + (axis @ n_pin) * axis - n_pin).max())
            worst_tau = max(worst_tau, abs(axis @ n_pin - tau_pin[pm.joints[jid].idx_v]))
            fmax, tmax = max(fmax, np.abs(f_pin).max()), max(tmax, np.abs(n_pin).max())
        # armdyn's inverse dynamics is Pinocchio's joint torque with the URDF's friction
        tau_ref = tau_pin - friction
        worst_tau = max(worst_tau, np.abs(tau[i] - tau_ref[perm]).max())
        taumax = max(taumax, np.abs(tau_ref).max())
    # measured: forces 7.9e-16, torques 6.5e-16, joint torques 3.8e-16 relative
    assert worst_f <= 1e-9 * fmax
    assert worst_t <= 1e-9 * tmax
    assert worst_tau <= 1e-9 * taumax


def test_one_state_and_scalar_or_default_time():
    _, model = ur5()
    t, q, qd, qdd = motion(model.n_coords, n=3)
    rows = ad.joint_reactions(model, q, qd, qdd, t[1])
    f1, n1 = ad.joint_reactions(model, q[1], qd[1], qdd[1], t[1])
    assert f1.shape == n1.shape == (len(model.joint_names), 3)
    np.testing.assert_array_equal(f1, rows[0][1])
    np.testing.assert_array_equal(n1, rows[1][1])
    # t=None is t=0 (the UR5 has no time-dependent load)
    f0, n0 = ad.joint_reactions(model, q[1], qd[1], qdd[1])
    np.testing.assert_array_equal(f0, f1)
    np.testing.assert_array_equal(n0, n1)
