"""armdyn.rollout: many runs on C++ threads, each equal bit for bit to a serial simulate of the
same inputs, in input order; a failing run is recorded and does not stop the others."""

from __future__ import annotations

import os
import signal
import threading

import armdyn as ad
import numpy as np
import pytest
from conftest import assert_same_run as same_run
from scipy.integrate import solve_ivp

from benchmarks import common


def assert_same_run(a, b):
    """Every table equal bit for bit, and the same step statistics (the run time aside)."""
    same_run(a, b, stats=True)


def ur5():
    path = common.robot_urdf("ur5")
    if path is None:
        pytest.skip("example-robot-data is not installed")
    return ad.load_urdf(path)


def ur5_starts(model, n, seed=0):
    rng = np.random.default_rng(seed)
    q0 = np.array(common.UR5_Q0)[None, :] + rng.uniform(-0.3, 0.3, size=(n, model.n_coords))
    qd0 = rng.uniform(-0.5, 0.5, size=(n, model.n_dofs))
    return q0, qd0


OPTS = dict(limits="ignore", output_dt=0.05)


@pytest.mark.parametrize("threads", [1, 2, 4])
def test_equals_serial_simulate_in_input_order(threads):
    model = ur5()
    q0, qd0 = ur5_starts(model, 6)
    runs = ad.rollout(model, q0, qd0, 0.3, threads=threads, **OPTS)
    assert len(runs) == 6
    for k, r in enumerate(runs):
        assert r.error is None and r.status == "ok"
        ref = ad.simulate(model, 0.3, q0=q0[k], qd0=qd0[k], **OPTS)
        assert_same_run(r, ref)
    # the runs differ, so the order is really checked
    finals = np.array([r.q[-1] for r in runs])
    assert np.all(np.abs(np.diff(finals, axis=0)).max(axis=1) > 1e-3)


def test_options_pass_through_joint_coordinates_and_u0_rows():
    model = ur5()
    q0, qd0 = ur5_starts(model, 3, seed=1)
    opts = dict(limits="ignore", coordinates="joint", integrator="dop853", rtol=1e-9, atol=1e-11)
    runs = ad.rollout(model, q0, qd0, 0.2, threads=2, **opts)
    for k, r in enumerate(runs):
        assert_same_run(r, ad.simulate(model, 0.2, q0=q0[k], qd0=qd0[k], **opts))
    uv = [ad.state_from_joints(model, q0[k], qd0[k]) for k in range(3)]
    us, vs = np.array([u for u, _ in uv]), np.array([v for _, v in uv])
    runs = ad.rollout(model, u0=us, v0=vs, t_end=0.2, threads=2, **OPTS)
    for k, r in enumerate(runs):
        assert_same_run(r, ad.simulate(model, 0.2, u0=us[k], v0=vs[k], **OPTS))


def test_pendulum_runs_against_the_pendulum_ode():
    """Independent reference: theta'' = -(g / L_eq) sin(theta), per run its own amplitude."""
    from conftest import simple_pendulum

    p = simple_pendulum(theta0=0.0, L=0.7, r=0.05)
    amplitudes = np.array([0.1, 0.6, 1.5, 2.8])
    t_end = 1.3
    runs = ad.rollout(
        p.model,
        amplitudes[:, None],
        None,
        t_end,
        threads=2,
        integrator="dop853",
        rtol=1e-11,
        atol=1e-12,
        output_dt=0.1,
    )
    w2 = p.g / p.L_eq
    for a, r in zip(amplitudes, runs, strict=True):
        sol = solve_ivp(
            lambda _t, y: [y[1], -w2 * np.sin(y[0])],
            (0, t_end),
            [a, 0.0],
            method="DOP853",
            rtol=1e-13,
            atol=1e-13,
            t_eval=r.t,
        )
        assert np.abs(r.q[:, 0] - sol.y[0]).max() < 1e-8


def test_failing_runs_are_recorded_and_do_not_stop_the_others():
    model = ur5()
    q0, qd0 = ur5_starts(model, 5, seed=2)
    q0[1, 2] = np.nan  # cannot start
    qd0[3] = 2e3  # far more steps than max_steps allows: a SolverError mid-run
    opts = dict(limits="ignore", max_steps=300)
    runs = ad.rollout(model, q0, qd0, 0.3, threads=2, **opts)
    assert [r.status == "ok" for r in runs] == [True, False, True, False, True]
    assert "NaN" in runs[1].error and runs[1].t.shape == (0,)
    assert runs[1].q.shape == (0, model.n_coords)
    with pytest.raises(ad.ModelError):
        ad.simulate(model, 0.3, q0=q0[1], qd0=qd0[1], **opts)
    with pytest.raises(ad.SolverError) as exc:
        ad.simulate(model, 0.3, q0=q0[3], qd0=qd0[3], **opts)
    assert runs[3].error == str(exc.value)
    assert len(runs[3].t) > 1 and runs[3].t[-1] < 0.3
    assert_same_run(runs[3], exc.value.result)
    for k in (0, 2, 4):
        assert_same_run(runs[k], ad.simulate(model, 0.3, q0=q0[k], qd0=qd0[k], **opts))


