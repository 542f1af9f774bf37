"""The joint-level functions of models with closed loops, in independent coordinates
(armdyn/algorithm/loop_coordinates.hpp): against the Cartesian path (driven_inverse_dynamics
with the independent coordinates driven, body_accelerations) and against a second method (the
spanning tree's recursive Newton-Euler and mass matrix, reduced by the loop's velocity map from
closed-form planar kinematics, or from the tree's frame_jacobian for the spatial Bricard loop)."""

from __future__ import annotations

import pickle

import armdyn as ad
import numpy as np
import pytest
from armdyn.scenes import four_bar

A, B, C, D = 0.3, 0.6, 0.5, 0.7  # crank, coupler, rocker, ground (the scene's defaults)
TH0 = np.pi / 3  # the scene's crank angle at assembly (q = 0)


def _rod(mass, length, radius=0.01):
    ia, it = 0.5 * mass * radius**2, mass * (3 * radius**2 + length**2) / 12.0
    return [ia, it, it]


def _e(t):
    return np.array([np.cos(t), np.sin(t)])


def _perp(t):
    return np.array([-np.sin(t), np.cos(t)])


def closure(theta1):
    """Closed-form position of the four-bar at absolute crank angle theta1 (the assembly's
    branch): the absolute angles of crank, coupler and rocker, and the pins A..C."""
    pa = A * _e(theta1)
    pd = np.array([D, 0.0])
    dist = np.linalg.norm(pd - pa)
    x = (B**2 - C**2 + dist**2) / (2 * dist)
    h = np.sqrt(B**2 - x**2)
    e = (pd - pa) / dist
    pb = pa + x * e + h * np.array([-e[1], e[0]])
    t2 = np.arctan2(*(pb - pa)[::-1])
    t3 = np.arctan2(*(pd - pb)[::-1])
    return np.array([theta1, t2, t3]), pa, pb


def planar_motion(qa, qda, qdda):
    """Absolute angles, rates and accelerations of the three links for the crank's motion
    (closure a e1 + b e2 + c e3 = d, differentiated twice)."""
    th, _, _ = closure(TH0 + qa)
    lengths = (A, B, C)
    jd = np.column_stack([B * _perp(th[1]), C * _perp(th[2])])
    w23 = np.linalg.solve(jd, -A * _perp(th[0]) * qda)
    w = np.r_[qda, w23]
    acc = sum(lengths[i] * _e(th[i]) * w[i] ** 2 for i in range(3)) - A * _perp(th[0]) * qdda
    a23 = np.linalg.solve(jd, acc)
    return th, w, np.r_[qdda, a23]


def four_bar_builder(close=True, frame=False):
    """The scene's four-bar (armdyn.scenes.four_bar) rebuilt, optionally without its closing
    joint D (the spanning tree) and with a frame at the coupler's centre."""
    _, pa, pb = closure(TH0)
    pa, pb, pd = np.r_[pa, 0], np.r_[pb, 0], np.array([D, 0.0, 0.0])
    bld = ad.ModelBuilder(gravity=(0.0, -9.81, 0.0))
    for name, mass, length, p in (
        ("crank", 1.0, A, pa / 2),
        ("coupler", 2.0, B, (pa + pb) / 2),
        ("rocker", 1.5, C, (pb + pd) / 2),
    ):
        # the scene's inertias: a rod's along body z (armdyn.scenes.basic._rod(..., axis=2))
        ia, it, _ = _rod(mass, length)
        bld.add_body(name, mass, [it, it, ia], position=p)
    z = (0, 0, 1)
    bld.add_revolute("A", "ground", "crank", point=(0, 0, 0), axis=z)
    bld.add_revolute("B", "crank", "coupler", point=pa, axis=z)
    bld.add_revolute("C", "coupler", "rocker", point=pb, axis=z)
    if close:
        bld.add_revolute("D", "rocker", "ground", point=pd, axis=z)
    if frame:
        bld.add_frame("mid", "coupler", position=(pa + pb) / 2)
    return bld


def tree_reduction(qa, qda, qdda):
    """The spanning tree's (q, qd, qdd) and the velocity map S = d(tree qd)/d(crank rate)."""
    th, w, al = planar_motion(qa, qda, qdda)
    th0, _, _ = closure(TH0)
    rel = lambda x: np.r_[x[0], x[1] - x[0], x[2] - x[1]]  # noqa: E731
    _, s, _ = planar_motion(qa, 1.0, 0.0)
    return rel(th - th0), rel(w), rel(al), rel(s)


