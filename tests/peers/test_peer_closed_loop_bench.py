"""The peers of the closed-loop benchmark (benchmarks.closed_loop) are the same mechanisms as
armdyn's: at a moving state of each problem, the bodies' centre-of-mass accelerations of
Pinocchio's constrained dynamics, MuJoCo's exact-constraint KKT on its own terms and Exudyn's
initial-acceleration solve equal armdyn's ``body_accelerations`` (a state off the constraint
manifold's velocity space, or a different mechanism, would not). The quick benchmark runs and
every peer reaches the error the settings promise."""

from __future__ import annotations

import armdyn as ad
import numpy as np
import pytest

from benchmarks import closed_loop as cl
from benchmarks.peers import loop_models as lm

PROBLEMS = ("four_bar", "four_bar_revolute", "slider_crank", "squeezer", "palletizer")


def _moving_state(problem):
    """armdyn's model, its topology, the Pinocchio peer and a velocity v (Pinocchio's joint
    rates) in the null space of the loop constraints at the assembled configuration, scaled to
    a largest rate of 3 rad/s (m/s)."""
    pytest.importorskip("pinocchio")
    p = cl.PROBLEMS[problem]
    model = p.build()
    topo = lm.Topology(model)
    pin_peer = lm.PinocchioLoop(topo, extra_tau=p.extra_tau)
    q = np.zeros(pin_peer.nq)
    jac = pin_peer.constraint_jacobian(q)
    _u, s, vt = np.linalg.svd(jac)
    rank = int((s > 1e-10 * s[0]).sum())
    null = vt[rank:]
    assert null.shape[0] == model.mobility
    v = null[0] * 3.0 / np.abs(null[0]).max()
    return model, topo, pin_peer, q, v


def _armdyn_com_accelerations(model, topo, lin_v, ang_v):
    """armdyn's CoM accelerations at the assembled pose with the bodies' CoM velocities and
    world angular velocities (armdyn takes the angular velocity in the body frame)."""
    v = np.concatenate(
        [np.concatenate([lin_v[k], topo.rot[b].T @ ang_v[k]]) for k, b in enumerate(topo.bodies)]
    )
    acc, _mult = ad.body_accelerations(model, model.u0, v)
    return acc.reshape(-1, 6)[:, :3]


@pytest.mark.parametrize("problem", PROBLEMS)
def test_pinocchio_peer_is_the_same_mechanism(problem):
    model, topo, peer, q, v = _moving_state(problem)
    a = peer.accelerations(q, v)
    lin_a, lin_v, ang_v = peer.com_motion(q, v, a)
    ref = _armdyn_com_accelerations(model, topo, lin_v, ang_v)
    scale = np.abs(ref).max()
    assert scale > 1.0
    # measured 1e-15 to 1e-13 relative
    assert np.abs(lin_a - ref).max() < 1e-9 * scale
    # the velocity terms matter: the state at rest gives other accelerations (measured 1e-3
    # (squeezer, whose motor torque dominates) to 1e-1 relative)
    a0 = peer.accelerations(q, 0 * v)
    assert np.abs(peer.com_motion(q, 0 * v, a0)[0] - ref).max() > 1e-4 * scale


@pytest.mark.parametrize("problem", ("four_bar", "four_bar_revolute", "slider_crank", "palletizer"))
def test_mujoco_peer_is_the_same_mechanism(problem):
    pytest.importorskip("mujoco")
    model, topo, pin_peer, _q, v = _moving_state(problem)
    mj = lm.MujocoLoop(topo)
    pm = pin_peer.model
    qvel = np.zeros(mj.model.nv)
    for name, *_rest in topo.tree:
        qvel[mj.model.joint(name).dofadr[0]] = v[pm.joints[pm.getJointId(name)].idx_v]
    lin_a, lin_v, ang_v = mj.state_accelerations(qvel)
    ref = _armdyn_com_accelerations(model, topo, lin_v, ang_v)
    # MuJoCo's terms with exact constraints (its own qacc is soft); (d/dt J) v by central
    # differences: measured 1e-9 relative
    assert np.abs(lin_a - ref).max() < 1e-6 * np.abs(ref).max()


@pytest.mark.parametrize("problem", ("four_bar", "four_bar_revolute", "slider_crank", "palletizer"))
def test_exudyn_peer_is_the_same_mechanism(problem):
    pytest.importorskip("exudyn")
    model, topo, pin_peer, q, v = _moving_state(problem)
    _lin_a, lin_v, ang_v = pin_peer.com_motion(q, v, pin_peer.accelerations(q, v))
    velocities = {b: (lin_v[k], ang_v[k]) for k, b in enumerate(topo.bodies)}
    acc = lm.ExudynLoop(topo, velocities=velocities).initial_accelerations()
    ref = _armdyn_com_accelerations(model, topo, lin_v, ang_v)
    # Exudyn's initial-acceleration solve from Euler-parameter rates: measured 1.1e-8 (four-bar),
    # 8.6e-9 (slider-crank), 1.4e-7 (palletizer) relative, at rest 1e-15; the velocity terms
    # are 1e-3 to 1e-1 of the accelerations, so a different mechanism fails by far
    assert np.abs(acc - ref).max() < 1e-6 * np.abs(ref).max()


