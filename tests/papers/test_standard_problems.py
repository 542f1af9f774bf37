"""The standard problems (IFToMM A01/A02, Andrews' squeezer) against independent references and
published values; the inline and distance joints they are built with; the work-precision sweep
(`python -m benchmarks.workprecision`)."""

import json

import armdyn as ad
import numpy as np
import pytest
from armdyn.scenes import standard

from benchmarks import references
from benchmarks.workprecision import PROBLEMS, run_problem

# Hairer & Wanner (1996) §VII.7 / Test Set "andrews": consistent initial accelerations of β and Θ
# and the first two multipliers (all others are zero at rest)
HW_QDD0 = (14222.4439199541138705911625887, -10666.8329399655854029433719415)
HW_LAMBDA0 = (98.5668703962410896057654982170, -6.12268834425566265503114393122)


def test_inline_closure_gives_the_redundant_four_bar_motion_without_redundant_rows():
    red = ad.scenes.four_bar()
    inl = ad.scenes.four_bar(closure="inline")
    assert len(red.redundant_rows) == 3 and red.kkt_path == "dense"
    assert len(inl.redundant_rows) == 0 and inl.kkt_path != "dense"
    assert inl.nc == 17 and inl.mobility == 1
    a = ad.simulate(red, 1.5, rtol=1e-11, atol=1e-11, output_dt=0.05)
    b = ad.simulate(inl, 1.5, rtol=1e-11, atol=1e-11, output_dt=0.05)
    assert np.abs(a.u - b.u).max() < 1e-10
    assert b.position_residual.max() < 1e-12
    # the inline joint's reaction is the revolute's in-plane reaction (2 of its 3 force rows)
    d = red.joint_names.index("D")
    assert np.allclose(b.reaction_forces[:, d, :2], a.reaction_forces[:, d, :2], rtol=0, atol=1e-8)


def test_distance_joint_pendulum_is_the_closed_form_mass_point_pendulum():
    model = standard.iftomm_a01_pendulum()
    assert model.nc == 1 and model.mobility == 5  # the mass point's own rotation stays free
    t = np.linspace(0.0, 20.0, 201)
    res = ad.simulate(model, 20.0, rtol=1e-11, atol=1e-11, output_dt=0.1)
    exact = references.a01_points(t)
    assert np.abs(res.u[:, :2] - exact).max() < 1e-8
    assert np.abs(res.u[:, 2]).max() == 0.0
    assert np.abs(res.v[:, 3:6]).max() < 1e-12  # never spun up
    # the closed form against a second method: SciPy DOP853 on θ'' = -g sin θ
    from scipy.integrate import solve_ivp

    f, y0 = references.a01_rhs()
    sol = solve_ivp(f, (0, 20), y0, method="DOP853", rtol=1e-13, atol=1e-13, t_eval=t)
    assert np.abs(np.sin(sol.y[0]) - exact[:, 0]).max() < 1e-11


def test_distance_joint_rejects_coincident_points():
    b = ad.ModelBuilder()
    b.add_body("m", 1.0, [1e-3] * 3, position=(1, 0, 0))
    with pytest.raises(ad.ModelError, match=r"distance joint 'rod'.*coincide"):
        b.add_distance("rod", "ground", (1, 0, 0), "m", (1, 0, 0))
    with pytest.raises(ad.ModelError, match=r"distance joint 'rod': point_a"):
        b.add_distance("rod", "ground", (np.nan, 0, 0), "m", (1, 0, 0))
    with pytest.raises(ad.ModelError, match="unknown body 'nobody'"):
        b.add_distance("rod", "ground", (0, 0, 0), "nobody", (1, 0, 0))


def test_squeezer_reference_reproduces_the_published_start_and_end():
    q0 = np.array(standard.SQUEEZER["q0"])
    _m, _f, g, _gq, _gqq = references.squeezer_terms(q0, np.zeros(7))
    assert np.abs(g).max() < 1e-15
    qdd, lam = references.squeezer_accelerations(q0, np.zeros(7))
    np.testing.assert_allclose(qdd[:2], HW_QDD0, rtol=1e-12)
    np.testing.assert_allclose(lam[:2], HW_LAMBDA0, rtol=1e-12)
    assert np.abs(qdd[2:]).max() < 1e-9 and np.abs(lam[2:]).max() < 1e-9
    end = references.squeezer_angles([0.0, 0.03])[-1]
    assert np.abs(end - references.ANDREWS_TEST_SET_T003).max() < 2e-9


