"""The joint-level functions of fixed-base trees with ideal gears, in independent coordinates.

A pinion (joint ``ja``) turns a wheel (``jb``) carrying an offset load through an ideal gear of
pitch radii RA, RB: q_b = -r q_a with r = RA / RB. The reduced equation of the pinion's angle is
closed form: M = I_A + r^2 (I_B + I_L + m_L L^2) and tau = M qdd - r m_L g L cos(q_b) (gravity
-z, the load at distance L from the wheel's axis). The 44-body geared arm is checked against its
joint-space simulation (TreeDynamics: CRBA on all coordinates, the gear rows eliminated by their
null space), a second formulation."""

import armdyn as ad
import numpy as np
import pytest

RA, RB, L, G = 0.02, 0.05, 0.1, 9.81
R = RA / RB
MA, MB, ML = 0.2, 1.0, 0.5
IA, IB, IL = 2e-4, 2e-3, 1e-4  # about the gears' axis (x)


def rel_err(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300)


def pinion_wheel(independent=None, drive=None, floating=False):
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -G))
    base = "ground"
    if floating:
        b.add_body("base", 3.0, [0.1, 0.1, 0.1], position=(0, 0, -0.2))
        b.add_free("float", "base")
        base = "base"
    b.add_body("pinion", MA, [IA, 1e-4, 1e-4], position=(0, 0, 0))
    b.add_body("wheel", MB, [IB, 1e-3, 1e-3], position=(0, RA + RB, 0))
    b.add_body("load", ML, [IL, 2e-4, 3e-4], position=(0, RA + RB + L, 0))
    b.add_revolute("ja", base, "pinion", point=(0, 0, 0), axis=(1, 0, 0))
    b.add_revolute("jb", base, "wheel", point=(0, RA + RB, 0), axis=(1, 0, 0))
    b.add_fixed("arm", "wheel", "load", point=(0, RA + RB + L, 0))
    b.add_frame("tool", "load", position=(0.03, RA + RB + L + 0.05, 0.02))
    b.add_gear("mesh", "ja", "jb", RA, RB)
    if independent is not None:
        b.set_independent_coordinates(independent)
    if drive is not None:
        b.add_drive("ja", drive)
    return b.finalize()


M_RED = IA + R**2 * (IB + IL + ML * L**2)


def tau_closed_form(qa, qdd):
    return M_RED * qdd - R * ML * G * L * np.cos(-R * qa)


def test_geared_tree_reports_its_independent_coordinate():
    m = pinion_wheel()
    assert list(m.coord_names) == ["ja"] and m.n_coords == 1 and m.mobility == 1
    assert list(m.joint_coord_names) == ["ja", "jb"]
    assert list(m.independent_coords) == [0]
    # simulate still runs the joint space on every coordinate
    assert m.joint_path_reason == ""


def test_mass_matrix_and_dynamics_equal_the_reduced_closed_form():
    m = pinion_wheel()
    for qa, qd, qdd in ((0.0, 0.0, 1.0), (0.7, 3.0, -2.0), (-2.5, -1.0, 4.0)):
        assert rel_err(ad.mass_matrix(m, [qa]), [[M_RED]]) < 1e-12
        tau = ad.inverse_dynamics(m, [qa], [qd], [qdd])
        assert rel_err(tau, [tau_closed_form(qa, qdd)]) < 1e-11
        assert rel_err(ad.forward_dynamics(m, [qa], [qd], tau), [qdd]) < 1e-10
    # method: the Cartesian formulation only
    with pytest.raises(ad.ModelError, match="method must be 'auto' or 'cartesian'"):
        ad.forward_dynamics(m, [0.0], [0.0], [0.0], method="joint")


