"""The articulated-body solve of a tree's Cartesian KKT system (issue 36: the Cartesian path at
the joint path's speed; cpp/include/armdyn/kernels/articulated_sweep.hpp).

Every answer is checked two ways: against the KKT equations themselves (Gamma v' + zeta^T delta
= eta and zeta v' = -xi, with eta, zeta and xi from `body_forces` and `evaluate_constraints`),
and against the dense reference path (`model.with_kkt_path("dense")`: one dense Cholesky of the
Schur complement, which the sweep never takes), and where the model has a joint space, against
the joint-space ABA."""

from __future__ import annotations

import armdyn as ad
import numpy as np
import pytest
from armdyn.papers.geared_arm import geared_arm_6dof

TOL = 1e-10


def kkt_residuals(model, u, v, vd, delta, t=0.0):
    """Relative residuals of the two KKT equations at (u, v): the momentum balance and the
    constraint rows' accelerations."""
    c = ad.evaluate_constraints(model, u, v, t)
    eta = ad.body_forces(model, u, v, t)
    gamma = ad.body_mass_matrix(model)
    zeta = c["zeta"]
    bal = gamma @ vd + zeta.T @ delta - eta
    scale_f = max(1.0, np.max(np.abs(gamma @ vd)), np.max(np.abs(eta)))
    rows = zeta @ vd + c["xi"]
    scale_a = max(1.0, np.max(np.abs(zeta) * np.max(np.abs(vd))), np.max(np.abs(c["xi"])))
    return np.max(np.abs(bal)) / scale_f, np.max(np.abs(rows)) / scale_a


def assert_matches_dense(model, u, v, t=0.0):
    vd, delta = ad.body_accelerations(model, u, v, t)
    vd_ref, delta_ref = ad.body_accelerations(model.with_kkt_path("dense"), u, v, t)
    assert np.max(np.abs(vd - vd_ref)) <= TOL * max(1.0, np.max(np.abs(vd_ref)))
    assert np.max(np.abs(delta - delta_ref)) <= TOL * max(1.0, np.max(np.abs(delta_ref)))
    rb, ra = kkt_residuals(model, u, v, vd, delta, t)
    assert rb <= 1e-12 and ra <= 1e-12
    return vd, delta


@pytest.mark.parametrize("n", [1, 3, 8, 40])
def test_random_chains_match_aba_dense_and_the_kkt_equations(n):
    model = ad.scenes.random_chain(n, seed=n)
    rng = np.random.default_rng(n)
    for _ in range(3):
        q, qd, tau = rng.uniform(-2, 2, size=(3, n))
        u, v = ad.state_from_joints(model, q, qd)
        assert_matches_dense(model, u, v)
        a = ad.forward_dynamics(model, q, qd, tau, method="cartesian")
        b = ad.forward_dynamics(model, q, qd, tau, method="aba")
        assert np.max(np.abs(a - b)) <= TOL * max(1.0, np.max(np.abs(b)))


def test_off_the_constraint_manifold_it_solves_the_system_as_evaluated():
    # positions off by 1e-5 and velocities that break the velocity constraints: the sweep's
    # transport comes from the evaluated rows (A = -P Z_p), not from rigid-body kinematics, so it
    # still solves the KKT system exactly
    model = ad.scenes.random_chain(10, seed=4)
    rng = np.random.default_rng(4)
    u, v = ad.state_from_joints(model, rng.uniform(-1, 1, 10), rng.uniform(-1, 1, 10))
    u = u + 1e-5 * rng.normal(size=u.size)
    for i in range(model.nb):  # unit Euler parameters again
        u[7 * i + 3 : 7 * i + 7] /= np.linalg.norm(u[7 * i + 3 : 7 * i + 7])
    v = v + 0.1 * rng.normal(size=v.size)
    assert np.max(np.abs(ad.evaluate_constraints(model, u, v)["f"])) > 1e-6
    assert_matches_dense(model, u, v)


