"""The shared shapes of armdyn.motion: Trajectory (timed samples) and Path (geometric q(s))."""

import armdyn as ad
import numpy as np
import pytest
from armdyn.motion import Path, Trajectory


def _quintic(t):
    c = np.array([0.3, -1.0, 0.5, 2.0, -0.7, 0.2])
    q = np.polyval(c, t)
    qd = np.polyval(np.polyder(c), t)
    qdd = np.polyval(np.polyder(c, 2), t)
    return q[:, None], qd[:, None], qdd[:, None]


def test_sample_without_evaluator_is_exact_on_a_quintic():
    t = np.linspace(0.0, 2.0, 5)
    traj = Trajectory(t, *_quintic(t))
    fine = np.linspace(0.0, 2.0, 101)
    out = traj.sample(fine)
    for got, want in zip((out.q, out.qd, out.qdd), _quintic(fine), strict=True):
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-11)


def test_sample_uses_the_evaluator_and_dt_keeps_the_end():
    calls = []

    def evaluate(x):
        calls.append(len(x))
        return _quintic(x)

    traj = Trajectory([0.0, 1.0], *_quintic(np.array([0.0, 1.0])), evaluate=evaluate)
    out = traj.sample(dt=0.3)
    np.testing.assert_allclose(out.t, [0.0, 0.3, 0.6, 0.9, 1.0], atol=1e-15)
    assert calls == [5]


def test_trajectory_run_takes_a_trajectory():
    model = ad.scenes.basic.double_pendulum()
    t = np.linspace(0.0, 1.0, 11)
    q, qd, qdd = (np.tile(x, (1, model.n_dofs)) for x in _quintic(t))
    traj = Trajectory(t, q, qd, qdd)
    a = ad.trajectory_run(model, traj)
    b = ad.trajectory_run(model, t, q, qd, qdd)
    np.testing.assert_array_equal(a.joint_torques, b.joint_torques)
    with pytest.raises(ad.ModelError, match="Trajectory alone"):
        ad.trajectory_run(model, traj, q, qd, qdd)
    with pytest.raises(ad.ModelError, match="required"):
        ad.trajectory_run(model, t)


def test_path_timed_is_the_chain_rule():
    s = np.linspace(0.0, 1.0, 7)
    path = Path(s, np.column_stack([np.sin(s), s**2]))
    t = np.linspace(0.0, 2.0, 9)
    u = t / 2.0
    sd, sdd = np.full_like(t, 0.5), np.zeros_like(t)
    traj = path.timed(t, u, sd, sdd)
    q, d1, d2 = path.evaluate(u)
    np.testing.assert_allclose(traj.q, q)
    np.testing.assert_allclose(traj.qd, d1 * 0.5)
    np.testing.assert_allclose(traj.qdd, d2 * 0.25)
    # the default spline interpolates the knots
    np.testing.assert_allclose(path.evaluate(s)[0], path.q, atol=1e-14)


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (([0.0, 0.0], [[0.0], [1.0]], [[0.0], [0.0]], [[0.0], [0.0]]), "strictly increasing"),
        (([0.0, np.nan], [[0.0], [1.0]], [[0.0], [0.0]], [[0.0], [0.0]]), "not finite"),
        (([0.0, 1.0], [[0.0]], [[0.0], [0.0]], [[0.0], [0.0]]), "shape"),
    ],
)
def test_bad_trajectories_name_the_culprit(args, match):
    with pytest.raises(ad.ModelError, match=match):
        Trajectory(*args)


def test_then_hold_requires_rest_and_appends_the_dwell():
    t = np.array([0.0, 1.0])
    traj = Trajectory(t, [[0.0], [1.0]], [[0.0], [0.0]], [[0.0], [0.0]])
    held = traj.then_hold(0.5)
    assert held.duration == pytest.approx(1.5)
    np.testing.assert_array_equal(held.q[-1], [1.0])
    moving = Trajectory(t, [[0.0], [1.0]], [[0.0], [1.0]], [[0.0], [0.0]])
    with pytest.raises(ad.ModelError, match="at rest"):
        moving.then_hold(0.5)
