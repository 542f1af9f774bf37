"""The Lagrange and geometric validators and the five-DOF paper's metrics.

References used here: the numpy recursive Newton–Euler of ``tests/oracles/numpy_rne.py`` (random
arms), SymPy (the paper's printed equations and the complete Euler–Lagrange equations of the planar
point-mass arm), closed forms (the paper's equations (22)–(25)), and the paper's own arithmetic.
"""

import armdyn as ad
import numpy as np
import pytest
import sympy as sp
from armdyn.papers import five_dof
from armdyn.validation import (
    average_of,
    end_effector_position,
    paper_end_effector_5dof,
    paper_model_3dof,
    torque_error_metrics,
)
from conftest import quat_to_rot, rel_err, spatial_arm, to_armdyn, tol

# ----------------------------------------------------------------------------------------------
# complete Lagrange equations
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("prismatic", [False, True])
def test_lagrange_validator_vs_rnea_random_arms(rng, prismatic):
    """Random spatial arms: full (off-diagonal) inertias, random axes, prismatic joints."""
    for _ in range(3):
        arm = spatial_arm(rng, prismatic=prismatic)
        lag = ad.LagrangeValidator(arm.model)
        q_ref, qd_ref, qdd_ref = rng.normal(size=(3, arm.n))
        q, qd, qdd = (to_armdyn(arm.perm, x) for x in (q_ref, qd_ref, qdd_ref))
        tau = lag.torques(q, qd, qdd)
        assert rel_err(tau[arm.perm], arm.chain.rnea(q_ref, qd_ref, qdd_ref)) <= tol(1e-11)
        m = lag.mass_matrix(q)
        assert rel_err(m[np.ix_(arm.perm, arm.perm)], arm.chain.mass_matrix(q_ref)) <= tol(1e-12)


@pytest.mark.parametrize("scene", ["three", "five"])
def test_complete_lagrange_equals_multibody_on_paper_scenes(scene):
    """The paper's acceptance metric (RMS of eq. (26)) between our multibody torques and the
    complete Lagrange equations: ≤ 1e-6 % on every joint (the paper accepts 10 %)."""
    model = five_dof.three_dof_arm() if scene == "three" else five_dof.five_dof_arm()
    t_end = five_dof.ARM3.duration if scene == "three" else five_dof.ARM5.duration
    res = ad.simulate(model, t_end, rtol=1e-10, atol=1e-12, output_dt=0.01)
    assert len(res.t) == round(t_end / 0.01) + 1
    cmp = ad.LagrangeValidator(model).compare(res)
    assert np.all(cmp.rms <= 1e-6)
    assert cmp.average <= 1e-6
    # the torques are not trivially small: every joint carries load
    assert np.all(np.max(np.abs(cmp.reference), axis=0) > 1e-2)


def test_compare_requires_every_coordinate_driven():
    # the validator's model need not be the one that ran (here: the same arm without drives)
    model = five_dof.five_dof_arm()
    lag = ad.LagrangeValidator(five_dof.five_dof_arm(drives=False))
    res = ad.simulate(model, 0.5, rtol=1e-10, atol=1e-12, output_dt=0.01)
    assert np.all(lag.compare(res, model=model).rms <= 1e-6)
    b = ad.ModelBuilder()
    b.add_body("a", 1.0, [0.1, 0.1, 0.1], (0.5, 0, 0))
    b.add_body("b", 1.0, [0.1, 0.1, 0.1], (1.5, 0, 0))
    b.add_revolute("j1", "ground", "a", (0, 0, 0), (0, 1, 0))
    b.add_revolute("j2", "a", "b", (1, 0, 0), (0, 1, 0))
    b.add_drive("j1", 0.0)
    m = b.finalize()
    res = ad.simulate(m, 0.02, output_dt=0.01)
    with pytest.raises(ad.ModelError, match="every joint coordinate"):
        ad.LagrangeValidator(m).compare(res)


def test_lagrange_validator_rejects_loops_and_bad_input():
    with pytest.raises(ad.ModelError, match="LagrangeValidator"):
        ad.LagrangeValidator(ad.scenes.four_bar())
    lag = ad.LagrangeValidator(five_dof.three_dof_arm())
    with pytest.raises(ad.ModelError, match="qd"):
        lag.torques([0, 0, 0], [0, np.inf, 0], [0, 0, 0])
    with pytest.raises(ad.ModelError, match="shape"):
        lag.torques([0, 0], [0, 0], [0, 0])


# ----------------------------------------------------------------------------------------------
# the paper's printed 3-DOF equations
# ----------------------------------------------------------------------------------------------


