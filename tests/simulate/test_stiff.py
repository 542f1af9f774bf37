"""The implicit TR-BDF2 integrator and integrator="auto" on stiff scenes.

References: DOPRI5 at tight tolerance (a different, explicit method) and the second-order
convergence of TR-BDF2 itself. The stiff scene is a spring-mass pendulum whose spring stiffness
is swept over eight decades: the spring's frequency sqrt(k/m) goes from 10 to 1e5 rad/s while the
pendulum's motion stays at ≈ 3 rad/s.
"""

import armdyn as ad
import numpy as np
import pytest
from armdyn.scenes import double_pendulum, spring_mass_pendulum


def test_trbdf2_converges_with_order_two():
    model = double_pendulum()
    ref = ad.simulate(model, 2.0, rtol=1e-12, atol=1e-12, output_dt=2.0)
    errs, steps = [], []
    for tol in (1e-6, 1e-8):
        r = ad.simulate(model, 2.0, integrator="trbdf2", rtol=tol, atol=tol, output_dt=2.0)
        errs.append(np.max(np.abs(r.q[-1] - ref.q[-1])))
        steps.append(r.stats["steps"])
        assert r.stats["integrator"] == "trbdf2"
        assert np.max(r.position_residual) <= 1e-12  # projected after every step
    order = np.log(errs[0] / errs[1]) / np.log(steps[1] / steps[0])
    assert 1.7 <= order <= 2.4, order
    assert errs[1] <= 1e-4


@pytest.mark.parametrize("k", [1e2, 1e6, 1e10])
def test_stiffness_sweep_implicit_and_explicit_agree(k):
    # 0.5 s: the pendulum swings 0.45-0.51 rad, the 1e10 spring makes about 8,000 oscillations
    # (the explicit reference's cost); measured at 0.5 s (2 s before): angle 5.2e-6 (1.4e-5),
    # stretch 3.6e-6, 7.8e-10, 4.2e-12 (4.4e-6, 2.4e-10, 6.6e-12) for k = 1e2, 1e6, 1e10
    model = spring_mass_pendulum(stiffness=k)
    exp = ad.simulate(model, 0.5, integrator="dopri5", rtol=1e-8, atol=1e-10, output_dt=0.25)
    imp = ad.simulate(model, 0.5, integrator="trbdf2", rtol=1e-6, atol=1e-8, output_dt=0.25)
    assert np.ptp(exp.q[:, 0]) > 0.4  # it swings
    # the pendulum angle (slow motion) agrees where both run
    assert np.max(np.abs(imp.q[:, 0] - exp.q[:, 0])) <= 3e-5
    # the spring's stretch (static: m g cos(theta) / k, plus its oscillation) agrees
    assert np.max(np.abs(imp.q[:, 1] - exp.q[:, 1])) <= 1e-5 + 1e-3 * 9.81 / k


def test_implicit_takes_steps_the_explicit_cannot():
    k = 1e10
    model = spring_mass_pendulum(stiffness=k)
    omega = np.sqrt(k / 1.0)
    imp = ad.simulate(model, 1.0, integrator="trbdf2", rtol=1e-6, atol=1e-8, output_dt=0.5)
    mean_step = 1.0 / imp.stats["steps"]
    # RK4's stability limit on an oscillation is 2.83 / omega; TR-BDF2 steps far beyond it
    assert mean_step > 3 * 2.83 / omega
    with pytest.raises(ad.SolverError) as err:
        ad.simulate(model, 1.0, integrator="rk4", dt=mean_step, output_dt=0.5)
    assert err.value.result.t[-1] < 1.0  # the explicit run blew up; its good part is kept
    exp = ad.simulate(model, 1.0, integrator="dopri5", rtol=1e-6, atol=1e-8, output_dt=0.5)
    assert exp.stats["steps"] > 4 * imp.stats["steps"]


def test_auto_picks_by_stiffness_and_says_why():
    soft = ad.simulate(spring_mass_pendulum(stiffness=1e2), 1.0, integrator="auto", output_dt=0.5)
    assert soft.stats["integrator"] == "dopri5"
    assert "not stiff" in soft.stats["integrator_reason"]
    # not stiff, tight tolerance: the 8th-order pair
    tight = ad.simulate(
        spring_mass_pendulum(stiffness=1e2), 1.0, integrator="auto", rtol=1e-9, output_dt=0.5
    )
    assert tight.stats["integrator"] == "dop853"
    assert "not stiff" in tight.stats["integrator_reason"]
    assert "<= 1e-7 favours the 8th-order pair" in tight.stats["integrator_reason"]
    stiff = ad.simulate(spring_mass_pendulum(stiffness=1e10), 1.0, integrator="auto", output_dt=0.5)
    assert stiff.stats["integrator"] == "trbdf2"
    reason = stiff.stats["integrator_reason"]
    assert "joint 'slide' spring" in reason
    # the estimate is the spring's frequency under the constraints: sqrt(k / m_bob) = 1e5 rad/s
    rate = float(reason.split("fastest rate ")[1].split()[0])
    assert rate == pytest.approx(1e5, rel=1e-9)


def test_nan_force_mid_run_stops_with_the_result(tmp_path):
    """A user force that turns NaN after t = 0.31 s: the run stops with a SolverError naming the
    body and the time, for every integrator, and keeps the outputs before it."""
    for integrator in ("dopri5", "trbdf2", "rk4"):
        model = ad.scenes.nan_force_pendulum(t_nan=0.31)
        where = r"body 'bob'.*non-finite value at t=0\.[3-9]"
        with pytest.raises(ad.SolverError, match=where) as e:
            ad.simulate(model, 1.0, integrator=integrator, dt=0.01, output_dt=0.05)
        res = e.value.result
        assert 0.0 < res.t[-1] <= 0.31  # outputs before the first NaN evaluation
        if integrator == "rk4":  # fixed steps of 0.01 s: every output up to 0.3 s is kept
            assert res.t[-1] == pytest.approx(0.3)
        assert np.all(np.isfinite(res.q))