def rel_err(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300)


@pytest.fixture(scope="module")
def crank_motion():
    t = np.linspace(0.0, 2.0, 41)
    prof = ad.profiles.spline(t, 1.1 * np.sin(2.0 * t) + 0.4 * t)
    model = four_bar(crank_drive=prof)
    ts = np.linspace(0.05, 1.9, 25)
    res = ad.driven_inverse_dynamics(model, ts)
    ia = list(model.joint_coord_names).index("A")
    return model, ts, res, res.q[:, [ia]], res.qd[:, [ia]], res.qdd[:, [ia]]


def test_four_bar_reports_its_independent_coordinate():
    m = four_bar()
    assert m.mobility == 1
    assert list(m.coord_names) == ["A"] and list(m.dof_names) == ["A"]
    assert m.n_coords == 1 and m.n_dofs == 1
    assert list(m.independent_coords) == [0]
    assert list(m.joint_coord_names) == ["A", "B", "C", "D"]


def test_four_bar_equals_the_cartesian_path(crank_motion):
    """inverse_dynamics = driven_inverse_dynamics' drive force, joint_reactions its reactions,
    forward_dynamics inverts inverse_dynamics, all to 1e-10 (rows and one state at a time)."""
    model, ts, res, q, qd, qdd = crank_motion
    tau = ad.inverse_dynamics(model, q, qd, qdd, t=ts)
    assert rel_err(tau[:, 0], res.drive_forces[:, 0]) < 1e-10
    f, tq = ad.joint_reactions(model, q, qd, qdd, t=ts)
    assert rel_err(f, res.reaction_forces) < 1e-10
    assert rel_err(tq, res.reaction_torques) < 1e-10
    qdd_back = ad.forward_dynamics(model, q, qd, tau, t=ts)
    assert rel_err(qdd_back, qdd) < 1e-10
    for k in (0, 7, 19):  # one state at a time, a fresh Data each
        d = ad.Data(model)
        tk = ad.inverse_dynamics(model, q[k], qd[k], qdd[k], t=ts[k], data=d)
        assert rel_err(tk, res.drive_forces[k]) < 1e-10
    # u, v: the driven solution's Cartesian state
    u, v = ad.state_from_joints(model, q[7], qd[7])
    assert np.max(np.abs(u - res.u[7])) < 1e-10 and rel_err(v, res.v[7]) < 1e-10
    qq, qqd = ad.joint_coordinates(model, u, v)
    assert abs(qq[0] - q[7, 0]) < 1e-12 and abs(qqd[0] - qd[7, 0]) < 1e-12


def test_four_bar_forward_dynamics_equals_body_accelerations():
    """Without torques: the crank's acceleration = body_accelerations' at the same state."""
    m = four_bar()
    for qa, qda in ((0.3, 1.2), (-1.0, -0.4), (2.5, 3.0)):
        u, v = ad.state_from_joints(m, [qa], [qda])
        vd, _ = ad.body_accelerations(m, u, v)
        qdd = ad.forward_dynamics(m, [qa], [qda], [0.0])
        # the crank turns about world z on ground: its angular acceleration (body 0, z)
        assert rel_err(qdd, [vd[5]]) < 1e-10


def test_four_bar_equals_the_spanning_tree():
    """Second method: the spanning tree (joint D removed) by recursive Newton-Euler and CRBA,
    reduced by the loop's velocity map from the closed-form planar kinematics:
    M = S^T M_tree S, tau = S^T tau_tree(q, qd, qdd)."""
    loop, tree = four_bar(), four_bar_builder(close=False).finalize()
    assert list(tree.coord_names) == ["A", "B", "C"]
    rng = np.random.default_rng(3)
    for _ in range(6):
        qa, qda, qdda = rng.uniform(-np.pi, np.pi), rng.uniform(-3, 3), rng.uniform(-5, 5)
        qt, qdt, qddt, s = tree_reduction(qa, qda, qdda)
        m_ref = s @ ad.mass_matrix(tree, qt) @ s
        tau_ref = s @ ad.inverse_dynamics(tree, qt, qdt, qddt)
        assert rel_err(ad.mass_matrix(loop, [qa])[0, 0], m_ref) < 1e-10
        assert rel_err(ad.inverse_dynamics(loop, [qa], [qda], [qdda])[0], tau_ref) < 1e-10
        qdd = ad.forward_dynamics(loop, [qa], [qda], [tau_ref])
        assert abs(qdd[0] - qdda) < 1e-10 * max(1.0, abs(qdda))