def planar_point_mass_lagrangian():
    th = sp.symbols("th1:4")
    thd = sp.symbols("thd1:4")
    L = sp.symbols("L1:4", positive=True)
    M = sp.symbols("M1:4", positive=True)
    g = sp.Symbol("g", positive=True)
    x = y = 0
    xd = yd = 0
    kin = pot = 0
    for i in range(3):
        x = x + L[i] * sp.cos(th[i])
        y = y + L[i] * sp.sin(th[i])
        xd = xd - L[i] * sp.sin(th[i]) * thd[i]
        yd = yd + L[i] * sp.cos(th[i]) * thd[i]
        kin += sp.Rational(1, 2) * M[i] * (xd**2 + yd**2)
        pot += M[i] * g * y
    return th, thd, L, M, g, kin - pot


def test_paper_model_is_minus_dL_dtheta(rng):
    """Equations (9)–(11) as printed equal −∂L/∂θᵢ of the planar arm with point masses at the
    link ends (absolute angles): the d/dt ∂L/∂θ̇ᵢ terms are missing."""
    th, thd, L, M, g, lag = planar_point_mass_lagrangian()
    minus_dl = [-sp.diff(lag, th[i]) for i in range(3)]  # (lambdify needs no simplify)
    f = sp.lambdify((th, thd, L, M, g), minus_dl, "numpy")
    for _ in range(20):
        theta, thetad = rng.uniform(-3, 3, 3), rng.uniform(-5, 5, 3)
        lengths, masses = rng.uniform(0.1, 1, 3), rng.uniform(0.1, 3, 3)
        ours = paper_model_3dof(lengths, masses, theta, thetad, g=9.81)
        assert rel_err(ours, np.array(f(theta, thetad, lengths, masses, 9.81))) <= 1e-13


def test_complete_equations_of_the_point_mass_arm_match_the_validator(rng):
    """SymPy's complete Euler–Lagrange equations of the planar point-mass arm equal the
    Lagrange validator on the point-mass 3-DOF model (absolute → joint torques), and differ
    from the printed paper model by exactly the missing d/dt ∂L/∂θ̇ terms."""
    th, thd, L, M, g, lag = planar_point_mass_lagrangian()
    thdd = sp.symbols("thdd1:4")
    full = []
    for i in range(3):
        p = sp.diff(lag, thd[i])
        ddt = sum(sp.diff(p, th[k]) * thd[k] + sp.diff(p, thd[k]) * thdd[k] for k in range(3))
        full.append(ddt - sp.diff(lag, th[i]))
    f_full = sp.lambdify((th, thd, thdd, L, M, g), full, "numpy")
    model = five_dof.three_dof_arm(point_masses=True, drives=False)
    lagv = ad.LagrangeValidator(model, rotational_inertia=False)
    lengths, masses = five_dof.ARM3.lengths, five_dof.ARM3.masses
    for _ in range(10):
        q, qd, qdd = rng.normal(size=(3, 3))
        theta, thetad = five_dof.three_dof_absolute(q, qd)
        thetadd = np.cumsum(qdd)
        t_abs = np.array(f_full(theta, thetad, thetadd, lengths, masses, 9.81))
        assert rel_err(lagv.torques(q, qd, qdd), five_dof.absolute_to_joint_torques(t_abs)) <= 1e-12
        printed = paper_model_3dof(lengths, masses, theta, thetad)
        assert np.max(np.abs(printed - t_abs)) > 1e-3  # the missing terms are not small


# ----------------------------------------------------------------------------------------------
# metrics
# ----------------------------------------------------------------------------------------------


def test_metric_reproduces_the_papers_arithmetic():
    assert average_of(five_dof.PAPER.table2_rmse) == pytest.approx(7.6, abs=1e-12)
    assert average_of([24, 3, 4, 6, 1]) == pytest.approx(five_dof.PAPER.table2_average, abs=1e-12)


def test_torque_error_metrics_by_hand():
    a = np.array([[1.0, 0.0], [2.0, 1.0]])
    ref = np.array([[2.0, 0.5], [4.0, -1.0]])
    m = torque_error_metrics(a, ref)
    # eq. (26): |a - ref| / max|ref| * 100 per column
    assert m["ref_max"] == pytest.approx([4.0, 1.0])
    assert m["percent"] == pytest.approx(np.array([[25.0, 50.0], [50.0, 200.0]]))
    # eq. (27): RMS over samples
    assert m["rms"] == pytest.approx([np.sqrt((25**2 + 50**2) / 2), np.sqrt((50**2 + 200**2) / 2)])
    assert m["max"] == pytest.approx([50.0, 200.0])
    assert m["average"] == pytest.approx(np.mean(m["rms"]))
    with pytest.raises(ad.ModelError, match="identically zero"):
        torque_error_metrics(a, np.zeros_like(a))


# ----------------------------------------------------------------------------------------------
# geometric validator
# ----------------------------------------------------------------------------------------------


def test_paper_equations_at_position_1():
    a = five_dof.ARM5
    p = paper_end_effector_5dof([0, 0, 0, 0], a.h, a.L1, a.L2, a.L3 + a.L4)
    assert p == pytest.approx([0.66, 0.16, 0.0], abs=1e-15)


