"""Massless links and the physical_inertia option (issue 21).

Massless bodies (mass 0, zero inertia) and singular inertias (point masses, thin rods) are
accepted wherever every motion the joints allow still carries inertia (the joint-space mass
matrix is positive definite; for closed loops, Gamma positive definite on the null space of the
joint Jacobian); finalize() refuses the others naming the joint and the body. References:
Pinocchio (which loads any tensor) on example-robot-data's human.urdf (19 massless "virtual"
links between the joints of its 3-DOF hips, shoulders and spine) and on the published PUMA 560
parameters (tests/data/urdf/puma560_published_inertia.urdf), closed forms, and equivalent
models without the massless link.
"""

import re
import site
import warnings
from pathlib import Path

import armdyn as ad
import numpy as np
import pytest

from benchmarks.peers.pinocchio import mass_matrix as pin_mass_matrix
from benchmarks.peers.pinocchio import pinocchio_tree

pin = pytest.importorskip("pinocchio")

DATA = Path(__file__).resolve().parents[1] / "data" / "urdf"
PUMA = DATA / "puma560_published_inertia.urdf"
METHODS = ("auto", "joint", "crba", "aba", "cartesian")


def _erd(name):
    for base in [*site.getsitepackages(), site.getusersitepackages()]:
        path = Path(base) / "cmeel.prefix/share/example-robot-data/robots" / name
        if path.is_file():
            return path
    pytest.skip(f"example-robot-data's {name} not installed")


def _human():
    return _erd("human_description/robots/human.urdf")


def _pair(path, **kw):
    """(armdyn model, pinocchio model, perm) with q_armdyn[perm] = q_pinocchio."""
    model = ad.load_urdf(str(path), **kw)
    pm = pin.buildModelFromUrdf(str(path))
    names = list(model.coord_names)
    perm = np.array([names.index(pm.names[i]) for i in range(1, pm.njoints)])
    return model, pm, perm


def _worst_errors(model, pm, perm, n, seed):
    """Worst relative errors (to the largest entry of Pinocchio's answer) of mass_matrix,
    forward_dynamics (every method) and inverse_dynamics at n random states."""
    pd = pm.createData()
    rng = np.random.default_rng(seed)
    worst = dict.fromkeys(("M", "id", *METHODS), 0.0)

    def rel(a, b):
        return float(np.abs(a - b).max() / np.abs(b).max())

    for _ in range(n):
        q, v, tau, acc = rng.uniform(-np.pi, np.pi, size=(4, pm.nq))
        qa, va, ta, aa = (np.empty_like(x) for x in (q, v, tau, acc))
        for x, xa in ((q, qa), (v, va), (tau, ta), (acc, aa)):
            xa[perm] = x
        m_ref = pin_mass_matrix(pin, pm, pd, q)
        worst["M"] = max(worst["M"], rel(ad.mass_matrix(model, qa)[np.ix_(perm, perm)], m_ref))
        # the URDF's <dynamics> joint friction, which armdyn imports and Pinocchio leaves out
        friction = -pm.damping * v - pm.friction * np.tanh(v / ad._core.URDF_COULOMB_SMOOTHING)
        a_ref = pin.aba(pm, pd, q, v, tau + friction)
        for method in METHODS:
            a = ad.forward_dynamics(model, qa, va, ta, method=method)[perm]
            worst[method] = max(worst[method], rel(a, a_ref))
        t_ref = pin.rnea(pm, pd, q, v, acc) - friction
        worst["id"] = max(worst["id"], rel(ad.inverse_dynamics(model, qa, va, aa)[perm], t_ref))
    return worst


# ---------------------------------------------------------------- human.urdf (massless links


def test_human_urdf_loads_with_its_massless_virtual_links():
    model = ad.load_urdf(str(_human()))
    masses = np.asarray(model.masses)
    virtual = [n for n, m in zip(model.body_names, masses, strict=True) if m == 0.0]
    # the 19 "virtual" links between the joints of the 3-DOF hips, shoulders, spine, ...
    assert len(virtual) == 19 and all("virtual" in n for n in virtual)
    assert model.n_coords == 36 and model.joint_space