def test_delta_peers_are_the_same_mechanism():
    """The delta robot (plate held by six distance rods only: a free joint in MuJoCo, no
    Pinocchio model): MuJoCo's exact-constraint KKT and Exudyn at a moving state from the null
    space of MuJoCo's constraint Jacobian."""
    pytest.importorskip("mujoco")
    pytest.importorskip("exudyn")
    model = cl.PROBLEMS["delta"].build()
    topo = lm.Topology(model)
    assert topo.free == ["plate"]
    with pytest.raises(NotImplementedError, match="held only by constraints"):
        lm.PinocchioLoop(topo)
    mj = lm.MujocoLoop(topo)
    mujoco = mj.mujoco
    data = mujoco.MjData(mj.model)
    mj.model.opt.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
    mujoco.mj_forward(mj.model, data)
    jac = np.asarray(data.efc_J).reshape(-1, mj.model.nv)
    _u, s, vt = np.linalg.svd(jac)
    null = vt[int((s > 1e-10 * s[0]).sum()) :]
    assert null.shape[0] == model.mobility == 3
    qvel = null.sum(axis=0)
    qvel *= 3.0 / np.abs(qvel).max()
    lin_a, lin_v, ang_v = mj.state_accelerations(qvel)
    ref = _armdyn_com_accelerations(model, topo, lin_v, ang_v)
    scale = np.abs(ref).max()
    assert np.abs(lin_a - ref).max() < 1e-6 * scale  # measured 5.3e-11
    velocities = {b: (lin_v[k], ang_v[k]) for k, b in enumerate(topo.bodies)}
    acc = lm.ExudynLoop(topo, velocities=velocities).initial_accelerations()
    assert np.abs(acc - ref).max() < 1e-6 * scale  # measured 8.2e-9
    at_rest = _armdyn_com_accelerations(model, topo, 0 * lin_v, 0 * ang_v)
    assert np.abs(at_rest - ref).max() > 1e-2 * scale


def test_pinocchio_reference_agrees_with_armdyn_tight():
    """The benchmark's reference (DOP853 at 1e-13 on Pinocchio) and armdyn's DOP853 at 1e-12,
    two methods, agree at the end of the four-bar's 1.5 s swing."""
    pytest.importorskip("pinocchio")
    p = cl.PROBLEMS["four_bar"]
    model = p.build()
    ref = cl.pinocchio_reference(p, lm.Topology(model))
    res = ad.simulate(
        model,
        p.t_end,
        integrator="dop853",
        rtol=1e-12,
        atol=1e-12,
        output_dt=p.t_end,
        limits="ignore",
    )
    got = lm.Topology.observe_u(res.u[-1])
    assert np.abs(got - ref).max() < 1e-9  # measured 4.1e-12 m
    assert np.abs(got - lm.Topology.observe_u(model.u0)).max() > 0.05  # it moved 0.39 m


def test_quick_benchmark_runs_every_peer(tmp_path):
    pytest.importorskip("mujoco")
    pytest.importorskip("pinocchio")
    pytest.importorskip("exudyn")
    doc = cl.run(["four_bar"], quick=True, echo=False, out=tmp_path / "quick.json")
    r = doc["problems"]["four_bar"]
    assert set(r["curves"]) >= {"armdyn dop853", "MuJoCo rk4", "Exudyn GeneralizedAlpha"}
    for key, points in r["curves"].items():
        for point in points:
            assert "failed" not in point, key
            assert point["cpu_s"] > 0
            assert point["error"] < 1e-4, key
    assert (tmp_path / "quick.json").is_file()
    assert "| four_bar |" in doc["table_1e-6"]
    # the 1e-6 ratio: interleaved rounds of each curve's cheapest point reaching 1e-6, paired
    rounds = r["rounds_1e-6"]
    libs = rounds["libraries"]
    assert "armdyn" in libs and "Pinocchio" in libs
    for lib, rec in libs.items():
        assert len(rec["round_cpu_s"]) == rounds["rounds"] == 3
        assert all(t > 0 for t in rec["round_cpu_s"])
        for key, setting in rec["points"].items():  # the chosen point reached 1e-6 in the sweep
            point = next(q for q in r["curves"][key] if q["setting"] == setting)
            assert point["error"] <= 1e-6, (lib, key)
    for lib, q in rounds["ratios"].items():
        per = np.array(libs[lib]["round_cpu_s"]) / np.array(libs["armdyn"]["round_cpu_s"])
        np.testing.assert_allclose(q["per_round"], per, rtol=1e-12)
        assert q["min"] <= q["median"] <= q["max"]
        assert f"({q['median']:.1f}x [{q['min']:.1f}, {q['max']:.1f}])" in doc["table_1e-6"]
