"""armdyn.motion.profiles: limited point-to-point and via-point moves (ruckig), splines through
timed waypoints, the geometric waypoint path. References: closed forms written here (the
trapezoid; the double-S durations of Biagiotti & Melchiorri, Trajectory Planning for Automatic
Machines and Robots, 2008, sec. 3.4; the two-point cubic and quintic; the cubic and quintic
splines by a dense linear solve of their defining conditions)."""

import itertools
import math
import sys
from pathlib import Path as FilePath

import armdyn as ad
import numpy as np
import pytest
from armdyn.motion import (
    Path,
    Trajectory,
    drive_profile,
    point_to_point,
    spline,
    through_waypoints,
    waypoint_path,
)
from armdyn.motion.profiles import MAX_WAYPOINTS

ROOT = FilePath(__file__).resolve().parents[2]


# ---------------------------------------------------------------- references


def trapezoid(t, d, v, a):
    """(q, qd, qdd) of the rest-to-rest velocity trapezoid over distance d > 0."""
    vp = min(v, math.sqrt(a * d))  # peak: the triangle when the cruise is not reached
    ta = vp / a
    T = 2 * ta + (d - vp * ta) / vp
    t = np.asarray(t, float)
    q = np.where(
        t < ta,
        0.5 * a * t**2,
        np.where(t < T - ta, 0.5 * a * ta**2 + vp * (t - ta), d - 0.5 * a * (T - t) ** 2),
    )
    qd = np.where(t < ta, a * t, np.where(t < T - ta, vp, a * (T - t)))
    qdd = np.where(t < ta, a, np.where(t < T - ta, 0.0, -a))
    return T, q, qd, qdd


def double_s(d, vmax, amax, jmax):
    """Biagiotti & Melchiorri sec. 3.4.1 (eqs. 3.17-3.27) for v0 = v1 = 0, d > 0:
    (T, Tj, Ta, vlim, alim)."""
    if vmax * jmax >= amax**2:  # (3.19): the acceleration limit is reached
        tj, ta = amax / jmax, amax / jmax + vmax / amax
    else:
        tj, ta = math.sqrt(vmax / jmax), 2 * math.sqrt(vmax / jmax)
    tv = d / vmax - ta  # (3.25) with Td = Ta
    if tv > 0:  # case 1: the velocity limit is reached
        return 2 * ta + tv, tj, ta, vmax, jmax * tj
    # case 2 (3.26-3.27): vmax not reached
    tj = amax / jmax
    delta = amax**4 / jmax**2 + 4 * amax * d
    ta = (amax**2 / jmax + math.sqrt(delta)) / (2 * amax)
    if ta < 2 * tj:  # amax not reached either: the limit of the gamma iteration, Ta = 2 Tj
        tj = (d / (2 * jmax)) ** (1 / 3)
        ta = 2 * tj
    alim = jmax * tj
    return 2 * ta, tj, ta, (ta - tj) * alim, alim


def natural_cubic(t, y, x):
    """The natural cubic spline through (t, y) at x: the second derivatives M solve the
    tridiagonal moment equations (dense solve)."""
    m = len(t)
    h = np.diff(t)
    A, r = np.zeros((m, m)), np.zeros(m)
    A[0, 0] = A[-1, -1] = 1.0
    for i in range(1, m - 1):
        A[i, i - 1 : i + 2] = h[i - 1], 2 * (h[i - 1] + h[i]), h[i]
        r[i] = 6 * ((y[i + 1] - y[i]) / h[i] - (y[i] - y[i - 1]) / h[i - 1])
    M = np.linalg.solve(A, r)
    i = np.clip(np.searchsorted(t, x, side="right") - 1, 0, m - 2)
    a, b = t[i + 1] - x, x - t[i]
    hi = h[i]
    return (
        M[i] * a**3 / (6 * hi)
        + M[i + 1] * b**3 / (6 * hi)
        + (y[i] / hi - M[i] * hi / 6) * a
        + (y[i + 1] / hi - M[i + 1] * hi / 6) * b
    )


def quintic_spline(t, y, v0, v1, x):
    """The C4 piecewise quintic through (t, y), end velocities v0, v1, zero end
    accelerations: 6 coefficients per piece from a dense solve of its 6 (m-1) conditions.
    Returns (q, qd, qdd) at x."""
    m = len(t)
    n = 6 * (m - 1)
    A, r = np.zeros((n, n)), np.zeros(n)

    def row(i, tau, der):
        out = np.zeros(n)
        for p in range(der, 6):
            out[6 * i + p] = math.factorial(p) / math.factorial(p - der) * tau ** (p - der)
        return out

    rows = []
    for i in range(m - 1):
        h = t[i + 1] - t[i]
        rows += [(row(i, 0.0, 0), y[i]), (row(i, h, 0), y[i + 1])]
        if i < m - 2:
            rows += [(row(i, h, k) - row(i + 1, 0.0, k), 0.0) for k in range(1, 5)]
    h = t[-1] - t[-2]
    rows += [(row(0, 0.0, 1), v0), (row(0, 0.0, 2), 0.0), (row(m - 2, h, 1), v1)]
    rows += [(row(m - 2, h, 2), 0.0)]
    for k, (a, b) in enumerate(rows):
        A[k], r[k] = a, b
    c = np.linalg.solve(A, r).reshape(m - 1, 6)
    i = np.clip(np.searchsorted(t, x, side="right") - 1, 0, m - 2)
    tau = x - t[i]
    out = []
    for der in range(3):
        s = np.zeros_like(x)
        for p in range(der, 6):
            s += c[i, p] * math.factorial(p) / math.factorial(p - der) * tau ** (p - der)
        out.append(s)
    return out