def hand_on(joint_type, floating=False):
    """A 1 kg arm on a hinge (or free, when floating) and a hand at its tip on a joint of
    `joint_type`, then a finger on a hinge: every joint type with a parent that moves."""
    b = ad.ModelBuilder()
    b.add_body("arm", 1.0, np.diag([0.01, 0.02, 0.02]), position=(0.5, 0, 0))
    if floating:
        b.add_free("base", "arm")
    else:
        b.add_revolute("shoulder", "ground", "arm", (0, 0, 0), (0, 0.6, 0.8))
    b.add_body("hand", 0.7, np.diag([0.003, 0.004, 0.005]), position=(1.2, 0.1, 0))
    p, x = (1.0, 0, 0), (1, 0, 0)
    add = {
        "revolute": lambda: b.add_revolute("tip", "arm", "hand", p, (0.6, 0, 0.8)),
        "prismatic": lambda: b.add_prismatic("tip", "arm", "hand", p, x),
        "cylindrical": lambda: b.add_cylindrical("tip", "arm", "hand", p, x),
        "universal": lambda: b.add_universal("tip", "arm", "hand", p, x, (0, 1, 0)),
        "spherical": lambda: b.add_spherical("tip", "arm", "hand", p),
        "fixed": lambda: b.add_fixed("tip", "arm", "hand", p),
        "free": lambda: b.add_free("tip", "hand"),
    }
    add[joint_type]()
    b.add_body("finger", 0.2, np.diag([1e-4, 2e-4, 2e-4]), position=(1.5, 0.1, 0))
    b.add_revolute("knuckle", "hand", "finger", (1.4, 0.1, 0), (0, 0, 1))
    return b.finalize()


def moving_state(model, seed):
    """The assembly pose with a random velocity projected onto the velocity constraints
    (zeta v = 0): a state on the constraint manifold with every body moving."""
    rng = np.random.default_rng(seed)
    c = ad.evaluate_constraints(model, model.u0, np.zeros(model.nv))
    zeta = c["zeta"]
    # a random velocity projected onto zeta v = 0
    v = rng.normal(size=model.nv)
    if zeta.shape[0]:
        v -= zeta.T @ np.linalg.lstsq(zeta @ zeta.T, zeta @ v, rcond=None)[0]
    return model.u0.copy(), v


TYPES = ("revolute", "prismatic", "cylindrical", "universal", "spherical", "fixed", "free")


@pytest.mark.parametrize("floating", [False, True])
@pytest.mark.parametrize("joint_type", TYPES)
def test_every_joint_type_matches_dense(joint_type, floating):
    model = hand_on(joint_type, floating)
    u, v = moving_state(model, 7)
    vd, _ = assert_matches_dense(model, u, v)
    assert np.max(np.abs(vd)) > 0.1  # gravity and the motion load it
    # and along a run: fixed steps, so both paths take the same steps
    assert_run_matches_dense(model, 0.2, lambda r: r.reaction_forces)


def chain(n=5, coupling=False, drive=False, limits=False):
    """n links on alternating hinges (z, y): optionally a coupling (link 3 follows link 2), a
    drive on link 1 (rows outside the tree's joints, solved through their responses), and
    position limits on every joint."""
    b = ad.ModelBuilder()
    parent = "ground"
    for i in range(n):
        inertia = np.diag([0.01, 0.02, 0.03])
        b.add_body(f"l{i}", 1.0 + 0.2 * i, inertia, position=(0.3 * i + 0.15, 0, 0))
        axis = (0, 0, 1) if i % 2 == 0 else (0, 1, 0)
        b.add_revolute(f"j{i}", parent, f"l{i}", (0.3 * i, 0, 0), axis)
        if limits:
            b.set_joint_limits(f"j{i}", -0.3, 0.25)
        parent = f"l{i}"
    if coupling:
        b.add_coupling("c32", "j3", "j2", -0.5, 0.1)
    if drive:
        b.add_drive("j1", ad.profiles.sine(0.4, 2.0))
    return b.finalize()


def run_pair(model, t_end, **kw):
    """The run on the model's own path and on the dense reference: fixed steps, so both take
    the same ones, in Cartesian coordinates (a tree would otherwise run in joint space)."""
    kw.setdefault("coordinates", "cartesian")
    a = ad.simulate(model, t_end, integrator="rk4", dt=1e-3, output_dt=t_end / 4, **kw)
    b = ad.simulate(
        model.with_kkt_path("dense"), t_end, integrator="rk4", dt=1e-3, output_dt=t_end / 4, **kw
    )
    # the tree's solves went through the sweep (the dense reference never does)
    assert a.stats["articulated_solves"] > 0 and b.stats["articulated_solves"] == 0
    return a, b