def test_many_turns_keep_the_gear_ratio():
    """A pinion 10 turns (and 10.5, -7.3) from its start in one call: the wheel turns r times
    that, which is not a whole number of turns (a wrapped pinion angle would put the load
    elsewhere). Jumps on one Data and a fresh Data agree."""
    m = pinion_wheel()
    d = ad.Data(m)
    for qa in (20 * np.pi + 0.3, 21 * np.pi, -14.6, 0.3):
        tau = ad.inverse_dynamics(m, [qa], [0.0], [1.0], data=d)
        assert rel_err(tau, [tau_closed_form(qa, 1.0)]) < 1e-10
        fresh = ad.inverse_dynamics(m, [qa], [0.0], [1.0], data=ad.Data(m))
        assert rel_err(fresh, tau) < 1e-12
        # held at rest: the gravity torque alone
        hold = ad.inverse_dynamics(m, [qa], [0.0], [0.0], data=d)
        assert rel_err(hold, [tau_closed_form(qa, 0.0)]) < 1e-10
        # the load's centre of mass: the wheel's axis plus L turned by q_b = -r q_a
        u, _ = ad.state_from_joints(m, [qa], data=ad.Data(m))
        qb = -R * qa
        assert np.allclose(u[14:17], [0, RA + RB + L * np.cos(qb), L * np.sin(qb)], atol=1e-12)
    # rows over 10 turns
    qs = np.linspace(0.0, 20 * np.pi, 41)[:, None]
    tau = ad.inverse_dynamics(m, qs, np.zeros_like(qs), np.ones_like(qs))
    assert rel_err(tau[:, 0], tau_closed_form(qs[:, 0], 1.0)) < 1e-10


def test_frame_jacobian_equals_finite_differences():
    m = pinion_wheel()
    h = 1e-6
    for qa in (0.4, 31.0):
        J = ad.frame_jacobian(m, [qa], "tool")
        assert J.shape == (6, 1)
        Tp, Tm = (ad.frame_pose(m, [qa + s], "tool") for s in (h, -h))
        lin = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
        dR = (Tp[:3, :3] - Tm[:3, :3]) / (2 * h) @ ad.frame_pose(m, [qa], "tool")[:3, :3].T
        ang = np.array([dR[2, 1], dR[0, 2], dR[1, 0]])
        assert rel_err(J[:, 0], np.r_[lin, ang]) < 1e-8
        # closed form: the tool turns with the wheel about x at rate -r
        assert np.allclose(J[3:, 0], [-R, 0, 0], atol=1e-12)


def test_user_chosen_independent_coordinate():
    """The wheel's angle as the independent coordinate: M_b = M_a / r^2, tau_b = -tau_a / r."""
    m = pinion_wheel(independent=["jb"])
    assert list(m.coord_names) == ["jb"]
    for qb in (0.2, -3.0):
        assert rel_err(ad.mass_matrix(m, [qb]), [[M_RED / R**2]]) < 1e-12
        tau_b = ad.inverse_dynamics(m, [qb], [0.5], [2.0])
        qa, qdd_a = -qb / R, -2.0 / R
        assert rel_err(tau_b, [-tau_closed_form(qa, qdd_a) / R]) < 1e-10
    with pytest.raises(ad.ModelError, match=r"2 coordinate\(s\) given, the model's mobility is 1"):
        pinion_wheel(independent=["ja", "jb"])
    with pytest.raises(ad.ModelError, match="has a floating base"):
        pinion_wheel(independent=["ja"], floating=True)
    floating = pinion_wheel(floating=True)
    with pytest.raises(ad.ModelError, match="ideal gears on fixed-base trees only"):
        ad.mass_matrix(floating, np.r_[0, 0, -0.2, 1, 0, 0, 0, 0, 0])


