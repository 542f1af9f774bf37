"""Inverse dynamics through driving constraints.

* joint-space ``inverse_dynamics(model, q, qd, qdd)`` against the independent numpy
  recursive Newton–Euler of ``tests/oracles/numpy_rne.py`` on random spatial arms (full
  inertias, random axes, prismatic joints): ≤ 1e-10 relative;
* ``driven_inverse_dynamics(model, t)`` against the drive efforts of a forward
  simulation and against the independent Lagrange validator;
* replay: the computed torques fed back as joint torque inputs to the undriven model reproduce
  the prescribed trajectory (time-domain) and the prescribed accelerations (pointwise);
* sign convention: a horizontal link held against gravity needs +m g l/2 about the axis that
  raises it;
* errors: an under-driven model names its undriven coordinates; a driven slider-crank pushed to
  its dead centre names the singular drive.
"""

import armdyn as ad
import numpy as np
import pytest
from armdyn import _core
from armdyn.papers import five_dof
from conftest import G, rel_err, spatial_arm, to_armdyn, tol


@pytest.mark.parametrize("prismatic", [False, True])
def test_joint_space_inverse_dynamics_vs_rnea(rng, prismatic):
    for _ in range(3):
        arm = spatial_arm(rng, prismatic=prismatic)
        n = arm.n
        q_ref, qd_ref, qdd_ref = rng.normal(size=(3, n))
        tau_ref = arm.chain.rnea(q_ref, qd_ref, qdd_ref)
        q, qd, qdd = (to_armdyn(arm.perm, x) for x in (q_ref, qd_ref, qdd_ref))
        tau = ad.inverse_dynamics(arm.model, q, qd, qdd)
        assert tau.shape == (n,)
        assert rel_err(tau[arm.perm], tau_ref) <= tol(1e-10)
        # batch form (rows) gives the same numbers
        rows = ad.inverse_dynamics(arm.model, np.array([q, q]), np.array([qd, qd]), [qdd, qdd])
        assert rows.shape == (2, n)
        assert np.max(np.abs(rows - tau)) <= 1e-12 * np.max(np.abs(tau))


def test_pointwise_replay_through_forward_dynamics(rng):
    arm = spatial_arm(rng, prismatic=True)
    q, qd, qdd = rng.normal(size=(3, arm.n))
    tau = ad.inverse_dynamics(arm.model, q, qd, qdd)
    assert rel_err(ad.forward_dynamics(arm.model, q, qd, tau), qdd) <= tol(1e-9)


def driven_random_arm(rng, prismatic=True):
    """A random spatial arm with every joint driven by a sine (starting at the assembly pose)."""
    arm = spatial_arm(rng, prismatic=prismatic)
    b = _core.ModelBuilder(gravity=(0.0, 0.0, -G))
    for i in range(arm.n):
        b.add_body(
            arm.body_names[i],
            float(arm.masses[i]),
            arm.inertias_body[i],
            position=arm.coms[i],
            orientation=arm.quats[i],
        )
    for i in range(arm.n):
        parent = "ground" if i == 0 else arm.body_names[i - 1]
        add = b.add_revolute if arm.types[i] == "R" else b.add_prismatic
        add(arm.joint_names[i], parent, arm.body_names[i], arm.points[i], arm.axes[i])
        amp = 0.8 if arm.types[i] == "R" else 0.05
        freq = rng.uniform(0.3, 1.0)
        b.add_drive(arm.joint_names[i], _core.profiles.sine(amp, freq, 0.0, 0.0))
    return b.finalize()