def test_human_urdf_dynamics_equal_pinocchio():
    model, pm, perm = _pair(_human())
    worst = _worst_errors(model, pm, perm, n=20, seed=21)
    # measured: M 1.2e-15, forward dynamics 3.9e-14 (aba; crba/joint/auto run ABA on a model
    # with light bodies), 6.0e-15 (cartesian), inverse dynamics 9.6e-16
    assert max(worst.values()) <= 1e-10, worst


def test_human_urdf_simulates_in_joint_and_cartesian_coordinates():
    model = ad.load_urdf(str(_human()))
    rng = np.random.default_rng(5)
    q0 = rng.uniform(-0.5, 0.5, model.n_coords)
    qd0 = rng.uniform(-0.5, 0.5, model.n_coords)
    runs = {
        c: ad.simulate(
            model,
            0.05,
            rtol=1e-10,
            atol=1e-12,
            q0=q0,
            qd0=qd0,
            output_dt=0.01,
            coordinates=c,
            limits="ignore",  # a random start outside some joints' limits
        )
        for c in ("joint", "cartesian")
    }
    joint, cart = runs["joint"], runs["cartesian"]
    assert "joint space" in joint.stats["formulation"]
    assert cart.stats["formulation"].startswith("cartesian")
    # massless bodies: the floored range-space factor refined against the exact system, no
    # augmented LU (kernels/kkt_factor.hpp accelerations_refined)
    assert cart.stats["augmented_solves"] == 0 and cart.stats["kkt_solves"] > 0
    np.testing.assert_allclose(joint.q[0], q0, atol=1e-12)
    # the two formulations of the same motion (measured 2.3e-13 rad, 8.1e-12 rad/s), energy
    # conserved (measured drift 4.6e-12 and 1.0e-12 J, kinetic energy up to 6.4 J)
    assert np.abs(joint.q - cart.q).max() <= 1e-10
    assert np.abs(joint.qd - cart.qd).max() <= 1e-9
    for r in (joint, cart):
        e = np.asarray(r.total_energy)
        assert np.abs(e - e[0]).max() <= 1e-10 * np.abs(r.kinetic_energy).max()
    # the accelerations reported along the joint-space run are Pinocchio's ABA at its states
    pm = pin.buildModelFromUrdf(str(_human()))
    pd = pm.createData()
    names = list(model.coord_names)
    perm = np.array([names.index(pm.names[i]) for i in range(1, pm.njoints)])
    for q, qd, qdd in zip(joint.q, joint.qd, joint.qdd, strict=True):
        ref = pin.aba(pm, pd, q[perm], qd[perm], np.zeros(pm.nv))
        assert np.abs(qdd[perm] - ref).max() <= 1e-10 * np.abs(ref).max()


def test_falling_human_cartesian_run_follows_the_joint_space_run():
    # from rest under gravity at the default tolerances: the Cartesian run's projections use a
    # metric floored for the massless bodies (kernels/kkt_factor.cpp; with the light-body
    # floors, 1e-9 of the heaviest mass, a 1 s fall stalled at t = 0.13 s with |f| = 1.4e-9)
    model = ad.load_urdf(str(_human()))
    # (the stops' contact sequence is tested in tests/simulate/test_joint_limits.py)
    runs = {
        c: ad.simulate(model, 0.2, output_dt=0.05, coordinates=c, limits="ignore")
        for c in ("joint", "cartesian")
    }
    # measured 1.8e-8 rad (both at rtol 1e-6), position residual 1.7e-16
    assert np.abs(runs["joint"].q - runs["cartesian"].q).max() <= 1e-6
    assert np.abs(runs["cartesian"].position_residual).max() <= 1e-12
    assert np.abs(runs["joint"].q[-1]).max() > 0.1  # it fell


# ------------------------------------------------------------- hand-built massless links


def _gimbal(massless_mass=0.0, builder=None):
    """Two revolute joints through the origin, z (in ground) then x (in the massless link), a
    massless link between them and an arm below: a 2-DOF universal-like chain."""
    b = builder or ad.ModelBuilder()
    b.add_body("virtual", massless_mass, np.zeros((3, 3)), position=(0.0, 0.0, 0.0))
    b.add_revolute("yaw", "ground", "virtual", (0, 0, 0), (0, 0, 1))
    b.add_body("arm", 2.0, np.diag([0.03, 0.02, 0.01]), position=(0.1, 0.2, -0.5))
    b.add_revolute("roll", "virtual", "arm", (0, 0, 0), (1, 0, 0))
    return b.finalize()