def test_joint_reactions_and_trajectory_run_equal_driven_inverse_dynamics():
    """A planned pinion motion over several turns: trajectory_run's torques and reactions are
    driven_inverse_dynamics' with the pinion driven (the Cartesian path of a driven model)."""
    spline = ad.profiles.spline([0.0, 1.0, 2.0], [0.0, 25.0, 8.0])
    driven = pinion_wheel(drive=spline)
    ts = np.linspace(0.05, 1.95, 39)
    res = ad.driven_inverse_dynamics(driven, ts)
    ia = list(driven.joint_coord_names).index("ja")
    q, qd, qdd = (x[:, [ia]] for x in (res.q, res.qd, res.qdd))
    assert np.ptp(q) > 6 * np.pi  # several turns
    m = pinion_wheel()
    run = ad.trajectory_run(m, ts, q, qd, qdd)
    assert rel_err(run.joint_torques[:, 0], res.drive_forces[:, 0]) < 1e-10
    assert rel_err(run.joint_torques[:, 0], tau_closed_form(q[:, 0], qdd[:, 0])) < 1e-10
    assert rel_err(run.reaction_forces, res.reaction_forces) < 1e-10
    assert rel_err(run.reaction_torques, res.reaction_torques) < 1e-10
    rep = ad.sizing_report(run)
    assert list(rep.table.index) == ["ja"]


def test_geared_arm_equals_its_joint_space_simulation():
    """The 44-body geared arm (6 independent of 18 coordinates, 12 ideal gears): at the states
    of a joint-space run, forward_dynamics in the independent coordinates equals the run's qdd
    (TreeDynamics, a second formulation); inverse_dynamics and mass_matrix agree with it."""
    from armdyn.papers.geared_arm import geared_arm_6dof

    m = geared_arm_6dof(backlash=0.0, t_start=0.1, t_end=1.1)
    assert m.n_coords == 6 and m.n_joint_coords == 18
    res = ad.simulate(m, 0.8, coordinates="joint", integrator="dop853", rtol=1e-8, atol=1e-8)
    idx = list(m.independent_coords)
    assert [m.joint_coord_names[i] for i in idx] == list(m.coord_names)
    rows = np.linspace(0, len(res.t) - 1, 5).astype(int)
    q, qd, qdd, t = res.q[rows][:, idx], res.qd[rows][:, idx], res.qdd[rows][:, idx], res.t[rows]
    z = np.zeros_like(q)
    assert rel_err(ad.forward_dynamics(m, q, qd, z, t=t), qdd) < 1e-10
    e = np.array([1.0, -2.0, 0.5, 3.0, -1.0, 2.0])
    tau = ad.inverse_dynamics(m, q, qd, qdd + e, t=t)
    for k in range(len(rows)):
        assert rel_err(tau[k], ad.mass_matrix(m, q[k]) @ e) < 1e-9


def test_zero_independent_coordinates():
    """Three gears locking three wheels (mobility 0): empty results, and the reactions hold
    each wheel's weight (closed form)."""
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -G))
    for i, n in enumerate("abc"):
        b.add_body(n, 1.0, [1e-3, 1e-3, 1e-3], position=(0.3 * i, 0.1, 0))
        b.add_revolute("j" + n, "ground", n, point=(0.3 * i, 0, 0), axis=(0, 0, 1))
    b.add_gear("g1", "ja", "jb", 1.0, 1.0)
    b.add_gear("g2", "jb", "jc", 1.0, 1.0)
    b.add_gear("g3", "ja", "jc", 1.0, 2.0)
    b.add_frame("tip", "a", position=(0.1, 0.1, 0))
    m = b.finalize()
    assert m.mobility == 0 and m.n_coords == 0
    z = np.zeros(0)
    assert ad.forward_dynamics(m, z, z, z).shape == (0,)
    assert ad.inverse_dynamics(m, z, z, z).shape == (0,)
    assert ad.mass_matrix(m, z).shape == (0, 0)
    assert ad.frame_jacobian(m, z, "tip").shape == (6, 0)
    assert np.allclose(ad.frame_pose(m, z, "tip")[:3, 3], [0.1, 0.1, 0.0], atol=1e-12)
    forces, torques = ad.joint_reactions(m, z, z, z)
    assert np.allclose(forces, [[0, 0, G]] * 3, atol=1e-10)
    assert np.allclose(torques, [[0.1 * G, 0, 0]] * 3, atol=1e-10)
    res = ad.simulate(m, 0.1, q0=z)
    assert np.max(np.abs(res.q)) < 1e-12