def simulated_tip(q):
    """End effector from the Cartesian state the constraint solver gives for held joints."""
    model = five_dof.five_dof_arm(hold=q)
    res = ad.simulate(model, 0.02, rtol=1e-10, atol=1e-12, output_dt=0.01)
    body, point = five_dof.five_dof_tip()
    b = model.body_names.index(body)
    u = res.u[-1, 7 * b : 7 * b + 7]
    return model, res, u[:3] + quat_to_rot(u[3:]) @ point


def joint_sets(rng):
    sets = [np.append(d * five_dof.DEG, 0.0) for d in five_dof.PAPER.table3_deg]
    for _ in range(4):
        sets.append(np.append(rng.uniform(-1.2, 1.2, 4), rng.uniform(0, five_dof.ARM5.stroke)))
    return sets


def test_geometric_validator_vs_simulated_end_effector(rng):
    a = five_dof.ARM5
    for q in joint_sets(rng):
        model, res, tip = simulated_tip(q)
        assert np.max(np.abs(res.q[-1] - q)) <= 1e-12
        body, point = five_dof.five_dof_tip()
        geo = end_effector_position(model, body, point, q)
        assert np.max(np.abs(geo - tip)) <= 1e-9
        # the paper's equations with our joint angles made absolute (prismatic retracted)
        th = q[:4]
        absolute = [th[0], th[1], th[1] + th[2], th[1] + th[2] + th[3]]
        eq = paper_end_effector_5dof(absolute, a.h, a.L1, a.L2, a.L3 + a.L4 + q[4])
        assert np.max(np.abs(eq - five_dof.to_paper_axes(tip))) <= 1e-9


def test_geometric_validator_on_random_arms(rng):
    """Generic validator vs the numpy reference's forward kinematics on random spatial arms."""
    arm = spatial_arm(rng, prismatic=True)
    for _ in range(5):
        q_ref = rng.normal(size=arm.n)
        q = to_armdyn(arm.perm, q_ref)
        point = rng.normal(size=3) * 0.1
        coms, rots, _, _ = arm.chain.body_states(q_ref, np.zeros(arm.n))
        x, rot = coms[-1], rots[-1]
        ours = end_effector_position(arm.model, arm.body_names[-1], point, q)
        assert np.max(np.abs(ours - (x + rot @ point))) <= 1e-12


def test_paper_table4_is_inconsistent_with_its_equations():
    """Position 3 has θ1 = 45°, so eqs (24)–(25) force X = Z; the paper's row does not."""
    a = five_dof.ARM5
    th = five_dof.PAPER.table3_deg[2] * five_dof.DEG
    p = paper_end_effector_5dof(th, a.h, a.L1, a.L2, a.L3 + a.L4)
    assert p[0] == pytest.approx(p[2], abs=1e-15)
    row = five_dof.PAPER.table4_geometric[2]
    assert abs(row[0] - row[2]) > 0.1


# ----------------------------------------------------------------------------------------------
# simplified-model gaps, pinned (regression values)
# ----------------------------------------------------------------------------------------------
# Source: `armdyn reproduce` with the scenes of armdyn/papers/five_dof.py (the reconstructed arms
# documented there), DOPRI5 rtol 1e-10, outputs every 0.01 s. The values are the eq. (27) RMS of
# eq. (26) between our multibody torques and the simplified models. They depend only on the
# scene parameters (the motion is fully prescribed), so they change only if those do.
PINNED_3DOF_PRINTED = [23.565922, 32.729387, 44.502825]
PINNED_3DOF_POINT_MASS = [18.918699, 25.474589, 35.471420]
PINNED_5DOF_POINT_MASS = [13.441714, 16.533158, 18.656142, 26.956566, 0.190235]


def test_simplified_model_gaps_pinned():
    from armdyn.papers.reproduce import five_dof_study, three_dof_study

    s3, s5 = three_dof_study(), five_dof_study()
    assert s3.metrics["printed"]["rms"] == pytest.approx(PINNED_3DOF_PRINTED, abs=5e-6)
    assert s3.metrics["point_mass"]["rms"] == pytest.approx(PINNED_3DOF_POINT_MASS, abs=5e-6)
    assert s5.metrics["point_mass"]["rms"] == pytest.approx(PINNED_5DOF_POINT_MASS, abs=5e-6)


def test_lagrange_validator_on_a_urdf_arm(rng):
    """A URDF arm (merged fixed links, rpy origins, full inertias): the Lagrange validator, the
    joint-space inverse dynamics (KKT path) and forward dynamics agree."""
    from pathlib import Path

    model = ad.load_urdf(Path(__file__).resolve().parents[1] / "data" / "urdf" / "arm6.urdf")
    lag = ad.LagrangeValidator(model)
    for _ in range(5):
        q, qd, qdd = rng.normal(size=(3, model.n_coords))
        tau = ad.inverse_dynamics(model, q, qd, qdd)
        assert rel_err(lag.torques(q, qd, qdd), tau) <= tol(1e-10)
        assert rel_err(ad.forward_dynamics(model, q, qd, tau), qdd) <= tol(1e-9)