GIMBAL_MASS, GIMBAL_C0 = 2.0, np.array([0.1, 0.2, -0.5])
GIMBAL_IC = np.diag([0.03, 0.02, 0.01])


def _rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def _rx(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def _gimbal_closed_form(q):
    """M(q) and the gravity torques G(q) of the gimbal: R = Rz(q1) Rx(q2), angular velocity
    q1' z + q2' Rz(q1) x; M = J^T I_O J with I_O the arm's inertia about the pivot in world axes,
    G_i = -m g . (axis_i x R c0)."""
    m, c0, ic = GIMBAL_MASS, GIMBAL_C0, GIMBAL_IC
    r = _rz(q[0]) @ _rx(q[1])
    i_pivot = ic + m * (c0 @ c0 * np.eye(3) - np.outer(c0, c0))
    i_o = r @ i_pivot @ r.T
    axes = np.column_stack([[0, 0, 1], _rz(q[0]) @ [1, 0, 0]])
    g = np.array([0.0, 0.0, -9.81])
    grav = np.array([-m * g @ np.cross(axes[:, k], r @ c0) for k in range(2)])
    return axes.T @ i_o @ axes, grav


def test_massless_intermediate_link_equals_the_closed_form():
    model = _gimbal()
    assert list(model.masses) == [0.0, 2.0]
    rng = np.random.default_rng(2)
    for _ in range(10):
        q = rng.uniform(-np.pi, np.pi, 2)
        m_ref, g_ref = _gimbal_closed_form(q)
        # measured 2.2e-16 (|M| <= 0.61 kg m^2), 1.8e-15 (|G| <= 8.7 N m), 2.2e-15 relative
        np.testing.assert_allclose(ad.mass_matrix(model, q), m_ref, rtol=0, atol=1e-14)
        tau = ad.inverse_dynamics(model, q, np.zeros(2), np.zeros(2))
        np.testing.assert_allclose(tau, g_ref, rtol=0, atol=1e-13)
        # forward dynamics at rest: M qdd = tau_in - G, every method
        tau_in = rng.uniform(-1, 1, 2)
        qdd_ref = np.linalg.solve(m_ref, tau_in - g_ref)
        for method in METHODS:
            qdd = ad.forward_dynamics(model, q, np.zeros(2), tau_in, method=method)
            assert np.abs(qdd - qdd_ref).max() <= 1e-12 * np.abs(qdd_ref).max(), method


def test_massless_intermediate_link_equals_pinocchio_with_velocities():
    # the same chain rebuilt in Pinocchio from the model's own data (a different library's
    # ABA, RNEA and CRBA; a massless body is a zero Inertia there)
    model = _gimbal()
    pm, idx = pinocchio_tree(model)
    worst = _worst_errors(model, pm, np.argsort(idx), n=20, seed=4)
    # measured <= 2.4e-15
    assert max(worst.values()) <= 1e-12, worst


def test_massless_intermediate_link_equals_a_universal_joint():
    # merged away, the massless link is a universal joint (axis 1 fixed in ground, axis 2 in
    # the arm): the arm's Cartesian accelerations agree at random joint states
    chain = _gimbal()
    b = ad.ModelBuilder()
    b.add_body("arm", 2.0, np.diag([0.03, 0.02, 0.01]), position=(0.1, 0.2, -0.5))
    b.add_universal("cardan", "ground", "arm", (0, 0, 0), (0, 0, 1), (1, 0, 0))
    cardan = b.finalize()
    rng = np.random.default_rng(8)
    for _ in range(10):
        q, qd = rng.uniform(-1.2, 1.2, size=(2, 2))
        u, v = ad.state_from_joints(chain, q, qd)
        vdot_chain, _ = ad.body_accelerations(chain, u, v)
        vdot_cardan, _ = ad.body_accelerations(cardan, u[7:], v[6:])
        ref = vdot_cardan
        # measured <= 9.7e-15
        assert np.abs(vdot_chain[6:] - ref).max() <= 1e-12 * np.abs(ref).max()
        # and the joint-space path gives the same arm motion
        qdd = ad.forward_dynamics(chain, q, qd, np.zeros(2))
        _, v1 = ad.state_from_joints(chain, q + 1e-6 * qd, qd + 1e-6 * qdd)
        _, v0 = ad.state_from_joints(chain, q - 1e-6 * qd, qd - 1e-6 * qdd)
        fd = (v1[6:] - v0[6:]) / 2e-6  # d/dt of the arm's (xdot, omega_body)
        # central difference, O(h^2): measured <= 2.1e-11
        assert np.abs(fd - ref).max() <= 1e-8 * np.abs(ref).max()


def test_massless_coupler_in_a_closed_loop_equals_a_distance_joint():
    # a planar four-bar whose coupler is a massless link on revolute joints moves as the same
    # four-bar with the coupler replaced by a distance joint (a massless rod with ball ends):
    # Gamma is positive definite on the loop's null space though the coupler has no mass
    a, bpt, c, d = (
        np.array(p, float) for p in ((0, 0, 0), (0.3, 0, 0.4), (1.1, 0, 0.7), (1, 0, 0))
    )
    y = (0, 1, 0)

    def four_bar(massless_coupler):
        b = ad.ModelBuilder()
        b.add_body("crank", 1.0, np.diag([0.02, 0.02, 0.001]), position=(a + bpt) / 2)
        b.add_body("rocker", 1.5, np.diag([0.05, 0.05, 0.002]), position=(c + d) / 2)
        b.add_revolute("A", "ground", "crank", a, y)
        b.add_revolute("D", "ground", "rocker", d, y)
        if massless_coupler:
            b.add_body("coupler", 0.0, np.zeros((3, 3)), position=(bpt + c) / 2)
            b.add_revolute("B", "crank", "coupler", bpt, y)
            b.add_revolute("C", "coupler", "rocker", c, y)
        else:
            b.add_distance("rod", "crank", bpt, "rocker", c)
        return b.finalize()

    loop, rod = four_bar(True), four_bar(False)
    assert loop.mobility == 1 and rod.mobility == 1
    vdot_loop, _ = ad.body_accelerations(loop, loop.u0, loop.v0)
    vdot_rod, _ = ad.body_accelerations(rod, rod.u0, rod.v0)
    ref = vdot_rod[:12]
    # measured 8.8e-16
    assert np.abs(vdot_loop[:12] - ref).max() <= 1e-10 * np.abs(ref).max()
    # and a swing under gravity: the crank's and rocker's motion agree
    r_loop = ad.simulate(loop, 0.3, rtol=1e-10, atol=1e-12, output_dt=0.05)
    r_rod = ad.simulate(rod, 0.3, rtol=1e-10, atol=1e-12, output_dt=0.05)
    # measured 7.5e-13 (the massless coupler: the refined range-space solve)
    assert r_loop.stats["augmented_solves"] == 0
    assert np.abs(r_loop.u[:, :14] - r_rod.u[:, :14]).max() <= 1e-10
    assert np.abs(r_loop.u[-1, :3] - r_loop.u[0, :3]).max() > 1e-2  # it moved


# ------------------------------------------------------------------------- refusals


def test_massless_leaf_is_refused_naming_the_joint_and_the_body():
    b = ad.ModelBuilder()
    b.add_body("arm", 1.0, np.diag([0.01, 0.01, 0.01]), position=(0.5, 0, 0))
    b.add_revolute("shoulder", "ground", "arm", (0, 0, 0), (0, 0, 1))
    b.add_body("hand", 0.0, np.zeros((3, 3)), position=(1.0, 0, 0))
    b.add_revolute("wrist", "arm", "hand", (1.0, 0, 0), (0, 1, 0))
    with pytest.raises(ad.ModelError, match=r"joint 'wrist' carries no inertia.*body 'hand'"):
        b.finalize()
    # a point mass on its own joint axis: that joint's motion carries no inertia either
    b2 = ad.ModelBuilder()
    b2.add_body("arm", 1.0, np.diag([0.01, 0.01, 0.01]), position=(0.5, 0, 0))
    b2.add_revolute("shoulder", "ground", "arm", (0, 0, 0), (0, 0, 1))
    b2.add_body("ball", 2.0, np.zeros((3, 3)), position=(1.0, 0, 0))
    b2.add_revolute("spin", "arm", "ball", (1.0, 0, 0), (1, 0, 0))
    with pytest.raises(ad.ModelError, match=r"joint 'spin' carries no inertia.*body 'ball'"):
        b2.finalize()
    # off its axis, the point mass carries the joint's motion
    b3 = ad.ModelBuilder()
    b3.add_body("ball", 2.0, np.zeros((3, 3)), position=(1.0, 0, 0))
    b3.add_revolute("swing", "ground", "ball", (0, 0, 0), (0, 1, 0))
    m = b3.finalize()
    np.testing.assert_allclose(ad.mass_matrix(m, [0.3]), [[2.0]], rtol=1e-14)


def _bead_on_arm(offset):
    """A 1 g point mass on its own revolute (x) at `offset` from the axis, on a 1000 kg arm."""
    b = ad.ModelBuilder()
    b.add_body("heavy", 1000.0, np.eye(3) * 100, position=(0.5, 0, 0))
    b.add_revolute("swing", "ground", "heavy", (0, 0, 0), (0, 1, 0))
    b.add_body("bead", 1e-3, np.zeros((3, 3)), position=(1, offset, 0))
    b.add_revolute("spin", "heavy", "bead", (1, 0, 0), (1, 0, 0))
    return b.finalize()


def test_tiny_but_genuine_inertia_is_accepted_and_round_off_refused():
    # 0.1 mm off its axis the bead carries 1e-11 kg m^2 (2e-13 of the arm's 350): accepted, and
    # its dynamics equals Pinocchio's on the same data; 1 um off (2e-17) the mass matrix is
    # singular to round-off (the check's bound: 1e-14 of the largest)
    model = _bead_on_arm(1e-4)
    pm, idx = pinocchio_tree(model)
    worst = _worst_errors(model, pm, np.argsort(idx), n=10, seed=1)
    # measured 1.6e-16 (M), 9.6e-13 (forward, ABA), 1.1e-15 (cartesian)
    assert max(worst.values()) <= 1e-10, worst
    with pytest.raises(ad.ModelError, match=r"joint 'spin' carries no inertia.*body 'bead'"):
        _bead_on_arm(1e-6)


def test_icub_neck_singular_at_the_assembly_only_loads_with_a_warning():
    # icub.urdf's neck_2 and head are point masses (tensors of 1e-35) on nearly one axis at
    # q = 0: there the neck's motion carries 1.7e-16 of the largest inertia (Pinocchio's crba:
    # smallest eigenvalue 3.9e-18 kg m^2), elsewhere 1e-7 of it. Singular at one configuration
    # (not everywhere, as a massless leaf): loaded, with a warning naming the joints
    path = _erd("icub_description/robots/icub.urdf")
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        model, pm, perm = _pair(path, physical_inertia=False)
    notes = [str(w.message) for w in rec if "assembled configuration only" in str(w.message)]
    assert len(notes) == 1 and re.search(r"'neck_yaw', 'neck_roll'.*'neck_2'.*'head'", notes[0])
    worst = _worst_errors(model, pm, perm, n=3, seed=5)
    assert max(worst.values()) <= 1e-10, worst


def test_massless_link_between_aligned_axes_is_refused_naming_both_joints():
    # the massless link can spin between two coaxial joints with nothing moving
    b = ad.ModelBuilder()
    b.add_body("virtual", 0.0, np.zeros((3, 3)))
    b.add_revolute("j1", "ground", "virtual", (0, 0, 0), (0, 0, 1))
    b.add_body("arm", 1.0, np.diag([0.01, 0.01, 0.01]), position=(0.5, 0, 0))
    b.add_revolute("j2", "virtual", "arm", (0, 0, 0), (0, 0, 1))
    with pytest.raises(
        ad.ModelError, match=r"joints 'j1', 'j2' carries no inertia.*body 'virtual'"
    ):
        b.finalize()


def test_massless_coupler_on_ball_joints_is_refused():
    # a massless coupler with spherical ends spins freely about its own line (Cartesian check)
    b = ad.ModelBuilder()
    b.add_body("crank", 1.0, np.diag([0.02, 0.02, 0.001]), position=(0.15, 0, 0.2))
    b.add_body("rocker", 1.5, np.diag([0.05, 0.05, 0.002]), position=(1.05, 0, 0.35))
    b.add_revolute("A", "ground", "crank", (0, 0, 0), (0, 1, 0))
    b.add_revolute("D", "ground", "rocker", (1, 0, 0), (0, 1, 0))
    b.add_body("coupler", 0.0, np.zeros((3, 3)), position=(0.7, 0, 0.55))
    b.add_spherical("B", "crank", "coupler", (0.3, 0, 0.4))
    b.add_spherical("C", "coupler", "rocker", (1.1, 0, 0.7))
    with pytest.raises(ad.ModelError, match=r"joints 'B', 'C'.*no inertia.*'coupler'"):
        b.finalize()


def test_massless_leaf_urdf_is_refused_at_finalize():
    with pytest.raises(ad.ModelError, match=r"'wrist'.*'hand'"):
        ad.load_urdf(DATA / "bad_massless_moving.urdf")
    # the refusal comes from finalize: the builder itself holds the massless body
    builder = ad.urdf_builder(str(DATA / "bad_massless_moving.urdf"))
    assert "hand" in builder.body_names


def test_an_inertial_urdfdom_resets_is_not_taken_for_a_massless_link():
    # urdfdom resets an <inertial> whose origin holds a NaN to mass 0 and zero inertia: the
    # loader's number check refuses it before urdfdom reads it (and a reset that got through
    # would be compared with the file's declaration), never a massless carriage
    text = (DATA / "slider.urdf").read_text()
    bad = text.replace('<origin xyz="0.01 0 -0.005"', '<origin xyz="nan 0 -0.005"')
    assert bad != text
    with pytest.raises(ad.UrdfError, match=r"'carriage'.*<origin> attribute 'xyz'.*not finite"):
        ad.load_urdf(bad)


def test_massless_floating_root_is_refused_naming_its_free_joint():
    # slider.urdf's root link has no mass: fixed to ground it is no body; floating, the root can
    # slide along the rail with the carriage at rest, a motion that carries no inertia
    assert ad.load_urdf(DATA / "slider.urdf").n_coords == 2
    with pytest.raises(ad.ModelError, match=r"'root_free', 'rail' carries no inertia.*'base'"):
        ad.load_urdf(DATA / "slider.urdf", fixed_base=False)


def test_a_model_with_no_mass_at_all_is_refused():
    b = ad.ModelBuilder()
    b.add_body("ghost", 0.0, np.zeros((3, 3)), position=(0.0, 0.0, -1.0))
    b.add_revolute("hinge", "ground", "ghost", (0, 0, 0), (0, 1, 0))
    with pytest.raises(ad.ModelError, match=r"'hinge'.*'ghost'"):
        b.finalize()


def test_negative_mass_is_still_refused():
    with pytest.raises(ad.ModelError, match=r"heavy.*negative"):
        ad.ModelBuilder().add_body("heavy", -1e-9, np.zeros((3, 3)))


# ------------------------------------------------------------------- physical_inertia


def test_builder_option_accepts_a_triangle_violation():
    bad = np.diag([0.1, 0.1, 0.3])
    b = ad.ModelBuilder()
    assert b.physical_inertia is True
    with pytest.raises(ad.ModelError, match=r"weird.*triangle.*physical_inertia=False"):
        b.add_body("weird", 1.0, bad)
    b = ad.ModelBuilder(physical_inertia=False)
    assert b.add_body("weird", 1.0, bad, position=(0, 0, -1)) == 0
    b.add_revolute("hinge", "ground", "weird", (0, 0, 0), (1, 0, 0))
    m = b.finalize()
    # about the hinge (x): J_xx + m l^2 = 0.1 + 1
    np.testing.assert_allclose(ad.mass_matrix(m, [0.2]), [[1.1]], rtol=1e-14)
    # the attribute switches it for the bodies added afterwards
    b = ad.ModelBuilder(physical_inertia=False)
    b.physical_inertia = True
    with pytest.raises(ad.ModelError, match="weird"):
        b.add_body("weird", 1.0, bad)


@pytest.mark.parametrize("physical", [True, False])
def test_negative_moments_beyond_round_off_are_refused_in_both_modes(physical):
    b = ad.ModelBuilder(physical_inertia=physical)
    with pytest.raises(ad.ModelError, match=r"flat.*not positive semidefinite"):
        b.add_body("flat", 1.0, np.diag([0.1, 0.1, -1e-9]))
    assert b.body_names == []


def test_round_off_negative_moment_is_clamped_with_a_warning():
    b = ad.ModelBuilder(physical_inertia=False)
    b.add_body("rod", 1.0, np.diag([1.0, 1.0, -3e-13]), position=(0, 0, -1))
    b.add_revolute("hinge", "ground", "rod", (0, 0, 0), (0, 1, 0))
    with pytest.warns(UserWarning, match=r"body 'rod'.*clamped to zero") as rec:
        m = b.finalize()
    assert _clamped_moment(rec) == pytest.approx(-3e-13, rel=1e-12)
    np.testing.assert_array_equal(np.asarray(m.inertias)[0], np.diag([1.0, 1.0, 0.0]))
    # pure rotation round-off (below 64 eps of the largest moment) is clamped silently
    r = _rz(0.3) @ _rx(0.7)
    b = ad.ModelBuilder(physical_inertia=False)
    b.add_body("rod", 1.0, r @ np.diag([1.0, 1.0, 0.0]) @ r.T, position=(0, 0, -1))
    b.add_revolute("hinge", "ground", "rod", (0, 0, 0), (0, 1, 0))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        b.finalize()


def _clamped_moment(record):
    """The negative principal moment a clamping warning reports."""
    (text,) = [str(w.message) for w in record if "clamped" in str(w.message)]
    return float(re.search(r"negative principal moment (\S+) kg m\^2", text).group(1))


def test_puma560_published_inertias_are_refused_listing_every_link():
    with pytest.raises(ad.UrdfError) as err:
        ad.load_urdf(PUMA)
    text = str(err.value)
    # both offenders, each with its principal moments, and the option
    assert "2 links" in text
    assert "'link1' (principal moments 0, 0, 0.34999999999999998 kg m^2" in text
    assert "'link3' (principal moments 0.012499999999999999, 0.066000000000000003, " in text
    assert text.count("triangle inequality") == 2
    assert "physical_inertia=False" in text
    assert "'link2'" not in text


def test_puma560_published_inertias_load_with_the_option_and_equal_pinocchio():
    model, pm, perm = _pair(PUMA, physical_inertia=False)
    assert list(model.masses) == [0.0, 17.4, 4.8]
    worst = _worst_errors(model, pm, perm, n=30, seed=560)
    # measured: 2.3e-15 (M), 2.9e-15 (forward, every method), 3.7e-15 (inverse)
    assert max(worst.values()) <= 1e-10, worst
    # link1: mass 0, 0.35 kg m^2 about the joint-1 axis (its y axis turned onto z)
    assert np.isclose(np.asarray(model.inertias)[0][2, 2], 0.35, rtol=1e-15, atol=0)


def test_urdf_option_clamps_round_off_with_a_warning_naming_the_link(tmp_path):
    text = PUMA.read_text().replace(
        'ixx="0.066" ixy="0" ixz="0" iyy="0.086" iyz="0" izz="0.0125"',
        'ixx="0.066" ixy="0" ixz="0" iyy="0.086" iyz="0" izz="-2e-14"',
    )
    path = tmp_path / "puma_round_off.urdf"
    path.write_text(text)
    with pytest.warns(UserWarning, match=r"URDF link 'link3'.*clamped to zero") as rec:
        model = ad.load_urdf(path, physical_inertia=False)
    assert _clamped_moment(rec) == pytest.approx(-2e-14, rel=1e-12)
    assert np.linalg.eigvalsh(np.asarray(model.inertias)[2]).min() >= 0.0
    # beyond round-off it is refused even with the option, naming the link
    path.write_text(text.replace('izz="-2e-14"', 'izz="-1e-6"'))
    with pytest.raises(ad.UrdfError, match=r"'link3'.*not positive semidefinite"):
        ad.load_urdf(path, physical_inertia=False)


def _link(name, mass, diag, xyz="0 0 0"):
    ixx, iyy, izz = diag
    return (
        f'<link name="{name}"><inertial><origin xyz="{xyz}"/><mass value="{mass}"/>'
        f'<inertia ixx="{ixx}" ixy="0" ixz="0" iyy="{iyy}" iyz="0" izz="{izz}"/></inertial></link>'
    )


def _two_link_urdf(sensor_mass, sensor_diag):
    """An arm on a hinge with a sensor link fixed to it (merged into the arm's body)."""
    return (
        '<robot name="r"><link name="base"/>'
        + _link("arm", 2.0, (0.01, 0.02, 0.02), "0.2 0 0")
        + _link("sensor", sensor_mass, sensor_diag)
        + '<joint name="hinge" type="continuous"><parent link="base"/><child link="arm"/>'
        '<axis xyz="0 0 1"/></joint>'
        '<joint name="mount" type="fixed"><parent link="arm"/><child link="sensor"/>'
        '<origin xyz="0.4 0 0"/></joint></robot>'
    )


def test_merged_links_are_judged_by_their_body_as_before():
    # a sensor link whose own tensor violates the triangle inequality (pr2's sensor_mount_link:
    # 0.001, 0.001, 0.01) merged into a physical body loads by default, as it always did
    model = ad.load_urdf(_two_link_urdf(0.05, (0.001, 0.001, 0.01)))
    assert model.body_names == ["arm"]
    # alone on its body (the arm massless), the violation is the body's: refused, naming it
    text = _two_link_urdf(0.05, (0.001, 0.001, 0.01)).replace('"2.0"', '"0"')
    text = text.replace(
        'ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"',
        'ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"',
    )
    with pytest.raises(ad.UrdfError, match=r"'arm' \(merged with 'sensor'\).*triangle"):
        ad.load_urdf(text)
    assert ad.load_urdf(text, physical_inertia=False).masses[0] == pytest.approx(0.05, rel=1e-15)


def test_urdf_builder_keeps_the_option():
    builder = ad.urdf_builder(str(PUMA), physical_inertia=False)
    assert builder.physical_inertia is False
    builder.add_body("tool", 0.5, np.diag([0.1, 0.1, 0.3]), position=(0.5, 0.0, 0.6604))
    builder.add_revolute("tool_joint", "link3", "tool", (0.5, 0.0, 0.6604), (1, 0, 0))
    assert builder.finalize().n_coords == 4


def test_cad_point_mass_noise_is_clamped_against_the_robot_scale(tmp_path):
    # CAD exports write point masses as tensors of 1e-20 with either sign (icub): round-off
    # against the robot's largest link moment (0.539 kg m^2 here), though not against the
    # tensor's own (0)
    text = PUMA.read_text().replace(
        'ixx="0.066" ixy="0" ixz="0" iyy="0.086" iyz="0" izz="0.0125"',
        'ixx="-5.42101e-20" ixy="0" ixz="0" iyy="-5.42101e-20" iyz="0" izz="0"',
    )
    path = tmp_path / "puma_cad_point_mass.urdf"
    path.write_text(text)
    with pytest.raises(
        ad.UrdfError, match=r"'link3' \(principal moments -5.42100999.*not positive semidefinite"
    ):
        ad.load_urdf(path)
    with pytest.warns(UserWarning, match=r"URDF link 'link3'.*clamped to zero") as rec:
        model = ad.load_urdf(path, physical_inertia=False)
    assert _clamped_moment(rec) == pytest.approx(-5.42101e-20, rel=1e-12)
    # a point mass: no negative moment left, the others zero to the eigensolver's round-off
    # (measured 1.5e-32)
    inertia = np.asarray(model.inertias)[2]
    assert np.linalg.eigvalsh(inertia).min() >= 0.0 and np.abs(inertia).max() <= 1e-30
    # a point mass off its joint axis: the model is well posed and equals Pinocchio
    pm = pin.buildModelFromUrdf(str(path))
    worst = _worst_errors(model, pm, np.arange(3), n=10, seed=3)
    assert max(worst.values()) <= 1e-10, worst


def test_icub_reduced_loads_with_the_option_and_equals_pinocchio():
    # six links of icub_reduced.urdf hold point masses written as tensors of +-1e-20: refused by
    # default (listing them), loaded with physical_inertia=False (clamped, with warnings)
    path = _erd("icub_description/robots/icub_reduced.urdf")
    with pytest.raises(ad.UrdfError, match=r"'r_hip_2'.*physical_inertia=False"):
        ad.load_urdf(path)
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        model, pm, perm = _pair(path, physical_inertia=False)
    clamped = sorted(re.search(r"URDF link '(\w+)'", str(w.message)).group(1) for w in rec)
    # a lone link's tensor is its body's; a merged group's body is judged by its links' sum:
    # head + imu_frame and the ankles + feet sum to positive semidefinite tensors, r_hip_2 +
    # r_hip_3 to one with a round-off negative moment
    assert clamped == sorted(["r_hip_2", "r_upper_leg", "r_lower_leg"])
    worst = _worst_errors(model, pm, perm, n=5, seed=29)
    # measured 2.5e-14
    assert max(worst.values()) <= 1e-10, worst