def test_simulate_and_rollout_start_from_independent_coordinates():
    """q0 of a geared tree: its independent coordinates (turns kept); the start does not depend
    on earlier calls on this thread, and rollout's rows equal simulate's bit for bit."""
    m = pinion_wheel()
    ia, ib = (list(m.joint_coord_names).index(n) for n in ("ja", "jb"))
    q0, qd0 = [20 * np.pi + 0.3], [1.0]
    first = ad.simulate(m, 0.02, q0=q0, qd0=qd0, output_dt=0.01)
    ad.state_from_joints(m, [-5.0])  # moves this thread's Data elsewhere
    again = ad.simulate(m, 0.02, q0=q0, qd0=qd0, output_dt=0.01)
    assert np.array_equal(first.q, again.q) and np.array_equal(first.u, again.u)
    assert abs(first.q[0, ia] - q0[0]) < 1e-12
    assert abs(first.q[0, ib] + R * q0[0]) < 1e-12
    runs = ad.rollout(m, q0=[q0, [0.1]], qd0=[qd0, [0.0]], t_end=0.02, output_dt=0.01)
    assert np.array_equal(runs[0].q, first.q)


def test_singular_configuration_of_a_geared_mechanism():
    """A slider-crank whose crank a pinion turns through an ideal gear, the slider's position
    independent: the dead centre is a SolverError naming the coordinates; the Data survives."""
    crank, rod, th0 = 0.1, 0.35, 0.6
    b = ad.ModelBuilder(gravity=(0.0, -G, 0.0))
    a = crank * np.array([np.cos(th0), np.sin(th0), 0.0])
    x0 = crank * np.cos(th0) + np.sqrt(rod**2 - (crank * np.sin(th0)) ** 2)
    s = np.array([x0, 0, 0])
    b.add_body("pinion", 0.2, [1e-4, 1e-4, 1e-4], position=(0, -0.2, 0))
    b.add_body("crank", 1.0, [1e-4, 1e-3, 1e-3], position=a / 2)
    b.add_body("rod", 0.5, [1e-4, 5e-3, 5e-3], position=(a + s) / 2)
    b.add_body("slider", 2.0, [1e-3, 1e-3, 1e-3], position=s)
    b.add_revolute("P", "ground", "pinion", point=(0, -0.2, 0), axis=(0, 0, 1))
    b.add_revolute("crank_pin", "ground", "crank", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_revolute("crank_rod", "crank", "rod", point=a, axis=(0, 0, 1))
    b.add_revolute("rod_slider", "rod", "slider", point=s, axis=(0, 0, 1))
    b.add_prismatic("guide", "ground", "slider", point=s, axis=(1, 0, 0))
    b.add_gear("mesh", "P", "crank_pin", 0.05, 0.15)
    b.set_independent_coordinates(["guide"])
    m = b.finalize()
    d = ad.Data(m)
    good = ad.inverse_dynamics(m, [0.01], [0.1], [0.0], data=d)
    with pytest.raises(
        ad.SolverError,
        match=r"inverse_dynamics: no configuration at the independent coordinates \(guide = ",
    ):
        ad.inverse_dynamics(m, [crank + rod - x0], [0.0], [0.0], data=d)
    assert np.array_equal(ad.inverse_dynamics(m, [0.01], [0.1], [0.0], data=d), good)
    # rollout: the run starting past the dead centre fails alone
    runs = ad.rollout(m, q0=[[0.01], [crank + rod - x0 + 1e-3]], t_end=0.01, output_dt=0.005)
    assert runs[0].error is None and len(runs[0].t) == 3
    assert "no configuration at the independent coordinates" in runs[1].error


def test_inverse_kinematics_refuses_a_geared_tree():
    with pytest.raises(ad.ModelError, match="inverse_kinematics: the model has ideal gears"):
        ad.motion.inverse_kinematics(pinion_wheel(), "tool", np.eye(4), [0.0])


def test_forward_dynamics_equals_the_cartesian_simulation_over_turns():
    """A Cartesian run released 10 turns out, spinning: at its outputs forward_dynamics in the
    independent coordinate equals the run's qdd (the KKT system with every row), and the wheel
    keeps q_b = -r q_a over the turns."""
    m = pinion_wheel()
    ia, ib = (list(m.joint_coord_names).index(n) for n in ("ja", "jb"))
    res = ad.simulate(
        m,
        0.5,
        q0=[20 * np.pi + 0.3],
        qd0=[40.0],
        output_dt=0.05,
        rtol=1e-10,
        coordinates="cartesian",
    )
    q, qd, qdd = res.q[:, [ia]], res.qd[:, [ia]], res.qdd[:, [ia]]
    assert np.ptp(q) > 2 * np.pi
    assert np.max(np.abs(res.q[:, ib] + R * res.q[:, ia])) < 1e-10
    tau = np.zeros_like(q)
    assert rel_err(ad.forward_dynamics(m, q, qd, tau, t=res.t), qdd) < 1e-10
    # the closed form of the free pendulum-through-a-gear
    assert rel_err(qdd[:, 0], R * ML * G * L * np.cos(-R * q[:, 0]) / M_RED) < 1e-10


def gear_train(independent=None):
    """Three parallel shafts about z (no gravity torque): a pinion ``ja`` turns a wheel ``jb``
    (ideal gear, radii RA and RB), whose shaft couples a third ``jc``: q_c = 2 q_b + 0.3 (a
    coupling with an offset). q_b = -r q_a exactly, every coordinate affine in the one
    independent."""
    b = ad.ModelBuilder(gravity=(0.0, 0.0, -G))
    b.add_body("pinion", MA, [1e-4, 1e-4, IA], position=(0, 0, 0))
    b.add_body("wheel", MB, [1e-3, 1e-3, IB], position=(RA + RB, 0, 0))
    b.add_body("third", 0.3, [2e-4, 2e-4, 3e-4], position=(0.3, 0, 0))
    b.add_revolute("ja", "ground", "pinion", point=(0, 0, 0), axis=(0, 0, 1))
    b.add_revolute("jb", "ground", "wheel", point=(RA + RB, 0, 0), axis=(0, 0, 1))
    b.add_revolute("jc", "ground", "third", point=(0.3, 0, 0), axis=(0, 0, 1))
    b.add_frame("mark", "third", position=(0.35, 0, 0))
    b.add_gear("mesh", "ja", "jb", RA, RB)
    b.add_coupling("belt", "jc", "jb", 2.0, 0.3)
    if independent is not None:
        b.set_independent_coordinates(independent)
    return b.finalize()


@pytest.mark.parametrize("independent", [None, ["jb"], ["jc"]])
def test_a_gear_and_coupling_train_in_closed_form_over_many_turns(independent):
    """The rows place every shaft exactly from the independent coordinate (whichever it is):
    M = sum I_i s_i^2 with s_i each shaft's rate per unit of the independent one, tau = M qdd
    (fixed parallel axes: no velocity terms), and the third shaft's mark at its angle
    2 q_b + 0.3 however many turns the pinion made."""
    m = gear_train(independent)
    name = "ja" if independent is None else independent[0]
    assert list(m.coord_names) == [name]
    # each shaft's angle as q_i = s_i x + c_i of the independent x
    s_a, c_a = {"ja": (1.0, 0.0), "jb": (-1.0 / R, 0.0), "jc": (-0.5 / R, 0.15 / R)}[name]
    s = np.array([s_a, -R * s_a, -2 * R * s_a])
    c = np.array([c_a, -R * c_a, -2 * R * c_a + 0.3])
    inertia = np.array([IA, IB, 3e-4])
    m_red = float(np.sum(inertia * s**2))
    for qa in (0.0, 20 * np.pi + 0.3, -33.1):
        x = (qa - c_a) / s_a  # the independent coordinate at which the pinion is at qa
        assert rel_err(ad.mass_matrix(m, [x]), [[m_red]]) < 1e-12
        assert rel_err(ad.inverse_dynamics(m, [x], [1.7], [2.5]), [m_red * 2.5]) < 1e-12
        assert rel_err(ad.forward_dynamics(m, [x], [1.7], [m_red * 2.5]), [2.5]) < 1e-11
        pose = ad.frame_pose(m, [x], "mark")
        qc = s[2] * x + c[2]
        np.testing.assert_allclose(pose[:3, 3], [0.3 + 0.05 * np.cos(qc), 0.05 * np.sin(qc), 0])
        np.testing.assert_allclose(pose[:2, 0], [np.cos(qc), np.sin(qc)], atol=1e-12)
        # each shaft's joint carries its weight, and no torque off its axis (the torques about
        # the axes pass through the gear and coupling rows)
        f, t = ad.joint_reactions(m, [x], [1.7], [2.5])
        np.testing.assert_allclose(f, [[0, 0, MA * G], [0, 0, MB * G], [0, 0, 0.3 * G]], atol=1e-12)
        np.testing.assert_allclose(t, 0.0, atol=1e-12)


def test_a_ratio_that_overflows_a_finite_input_is_an_error_naming_the_coordinate():
    """The wheel independent: the pinion turns 2.5 times as far, so q = 1e308 (finite) has no
    finite pinion angle. Every joint-level function says so, naming the pinion, and the Data
    stays usable."""
    m = gear_train(["jb"])
    d = ad.Data(m)
    calls = {
        "forward_dynamics": lambda q, qd: ad.forward_dynamics(m, q, qd, [0.0], data=d),
        "inverse_dynamics": lambda q, qd: ad.inverse_dynamics(m, q, qd, [0.0], data=d),
        "joint_reactions": lambda q, qd: ad.joint_reactions(m, q, qd, [0.0], data=d),
        "state_from_joints": lambda q, qd: ad.state_from_joints(m, q, qd, data=d),
        "mass_matrix": lambda q, qd: ad.mass_matrix(m, q, data=d),
        "frame_pose": lambda q, qd: ad.frame_pose(m, q, "mark", data=d),
        "frame_jacobian": lambda q, qd: ad.frame_jacobian(m, q, "mark", data=d),
    }
    for name, call in calls.items():
        for q, qd in (([1e308], [0.0]), ([-1.7e308], [0.0])):
            with pytest.raises(ad.ModelError, match=f"{name}: joint coordinate 'ja' .* overflows"):
                call(q, qd)
        if name not in ("mass_matrix", "frame_pose", "frame_jacobian"):
            with pytest.raises(ad.ModelError, match=f"{name}: joint coordinate 'ja' .* overflows"):
                call([0.1], [1e308])
    # afterwards, the closed form again on the same Data
    m_red = IA * (1 / R) ** 2 + IB + 3e-4 * 4
    assert rel_err(ad.inverse_dynamics(m, [3.0], [0.5], [2.0], data=d), [2.0 * m_red]) < 1e-12


def test_geared_arm_inverse_dynamics_by_the_recursion_equals_the_kkt_solve():
    """The geared arm's gear rows form a forest: inverse_dynamics (method "auto") takes the
    Newton-Euler recursion over all 18 coordinates reduced by the rows' map, method
    "cartesian" the KKT system with a drive row per independent coordinate (a second method):
    equal to round-off at moving states many turns out and at rest, and forward_dynamics (the
    articulated sweep) inverts them."""
    from armdyn.papers.geared_arm import geared_arm_6dof

    m = geared_arm_6dof(backlash=0.0, t_start=0.1, t_end=1.1)
    rng = np.random.default_rng(3)
    q, qd, qdd = rng.uniform(-3, 3, size=(3, 20, m.n_coords))
    q *= 5  # rotors tens of turns out
    for x, xd, xdd in ((q, qd, qdd), (q, 0 * qd, 0 * qdd)):
        rec = ad.inverse_dynamics(m, x, xd, xdd)
        kkt = ad.inverse_dynamics(m, x, xd, xdd, method="cartesian")
        assert rel_err(rec, kkt) < 1e-11  # measured 1e-13
        fd = ad.forward_dynamics(m, x, xd, rec)
        assert np.max(np.abs(fd - xdd)) < 1e-9 * max(1.0, np.max(np.abs(xdd)))