# ---------------------------------------------------------------- closed forms


@pytest.mark.parametrize(
    ("d", "v", "a"), [(2.0, 1.0, 2.0), (0.1, 1.0, 2.0), (-3.0, 0.7, 0.4)], ids=str
)
def test_trapezoid_matches_its_closed_form(d, v, a):
    traj = point_to_point(0.5, 0.5 + d, max_velocity=v, max_acceleration=a, profile="trapezoidal")
    T, q, qd, qdd = trapezoid(traj.t, abs(d), v, a)
    assert traj.duration == pytest.approx(T, rel=1e-12)
    sign = np.sign(d)
    np.testing.assert_allclose(traj.q[:, 0], 0.5 + sign * q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(traj.qd[:, 0], sign * qd, rtol=0, atol=1e-12)
    # the acceleration steps at 0, ta, T - ta and T: compare away from them
    ta = min(v, math.sqrt(a * abs(d))) / a
    away = np.all(np.abs(traj.t[:, None] - [0.0, ta, T - ta, T]) > 1e-9, axis=1)
    np.testing.assert_allclose(traj.qdd[away, 0], sign * qdd[away], rtol=0, atol=1e-12)
    # the area under the velocity is the distance (trapezoid rule on a fine exact grid)
    fine = traj.sample(np.linspace(0.0, T, 20_001))
    assert np.trapezoid(fine.qd[:, 0], fine.t) == pytest.approx(d, rel=1e-8)
    assert traj.info["method"] == "point_to_point" and traj.info["profile"] == "trapezoidal"
    assert traj.info["max_jerk"] is None


@pytest.mark.parametrize(
    ("d", "vmax", "amax", "jmax"),
    [
        (5.0, 1.0, 2.0, 10.0),  # every limit reached
        (0.8, 2.0, 2.0, 10.0),  # the acceleration limit, not the velocity limit
        (0.01, 1.0, 2.0, 10.0),  # neither: a jerk-only profile
        (3.0, 0.2, 2.0, 10.0),  # the velocity limit, not the acceleration limit
    ],
    ids=["v-and-a", "a-only", "jerk-only", "v-only"],
)
def test_double_s_durations_are_biagiotti_melchiorri(d, vmax, amax, jmax):
    traj = point_to_point([0.0], [d], max_velocity=vmax, max_acceleration=amax, max_jerk=jmax)
    T, tj, ta, vlim, alim = double_s(d, vmax, amax, jmax)
    assert traj.duration == pytest.approx(T, rel=1e-9)
    np.testing.assert_allclose(traj.info["segment_durations"], [T], rtol=1e-9)
    # exact values at the profile's characteristic times: peak acceleration at Tj, peak
    # velocity and half the distance at T/2, the end at rest at the goal
    s = traj.sample([tj, T / 2, T])
    assert s.qdd[0, 0] == pytest.approx(alim, rel=1e-9)
    assert s.qd[1, 0] == pytest.approx(vlim, rel=1e-9)
    assert s.q[1, 0] == pytest.approx(d / 2, rel=1e-9)
    np.testing.assert_allclose([s.q[2, 0], s.qd[2, 0], s.qdd[2, 0]], [d, 0, 0], atol=1e-12)
    # the acceleration phase: ramp of jerk jmax, q = j t^3 / 6 during the first Tj
    early = traj.sample(np.linspace(0.0, tj, 11))
    np.testing.assert_allclose(early.q[:, 0], jmax * early.t**3 / 6, rtol=1e-9, atol=1e-15)
    # the acceleration phase ends at Ta with the peak velocity reached
    end = traj.sample([ta])
    assert end.qd[0, 0] == pytest.approx(vlim, rel=1e-9)
    assert end.qdd[0, 0] == pytest.approx(0.0, abs=1e-9 * alim)


# ---------------------------------------------------------------- limits, synchronisation


def _moves():
    rng = np.random.default_rng(34)
    start = rng.uniform(-2, 2, 4)
    goal = start + np.array([1.5, -0.2, 0.0, -2.5])
    return start, goal, np.array([1.0, 0.5, 2.0, 1.5]), np.array([2.0, 3.0, 1.0, 4.0])


def _assert_within(traj, vmax, amax, jmax):
    fine = traj.sample(dt=1e-4)
    assert np.all(np.abs(fine.qd) <= vmax * (1 + 1e-9) + 1e-12)
    assert np.all(np.abs(fine.qdd) <= amax * (1 + 1e-9) + 1e-12)
    if jmax is not None:
        jerk = np.diff(fine.qdd, axis=0) / np.diff(fine.t)[:, None]
        assert np.all(np.abs(jerk) <= jmax * (1 + 1e-6))
    return fine


@pytest.mark.parametrize("profile", ["double_s", "trapezoidal"])
@pytest.mark.parametrize("synchronize", [True, False])
def test_limits_hold_on_a_fine_grid(profile, synchronize):
    start, goal, v, a = _moves()
    j = 8.0 if profile == "double_s" else None
    traj = point_to_point(
        start,
        goal,
        max_velocity=v,
        max_acceleration=a,
        max_jerk=j,
        profile=profile,
        synchronize=synchronize,
    )
    fine = _assert_within(traj, v, a, j)
    np.testing.assert_allclose(fine.q[-1], goal, atol=1e-12)
    np.testing.assert_allclose(fine.qd[[0, -1]], 0.0, atol=1e-12)
    # the limits are reached by the slowest joint: the profile is time-optimal
    assert np.max(np.abs(fine.qd) / v) > 0.5


def test_synchronised_joints_arrive_together():
    start, goal, v, a = _moves()
    traj = point_to_point(start, goal, max_velocity=v, max_acceleration=a, max_jerk=8.0)
    moving = goal != start
    alone = [
        double_s(abs(g - s), vi, ai, 8.0)[0]
        for s, g, vi, ai in zip(start[moving], goal[moving], v[moving], a[moving], strict=True)
    ]
    assert traj.duration == pytest.approx(max(alone), rel=1e-9)
    # these limits leave no common phase profile: ruckig's time synchronisation
    np.testing.assert_array_equal(traj.info["phase_synchronized"], [False])
    # every moving joint is still short of its goal just before the end; the still joint stays
    before = traj.sample([traj.duration - 1e-3])
    assert np.all(np.abs(before.q[0, moving] - goal[moving]) > 1e-9)
    np.testing.assert_array_equal(traj.q[:, ~moving], np.tile(start[~moving], (len(traj), 1)))


@pytest.mark.parametrize("profile", ["double_s", "trapezoidal"])
def test_synchronised_joints_with_common_limits_move_on_the_line(profile):
    """Phase synchronisation: with the same limits for every joint, the joint with the
    longest distance sets the pace and every joint covers the same fraction of its distance
    at every instant (the straight line in joint space)."""
    start, goal, _, _ = _moves()
    j = 8.0 if profile == "double_s" else None
    traj = point_to_point(
        start, goal, max_velocity=1.0, max_acceleration=2.0, max_jerk=j, profile=profile
    )
    d = goal - start
    moving = d != 0
    lead = int(np.argmax(np.abs(d)))
    if profile == "double_s":
        assert traj.duration == pytest.approx(double_s(abs(d[lead]), 1.0, 2.0, 8.0)[0], rel=1e-9)
    else:
        assert traj.duration == pytest.approx(trapezoid([0.0], abs(d[lead]), 1.0, 2.0)[0])
    np.testing.assert_array_equal(traj.info["phase_synchronized"], [True])
    frac = (traj.q[:, moving] - start[moving]) / d[moving]
    np.testing.assert_allclose(frac, np.tile(frac[:, [0]], (1, moving.sum())), rtol=0, atol=1e-9)


def test_per_joint_profiles_are_each_time_optimal():
    start, goal, v, a = _moves()
    traj = point_to_point(
        start, goal, max_velocity=v, max_acceleration=a, max_jerk=8.0, synchronize=False
    )
    want = [
        double_s(abs(g - s), vi, ai, 8.0)[0] if g != s else 0.0
        for s, g, vi, ai in zip(start, goal, v, a, strict=True)
    ]
    np.testing.assert_allclose(traj.info["joint_durations"], want, rtol=1e-9)
    # each joint is at rest at its goal from its own arrival on
    assert traj.duration == pytest.approx(max(want), rel=1e-12)
    for j in np.flatnonzero(np.array(want) < 0.9 * traj.duration):
        after = traj.sample(np.linspace(want[j], traj.duration, 5))
        np.testing.assert_allclose(after.q[:, j], goal[j], atol=1e-12)
        np.testing.assert_allclose(after.qd[:, j], 0.0, atol=1e-12)


# ---------------------------------------------------------------- via points

WAYPOINTS = np.array(
    [[0.0, 0.0, 0.5], [0.6, 0.4, 0.5], [1.4, 0.9, 0.2], [1.5, 0.3, -0.4], [0.5, -0.2, -0.4]]
)


@pytest.mark.parametrize("profile", ["double_s", "trapezoidal"])
def test_through_waypoints_is_continuous_at_the_joins(profile):
    j = 6.0 if profile == "double_s" else None
    v, a = np.array([1.0, 0.8, 1.2]), 2.0
    traj = through_waypoints(
        WAYPOINTS, max_velocity=v, max_acceleration=a, max_jerk=j, profile=profile
    )
    times = traj.info["waypoint_times"]
    # it passes every waypoint, at the velocity it chose, at its time
    at = traj.sample(times)
    np.testing.assert_allclose(at.q, WAYPOINTS, atol=1e-9)
    np.testing.assert_allclose(at.qd, traj.info["waypoint_velocities"], atol=1e-9)
    assert np.any(np.abs(traj.info["waypoint_velocities"]) > 0.05)  # it does not stop
    # continuous across each join: position and velocity always, acceleration with jerk limits
    eps = 1e-9
    for tk in times[1:-1]:
        side = traj.sample([tk - eps, tk + eps])
        np.testing.assert_allclose(side.q[0], side.q[1], rtol=0, atol=2 * np.max(v) * eps)
        np.testing.assert_allclose(side.qd[0], side.qd[1], rtol=0, atol=2.001 * a * eps)
        if j is not None:  # the acceleration too: zero at the waypoint
            np.testing.assert_allclose(side.qdd, 0.0, rtol=0, atol=j * eps + 1e-12)
    fine = _assert_within(traj, v, a, j)
    # no overshoot: inside each segment every joint stays between the segment's end values
    k = np.clip(np.searchsorted(times, fine.t, side="right") - 1, 0, len(times) - 2)
    lo = np.minimum(WAYPOINTS[k], WAYPOINTS[k + 1]) - 1e-9
    hi = np.maximum(WAYPOINTS[k], WAYPOINTS[k + 1]) + 1e-9
    assert np.all((fine.q >= lo) & (fine.q <= hi))
    # faster than stopping at every waypoint, whose segments are each time-optimal
    stop = through_waypoints(
        WAYPOINTS,
        max_velocity=v,
        max_acceleration=a,
        max_jerk=j,
        profile=profile,
        stop_at_waypoints=True,
    )
    legs = [
        point_to_point(
            p, q, max_velocity=v, max_acceleration=a, max_jerk=j, profile=profile
        ).duration
        for p, q in itertools.pairwise(WAYPOINTS)
    ]
    np.testing.assert_allclose(stop.info["segment_durations"], legs, rtol=1e-12)
    assert traj.duration < stop.duration


def test_evaluation_is_ruckigs_at_time():
    """The closed-form phase integration equals ruckig's own Trajectory.at_time on segments
    solved here directly from the waypoints and the velocities the planner chose; so does the
    at_time fallback."""
    import ruckig
    from armdyn.motion import profiles

    traj = through_waypoints(WAYPOINTS, max_velocity=1.0, max_acceleration=2.0, max_jerk=6.0)
    vel, times = traj.info["waypoint_velocities"], traj.info["waypoint_times"]
    x = np.sort(np.random.default_rng(7).uniform(0.0, traj.duration, 300))
    got = traj.sample(x)
    for k in range(len(WAYPOINTS) - 1):
        inp = ruckig.InputParameter(3)
        inp.current_position, inp.current_velocity = WAYPOINTS[k], vel[k]
        inp.target_position, inp.target_velocity = WAYPOINTS[k + 1], vel[k + 1]
        inp.max_velocity, inp.max_acceleration, inp.max_jerk = [1.0] * 3, [2.0] * 3, [6.0] * 3
        inp.synchronization = ruckig.Synchronization.Phase
        seg = ruckig.Trajectory(3)
        assert ruckig.Ruckig(3).calculate(inp, seg) == ruckig.Result.Working
        assert seg.duration == pytest.approx(times[k + 1] - times[k], rel=1e-12)
        inside = (x >= times[k]) & (x < times[k + 1])
        want = np.array([seg.at_time(xi - times[k]) for xi in x[inside]])
        for r, got_r in enumerate((got.q, got.qd, got.qdd)):
            np.testing.assert_allclose(got_r[inside], want[:, r], rtol=0, atol=1e-12)
    # the per-sample at_time path (taken when ruckig adds a brake phase) gives the same
    lim = (np.ones(3), np.full(3, 2.0), np.full(3, 6.0))
    fast, _ = profiles._chain("test", WAYPOINTS, [0, 1, 2], lim, False)
    slow, _ = profiles._chain("test", WAYPOINTS, [0, 1, 2], lim, False, phases=False)
    assert fast.segments is None and slow.tables is None
    np.testing.assert_allclose(slow.at(x), fast.at(x), rtol=0, atol=1e-12)


def test_through_waypoints_per_joint_runs_each_column():
    traj = through_waypoints(
        WAYPOINTS, max_velocity=1.0, max_acceleration=2.0, max_jerk=6.0, synchronize=False
    )
    durations = traj.info["segment_durations"]
    assert durations.shape == (3, 4)
    for j in range(3):
        times = np.concatenate([[0.0], np.cumsum(durations[j])])
        at = np.array([traj.sample([tk]).q[0, j] for tk in times])  # some legs last 0 s
        np.testing.assert_allclose(at, WAYPOINTS[:, j], atol=1e-9)
        # each column alone gives the same motion
        alone = through_waypoints(
            WAYPOINTS[:, j], max_velocity=1.0, max_acceleration=2.0, max_jerk=6.0
        )
        np.testing.assert_allclose(alone.duration, times[-1], rtol=1e-12)
    np.testing.assert_allclose(traj.duration, np.max(np.sum(durations, axis=1)), rtol=1e-12)
    _assert_within(traj, 1.0, 2.0, 6.0)


@pytest.mark.parametrize("seed", range(6))
def test_random_via_point_moves_stay_within_limits_and_between_waypoints(seed):
    """Random waypoints (some joints still on some legs), limits and profiles: every solve
    succeeds, every limit holds on a fine grid, and inside each leg every joint stays
    between the leg's end values (the pass-through velocities never force an overshoot)."""
    rng = np.random.default_rng(seed)
    n, m = int(rng.integers(1, 5)), int(rng.integers(3, 7))
    steps = rng.normal(0.0, 1.0, (m, n)) * rng.choice([1.0, 0.01, 0.0], (m, n), p=[0.8, 0.1, 0.1])
    wp = np.cumsum(steps, axis=0)
    v, a = rng.uniform(0.2, 3.0, n), rng.uniform(0.2, 5.0, n)
    for profile, j in (("double_s", rng.uniform(1.0, 50.0, n)), ("trapezoidal", None)):
        traj = through_waypoints(
            wp, max_velocity=v, max_acceleration=a, max_jerk=j, profile=profile, dt=0.01
        )
        fine = _assert_within(traj, v, a, j)
        times = traj.info["waypoint_times"]
        k = np.clip(np.searchsorted(times, fine.t, side="right") - 1, 0, m - 2)
        lo = np.minimum(wp[k], wp[k + 1]) - 1e-9
        hi = np.maximum(wp[k], wp[k + 1]) + 1e-9
        assert np.all((fine.q >= lo) & (fine.q <= hi))


# ---------------------------------------------------------------- splines


def test_two_point_quintic_and_cubic_are_the_classic_moves():
    T, d = 2.0, np.array([1.0, -0.5])
    for kind, shape in (
        (
            "quintic",
            lambda u: (
                10 * u**3 - 15 * u**4 + 6 * u**5,
                30 * u**2 - 60 * u**3 + 30 * u**4,
                60 * u - 180 * u**2 + 120 * u**3,
            ),
        ),
        ("cubic", lambda u: (3 * u**2 - 2 * u**3, 6 * u - 6 * u**2, 6 - 12 * u)),
    ):
        traj = spline([1.0, 1.0 + T], [np.zeros(2), d], kind=kind, dt=0.01)
        u = (traj.t - 1.0) / T
        s, sd, sdd = shape(u)
        np.testing.assert_allclose(traj.q, np.outer(s, d), atol=1e-12)
        np.testing.assert_allclose(traj.qd, np.outer(sd / T, d), atol=1e-11)
        np.testing.assert_allclose(traj.qdd, np.outer(sdd / T**2, d), atol=1e-10)
        assert traj.t[0] == 1.0 and traj.duration == pytest.approx(T)


def test_natural_cubic_spline_is_the_moment_solution():
    t = np.array([0.0, 0.7, 1.5, 2.0, 3.2])
    y = np.array([[0.0, 1.0], [0.5, 0.2], [0.1, -0.3], [0.9, 0.0], [1.2, 0.6]])
    traj = spline(t, y, kind="cubic", end_conditions="natural", dt=0.01)
    x = np.linspace(0.0, 3.2, 97)
    got = traj.sample(x).q
    for j in range(2):
        np.testing.assert_allclose(got[:, j], natural_cubic(t, y[:, j], x), atol=1e-12)
    np.testing.assert_allclose(traj.sample([0.0, 3.2]).qdd, 0.0, atol=1e-12)


def test_quintic_spline_is_the_c4_solution_with_its_end_conditions():
    t = np.array([0.0, 0.5, 1.3, 2.0, 2.4, 3.0])
    y = np.array([[0.0], [0.4], [0.1], [0.8], [1.0], [0.3]])
    v_ends = np.array([[0.2], [-0.1]])
    traj = spline(t, y, end_velocities=v_ends, dt=0.01)
    x = np.linspace(0.0, 3.0, 151)
    got = traj.sample(x)
    want = quintic_spline(t, y[:, 0], 0.2, -0.1, x)
    for g, w in zip((got.q, got.qd, got.qdd), want, strict=True):
        np.testing.assert_allclose(g[:, 0], w, atol=1e-9)
    # the exact peaks in info bound the samples and are reached
    fine = traj.sample(dt=1e-4)
    peak = traj.info["peak_velocity"][0]
    assert np.max(np.abs(fine.qd)) <= peak * (1 + 1e-12)
    assert np.max(np.abs(fine.qd)) == pytest.approx(peak, rel=1e-6)


def test_cubic_end_conditions():
    t = np.array([0.0, 1.0, 2.5, 4.0])
    y = np.array([[0.0], [1.0], [-0.5], [0.0]])
    clamped = spline(t, y, kind="cubic", end_velocities=[[0.3], [-0.2]])
    np.testing.assert_allclose(clamped.sample([0.0, 4.0]).qd[:, 0], [0.3, -0.2], atol=1e-12)
    periodic = spline(t, y, kind="cubic", end_conditions="periodic").sample([0.0, 4.0])
    np.testing.assert_allclose(periodic.qd[0], periodic.qd[1], atol=1e-12)
    np.testing.assert_allclose(periodic.qdd[0], periodic.qdd[1], atol=1e-12)
    nak = spline(t, y, kind="cubic", end_conditions="not-a-knot")
    third = [np.diff(nak.sample([a, b]).qdd[:, 0]) / (b - a) for a, b in ((0.1, 0.9), (1.1, 2.4))]
    assert third[0] == pytest.approx(third[1], rel=1e-9)  # one cubic over the first two pieces


def test_spline_over_a_limit_names_the_joint_and_time():
    t, y = [0.0, 0.5], [[0.0, 0.0], [0.1, 2.0]]
    with pytest.raises(ad.SolverError, match=r"joint 1 reaches velocity 7\.5 at t = 0\.25 s"):
        spline(t, y, max_velocity=[1.0, 3.0])
    with pytest.raises(ad.SolverError, match=r"joint 1 reaches acceleration .* above max_accel"):
        spline(t, y, max_acceleration=20.0)
    ok = spline(t, y, max_velocity=[1.0, 8.0], max_acceleration=[3.0, 50.0])
    np.testing.assert_allclose(ok.info["peak_velocity"], [0.375, 7.5], rtol=1e-12)  # 15/8 d/T


# ---------------------------------------------------------------- the geometric path


def test_waypoint_path_interpolates_in_chord_length_and_keeps_lines_straight():
    path = waypoint_path(WAYPOINTS)
    assert isinstance(path, Path)
    chords = np.linalg.norm(np.diff(WAYPOINTS, axis=0), axis=1)
    np.testing.assert_allclose(path.s, np.concatenate([[0], np.cumsum(chords)]) / chords.sum())
    np.testing.assert_allclose(path.evaluate(path.s)[0], WAYPOINTS, atol=1e-14)
    # C2 across the interior knots
    for sk in path.s[1:-1]:
        left, right = path.evaluate([sk - 1e-9]), path.evaluate([sk + 1e-9])
        np.testing.assert_allclose(left[1], right[1], atol=1e-6)
        np.testing.assert_allclose(left[2], right[2], atol=1e-5)
    # collinear waypoints at uneven spacing: exactly the straight line at constant dq/ds
    line = np.outer([0.0, 0.1, 0.5, 0.6, 1.0], [1.0, -2.0, 0.5]) + 0.3
    straight = waypoint_path(line)
    s = np.linspace(0.0, 1.0, 41)
    q, d1, d2 = straight.evaluate(s)
    np.testing.assert_allclose(q, 0.3 + np.outer(s, [1.0, -2.0, 0.5]), atol=1e-14)
    np.testing.assert_allclose(d1, np.tile([1.0, -2.0, 0.5], (41, 1)), atol=1e-13)
    np.testing.assert_allclose(d2, 0.0, atol=1e-12)


# ---------------------------------------------------------------- the UR5


def _ur5():
    sys.path.insert(0, str(ROOT))
    from benchmarks.common import robot_urdf

    path = robot_urdf("ur5")
    if path is None:
        pytest.skip("example-robot-data is not installed")
    return ad.load_urdf(path)


def test_ur5_sizing_takes_the_trajectories():
    model = _ur5()
    wp = np.array(
        [
            [0.0, -1.2, 1.0, -1.4, -1.57, 0.0],
            [0.8, -1.0, 1.3, -1.8, -1.57, 0.4],
            [1.6, -1.4, 0.9, -1.2, -1.57, 0.0],
        ]
    )
    traj = through_waypoints(wp, max_acceleration=4.0, max_jerk=40.0, model=model, dt=0.004)
    assert traj.names == tuple(model.coord_names)
    np.testing.assert_allclose(traj.info["max_velocity"], model.coord_velocity_limit)
    run = ad.trajectory_run(model, traj)
    k = len(traj) // 3
    np.testing.assert_allclose(
        run.joint_torques[k],
        ad.inverse_dynamics(model, traj.q[k], traj.qd[k], traj.qdd[k]),
        atol=1e-9,
    )
    cycle = ad.duty_cycle(model, traj, dwell=0.5)
    assert cycle is not None
    smooth = spline([0.0, 1.5, 3.0], wp, model=model, dt=0.01)
    ad.duty_cycle(model, smooth.then_hold(0.5))
    with pytest.raises(ad.ModelError, match=r"waypoints\[1\] puts joint 'elbow_joint' at 3\.5"):
        through_waypoints(
            np.vstack([wp[0], [0, 0, 3.5, 0, 0, 0]]),
            max_acceleration=1.0,
            max_jerk=1.0,
            model=model,
        )
    # splines and paths that leave a joint's range between in-range waypoints
    turn = np.zeros((4, 6))
    turn[:, 2] = [0.0, 2.8, 3.1, 2.8]
    with pytest.raises(ad.SolverError, match=r"joint 'elbow_joint' to 3\.2035\d* at t = 2\.61"):
        spline([0.0, 2.0, 3.0, 4.0], turn, model=model)
    turn[:, 2], turn[:, 0] = [0.0, 3.1, 3.1, 0.0], [0.0, 0.0, 1.0, 1.0]
    with pytest.raises(ad.SolverError, match=r"joint 'elbow_joint' to 3\.18152 at s = 0\.5,"):
        waypoint_path(turn, model=model)
    assert waypoint_path(turn).n_joints == 6  # without the model nothing is checked
    with pytest.raises(ad.ModelError, match="2 joints given, the model has 6"):
        point_to_point([0.0, 0.0], [1.0, 1.0], max_acceleration=1.0, max_jerk=1.0, model=model)


def _hinge(gravity=(0.0, 0.0, -9.81)):
    b = ad.ModelBuilder(gravity=gravity)
    b.add_body("link", 1.0, np.diag([0.01, 0.02, 0.025]), position=(0.0, 0.0, -0.5))
    b.add_revolute("hinge", "ground", "link", (0, 0, 0), (0, 1, 0))
    return b


def test_drive_profile_prescribes_the_motion_in_a_simulation():
    """A pendulum driven by the profile follows it exactly, holds its goal afterwards, and the
    drive's effort is the inverse dynamics torque of the motion."""
    free = _hinge().finalize()
    traj = point_to_point(0.2, 1.2, **L, model=free)
    b = _hinge()
    b.add_drive("hinge", drive_profile(traj, "hinge"))
    run = ad.simulate(b.finalize(), traj.duration + 0.3, output_dt=0.01)
    inside = run.t <= traj.duration
    want = traj.sample(run.t[inside])
    np.testing.assert_allclose(run.q[inside, 0], want.q[:, 0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(run.qd[inside, 0], want.qd[:, 0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(run.q[~inside, 0], 1.2, rtol=0, atol=1e-12)
    tau = ad.inverse_dynamics(free, want.q, want.qd, want.qdd)[:, 0]
    np.testing.assert_allclose(run.drive_forces[inside, 0], tau, rtol=0, atol=1e-9)
    assert np.max(np.abs(tau)) > 1.0
    # by index too; refusals
    assert drive_profile(traj, 0)(0.5) == drive_profile(traj, "hinge")(0.5)
    with pytest.raises(ad.ModelError, match=r"joint 'elbow' is not one of traj\.names"):
        drive_profile(traj, "elbow")
    with pytest.raises(ad.ModelError, match="joint must be an integer in"):
        drive_profile(traj, 1)
    moving = drive_profile(spline([0.0, 1.0], [0.0, 1.0], end_velocities=[[0.0], [0.5]]), 0)
    with pytest.raises(ad.ModelError, match=r"t = 1\.5 s is outside .* not at rest at its end"):
        moving(1.5)
    assert moving(-1.0) == (0.0, 0.0, 0.0)


# ---------------------------------------------------------------- hostile inputs

L = {"max_velocity": 1.0, "max_acceleration": 2.0, "max_jerk": 10.0}


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: point_to_point([0.0, np.nan], [1.0, 1.0], **L), r"start\[1\] = .*nan"),
        (lambda: point_to_point([0.0, 0.0], [np.inf, 1.0], **L), r"goal\[0\] = .*inf"),
        (lambda: point_to_point([0.0, 0.0], [1.0, 1.0, 2.0], **L), r"goal must have shape \(2,\)"),
        (
            lambda: point_to_point(0, 1, **{**L, "max_velocity": 0.0}),
            r"max_velocity\[0\] = 0\.0 must be positive",
        ),
        (
            lambda: point_to_point(0, 1, **{**L, "max_acceleration": -1.0}),
            r"max_acceleration\[0\] = -1\.0",
        ),
        (
            lambda: point_to_point(0, 1, **{**L, "max_jerk": np.inf}),
            r"max_jerk\[0\] = inf must be positive and finite",
        ),
        (lambda: point_to_point(0, 1, **{**L, "max_velocity": np.nan}), r"max_velocity\[0\] = nan"),
        (
            lambda: point_to_point([0, 0], [1, 1], **{**L, "max_velocity": [1, 2, 3]}),
            r"max_velocity must be a scalar or have shape \(2,\)",
        ),
        (lambda: point_to_point(0, 1, max_velocity=1.0, max_acceleration=1.0), "needs max_jerk"),
        (lambda: point_to_point(0, 1, **L, profile="trapezoidal"), "max_jerk is not used"),
        (lambda: point_to_point(0, 1, max_velocity=1.0, max_jerk=1.0), "give max_acceleration"),
        (lambda: point_to_point(0, 1, max_acceleration=1.0, max_jerk=1.0), "give max_velocity"),
        (lambda: point_to_point(0, 1, **L, profile="s-curve"), "profile must be"),
        (lambda: point_to_point(0, 1, **L, synchronize="yes"), "synchronize must be True or False"),
        (lambda: point_to_point(0, 1, **L, dt=0.0), "dt must be a positive number"),
        (lambda: point_to_point(0, 1, **L, dt=np.nan), "dt must be a positive number"),
        (
            lambda: point_to_point(0, 1e4, **L, dt=1e-6),
            r"dt = 1e-06 s over .* samples \(> 10000000\)",
        ),
        (lambda: point_to_point(np.zeros(10_001), np.ones(10_001), **L), "10001 joints"),
        (
            lambda: point_to_point(np.zeros(20), np.ones(20), **L, dt=1e-6),
            r"samples of 20 joints \(> 20000000 values\)",
        ),
        (lambda: through_waypoints([[0.0, 1.0]], **L), "at least two points, got 1"),
        (
            lambda: through_waypoints([[0.0, 1.0], [1.0]], **L),
            "waypoints must be an array of numbers",
        ),
        (lambda: through_waypoints([[0.0, 1.0], [1.0, np.nan]], **L), r"waypoints\[1, 1\] = .*nan"),
        (
            lambda: through_waypoints(np.zeros((MAX_WAYPOINTS + 1, 1)), **L),
            r"100001 points \(> 100000\)",
        ),
        (
            lambda: through_waypoints([[0, 0], [1, 1]], **L, stop_at_waypoints=1),
            "stop_at_waypoints must be True",
        ),
        (
            lambda: spline([0.0, 1.0, 1.0], [0.0, 1.0, 2.0]),
            r"times must be strictly increasing \(times\[2\]",
        ),
        (lambda: spline([0.0, 1.0], [0.0, 1.0, 2.0]), "2 times for 3 waypoints"),
        (lambda: spline([0.0], [[0.0, 1.0]]), "at least two points, got 1"),
        (lambda: spline([0.0, np.inf], [0.0, 1.0]), r"times\[1\] = .*inf"),
        (lambda: spline([0.0, 1.0], [0.0, 1.0], kind="septic"), "kind must be"),
        (lambda: spline([0.0, 1.0], [0.0, 1.0], end_conditions="natural"), "kind='cubic' only"),
        (
            lambda: spline([0.0, 1.0], [0.0, 1.0], kind="cubic", end_conditions="periodic"),
            "periodic",
        ),
        (
            lambda: spline([0.0, 1.0], [[0.0, 0.0], [1.0, 1.0]], end_velocities=[1.0, 2.0, 3.0]),
            r"end_velocities must have shape \(2, 2\)",
        ),
        (
            lambda: spline(
                [0.0, 1.0],
                [0.0, 1.0],
                kind="cubic",
                end_conditions="natural",
                end_velocities=[[0.0], [0.0]],
            ),
            "only go with end_conditions='clamped'",
        ),
        (lambda: spline([0.0, 1e9], [0.0, 1.0], dt=1e-3), "dt = 0.001 s over 1e.09 s"),
        (lambda: spline([0.0, 1.0], [0.0, 1.0], max_velocity=-1.0), r"max_velocity\[0\] = -1\.0"),
        (lambda: waypoint_path([[0.0, 1.0]]), "at least two points, got 1"),
        (
            lambda: waypoint_path([[0.0, 1.0], [0.0, 1.0], [1.0, 1.0]]),
            r"waypoints\[0\] and waypoints\[1\] are equal",
        ),
        (lambda: point_to_point(0, 1, **L, model="ur5"), "model must be an armdyn.Model"),
        (lambda: spline([0.0, 1e-300], [0.0, 1e300]), "the spline overflows"),
        (lambda: spline([0, 1, 2], [[0], [1e308], [-1e308]]), "the spline overflows"),
        (lambda: spline([1e15, 1e15 + 1], [0, 1], dt=0.01), "below the floating-point resolution"),
        (
            lambda: waypoint_path([[0.0], [1e308], [-1e308]]),
            r"waypoints\[0\] to waypoints\[1\] overflows",
        ),
    ],
)
def test_hostile_inputs_name_the_argument(call, match):
    with pytest.raises(ad.ModelError, match=match):
        call()


def test_unsolvable_scales_are_solver_errors_naming_the_segment():
    with pytest.raises(ad.SolverError, match=r"segment 0 \(waypoint 0 to 1\) of joint 0: ruckig"):
        point_to_point(0.0, 1e300, **L)


def test_floating_model_is_refused():
    b = ad.ModelBuilder()
    b.add_body("base", 1.0, np.eye(3) * 0.01)
    b.add_free("float", "base")
    model = b.finalize()
    with pytest.raises(ad.ModelError, match="floating base"):
        point_to_point(np.zeros(7), np.ones(7), **L, model=model)


def test_no_motion_is_one_sample_at_rest():
    traj = point_to_point([0.3, -0.2], [0.3, -0.2], **L)
    assert isinstance(traj, Trajectory) and len(traj) == 1 and traj.duration == 0.0
    np.testing.assert_array_equal(traj.q, [[0.3, -0.2]])
    np.testing.assert_array_equal(traj.qd, 0.0)