def assert_run_matches_dense(model, t_end, output):
    """run_pair's two runs: the same states to 1e-12 and output(result) to 1e-9 relative."""
    a, b = run_pair(model, t_end)
    assert np.max(np.abs(a.u - b.u)) <= 1e-12
    fa, fb = output(a), output(b)
    assert np.max(np.abs(fa - fb)) <= 1e-9 * max(1.0, np.max(np.abs(fb)))


def test_couplings_and_a_partial_drive_match_dense():
    model = chain(coupling=True, drive=True)
    u, v = moving_state(model, 3)
    # the drive's velocity row does not hold on this state: the solve does not need it to
    assert_matches_dense(model, u, v, t=0.3)
    assert_run_matches_dense(model, 0.5, lambda r: r.drive_forces)
    # the coupled model's joint-level forward dynamics: Cartesian against joint space
    cm = chain(coupling=True)
    rng = np.random.default_rng(5)
    q, qd, tau = rng.uniform(-1, 1, size=(3, 4))
    x = ad.forward_dynamics(cm, q, qd, tau, method="cartesian")
    y = ad.forward_dynamics(cm, q, qd, tau, method="crba")
    assert np.max(np.abs(x - y)) <= TOL * max(1.0, np.max(np.abs(y)))


def test_geared_arm_with_ideal_gears_matches_dense():
    # 18 bodies, ideal gears between motor, gear and link bodies: gear rows outside the tree's
    # joints, each on a body and some of its children (a group) or handed to the KKT path
    model = geared_arm_6dof(n_motors=1, backlash=0.0)
    u, v = moving_state(model, 11)
    assert_matches_dense(model, u, v)
    a, b = run_pair(model, 0.02)
    assert np.max(np.abs(a.u - b.u)) <= 1e-11
    fa, fb = a.gear_forces["force"], b.gear_forces["force"]
    assert np.max(np.abs(fa - fb)) <= 1e-9 * np.max(np.abs(fb))


def hand_with_fingers(kind="prismatic", fingers=2, base="arm", drive=False):
    """An arm on a skew hinge (or the fingers straight on ground: base="ground"), a hand, and
    fingers on the hand, the second (and third) coupled to the first (URDF <mimic>): coupling
    rows on the hand and its children only, a group of the sweep; optionally the shoulder
    driven (a row outside the group, solved through its response)."""
    b = ad.ModelBuilder()
    parent = "ground"
    if base == "arm":
        b.add_body("arm", 1.0, np.diag([0.01, 0.02, 0.02]), position=(0.5, 0, 0))
        b.add_revolute("shoulder", "ground", "arm", (0, 0, 0), (0, 0.6, 0.8))
        b.add_body("hand", 0.7, np.diag([0.003, 0.004, 0.005]), position=(1.1, 0.05, 0))
        b.add_revolute("wrist", "arm", "hand", (1.0, 0, 0), (0.6, 0, 0.8))
        parent = "hand"
    mult = [None, -1.0, 0.5]
    for i in range(fingers):
        y = 0.05 * (i - 1)
        b.add_body(f"f{i}", 0.1 + 0.05 * i, np.diag([1e-4, 2e-4, 3e-4]), position=(1.3, y, 0.02))
        if kind == "prismatic":
            b.add_prismatic(f"s{i}", parent, f"f{i}", (1.2, y, 0), (0, 1 if i % 2 else -1, 0.2))
        else:
            b.add_revolute(f"s{i}", parent, f"f{i}", (1.2, y, 0), (0.3, 0.1 * i, 1))
        if i:
            b.add_coupling(f"mimic{i}", f"s{i}", "s0", mult[i], 0.01 * i)
    if drive:
        b.add_drive("shoulder", ad.profiles.sine(0.3, 1.5))
    return b.finalize()