def test_stress_many_threads_on_a_fresh_model():
    """A model whose derived caches (welded model, KKT plans) are built by the threads
    themselves, concurrently: 24 runs on 8 threads, every one equal to its serial run."""
    model = ur5()
    q0, qd0 = ur5_starts(model, 24, seed=3)
    runs = ad.rollout(model, q0, qd0, 0.15, threads=8, **OPTS)
    for k, r in enumerate(runs):
        assert_same_run(r, ad.simulate(model, 0.15, q0=q0[k], qd0=qd0[k], **OPTS))


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(q0=np.zeros(6)), r"q0 must have shape \(n_runs, 6\).*\(6,\)"),
        (dict(q0=np.zeros((3, 5))), r"q0 must have shape \(n_runs, 6\).*\(3, 5\)"),
        (dict(q0=np.zeros((3, 6)), qd0=np.zeros((2, 6))), r"qd0 must have shape \(3, 6\)"),
        (dict(u0=np.zeros((2, 3))), r"u0 must have shape"),
        (dict(q0=np.zeros((2, 6)), u0=np.zeros((2, 3))), "either q0/qd0 or u0/v0"),
        (dict(qd0=np.zeros((2, 6))), "qd0 given without q0"),
        (dict(), "give the initial states"),
        (dict(q0=np.zeros((2, 6)), threads=0), "threads must be a positive integer"),
        (dict(q0=np.zeros((2, 6)), t_end=-1.0), "t_end must be a positive number"),
        (dict(q0=np.zeros((2, 6)), integrator="euler"), "euler"),
        (dict(q0=np.zeros((2, 6)), limits="off"), "limits must be"),
    ],
)
def test_bad_input_raises_model_error_naming_it(kwargs, match):
    model = ur5()
    kwargs.setdefault("t_end", 0.1)
    with pytest.raises(ad.ModelError, match=match):
        ad.rollout(model, **kwargs)


def test_unknown_option_and_option_errors():
    model = ur5()
    with pytest.raises(TypeError, match="q_start"):
        ad.rollout(model, np.zeros((2, 6)), None, 0.1, q_start=1)
    # an option every run refuses (rk4 without dt) is the options' fault: raised, not recorded
    with pytest.raises(ad.ModelError, match=r"every run failed to start.*dt"):
        ad.rollout(model, np.zeros((2, 6)), None, 0.1, integrator="rk4", limits="ignore")
    assert ad.rollout(model, np.zeros((0, 6)), None, 0.1) == []
    # q0 rows for a model without a joint space (a ball-jointed link carrying a hinged one):
    # the model's fault, raised
    b = ad.ModelBuilder()
    b.add_body("bob", 1.0, [0.01, 0.01, 0.01], position=(0, 0, -1))
    b.add_body("tip", 1.0, [0.01, 0.01, 0.01], position=(0, 0, -2))
    b.add_spherical("ball", "ground", "bob", (0, 0, 0))
    b.add_revolute("hinge", "bob", "tip", (0, 0, -1.5), (0, 1, 0))
    ball = b.finalize()
    with pytest.raises(ad.ModelError, match="every run failed to start"):
        ad.rollout(ball, np.zeros((2, ball.n_coords)), None, 0.1)
    # a closed loop takes its independent coordinates (the four-bar's crank): the runs start
    loop = ad.scenes.four_bar()
    runs = ad.rollout(loop, np.array([[0.0], [0.3]]), None, 0.05)
    assert [r.error for r in runs] == [None, None]
    assert abs(runs[1].q[0, list(loop.joint_coord_names).index("A")] - 0.3) < 1e-12


def test_interrupt_between_runs_keeps_the_finished_runs():
    """A signal during the batch (Ctrl-C's path: the handler's exception) stops it between runs;
    the exception carries the list, finished runs intact, the others marked."""
    model = ur5()
    q0, qd0 = ur5_starts(model, 400, seed=4)

    class Stop(Exception):
        pass

    def handler(_sig, _frame):
        raise Stop()

    old = signal.signal(signal.SIGUSR1, handler)
    timer = threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGUSR1))
    try:
        timer.start()
        with pytest.raises(Stop) as exc:
            ad.rollout(model, q0, qd0, 1.0, threads=1, limits="ignore")
    finally:
        timer.cancel()
        signal.signal(signal.SIGUSR1, old)
    runs = exc.value.result
    assert len(runs) == 400
    done = [k for k, r in enumerate(runs) if r.error is None]
    assert 0 < len(done) < 400
    # the run in progress stops within its stepping loop (the poll sees the stop flag), its
    # outputs so far kept; the rest never started
    cut = [k for k, r in enumerate(runs) if r.error == "run cancelled"]
    assert len(cut) <= 1
    assert all(
        runs[k].error == "interrupted before the run started"
        for k in range(400)
        if k not in done and k not in cut
    )
    k = done[-1]
    assert_same_run(runs[k], ad.simulate(model, 1.0, q0=q0[k], qd0=qd0[k], limits="ignore"))
    for k in cut:
        full = ad.simulate(model, 1.0, q0=q0[k], qd0=qd0[k], limits="ignore")
        n = len(runs[k].t)
        np.testing.assert_array_equal(runs[k].t, full.t[:n])
        np.testing.assert_array_equal(runs[k].q, full.q[:n])


def test_rollout_progress_reports_the_runs_finished():
    model = ur5()
    q0, qd0 = ur5_starts(model, 40, seed=6)
    seen = []
    runs = ad.rollout(
        model, q0, qd0, 0.5, threads=2, limits="ignore", progress=lambda d, n: seen.append((d, n))
    )
    assert seen[-1] == (40, 40)
    assert all(n == 40 and 0 <= d <= 40 for d, n in seen)
    assert [d for d, _ in seen] == sorted(d for d, _ in seen)
    assert all(r.error is None for r in runs)

    class Enough(Exception):
        pass

    def stop(done, n):
        raise Enough()

    q0, qd0 = ur5_starts(model, 400, seed=7)
    with pytest.raises(Enough) as exc:
        ad.rollout(model, q0, qd0, 1.0, threads=2, limits="ignore", progress=stop)
    assert len(exc.value.result) == 400
    assert any(r.error is not None for r in exc.value.result)
    with pytest.raises(ad.ModelError, match="progress must be"):
        ad.rollout(model, q0[:2], qd0[:2], 0.1, progress="yes")