def test_rebuilt_four_bar_is_the_scene():
    """The test's builder reproduces the scene (so the tree above is the scene's tree)."""
    a, b = four_bar(), four_bar_builder().finalize()
    for q in ([0.4], [-2.0]):
        assert rel_err(ad.mass_matrix(b, q), ad.mass_matrix(a, q)) < 1e-12
        assert (
            rel_err(
                ad.inverse_dynamics(b, q, [1.0], [0.5]), ad.inverse_dynamics(a, q, [1.0], [0.5])
            )
            < 1e-12
        )


def test_frame_pose_and_jacobian_of_a_loop_model():
    """The coupler's centre: pose and Jacobian (columns: the crank) in closed form."""
    m = four_bar_builder(frame=True).finalize()
    for qa in (0.0, 0.7, -2.2):
        th, w, _ = planar_motion(qa, 1.0, 0.0)
        pa = A * _e(th[0])
        p = pa + 0.5 * B * _e(th[1])
        T = ad.frame_pose(m, [qa], "mid")
        assert np.allclose(T[:2, 3], p, rtol=0, atol=1e-12) and abs(T[2, 3]) < 1e-12
        # the frame's axes turn with the coupler from its build pose
        dt = th[1] - closure(TH0)[0][1]
        assert np.allclose(
            T[:2, :2], [[np.cos(dt), -np.sin(dt)], [np.sin(dt), np.cos(dt)]], atol=1e-12
        )
        J = ad.frame_jacobian(m, [qa], "mid")
        v = A * _perp(th[0]) * w[0] + 0.5 * B * _perp(th[1]) * w[1]
        ref = np.r_[v, 0.0, 0.0, 0.0, w[1]]
        assert J.shape == (6, 1)
        assert rel_err(J[:, 0], ref) < 1e-10


def test_branch_continuity_over_a_turn():
    """Rows over a full crank turn stay on the assembly's branch (the closed-form one); so do
    successive one-state calls on one Data, and a jump back to an earlier angle."""
    m = four_bar()
    qs = np.linspace(0.0, 2 * np.pi, 73)[:, None]
    tau = ad.inverse_dynamics(m, qs, np.zeros_like(qs), np.zeros_like(qs))
    d = ad.Data(m)
    for k in (0, 10, 40, 72, 5):
        _, pa, pb = closure(TH0 + qs[k, 0])
        u, _ = ad.state_from_joints(m, qs[k], [0.0])
        # the coupler's centre of mass (body 1) from the closed form
        assert np.allclose(u[7:9], (pa + pb) / 2, atol=1e-10)
        tk = ad.inverse_dynamics(m, qs[k], [0.0], [0.0], data=d)
        assert rel_err(tk, tau[k]) < 1e-10
    # the static torque balances gravity: the tree's (second method)
    tree = four_bar_builder(close=False).finalize()
    for k in (3, 30, 60):
        qt, _, _, s = tree_reduction(qs[k, 0], 0.0, 0.0)
        assert (
            rel_err(tau[k], [s @ ad.inverse_dynamics(tree, qt, np.zeros(3), np.zeros(3))]) < 1e-10
        )