def test_squeezer_model_matches_hairer_wanner():
    model = standard.andrews_squeezer()
    assert model.nb == 7 and model.nc == 41 and model.mobility == 1
    assert len(model.redundant_rows) == 0
    vdot, _ = ad.body_accelerations(model, model.u0, model.v0)
    k1, k2 = 6 * 0 + 5, 6 * 1 + 5  # omega_z of K1, K2 (body z = world z)
    np.testing.assert_allclose([vdot[k1], vdot[k2] - vdot[k1]], HW_QDD0, rtol=1e-12)
    res = ad.simulate(model, 0.03, rtol=1e-10, atol=1e-10, output_dt=1e-4)
    obs = PROBLEMS["squeezer"].observe(model, res)
    ref = references.squeezer_angles(res.t)
    wrap = lambda a: np.remainder(a + np.pi, 2 * np.pi) - np.pi  # noqa: E731
    assert np.abs(wrap(obs - ref)).max() < 1e-9
    assert np.abs(wrap(obs[-1] - references.ANDREWS_TEST_SET_T003)).max() < 2e-9


def test_a02_model_and_its_motion_before_the_singular_position():
    n = 40
    model = standard.iftomm_a02_four_bar(n)
    assert model.nb == 2 * n + 1 and model.mobility == 1 and len(model.redundant_rows) == 0
    v0 = standard.a02_initial_velocity(model, n)
    # the cranks first reach the horizontal, singular position at t ≈ 0.67 s
    res = ad.simulate(model, 0.5, rtol=1e-10, atol=1e-10, output_dt=0.05, v0=v0)
    b0 = PROBLEMS["a02"].observe(model, res)
    assert np.abs(b0 - references.a02_points(res.t, n)).max() < 1e-10
    # every crank parallel to crank 0 (the one-DOF branch)
    assert np.abs(res.q[:, : n + 1] - res.q[:, :1]).max() < 1e-11


def test_workprecision_sweep_writes_curves(tmp_path):
    r = run_problem("squeezer", quick=True, peers=False, echo=False)
    pts = r["curves"]["armdyn dopri5"]
    errors = [p["error"] for p in pts]
    assert errors[1] < errors[0] / 20  # rtol 1e-6 -> 1e-8: the error follows the tolerance
    assert all(p["steps"] > 0 and p["cpu_s"] > 0 for p in pts)
    from benchmarks.workprecision import main

    assert main(["squeezer", "--quick", "--no-peers", "--out", str(tmp_path)]) == 0
    saved = json.loads((tmp_path / "squeezer.json").read_text())
    assert saved["machine"]["cores"] >= 1 and "armdyn dopri5" in saved["curves"]
    assert (tmp_path / "squeezer.png").stat().st_size > 0


def test_five_dof_driven_run_matches_the_complete_lagrange_torques_at_any_tolerance():
    # fully driven: the motion is prescribed, so the efforts are round-off exact however loose
    # the integrator's tolerance
    r = run_problem("five_dof", quick=True, peers=False, echo=False)
    for pts in r["curves"].values():
        assert all(p["error"] < 1e-10 for p in pts)


def test_mujoco_peer_solves_the_same_a01():
    mujoco = pytest.importorskip("mujoco")
    from benchmarks.workprecision import _A01_XML

    m = mujoco.MjModel.from_xml_string(_A01_XML)
    m.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    d = mujoco.MjData(m)
    mujoco.mj_step(m, d, nstep=round(5.0 / m.opt.timestep))
    exact = references.a01_points([5.0])[0]
    got = PROBLEMS["a01"].mujoco_observe(d.qpos[None, :])[0]
    assert np.abs(got - exact).max() < 1e-8


def test_a02_through_its_singular_positions_stays_on_the_parallel_branch():
    """5 s: the cranks pass the horizontal (rank 485 -> 445) five times. Near it the KKT solver
    switches to its regularised block-sparse factor (no dense fallback) and the motion stays on
    the one-DOF branch: B0 against the reference and every crank parallel to crank 0."""
    n = 40
    model = standard.iftomm_a02_four_bar(n)
    v0 = standard.a02_initial_velocity(model, n)
    res = ad.simulate(model, 5.0, rtol=1e-9, atol=1e-9, output_dt=0.05, v0=v0)
    assert res.stats["singular_evaluations"] > 0
    assert "dependent rows" in res.stats["singular_note"]
    b0 = PROBLEMS["a02"].observe(model, res)
    # measured 1.1e-8
    assert np.abs(b0 - references.a02_points(res.t, n)).max() < 1e-7
    crank = np.unwrap(res.q[:, : n + 1], axis=0)
    assert np.abs(crank - crank[:, :1]).max() < 1e-9  # measured 1.7e-10
    assert np.max(res.position_residual) < 1e-12