def test_driven_inverse_dynamics_matches_simulation_and_lagrange(rng):
    model = driven_random_arm(rng)
    assert model.mobility_driven == 0
    # integrated (not the kinematic path, which is inverse dynamics' own solver)
    sim = ad.simulate(model, 1.0, integrator="dopri5", rtol=1e-10, atol=1e-12, output_dt=0.02)
    assert sim.stats["steps"] > 0
    idr = ad.driven_inverse_dynamics(model, sim.t)
    scale = np.max(np.abs(sim.drive_forces))
    assert np.max(np.abs(idr.drive_forces - sim.drive_forces)) <= tol(1e-10) * scale
    assert np.max(np.abs(idr.q - sim.q)) <= tol(1e-10)
    assert np.max(idr.position_residual) <= 1e-12
    # against the complete Euler-Lagrange equations (independent derivation)
    lag = ad.LagrangeValidator(model)
    ref = lag.torques(idr.q, idr.qd, idr.qdd, idr.t)
    mb = np.empty_like(idr.drive_forces)
    mb[:, list(model.drive_coords)] = idr.drive_forces
    assert rel_err(mb, ref) <= tol(1e-10)


def test_forward_replay_tracks_the_drives():
    """Torques from inverse dynamics, applied as joint torque inputs to the undriven 3-DOF
    arm, reproduce the prescribed cubic trajectories when integrated forward."""
    driven = five_dof.three_dof_arm()
    free = five_dof.three_dof_arm(drives=False)

    def solver(q, qd, qdd, t):
        return ad.inverse_dynamics(free, q, qd, qdd, t)

    targets, T = five_dof.ARM3.targets, five_dof.ARM3.duration
    profiles = [_core.profiles.cubic(0.0, float(x), 0.0, T) for x in targets]

    def reference(t):
        vals = np.array([p.eval(t) for p in profiles])  # rows (y, yd, ydd)
        return vals[:, 0], vals[:, 1], vals[:, 2]

    b = _core.ModelBuilder(gravity=(0.0, 0.0, -G))
    # the same arm, with torque inputs computed by inverse dynamics along the reference
    x = 0.0
    for i, (length, mass) in enumerate(
        zip(five_dof.ARM3.lengths, five_dof.ARM3.masses, strict=True)
    ):
        inertia = five_dof._box(mass, length, five_dof.ARM3.thickness, five_dof.ARM3.width)
        b.add_body(f"link{i + 1}", mass, inertia, position=(x + 0.5 * length, 0, 0))
        parent = "ground" if i == 0 else f"link{i}"
        b.add_revolute(f"j{i + 1}", parent, f"link{i + 1}", point=(x, 0, 0), axis=five_dof.PITCH)
        x += length
    for i in range(3):

        def tau_i(t, i=i):
            q, qd, qdd = reference(t)
            return (float(solver(q, qd, qdd, t)[i]), 0.0, 0.0)

        b.add_joint_torque(f"j{i + 1}", tau_i)
    replay = b.finalize()
    res = ad.simulate(replay, T, rtol=1e-11, atol=1e-13, output_dt=0.05)
    q_ref = np.array([reference(t)[0] for t in res.t])
    assert np.max(np.abs(res.q - q_ref)) <= tol(1e-8)
    # and the driven model's efforts equal those inputs
    sim = ad.simulate(driven, T, rtol=1e-10, atol=1e-12, output_dt=0.05)
    inputs = np.array([solver(*reference(t), t) for t in sim.t])
    assert rel_err(sim.drive_forces, inputs) <= tol(1e-10)


def test_sign_convention_static_link():
    """A horizontal bar on a pitch joint (axis −y, positive raises it) held still needs
    τ = +m g l/2: the torque the actuator applies to the child about the joint axis."""
    m, length = 2.0, 0.5
    b = _core.ModelBuilder(gravity=(0.0, 0.0, -G))
    b.add_body("bar", m, [1e-3, m * length**2 / 12, m * length**2 / 12], (length / 2, 0, 0))
    b.add_revolute("pitch", "ground", "bar", point=(0, 0, 0), axis=(0, -1, 0))
    b.add_drive("pitch", 0.0)
    model = b.finalize()
    idr = ad.driven_inverse_dynamics(model, [0.0, 1.0])
    assert idr.drive_forces[:, 0] == pytest.approx(m * G * length / 2, rel=1e-12)
    tau = ad.inverse_dynamics(model, [0.0], [0.0], [0.0])
    assert tau[0] == pytest.approx(m * G * length / 2, rel=1e-12)
    # raised by 90 degrees the bar points up: no torque; at 180 degrees: -m g l/2
    assert ad.inverse_dynamics(model, [np.pi / 2], [0.0], [0.0])[0] == pytest.approx(0, abs=1e-12)
    assert ad.inverse_dynamics(model, [np.pi], [0.0], [0.0])[0] == pytest.approx(
        -m * G * length / 2, rel=1e-12
    )