def test_user_chosen_independent_coordinate():
    """The rocker D as the independent coordinate: power balance with the crank's choice
    (tau_D qd_D = tau_A qd_A) and M_D = M_A (qd_A / qd_D)^2."""
    bld = four_bar_builder()
    bld.set_independent_coordinates(["D"])
    md = bld.finalize()
    ma = four_bar()
    assert list(md.coord_names) == ["D"]
    names = list(md.joint_coord_names)
    prof = ad.profiles.spline([0.0, 1.0, 2.0], [0.0, 0.8, 0.3])
    mdrv = four_bar(crank_drive=prof)
    res = ad.driven_inverse_dynamics(mdrv, [0.3, 0.9, 1.5])
    ia, idd = names.index("A"), names.index("D")
    for k in range(3):
        qa, qda, qdda = res.q[k, ia], res.qd[k, ia], res.qdd[k, ia]
        qd_, qdd_, qddd = res.q[k, idd], res.qd[k, idd], res.qdd[k, idd]
        ta = ad.inverse_dynamics(ma, [qa], [qda], [qdda])[0]
        td = ad.inverse_dynamics(md, [qd_], [qdd_], [qddd])[0]
        assert abs(td * qdd_ - ta * qda) < 1e-10 * abs(ta * qda)
        ratio = qda / qdd_
        assert rel_err(ad.mass_matrix(md, [qd_]), ad.mass_matrix(ma, [qa]) * ratio**2) < 1e-10
    # the choice survives pickling: the same model, the same numbers (fresh Data each: the
    # results near the rocker's limit carry the round-off of the state Newton started from)
    back = pickle.loads(pickle.dumps(md))
    assert list(back.coord_names) == ["D"]
    for q in ([0.02], [-0.3]):
        assert np.array_equal(
            ad.mass_matrix(back, q, data=ad.Data(back)), ad.mass_matrix(md, q, data=ad.Data(md))
        )


def test_invalid_choices_name_the_culprit():
    def fin(names):
        bld = four_bar_builder()
        bld.set_independent_coordinates(names)
        return bld.finalize()

    with pytest.raises(ad.ModelError, match=r"unknown joint coordinate 'E'.*'A', 'B', 'C', 'D'"):
        fin(["E"])
    with pytest.raises(ad.ModelError, match=r"2 coordinate\(s\) given, the model's mobility is 1"):
        fin(["A", "B"])
    assert list(fin([]).coord_names) == ["A"]  # an empty list: armdyn's default
    with pytest.raises(ad.ModelError, match="given twice"):
        fin(["A", "A"])
    with pytest.raises(ad.ModelError, match="must be a list"):
        four_bar_builder().set_independent_coordinates("A")
    with pytest.raises(ad.ModelError, match="must be a str"):
        four_bar_builder().set_independent_coordinates([1])
    # a tree has no choice to make
    tree = four_bar_builder(close=False)
    tree.set_independent_coordinates(["A"])
    with pytest.raises(ad.ModelError, match="applies to models with closed loops"):
        tree.finalize()
    # a coordinate the loop determines at the assembled state: the slider at a dead centre
    sc = _slider_crank(theta0=0.0)
    sc.set_independent_coordinates(["guide"])
    with pytest.raises(ad.ModelError, match=r"coordinate 'guide' is not independent"):
        sc.finalize()


