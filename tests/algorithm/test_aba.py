"""The articulated-body algorithm (issue 20): ``forward_dynamics(method="aba")`` against
Pinocchio's ABA on the example-robot-data UR5 and Panda (the same URDF read by both libraries,
:class:`benchmarks.peers.pinocchio.PinPair`) and on a 300-link spatial chain rebuilt in
Pinocchio from the model's own data (:func:`benchmarks.peers.pinocchio.pinocchio_tree`), against
armdyn's CRBA path there; and the measured cost model's choices (``dynamics_cost``): which
algorithm ``method="joint"``/``"auto"`` and ``simulate(coordinates="auto")`` take, and that the
chosen path gives the forced one's answer. No timings: speed is measured by
``python -m benchmarks.chain_scaling`` and ``python -m benchmarks.cost_model``."""

import armdyn as ad
import numpy as np
import pytest
from armdyn.scenes import random_chain

from benchmarks import common
from benchmarks.peers.pinocchio import PinPair, pinocchio_tree

pin = pytest.importorskip("pinocchio")


def rel(a, b):
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


@pytest.mark.parametrize("robot", ["ur5", "panda"])
def test_aba_equals_pinocchio_aba_on_urdf_arms(robot):
    path = common.robot_urdf(robot)
    assert path is not None, "example-robot-data is part of the test extra"
    pair = PinPair(path)
    rng = np.random.default_rng(11)
    worst = 0.0
    for _ in range(50):
        q, v, tau = rng.uniform(-np.pi, np.pi, size=(3, pair.pm.nq))
        ref = pair.aba(q, v, tau)
        qa, va, ta = (pair.to_armdyn(x) for x in (q, v, tau))
        got = ad.forward_dynamics(pair.am, qa, va, ta, method="aba")[pair.perm]
        worst = max(worst, rel(got, ref))
        # and the batch form
    assert worst <= 1e-10
    q, v, tau = rng.uniform(-np.pi, np.pi, size=(3, 8, pair.pm.nq))
    batch = ad.forward_dynamics(
        pair.am, pair.to_armdyn(q), pair.to_armdyn(v), pair.to_armdyn(tau), method="aba"
    )
    for i in range(8):
        assert rel(batch[i][pair.perm], pair.aba(q[i], v[i], tau[i])) <= 1e-10


def test_cost_model_choice_on_a_short_arm():
    # a 6-joint arm: the algorithm "joint" and "auto" take is the cost model's (the measured
    # constants, benchmarks/results/cost_model.json), and its answer is the forced method's, bit
    # for bit
    pair = PinPair(common.robot_urdf("ur5"))
    m = pair.am
    cost = ad.dynamics_cost(m)
    assert cost["joint"] in ("crba", "aba")
    assert cost["joint"] == ("aba" if cost["aba_us"] < cost["crba_us"] else "crba")
    assert cost["auto"] == min(("crba", "aba", "cartesian"), key=lambda k: cost[f"{k}_us"])
    rng = np.random.default_rng(3)
    q, qd, tau = rng.uniform(-1, 1, size=(3, m.n_coords))
    joint = ad.forward_dynamics(m, q, qd, tau, method="joint")
    np.testing.assert_array_equal(joint, ad.forward_dynamics(m, q, qd, tau, method=cost["joint"]))
    np.testing.assert_array_equal(
        ad.forward_dynamics(m, q, qd, tau), ad.forward_dynamics(m, q, qd, tau, method=cost["auto"])
    )
    # every method agrees
    for method in ("crba", "aba", "cartesian"):
        assert rel(ad.forward_dynamics(m, q, qd, tau, method=method), joint) <= 1e-9
    # short arms: joint space is predicted cheaper per right-hand side than the Cartesian system
    assert cost["simulate"] == "joint"


def test_long_chain_takes_aba_and_agrees_with_crba_and_pinocchio():
    model = random_chain(300)
    cost = ad.dynamics_cost(model)
    assert (cost["n"], cost["nb"], cost["path"]) == (300, 300, 300 * 301 / 2)
    assert cost["joint"] == "aba"
    assert cost["auto"] == "aba"
    assert cost["crba_us"] > 3 * cost["aba_us"]
    pm, idx = pinocchio_tree(model)
    pd = pm.createData()
    rng = np.random.default_rng(5)
    for _ in range(3):
        q, qd, tau = rng.uniform(-1, 1, size=(3, 300))
        aba = ad.forward_dynamics(model, q, qd, tau, method="aba")
        crba = ad.forward_dynamics(model, q, qd, tau, method="crba")
        np.testing.assert_array_equal(ad.forward_dynamics(model, q, qd, tau), aba)
        np.testing.assert_array_equal(ad.forward_dynamics(model, q, qd, tau, method="joint"), aba)
        qp, vp, tp = (np.empty(300) for _ in range(3))
        qp[idx], vp[idx], tp[idx] = q, qd, tau
        ref = pin.aba(pm, pd, qp, vp, tp)[idx]
        assert rel(aba, ref) <= 1e-9
        assert rel(crba, aba) <= 1e-8


def test_simulate_auto_takes_joint_space_aba_on_a_long_chain():
    model = random_chain(300)
    assert ad.dynamics_cost(model)["simulate"] == "joint"
    auto = ad.simulate(model, 0.004, integrator="rk4", dt=1e-3, coordinates="auto")
    form = auto.stats["formulation"]
    assert form.startswith("joint space: 300 coordinates, articulated-body algorithm")
    assert "cost model" in form and "per right-hand side" in form
    # the same run as coordinates="joint" (which takes ABA too), and close to the Cartesian one
    joint = ad.simulate(model, 0.004, integrator="rk4", dt=1e-3, coordinates="joint")
    np.testing.assert_array_equal(auto.q, joint.q)
    cart = ad.simulate(model, 0.004, integrator="rk4", dt=1e-3, coordinates="cartesian")
    assert np.abs(np.asarray(cart.q) - np.asarray(joint.q)).max() <= 1e-8


def test_method_names():
    m = random_chain(3)
    z = np.zeros(3)
    with pytest.raises(ad.ModelError, match="'auto', 'joint', 'crba', 'aba' or 'cartesian'"):
        ad.forward_dynamics(m, z, z, z, method="featherstone")
    with pytest.raises(ad.ModelError, match="'auto', 'joint' or 'cartesian'"):
        ad.inverse_dynamics(m, z, z, z, method="aba")