def test_under_driven_model_names_coordinates():
    model = five_dof.five_dof_arm(drives=False)
    with pytest.raises(ad.ModelError, match=r"5 degree.*'twist'.*'extend'"):
        ad.driven_inverse_dynamics(model, [0.0, 1.0])


def test_singular_driven_slider_crank_names_the_drive():
    """A slider-crank whose slider position is driven to the dead centre (x = r + l): the
    driven constraints lose rank there; the error names the drive."""
    model = ad.scenes.slider_driven_to_dead_centre()
    assert model.mobility_driven == 0
    # away from the dead centre it is fine
    ok = ad.driven_inverse_dynamics(model, np.linspace(0.0, 0.5, 6))
    assert np.all(np.isfinite(ok.drive_forces))
    with pytest.raises(ad.SolverError, match=r"singular.*drive 'guide'"):
        ad.driven_inverse_dynamics(model, np.linspace(0.0, 1.0, 11))


def test_inverse_dynamics_bad_input():
    arm_model = five_dof.three_dof_arm()
    with pytest.raises(ad.ModelError, match="qdd"):
        ad.inverse_dynamics(arm_model, [0, 0, 0], [0, 0, 0], [0, np.nan, 0])
    with pytest.raises(ad.ModelError, match=r"q.*length|shape"):
        ad.inverse_dynamics(arm_model, [0, 0], [0, 0, 0], [0, 0, 0])
    with pytest.raises(ad.ModelError, match="increase"):
        ad.driven_inverse_dynamics(arm_model, [0.0, 0.5, 0.5])
    with pytest.raises(TypeError, match="qd"):
        ad.inverse_dynamics(arm_model, [0, 0, 0])
    loop = ad.scenes.four_bar()  # takes its independent coordinate (the crank) alone
    with pytest.raises(ad.ModelError, match=r"qdd: expected shape \(1,\)"):
        ad.inverse_dynamics(loop, [0.0] * loop.n_coords, [0.0] * loop.n_coords, [0.0] * 4)


def test_driven_loop_on_a_coarse_grid_by_continuation():
    """A driven closed loop (slider-crank, crank at 2π rad/s) solved at times far apart: the
    position problem is continued through intermediate times and gives the fine-grid answer."""
    model = ad.scenes.slider_crank()
    fine = ad.driven_inverse_dynamics(model, np.linspace(0.0, 0.37, 75))
    coarse = ad.driven_inverse_dynamics(model, [0.0, 0.37])
    assert np.max(np.abs(coarse.q[-1] - fine.q[-1])) <= 1e-11  # (quaternions may differ in sign)
    assert np.max(np.abs(coarse.drive_forces[-1] - fine.drive_forces[-1])) <= 1e-9 * max(
        1.0, np.max(np.abs(fine.drive_forces))
    )
    # and equals the forward simulation's drive effort there
    sim = ad.simulate(model, 0.37, rtol=1e-11, atol=1e-12, output_dt=0.37)
    assert np.max(np.abs(sim.drive_forces[-1] - coarse.drive_forces[-1])) <= 1e-7 * max(
        1.0, np.max(np.abs(fine.drive_forces))
    )