def _slider_crank(theta0=0.6, crank=0.1, rod=0.35):
    """A slider-crank (as armdyn.scenes.slider_crank) assembled at crank angle theta0, with
    gravity along -y."""
    b = ad.ModelBuilder(gravity=(0.0, -9.81, 0.0))
    a = crank * np.array([np.cos(theta0), np.sin(theta0), 0.0])
    s = np.array([crank * np.cos(theta0) + np.sqrt(rod**2 - (crank * np.sin(theta0)) ** 2), 0, 0])
    b.add_body("crank", 1.0, [1e-4, 1e-3, 1e-3], position=a / 2)
    b.add_body("rod", 0.5, [1e-4, 5e-3, 5e-3], position=(a + s) / 2)
    b.add_body("slider", 2.0, [1e-3, 1e-3, 1e-3], position=s)
    b.add_revolute("crank_pin", "ground", "crank", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_revolute("crank_rod", "crank", "rod", point=a, axis=(0, 0, 1))
    b.add_revolute("rod_slider", "rod", "slider", point=s, axis=(0, 0, 1))
    b.add_prismatic("guide", "ground", "slider", point=s, axis=(1, 0, 0))
    return b


def test_slider_crank_against_the_cartesian_path_and_closed_form():
    crank, rod, th0 = 0.1, 0.35, 0.6
    m = _slider_crank(th0).finalize()
    assert list(m.coord_names) == ["crank_pin"]
    # closed form: slider x(theta) and its rate; kinetic energy 1/2 v^T Gamma v = 1/2 M qd^2
    gamma = ad.body_mass_matrix(m)
    for q, qd in ((0.3, 2.0), (2.0, -1.5), (-2.9, 0.7)):
        th = th0 + q
        x = crank * np.cos(th) + np.sqrt(rod**2 - (crank * np.sin(th)) ** 2)
        xd = (
            -crank * np.sin(th)
            - crank**2 * np.sin(th) * np.cos(th) / np.sqrt(rod**2 - (crank * np.sin(th)) ** 2)
        ) * qd
        u, v = ad.state_from_joints(m, [q], [qd])
        assert abs(u[14] - x) < 1e-12 and abs(v[12] - xd) < 1e-10 * abs(xd)
        assert rel_err(ad.mass_matrix(m, [q])[0, 0] * qd**2, v @ gamma @ v) < 1e-10
    # driven inverse dynamics with the crank driven
    bld = _slider_crank(th0)
    bld.add_drive("crank_pin", ad.profiles.spline([0.0, 1.0, 2.0, 3.0], [0.0, 1.5, 0.5, 4.0]))
    md = bld.finalize()
    ts = np.linspace(0.1, 2.9, 15)
    res = ad.driven_inverse_dynamics(md, ts)
    i = list(md.joint_coord_names).index("crank_pin")
    q, qd, qdd = res.q[:, [i]], res.qd[:, [i]], res.qdd[:, [i]]
    tau = ad.inverse_dynamics(md, q, qd, qdd, t=ts)
    assert rel_err(tau[:, 0], res.drive_forces[:, 0]) < 1e-10
    assert rel_err(ad.forward_dynamics(md, q, qd, tau, t=ts), qdd) < 1e-10


def test_singular_configuration_is_a_solver_error_and_the_data_survives():
    """The slider as the independent coordinate: the dead centre (x = crank + rod) and beyond
    are refused naming the rows; the Data then still serves the next state, on its branch."""
    m = _slider_crank(0.6)
    m.set_independent_coordinates(["guide"])
    m = m.finalize()
    assert list(m.coord_names) == ["guide"]
    crank, rod = 0.1, 0.35
    x0 = crank * np.cos(0.6) + np.sqrt(rod**2 - (crank * np.sin(0.6)) ** 2)
    d = ad.Data(m)
    good = ad.inverse_dynamics(m, [0.01], [0.1], [0.0], data=d)
    for s in (crank + rod - x0 + 1e-3, crank + rod - x0):
        with pytest.raises(
            ad.SolverError,
            match=r"inverse_dynamics: no configuration at the independent coordinates \(guide = ",
        ):
            ad.inverse_dynamics(m, [s], [0.0], [0.0], data=d)
    assert np.array_equal(ad.inverse_dynamics(m, [0.01], [0.1], [0.0], data=d), good)
    # rows: the failing row is named
    with pytest.raises(ad.SolverError, match=r"row 2: "):
        ad.inverse_dynamics(
            m,
            np.array([[0.0], [0.02], [crank + rod - x0 + 0.01]]),
            np.zeros((3, 1)),
            np.zeros((3, 1)),
        )


def _bricard(drive=None):
    side, mass = 0.3, 1.0
    p = np.array([(1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 1, 1), (0, 0, 1), (1, 0, 1)], float) * side
    d = [p[(i + 1) % 6] - p[i] for i in range(6)]
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    links = [f"link{i}" for i in range(5)]
    for i in range(5):
        b.add_body(links[i], mass, [2e-3, 2e-3, 1e-3], position=(p[i] + p[i + 1]) / 2)
    axes = []
    for i in range(6):
        axis = np.cross(d[i - 1], d[i])
        axes.append(axis / np.linalg.norm(axis))
        parent = "ground" if i == 0 else links[i - 1]
        child = links[i] if i < 5 else "ground"
        if i < 5 or drive != "tree":
            b.add_revolute(f"J{i}", parent, child, point=p[i], axis=axes[i])
    if drive == "tree":
        b.add_frame("J5", "link4", position=p[5])
    elif drive is not None:
        b.add_drive("J0", drive)
    return b.finalize(), axes[5]


def test_spatial_bricard_loop():
    """A spatial overconstrained loop: against the Cartesian path (J0 driven), and at rest
    against the spanning tree reduced by the null space of its closure Jacobian (frame_jacobian
    of the tree's frame at J5: the point's velocity and the angular velocity across the axis)."""
    loop = ad.scenes.bricard()
    assert loop.mobility == 1 and list(loop.coord_names) == ["J0"]
    drv, _ = _bricard(ad.profiles.spline([0.0, 1.0, 2.0], [0.0, 0.3, -0.2]))
    ts = np.linspace(0.1, 1.9, 10)
    res = ad.driven_inverse_dynamics(drv, ts)
    names = list(drv.joint_coord_names)
    q, qd, qdd = (x[:, [names.index("J0")]] for x in (res.q, res.qd, res.qdd))
    tau = ad.inverse_dynamics(loop, q, qd, qdd, t=ts)
    assert rel_err(tau[:, 0], res.drive_forces[:, 0]) < 1e-10
    assert rel_err(ad.forward_dynamics(loop, q, qd, tau, t=ts), qdd) < 1e-10
    tree, axis5 = _bricard("tree")
    basis = np.linalg.svd(np.cross(axis5, np.eye(3)))[0][:, :2]  # across the J5 axis
    for k in (0, 4, 9):
        qt = res.q[k, [names.index(f"J{i}") for i in range(5)]]
        J = ad.frame_jacobian(tree, qt, "J5")
        # J5's axis in world turns with link4: the closure rows are the point's velocity and
        # the relative angular velocity across the axis (at the assembled axis, as the loop's
        # revolute keeps it aligned)
        R = ad.frame_pose(tree, qt, "J5")[:3, :3]
        across = R @ basis
        jc = np.vstack([J[:3], across.T @ J[3:]])
        s = np.linalg.svd(jc)[2][-1]
        s = s / s[0]
        m_ref = s @ ad.mass_matrix(tree, qt) @ s
        tau_ref = s @ ad.inverse_dynamics(tree, qt, np.zeros(5), s * 0.8)
        assert rel_err(ad.mass_matrix(loop, q[k])[0, 0], m_ref) < 1e-10
        assert rel_err(ad.inverse_dynamics(loop, q[k], [0.0], [0.8])[0], tau_ref) < 1e-10


def test_hostile_inputs():
    m = four_bar()
    with pytest.raises(ad.ModelError, match=r"q contains NaN"):
        ad.inverse_dynamics(m, [np.nan], [0.0], [0.0])
    with pytest.raises(ad.ModelError, match=r"tau contains NaN"):
        ad.forward_dynamics(m, [0.0], [0.0], [np.inf])
    with pytest.raises(ad.ModelError, match=r"q: expected shape \(1,\)"):
        ad.mass_matrix(m, [0.0, 0.0])
    with pytest.raises(ad.ModelError, match=r"row 1: .*qd contains NaN"):
        ad.forward_dynamics(m, np.zeros((2, 1)), np.array([[0.0], [np.nan]]), np.zeros((2, 1)))
    with pytest.raises(ad.ModelError, match="method must be 'auto' or 'cartesian'"):
        ad.forward_dynamics(m, [0.0], [0.0], [0.0], method="aba")
    with pytest.raises(ad.ModelError, match="method must be 'auto' or 'cartesian'"):
        ad.inverse_dynamics(m, [0.0], [0.0], [0.0], method="joint")
    with pytest.raises(ad.ModelError, match=r"unknown frame 'nope'"):
        ad.frame_pose(four_bar_builder(frame=True).finalize(), [0.0], "nope")
    with pytest.raises(ad.ModelError, match="t is not finite"):
        ad.inverse_dynamics(m, [0.0], [0.0], [0.0], t=np.nan)
    # huge but finite: a clear error or finite numbers, never NaN
    try:
        out = ad.inverse_dynamics(m, [1e300], [1e150], [0.0])
        assert np.all(np.isfinite(out))
    except (ad.SolverError, ad.ModelError):
        pass


def test_trajectory_run_and_sizing_of_a_loop_mechanism(crank_motion):
    """trajectory_run on the crank's planned motion: the torque is driven_inverse_dynamics'
    with the crank driven; sizing_report takes the run."""
    model, ts, res, q, qd, qdd = crank_motion
    run = ad.trajectory_run(model, ts, q, qd, qdd)
    assert rel_err(run.joint_torques[:, 0], res.drive_forces[:, 0]) < 1e-10
    assert rel_err(run.reaction_forces, res.reaction_forces) < 1e-10
    rep = ad.sizing_report(run)
    assert list(rep.table.index) == ["A"]
    assert abs(rep.table.loc["A", "peak_torque"] - np.max(np.abs(res.drive_forces[:, 0]))) < 1e-9


def _geared_four_bar(drive=None):
    """The four-bar's crank turned by a pinion through an ideal gear (pitch radii 0.05 and
    0.15: q_A = -q_P / 3), the pinion's angle the independent coordinate."""
    bld = four_bar_builder()
    bld.add_body("pinion", 0.5, [1e-3, 1e-3, 2e-3], position=(-0.2, 0.0, 0.0))
    bld.add_revolute("P", "ground", "pinion", point=(-0.2, 0.0, 0.0), axis=(0, 0, 1))
    bld.add_gear("mesh", "P", "A", 0.05, 0.15)
    bld.set_independent_coordinates(["P"])
    if drive is not None:
        bld.add_drive("P", drive)
    return bld.finalize()


def test_geared_loop():
    """An ideal gear in a loop model: against the Cartesian path (the pinion driven) and against
    the four-bar alone by virtual work, tau_P = J_P qdd_P - tau_A / 3."""
    m, fb = _geared_four_bar(), four_bar()
    assert list(m.coord_names) == ["P"] and m.mobility == 1
    drv = _geared_four_bar(ad.profiles.spline([0.0, 1.0, 2.0], [0.0, 2.0, -1.0]))
    ts = np.linspace(0.1, 1.9, 12)
    res = ad.driven_inverse_dynamics(drv, ts)
    i = list(drv.joint_coord_names).index("P")
    q, qd, qdd = res.q[:, [i]], res.qd[:, [i]], res.qdd[:, [i]]
    tau = ad.inverse_dynamics(m, q, qd, qdd, t=ts)
    assert rel_err(tau[:, 0], res.drive_forces[:, 0]) < 1e-10
    assert rel_err(ad.forward_dynamics(m, q, qd, tau, t=ts), qdd) < 1e-10
    tau_a = ad.inverse_dynamics(fb, -q / 3, -qd / 3, -qdd / 3)
    assert rel_err(tau[:, 0], 2e-3 * qdd[:, 0] - tau_a[:, 0] / 3) < 1e-10
    for k in (0, 6):
        assert rel_err(ad.mass_matrix(m, q[k]), 2e-3 + ad.mass_matrix(fb, -q[k] / 3) / 9) < 1e-10


def test_select_drivetrain_takes_a_loop_mechanism():
    """A rest-to-rest crank motion of the four-bar through trajectory_run into
    select_drivetrain: a selection for the crank, whose cycle torque is the loop's."""
    import importlib.util
    import pathlib

    spec = importlib.util.spec_from_file_location(
        "_sel", pathlib.Path(__file__).parents[1] / "validate" / "test_select_drivetrain.py"
    )
    sel_mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(sel_mod)
    m = four_bar()
    t = np.linspace(0.0, 2.0, 81)
    q = 0.5 * (1 - np.cos(np.pi * t))[:, None]
    qd = 0.5 * np.pi * np.sin(np.pi * t)[:, None]
    qdd = 0.5 * np.pi**2 * np.cos(np.pi * t)[:, None]
    run = ad.trajectory_run(m, t, q, qd, qdd)
    sel = ad.select_drivetrain(m, run, sel_mod.catalog(), drives=False)
    assert sel.converged and list(sel.table.index) == ["A"]
    assert sel.table.loc["A", "motor"] in sel_mod.MOTORS.index


def test_simulate_from_independent_coordinates():
    """simulate(q0=, qd0=) of a loop model takes its independent coordinates (turns kept): the
    run starts at state_from_joints' state, the crank at 7 rad."""
    m = four_bar()
    res = ad.simulate(m, 0.01, q0=[7.0], qd0=[1.0], output_dt=0.005)
    u, v = ad.state_from_joints(m, [7.0], [1.0])
    ia = list(m.joint_coord_names).index("A")
    assert abs(res.q[0, ia] - 7.0) < 1e-12 and abs(res.qd[0, ia] - 1.0) < 1e-12
    assert np.max(np.abs(res.u[0] - u)) < 1e-12 and np.max(np.abs(res.v[0] - v)) < 1e-10