@pytest.mark.parametrize(
    "kind, fingers, base",
    [
        ("prismatic", 2, "arm"),  # mimic fingers on a hand: one row, the fast path
        ("revolute", 2, "arm"),
        ("revolute", 2, "ground"),  # the group's body is ground
        ("revolute", 3, "arm"),  # two rows on one hand: the general path
        ("prismatic", 3, "ground"),
    ],
)
def test_rows_on_a_body_and_its_children_match_dense(kind, fingers, base):
    model = hand_with_fingers(kind, fingers, base)
    u, v = moving_state(model, 13)
    _, delta = assert_matches_dense(model, u, v)
    assert np.max(np.abs(delta[-(fingers - 1) :])) > 1e-3  # the couplings carry force
    assert_run_matches_dense(model, 0.2, lambda r: r.reaction_forces)
    # joint level: the Cartesian forward dynamics against joint space (CRBA on the independent
    # coordinates), off the assembly pose
    rng = np.random.default_rng(3)
    for _ in range(3):
        q, qd, tau = rng.uniform(-1, 1, size=(3, model.n_coords))
        x = ad.forward_dynamics(model, q, qd, tau, method="cartesian")
        y = ad.forward_dynamics(model, q, qd, tau, method="crba")
        assert np.max(np.abs(x - y)) <= TOL * max(1.0, np.max(np.abs(y)))


def test_a_group_and_a_drive_response_together_match_dense():
    # the drive's row is solved through its response sweep, which passes through the fingers'
    # group with no row values; the couplings' and the drive's forces against the dense path
    model = hand_with_fingers("prismatic", 3, "arm", drive=True)
    u, v = moving_state(model, 19)
    assert_matches_dense(model, u, v, t=0.2)
    assert_run_matches_dense(model, 0.2, lambda r: r.drive_forces)


def test_groups_take_rows_the_responses_could_not():
    # three couplings on three different bodies' children: beyond kMaxExtraRows (2) as
    # responses, so before the groups the KKT path took every solve; now the sweep does
    b = ad.ModelBuilder()
    parent = "ground"
    for i in range(3):
        b.add_body(f"l{i}", 1.0, np.diag([0.01, 0.02, 0.03]), position=(0.4 * i + 0.2, 0, 0))
        b.add_revolute(f"j{i}", parent, f"l{i}", (0.4 * i, 0, 0), (0, 0, 1) if i % 2 else (0, 1, 0))
        b.add_body(f"r{i}", 0.2, np.diag([1e-3, 1e-3, 2e-3]), position=(0.4 * i + 0.1, 0.1, 0))
        b.add_revolute(f"m{i}", parent, f"r{i}", (0.4 * i + 0.1, 0.1, 0), (0, 0, 1))
        b.add_coupling(f"g{i}", f"m{i}", f"j{i}", -20.0)  # a motor's rotor through a gear
        parent = f"l{i}"
    model = b.finalize()
    u, v = moving_state(model, 17)
    assert_matches_dense(model, u, v)
    a, _ = run_pair(model, 0.05)
    # at least one stage of every step on the sweep (the others reuse a projection's factor)
    assert a.stats["articulated_solves"] >= a.stats["steps"] > 0


def test_limit_stops_and_the_reused_factor_match_dense():
    # the stops re-solve at one pose with other joint torques (the reused factor): a chain
    # falling onto its limits, in Cartesian coordinates, against the dense path
    model = chain(limits=True)
    a, b = run_pair(model, 1.0, limits="enforce")
    fa, fb = a.limit_forces["force"], b.limit_forces["force"]
    assert np.count_nonzero(fb[-1]) >= 2  # two joints rest on their stops at the end
    assert np.max(np.abs(a.u - b.u)) <= 1e-12
    assert np.max(np.abs(fa - fb)) <= 1e-9 * np.max(np.abs(fb))


def test_a_joint_declared_from_child_to_parent_takes_the_kkt_path_with_the_same_answer():
    # the middle joint names the deeper link as its parent: the sweep, which runs parents
    # first, refuses the model and the KKT path solves it
    b = ad.ModelBuilder()
    for i in range(3):
        b.add_body(f"l{i}", 1.0, np.diag([0.01, 0.02, 0.03]), position=(0.3 * i + 0.15, 0, 0))
    b.add_revolute("j0", "ground", "l0", (0, 0, 0), (0, 0, 1))
    b.add_revolute("j1", "l1", "l0", (0.3, 0, 0), (0, 1, 0))
    b.add_revolute("j2", "l1", "l2", (0.6, 0, 0), (0, 0, 1))
    model = b.finalize()
    u, v = moving_state(model, 2)
    assert_matches_dense(model, u, v)
    a = ad.simulate(model, 0.1, integrator="rk4", dt=1e-3, coordinates="cartesian")
    assert a.stats["articulated_solves"] == 0 and a.stats["kkt_solves"] > 0