def _branched_tree_with_force_elements(rng):
    """A branched tree of every joint-space joint type (revolute, prismatic, cylindrical,
    fixed; random points, axes, full inertias) carrying every kind of force element."""
    from conftest import random_inertia, random_quat, random_unit

    b = ad.ModelBuilder(gravity=(0.0, 0.0, -G))
    names = [f"b{i}" for i in range(7)]
    for n in names:
        m = rng.uniform(0.5, 3.0)
        b.add_body(
            n,
            m,
            random_inertia(rng, m),
            position=rng.normal(scale=0.6, size=3),
            orientation=random_quat(rng),
        )
    # ground - b0 - b1 - b2, b1 - b3 - b4 (branch), ground - b5 - b6
    tree = [
        ("j0", "ground", "b0", "revolute"),
        ("j1", "b0", "b1", "cylindrical"),
        ("j2", "b1", "b2", "prismatic"),
        ("j3", "b1", "b3", "fixed"),
        ("j4", "b3", "b4", "revolute"),
        ("j5", "ground", "b5", "prismatic"),
        ("j6", "b5", "b6", "cylindrical"),
    ]
    for name, parent, child, kind in tree:
        point = rng.normal(scale=0.5, size=3)
        if kind == "fixed":
            b.add_fixed(name, parent, child, point)
        else:
            getattr(b, f"add_{kind}")(name, parent, child, point, random_unit(rng))
    sine = ad.profiles.sine(0.4, 1.3, 0.2, 0.1)
    b.add_joint_spring_damper("j0", stiffness=30.0, damping=2.0, rest=0.3)
    b.add_joint_spring_damper("j1", stiffness=50.0, damping=1.0, rest=-0.1, coord=1)
    b.add_joint_friction("j2", viscous=3.0, coulomb=1.5)
    b.add_motor("j4", sine, kp=80.0, kd=4.0, torque_limit=15.0, feedforward=2.0)
    b.add_joint_torque("j6", sine, coord=0)
    b.add_body_force("b2", force=(1.0, -2.0, 0.5), torque=(0.3, 0.1, -0.2), point=(0.1, 0, 0.2))
    b.add_body_force("b6", force=(0.0, 4.0, 0.0), profile=sine)
    b.add_spring_damper("s", "b2", (0.1, 0.0, 0.0), "b4", (0.0, 0.2, 0.0), 120.0, damping=3.0)
    return b.finalize()


def test_recursive_and_kkt_paths_agree(rng):
    """The O(n) Newton–Euler sweeps (method "joint", the default) and the driven-KKT
    multipliers (method "cartesian") are two derivations of the same torques: the joint path
    takes the coordinate forces straight from q, the Cartesian one through the bodies' eta;
    the accelerations and projections are derived separately."""
    model = _branched_tree_with_force_elements(rng)
    n = model.n_coords
    assert n == 8
    for _ in range(20):
        q, qd, qdd = rng.uniform(-2.0, 2.0, size=(3, n))
        t = rng.uniform(0.0, 3.0)
        a = ad.inverse_dynamics(model, q, qd, qdd, t, method="joint")
        b = ad.inverse_dynamics(model, q, qd, qdd, t, method="cartesian")
        assert rel_err(a, b) <= tol(1e-12)
        assert np.array_equal(ad.inverse_dynamics(model, q, qd, qdd, t), a)  # auto: joint
    # one state per row, one time per row, and an explicit workspace
    q, qd, qdd = rng.uniform(-2.0, 2.0, size=(3, 2, n))
    times = np.array([0.7, 1.9])
    rows = ad.inverse_dynamics(model, q, qd, qdd, t=times, method="cartesian")
    data = ad.Data(model)
    joint_rows = ad.inverse_dynamics(model, q, qd, qdd, t=times, data=data)
    assert rel_err(joint_rows, rows) <= tol(1e-12)
    for i in range(2):
        single = ad.inverse_dynamics(model, q[i], qd[i], qdd[i], times[i])
        assert np.array_equal(joint_rows[i], single)
    with pytest.raises(_core.ModelError, match="method must be 'auto', 'joint' or 'cartesian'"):
        ad.inverse_dynamics(model, q[0], qd[0], qdd[0], method="aba")
    with pytest.raises(_core.ModelError, match=r"data must be an armdyn\.Data"):
        ad.inverse_dynamics(model, q[0], qd[0], qdd[0], data=model)
    with pytest.raises(_core.ModelError, match="data was made for another model"):
        ad.inverse_dynamics(five_dof.three_dof_arm(), [0.0] * 3, [0.0] * 3, [0.0] * 3, data=data)
