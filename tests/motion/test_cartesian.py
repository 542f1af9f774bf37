"""Inverse kinematics and Cartesian moves (armdyn.motion.ik / cartesian): closed forms of planar
arms, the UR5 round trip, lines and arcs to 1e-9 m at any s, slerp against scipy's, the
derivatives against finite differences, branch continuity, singular and unreachable moves,
hostile inputs."""

import armdyn as ad
import numpy as np
import pytest
from armdyn.motion import (
    CartesianPath,
    IKResult,
    arc_move,
    inverse_kinematics,
    linear_move,
    manipulability,
)
from armdyn.motion.ik import Task, rotation_exp, rotation_log
from scipy.spatial.transform import Rotation, Slerp

from benchmarks.common import UR5_Q0, robot_urdf

L1, L2, L3 = 1.0, 0.8, 0.3
PLANAR = [1, 1, 0, 0, 0, 1]
XY = [1, 1, 0, 0, 0, 0]


def _planar(n: int, limits=None):
    """A planar arm of ``n`` revolute joints about z (links L1, L2, L3 along x), frame 'tip' at
    the end of the last link; ``limits`` {joint: (lower, upper)}."""
    b = ad.ModelBuilder()
    x, parent = 0.0, "ground"
    for i, length in enumerate((L1, L2, L3)[:n]):
        b.add_body(f"l{i}", 1.0, np.eye(3) * 0.01, position=(x + length / 2, 0.0, 0.0))
        b.add_revolute(f"j{i}", parent, f"l{i}", (x, 0.0, 0.0), (0.0, 0.0, 1.0))
        x, parent = x + length, f"l{i}"
    b.add_frame("tip", parent, position=(x, 0.0, 0.0))
    for name, (lo, hi) in (limits or {}).items():
        b.set_joint_limits(name, lo, hi)
    return b.finalize()


def _pose(p, phi=0.0):
    t = np.eye(4)
    t[:3, :3] = Rotation.from_rotvec([0.0, 0.0, phi]).as_matrix()
    t[:2, 3] = p
    return t


def _two_link(p, elbow):
    """Closed-form IK of the 2R arm (L1, L2) reaching the point p: elbow = +1 or -1."""
    c2 = (p[0] ** 2 + p[1] ** 2 - L1**2 - L2**2) / (2 * L1 * L2)
    q2 = elbow * np.arccos(c2)
    q1 = np.arctan2(p[1], p[0]) - np.arctan2(L2 * np.sin(q2), L1 + L2 * np.cos(q2))
    return np.array([q1, q2])


@pytest.fixture(scope="module")
def ur5():
    path = robot_urdf("ur5")
    if path is None:
        pytest.skip("example-robot-data is not installed")
    return ad.load_urdf(path)


def _ur5_move(ur5, dp=(0.1, 0.15, -0.2), rotvec=(0.2, -0.3, 0.4)):
    q0 = np.array(UR5_Q0)
    t0 = ad.frame_pose(ur5, q0, "tool0")
    t1 = t0.copy()
    t1[:3, 3] += dp
    t1[:3, :3] = Rotation.from_rotvec(rotvec).as_matrix() @ t0[:3, :3]
    return q0, t0, t1


# ---- inverse kinematics


@pytest.mark.parametrize("elbow", [1, -1])
def test_planar_3r_ik_equals_the_closed_form(elbow):
    model = _planar(3)
    p, phi = np.array([0.9, 0.7]), 0.4
    wrist = p - L3 * np.array([np.cos(phi), np.sin(phi)])
    q12 = _two_link(wrist, elbow)
    want = np.array([*q12, phi - q12.sum()])
    start = want + np.array([0.2, -0.15, 0.1])
    for mask in (None, PLANAR):  # the full pose (the arm's zero rows dropped) or the plane's
        r = inverse_kinematics(model, "tip", _pose(p, phi), start, mask=mask)
        assert isinstance(r, IKResult)
        np.testing.assert_allclose(r.q, want, rtol=0, atol=1e-10)
        assert r.position_error <= 1e-12 and r.orientation_error <= 1e-12
    # the manipulability over (vx, vy, wz): |det J| = L1 L2 |sin q2| for a planar 3R arm
    assert r.manipulability == pytest.approx(L1 * L2 * abs(np.sin(want[1])), rel=1e-12)


@pytest.mark.parametrize("elbow", [1, -1])
def test_planar_2r_position_only_ik_and_manipulability(elbow):
    model = _planar(2)
    p = np.array([1.2, -0.5])
    want = _two_link(p, elbow)
    r = inverse_kinematics(model, "tip", _pose(p, 1.0), want + 0.3, mask=XY)
    np.testing.assert_allclose(r.q, want, rtol=0, atol=1e-10)
    # Yoshikawa's closed form for the 2R arm: w = L1 L2 |sin q2|
    qs = np.array([[0.3, 0.2], [-1.0, 1.5], [2.0, -2.5], [0.0, 0.0]])
    np.testing.assert_allclose(
        manipulability(model, qs, "tip", mask=XY), L1 * L2 * np.abs(np.sin(qs[:, 1])), atol=1e-15
    )
    assert manipulability(model, qs[0], "tip", mask=XY) == pytest.approx(
        L1 * L2 * np.sin(0.2), rel=1e-13
    )
    assert manipulability(model, qs[0], "tip") == 0.0  # 2 joints cannot span 6 rows


def test_ur5_round_trip(ur5):
    rng = np.random.default_rng(7)
    for _ in range(12):
        q = rng.uniform(-np.pi, np.pi, 6)
        target = ad.frame_pose(ur5, q, "tool0")
        r = inverse_kinematics(ur5, "tool0", target, q + rng.normal(0.0, 0.2, 6))
        got = ad.frame_pose(ur5, r.q, "tool0")
        assert np.max(np.abs(got[:3, 3] - target[:3, 3])) <= 1e-12
        assert np.max(np.abs(got[:3, :3] - target[:3, :3])) <= 1e-12
        assert r.position_error <= 1e-12 and r.orientation_error <= 1e-12
        j = ad.frame_jacobian(ur5, r.q, "tool0")
        assert r.manipulability == pytest.approx(abs(np.linalg.det(j)), rel=1e-10)
        assert np.all(r.q >= ur5.coord_lower) and np.all(r.q <= ur5.coord_upper)


def test_ik_respects_joint_limits():
    model = _planar(2, limits={"j1": (0.1, 2.0)})
    p = np.array([1.0, 0.9])
    want = _two_link(p, +1)  # q2 > 0: the only branch within j1's limits
    assert 0.1 < want[1] < 2.0
    r = inverse_kinematics(model, "tip", _pose(p), [0.0, -0.8], mask=XY)  # starts below 0.1
    np.testing.assert_allclose(r.q, want, rtol=0, atol=1e-10)
    near = np.array([L1 + L2 * np.cos(2.4), L2 * np.sin(2.4)])  # needs |q2| = 2.4 > 2.0
    with pytest.raises(ad.SolverError, match=r"joints at their limits: 'j1'") as err:
        inverse_kinematics(model, "tip", _pose(near), [0.0, 1.0], mask=XY)
    assert "position error" in str(err.value)


def test_jdot_qdot_equals_a_difference_of_the_jacobian(ur5):
    """The exact J̇ q̇ against a central difference of armdyn.frame_jacobian (h = 1e-5: error
    about 1e-10), on the UR5 and on a chain with prismatic and cylindrical joints."""
    b = ad.ModelBuilder()
    b.add_body("a", 1.0, np.eye(3) * 0.01, position=(0.2, 0.0, 0.0))
    b.add_revolute("r1", "ground", "a", (0, 0, 0), (0, 0, 1))
    b.add_body("b", 1.0, np.eye(3) * 0.01, position=(0.5, 0.0, 0.0))
    b.add_prismatic("p2", "a", "b", (0.4, 0, 0), (1, 0, 0.5))
    b.add_body("c", 1.0, np.eye(3) * 0.01, position=(0.8, 0.0, 0.1))
    b.add_revolute("r3", "b", "c", (0.7, 0, 0), (0, 1, 0))
    b.add_body("d", 1.0, np.eye(3) * 0.01, position=(0.9, 0.0, 0.3))
    b.add_cylindrical("c4", "c", "d", (0.85, 0, 0.2), (0.3, 1, 0.2))
    b.add_frame("tip", "d", position=(0.9, 0.1, 0.4))
    rng = np.random.default_rng(3)
    for model, frame in ((ur5, "tool0"), (b.finalize(), "tip")):
        task = Task("test", model, frame)
        n = model.n_coords
        q, qd = rng.uniform(-2, 2, (4, n)), rng.normal(size=(4, n))
        h = 1e-5
        jp = ad.frame_jacobian(model, q + h * qd, frame)
        jm = ad.frame_jacobian(model, q - h * qd, frame)
        want = np.einsum("rij,rj->ri", (jp - jm) / (2 * h), qd)
        got = task.jdot_qdot(q, ad.frame_jacobian(model, q, frame), qd)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-8 * np.abs(want).max())


def test_rotation_log_and_exp_equal_scipys_at_every_angle():
    """The IK's rotation error (log) and the slerp (exp) against scipy's rotation vectors, from
    1e-15 rad to the half turn (where the log's axis comes from the symmetric part)."""
    rng = np.random.default_rng(11)
    axis = rng.normal(size=(4000, 3))
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    angle = np.concatenate(
        [
            rng.uniform(0.0, np.pi, 1000),
            10 ** rng.uniform(-15, -1, 1000),
            np.pi - 10 ** rng.uniform(-12, -1, 1000),
            rng.uniform(1.5, 1.7, 1000),
        ]
    )
    w = axis * angle[:, None]
    r = Rotation.from_rotvec(w).as_matrix()
    np.testing.assert_allclose(rotation_log(r), w, rtol=0, atol=1e-14)
    np.testing.assert_allclose(rotation_exp(w), r, rtol=0, atol=1e-15)
    np.testing.assert_allclose(rotation_log(np.diag([-1.0, -1.0, 1.0])), [0, 0, np.pi], atol=1e-15)
    assert not np.any(rotation_log(np.eye(3)))


# ---- linear moves


def _distance_to_line(x, p0, p1):
    d = (p1 - p0) / np.linalg.norm(p1 - p0)
    r = x - p0
    return np.linalg.norm(r - np.outer(r @ d, d), axis=1), r @ d


def test_linear_move_stays_on_the_line_at_any_s(ur5):
    q0, t0, t1 = _ur5_move(ur5)
    path = linear_move(ur5, "tool0", q0, t1)
    assert isinstance(path, CartesianPath) and path.info["method"] == "linear_move"
    np.testing.assert_allclose(path.q[0], q0, rtol=0, atol=1e-12)
    rng = np.random.default_rng(1)
    s = np.sort(np.concatenate([np.linspace(0, 1, 1001), rng.uniform(0, 1, 200)]))
    q, _, _ = path.evaluate(s)
    length = np.linalg.norm(t1[:3, 3] - t0[:3, 3])
    for qs, ss in ((q, s), (path.q, path.s)):  # anywhere, and at the knots
        poses = ad.frame_pose(ur5, qs, "tool0")
        off, along = _distance_to_line(poses[:, :3, 3], t0[:3, 3], t1[:3, 3])
        assert off.max() <= 1e-9
        np.testing.assert_allclose(along, ss * length, rtol=0, atol=1e-9)
        # the orientation is scipy's slerp between the two ends
        slerp = Slerp([0.0, 1.0], Rotation.from_matrix([t0[:3, :3], t1[:3, :3]]))
        np.testing.assert_allclose(poses[:, :3, :3], slerp(ss).as_matrix(), rtol=0, atol=1e-9)
    np.testing.assert_allclose(path.poses, ad.frame_pose(ur5, path.q, "tool0"), atol=1e-12)
    np.testing.assert_allclose(
        path.manipulability, np.abs(np.linalg.det(ad.frame_jacobian(ur5, path.q, "tool0")))
    )
    assert path.info["lowest_manipulability"] == path.manipulability.min()


def test_a_path_evaluates_the_same_from_several_threads(ur5):
    from concurrent.futures import ThreadPoolExecutor

    q0, _, t1 = _ur5_move(ur5)
    path = linear_move(ur5, "tool0", q0, t1)
    grids = [np.linspace(0.0, 1.0, 301) ** k for k in (1, 2, 3, 4)]
    serial = [path.evaluate(g) for g in grids]
    with ThreadPoolExecutor(4) as pool:
        parallel = list(pool.map(path.evaluate, grids * 3))
    for got, want in zip(parallel, serial * 3, strict=True):
        for a, b in zip(got, want, strict=True):
            np.testing.assert_array_equal(a, b)


def test_linear_move_derivatives_equal_finite_differences(ur5):
    """dq/ds against central differences of the exact q(s), d2q/ds2 against those of dq/ds
    (h = 1e-4: truncation about 1e-8, the IK's 1e-12 noise / h about 1e-8)."""
    q0, _, t1 = _ur5_move(ur5)
    path = linear_move(ur5, "tool0", q0, t1, samples=5)
    s, h = np.linspace(0.05, 0.95, 13), 1e-4
    qp, dp, _ = path.evaluate(s + h)
    qm, dm, _ = path.evaluate(s - h)
    _, d1, d2 = path.evaluate(s)
    np.testing.assert_allclose(d1, (qp - qm) / (2 * h), rtol=0, atol=1e-6 * np.abs(d1).max())
    np.testing.assert_allclose(d2, (dp - dm) / (2 * h), rtol=0, atol=1e-6 * np.abs(d2).max())
    assert np.abs(d2).max() > 0.1  # a straight line is not straight in the joints


def test_a_timed_linear_move_stays_on_the_line(ur5):
    """Path.timed evaluates the path on the timing's own grid: every sample on the line, and
    the frame's velocity along it."""
    q0, t0, t1 = _ur5_move(ur5, dp=(-0.2, 0.1, 0.05), rotvec=(0.0, 0.0, 0.0))
    path = linear_move(ur5, "tool0", q0, t1[:3, 3])  # a position: the orientation is kept
    t = np.linspace(0.0, 2.0, 777)
    x = t / 2.0
    s, sd, sdd = 10 * x**3 - 15 * x**4 + 6 * x**5, (30 * x**2 - 60 * x**3 + 30 * x**4) / 2, None
    sdd = (60 * x - 180 * x**2 + 120 * x**3) / 4
    traj = path.timed(t, s, sd, sdd)
    poses = ad.frame_pose(ur5, traj.q, "tool0")
    off, _ = _distance_to_line(poses[:, :3, 3], t0[:3, 3], t1[:3, 3])
    assert off.max() <= 1e-9
    np.testing.assert_allclose(
        poses[:, :3, :3], np.broadcast_to(t0[:3, :3], (777, 3, 3)), atol=1e-9
    )
    twist = np.einsum("rij,rj->ri", ad.frame_jacobian(ur5, traj.q, "tool0"), traj.qd)
    np.testing.assert_allclose(twist[:, :3], np.outer(sd, t1[:3, 3] - t0[:3, 3]), rtol=0, atol=1e-9)
    np.testing.assert_allclose(twist[:, 3:], 0.0, atol=1e-9)


def test_planar_3r_linear_move_against_the_closed_form():
    model = _planar(3)
    p0, phi0 = np.array([1.2, 0.3]), 0.2
    wrist = p0 - L3 * np.array([np.cos(phi0), np.sin(phi0)])
    q12 = _two_link(wrist, 1)
    q_start = np.array([*q12, phi0 - q12.sum()])
    p1, phi1 = np.array([0.6, 1.0]), 0.9
    path = linear_move(model, "tip", q_start, _pose(p1, phi1), mask=PLANAR)
    s = np.linspace(0.0, 1.0, 97)
    q, _, _ = path.evaluate(s)
    for si, qi in zip(s, q, strict=True):
        p, phi = p0 + si * (p1 - p0), phi0 + si * (phi1 - phi0)
        w = _two_link(p - L3 * np.array([np.cos(phi), np.sin(phi)]), 1)
        np.testing.assert_allclose(qi, [*w, phi - w.sum()], rtol=0, atol=1e-10)


# ---- arcs


def _circle(p0, pv, p1):
    """Centre, radius and unit normal of the circle through three points (a linear solve)."""
    n = np.cross(pv - p0, p1 - p0)
    a = np.array([pv - p0, p1 - p0, n])
    rhs = np.array([(pv @ pv - p0 @ p0) / 2, (p1 @ p1 - p0 @ p0) / 2, n @ p0])
    c = np.linalg.solve(a, rhs)
    return c, np.linalg.norm(p0 - c), n / np.linalg.norm(n)


def test_arc_move_stays_on_its_circle_and_passes_the_via_point(ur5):
    q0, t0, t1 = _ur5_move(ur5)
    via = 0.5 * (t0[:3, 3] + t1[:3, 3]) + np.array([0.08, -0.05, 0.03])
    path = arc_move(ur5, "tool0", q0, via, t1)
    c, radius, n = _circle(t0[:3, 3], via, t1[:3, 3])
    s = np.linspace(0.0, 1.0, 1501)
    q, d1, _ = path.evaluate(s)
    poses = ad.frame_pose(ur5, q, "tool0")
    x = poses[:, :3, 3]
    np.testing.assert_allclose(np.linalg.norm(x - c, axis=1), radius, rtol=0, atol=1e-9)
    np.testing.assert_allclose((x - c) @ n, 0.0, atol=1e-9)
    np.testing.assert_allclose(x[-1], t1[:3, 3], atol=1e-12)
    assert np.min(np.linalg.norm(x - via, axis=1)) < 2 * path.info["length"] / 1500
    # constant speed along the arc, one way round: the length is the arc's
    speed = np.linalg.norm(
        np.einsum("rij,rj->ri", ad.frame_jacobian(ur5, q, "tool0"), d1)[:, :3], axis=1
    )
    np.testing.assert_allclose(speed, path.info["length"], rtol=1e-9)
    chord = np.sum(np.linalg.norm(np.diff(x, axis=0), axis=1))
    assert chord == pytest.approx(path.info["length"], rel=1e-6)
    slerp = Slerp([0.0, 1.0], Rotation.from_matrix([t0[:3, :3], t1[:3, :3]]))
    np.testing.assert_allclose(poses[:, :3, :3], slerp(s).as_matrix(), rtol=0, atol=1e-9)


def test_arc_move_goes_the_way_of_the_via_point():
    """A half circle of the 2R arm's tip: via on the far side picks the long way round."""
    model = _planar(2)
    q_start = _two_link(np.array([1.2, 0.0]), 1)
    c, radius = np.array([1.0, 0.0]), 0.2
    # from (1.2, 0) to (1.0, -0.2): through (1.0, 0.2) three quarters of the circle, through
    # (1.2 - 0.2 (1 - cos 45°), -0.2 sin 45°) the short quarter
    short = [1.0 + radius * np.cos(np.pi / 4), -radius * np.sin(np.pi / 4), 0.0]
    for via, turns in (([1.0, 0.2, 0.0], 0.75), (short, 0.25)):
        path = arc_move(model, "tip", q_start, via, [1.0, -0.2, 0.0], mask=XY)
        q, _, _ = path.evaluate(np.linspace(0, 1, 201))
        x = ad.frame_pose(model, q, "tip")[:, :2, 3]
        np.testing.assert_allclose(np.linalg.norm(x - c, axis=1), radius, rtol=0, atol=1e-9)
        assert path.info["length"] == pytest.approx(2 * np.pi * radius * turns, rel=1e-12)
        assert np.min(np.linalg.norm(x - np.asarray(via)[:2], axis=1)) < 2e-3


# ---- branch continuity, singular and unreachable moves


def test_each_branch_is_kept_along_the_move(ur5):
    """Two IK branches of the same start pose: each move stays on its own (the joints never
    come near the other branch), with small steps between knots."""
    q0, t0, t1 = _ur5_move(ur5)
    flipped = inverse_kinematics(ur5, "tool0", t0, q0 + np.array([0, 0.9, -2.4, 1.2, 0, 0])).q
    assert np.max(np.abs(flipped - q0)) > 1.0  # another branch (the elbow flipped)
    a = linear_move(ur5, "tool0", q0, t1, max_joint_step=0.05)
    b = linear_move(ur5, "tool0", flipped, t1, max_joint_step=0.05)
    s = np.linspace(0.0, 1.0, 2001)
    qa, qb = a.evaluate(s)[0], b.evaluate(s)[0]
    assert np.min(np.max(np.abs(qa - qb), axis=1)) > 0.5
    for path, q in ((a, qa), (b, qb)):
        assert np.max(np.abs(np.diff(path.q, axis=0))) <= 0.05
        assert np.max(np.abs(np.diff(q, axis=0))) <= 0.05 * 2000 / (len(path.s) - 1)
        np.testing.assert_allclose(q[-1] - q[0], path.q[-1] - path.q[0], atol=1e-12)
    np.testing.assert_allclose(ad.frame_pose(ur5, qa[-1], "tool0"), t1, atol=1e-12)
    np.testing.assert_allclose(ad.frame_pose(ur5, qb[-1], "tool0"), t1, atol=1e-12)


def test_a_move_into_the_stretched_arm_stops_at_the_singularity():
    model = _planar(2)
    q_start = _two_link(np.array([1.0, 0.5]), 1)
    with pytest.raises(ad.SolverError, match=r"singularity at s = ([0-9.]+)") as err:
        linear_move(model, "tip", q_start, [2.5, 0.0, 0.0], mask=XY, min_manipulability=0.05)
    s = float(str(err.value).split("s = ")[1].split(" ")[0])
    # closed form: the tip at p(s) has L1 L2 |sin q2| = 0.05 where |p(s)| = r* (first time)
    r_star = np.sqrt(L1**2 + L2**2 + 2 * L1 * L2 * np.cos(np.arcsin(0.05 / (L1 * L2))))
    grid = np.linspace(0, 1, 100001)
    dist = np.linalg.norm(np.array([1.0, 0.5]) + np.outer(grid, [1.5, -0.5]), axis=1)
    s_star = grid[np.argmax(dist >= r_star)]
    assert s_star <= s <= s_star + 0.01  # the first knot past it (knots every 0.01 m or less)
    assert "position [" in str(err.value)


def test_a_move_through_the_ur5_wrist_singularity_is_refused(ur5):
    """wrist_2 = 0 puts the UR5's wrist axes 4 and 6 in line (det J = 0): a straight move
    through that pose, from one side to the other, crosses it at s = 0.5 where no knot lies
    (11 knots); det J changes sign between the knots either side, so the move is refused
    there, and the same move stopped before it passes."""
    q_sing = np.array([0.3, -1.0, 1.2, -0.5, 0.0, 0.1])
    assert manipulability(ur5, q_sing, "tool0") == 0.0
    t_sing = ad.frame_pose(ur5, q_sing, "tool0")
    dp, dw = np.array([0.03, 0.02, -0.04]), np.array([0.05, -0.1, 0.08])

    def pose(k):
        t = t_sing.copy()
        t[:3, 3] += k * dp
        t[:3, :3] = Rotation.from_rotvec(k * dw).as_matrix() @ t_sing[:3, :3]
        return t

    q_start = inverse_kinematics(ur5, "tool0", pose(-1), q_sing + np.array([0, 0, 0, 0, 0.1, 0])).q
    with pytest.raises(
        ad.SolverError, match=r"singularity met between s = 0\.45.* and 0\.54.*det J changes sign"
    ):
        linear_move(ur5, "tool0", q_start, pose(1), samples=12)
    before = linear_move(ur5, "tool0", q_start, pose(-0.2), samples=12)
    assert 1e-4 < before.manipulability[-1] < before.manipulability[0]


def test_a_move_blocked_by_a_joint_limit_names_the_first_unreachable_point():
    model = _planar(2, limits={"j1": (0.1, 1.2)})
    q_start = _two_link(np.array([1.5, 0.0]), 1)
    with pytest.raises(ad.SolverError, match=r"unreachable.*'j1'") as err:
        linear_move(model, "tip", q_start, [0.9, 0.0, 0.0], mask=XY)
    s = float(str(err.value).split("s = ")[1].split(" ")[0])
    # closed form: q2 = 1.2 where |p| = sqrt(L1² + L2² + 2 L1 L2 cos 1.2)
    r = np.sqrt(L1**2 + L2**2 + 2 * L1 * L2 * np.cos(1.2))
    s_star = (1.5 - r) / 0.6
    assert s_star < s <= s_star + 1e-6
    x, y, z = (float(v) for v in str(err.value).split("position [")[1].split("]")[0].split(","))
    np.testing.assert_allclose([x, y, z], [1.5 - 0.6 * s, 0.0, 0.0], atol=1e-6)


def test_a_limit_crossed_between_two_knots_is_caught_by_the_midpoint_check():
    """A chord of the 2R arm's reach circle: |p| is smallest at s = 0.5, so the elbow bends
    most there (q2 = 1.180 against 1.118 at the ends, closed form); with the only knots at the
    ends (within j1's upper limit 1.15), the midpoint's exact evaluation finds the limit
    crossed."""
    model = _planar(2, limits={"j1": (-1.15, 1.15)})
    q_start = _two_link(np.array([1.5, -0.3]), 1)
    assert q_start[1] == pytest.approx(np.arccos((1.5**2 + 0.3**2 - L1**2 - L2**2) / 1.6))
    with pytest.raises(ad.SolverError, match=r"at s = 0\.5 joint 'j1' leaves its limits") as err:
        linear_move(model, "tip", q_start, [1.5, 0.3, 0.0], mask=XY, samples=2, max_joint_step=1.0)
    q_mid = float(str(err.value).split("(q = ")[1].rstrip(")"))
    assert q_mid == pytest.approx(np.arccos((1.5**2 - L1**2 - L2**2) / 1.6), abs=1e-8)
    # up to y = -0.22 (|p|² = 2.2984 > L1² + L2² + 2 L1 L2 cos 1.15 = 2.2936): within the limit
    ok = linear_move(model, "tip", q_start, [1.5, -0.22, 0.0], mask=XY)
    assert 1.14 < ok.q[-1, 1] < 1.15


def test_an_unreachable_ur5_target_is_refused_with_where(ur5):
    q0, t0, _ = _ur5_move(ur5)
    with pytest.raises(ad.SolverError, match=r"at s = 0\.[0-9]+.*position \["):
        linear_move(ur5, "tool0", q0, t0[:3, 3] + [2.0, 0.0, 0.0])


# ---- hostile inputs


def _bad_pose(kind):
    t = np.eye(4)
    t[:3, 3] = (0.5, 0.1, 0.3)
    if kind == "nan":
        t[1, 3] = np.nan
    elif kind == "scaled":
        t[:3, :3] *= 1.01
    elif kind == "reflection":
        t[2, 2] = -1.0
    elif kind == "last-row":
        t[3, 0] = 0.1
    elif kind == "shape":
        t = t[:3]
    return t


@pytest.mark.parametrize(
    "kind, pattern",
    [
        ("nan", r"target\[1, 3\] = .*nan.* is not finite"),
        ("scaled", r"target\[:3, :3\] is not a rotation matrix"),
        ("reflection", r"reflection"),
        ("last-row", r"last row"),
        ("shape", r"4x4 pose"),
    ],
)
def test_bad_target_poses_are_refused(ur5, kind, pattern):
    with pytest.raises(ad.ModelError, match=pattern):
        inverse_kinematics(ur5, "tool0", _bad_pose(kind), np.zeros(6))
    with pytest.raises(ad.ModelError, match=pattern):
        linear_move(ur5, "tool0", np.array(UR5_Q0), _bad_pose(kind))


@pytest.mark.parametrize(
    "call, pattern",
    [
        (lambda m, t: inverse_kinematics(m, "nope", t, np.zeros(6)), r"unknown frame 'nope'"),
        (lambda m, t: inverse_kinematics(m, 99, t, np.zeros(6)), r"frame index 99 out of range"),
        (lambda m, t: inverse_kinematics(m, 1.5, t, np.zeros(6)), r"frame must be a frame name"),
        (lambda m, t: inverse_kinematics(m, "world", t, np.zeros(6)), r"not moved by any joint"),
        (lambda m, t: inverse_kinematics(m, "tool0", t, np.zeros(5)), r"q0 must have shape \(6,\)"),
        (lambda m, t: inverse_kinematics(m, "tool0", t, [np.nan] * 6), r"q0\[0\] = .*nan"),
        (lambda m, t: inverse_kinematics(m, "tool0", t, np.zeros(6), tol=-1), r"tol must be"),
        (lambda m, t: inverse_kinematics(m, "tool0", t, np.zeros(6), mask=[1, 1]), r"mask must"),
        (lambda m, t: inverse_kinematics(m, "tool0", t, np.zeros(6), mask=[0] * 6), r"no row"),
        (lambda m, t: inverse_kinematics("ur5", "tool0", t, np.zeros(6)), r"armdyn.Model"),
        (lambda m, t: manipulability(m, np.zeros((2, 5)), "tool0"), r"q must have shape"),
        (lambda m, t: linear_move(m, "tool0", [7.0, 0, 0, 0, 0, 0], t), r"outside joint"),
        (lambda m, t: linear_move(m, "tool0", UR5_Q0, t, samples=1), r"samples must be"),
        (lambda m, t: linear_move(m, "tool0", UR5_Q0, t, samples=10**6), r"samples must be"),
        (lambda m, t: linear_move(m, "tool0", UR5_Q0, [0, 0, 1e10]), r"farther than 1e\+09 m"),
        (lambda m, t: linear_move(m, "tool0", UR5_Q0, t, samples=3, max_step=0.1), r"at most one"),
        (lambda m, t: linear_move(m, "tool0", UR5_Q0, t, max_step=1e-9), r"at most 10000"),
        (lambda m, t: linear_move(m, "tool0", UR5_Q0, t, orientation="lerp"), r"orientation"),
        (lambda m, t: linear_move(m, "tool0", UR5_Q0, t, mask=XY), r"moved by 6 joints .* 2 rows"),
        (lambda m, t: linear_move(m, "tool0", UR5_Q0, t, min_manipulability=np.inf), "min_manip"),
        (lambda m, t: arc_move(m, "tool0", UR5_Q0, [0, 0], t), r"via must be a position \(3,\)"),
        (lambda m, t: arc_move(m, "tool0", UR5_Q0, [np.inf, 0, 0], t), r"via\[0\] = .*inf"),
    ],
)
def test_hostile_arguments_are_named(ur5, call, pattern):
    target = ad.frame_pose(ur5, np.array(UR5_Q0) + 0.05, "tool0")
    with pytest.raises(ad.ModelError, match=pattern):
        call(ur5, target)


def test_panda_redundant_ik_round_trip_within_its_limits():
    """7 joints for 6 rows: the least-norm steps reach the pose (within the Panda's tight
    limits); a Cartesian path, which needs a unique q(s), is refused with what to change."""
    path = robot_urdf("panda")
    if path is None:
        pytest.skip("example-robot-data is not installed")
    panda = ad.load_urdf(path)
    rng = np.random.default_rng(5)
    lo, hi = panda.coord_lower, panda.coord_upper
    for _ in range(6):
        q = lo + (hi - lo) * rng.uniform(0.1, 0.9, panda.n_coords)
        target = ad.frame_pose(panda, q, "panda_hand_tcp")
        start = np.clip(q + rng.normal(0.0, 0.15, panda.n_coords), lo, hi)
        r = inverse_kinematics(panda, "panda_hand_tcp", target, start)
        np.testing.assert_allclose(
            ad.frame_pose(panda, r.q, "panda_hand_tcp"), target, rtol=0, atol=1e-12
        )
        assert np.all(r.q >= lo) and np.all(r.q <= hi)
        j = ad.frame_jacobian(panda, r.q, "panda_hand_tcp")
        assert r.manipulability == pytest.approx(np.sqrt(np.linalg.det(j @ j.T)), rel=1e-10)
    with pytest.raises(ad.ModelError, match=r"moved by 7 joints but the move keeps 6 rows"):
        linear_move(panda, "panda_hand_tcp", r.q, target[:3, 3] + 0.01)


def test_degenerate_moves_are_refused(ur5):
    q0 = np.array(UR5_Q0)
    t0 = ad.frame_pose(ur5, q0, "tool0")
    p0 = t0[:3, 3]
    with pytest.raises(ad.ModelError, match="collinear"):
        arc_move(ur5, "tool0", q0, p0 + np.array([0.05, 0, 0]), p0 + np.array([0.1, 0, 0]))
    with pytest.raises(ad.ModelError, match="collinear or coincide"):
        arc_move(ur5, "tool0", q0, p0, p0 + np.array([0.1, 0, 0]))
    half = t0.copy()
    half[:3, :3] = Rotation.from_rotvec([0, 0, np.pi]).as_matrix() @ t0[:3, :3]
    with pytest.raises(ad.ModelError, match="half turn"):
        linear_move(ur5, "tool0", q0, half)
    path = linear_move(ur5, "tool0", q0, p0 + np.array([0.02, 0, 0]))
    with pytest.raises(ad.ModelError, match="within"):
        path.evaluate([0.5, 1.2])
    with pytest.raises(ad.ModelError, match="s"):
        path.evaluate([np.nan])


def test_a_coupled_joint_on_the_chain_is_refused():
    b = ad.ModelBuilder()
    b.add_body("a", 1.0, np.eye(3) * 0.01, position=(0.5, 0.0, 0.0))
    b.add_revolute("j0", "ground", "a", (0, 0, 0), (0, 0, 1))
    b.add_body("b", 1.0, np.eye(3) * 0.01, position=(1.5, 0.0, 0.0))
    b.add_revolute("j1", "a", "b", (1, 0, 0), (0, 0, 1))
    b.add_coupling("c", "j1", "j0", 2.0)
    b.add_frame("tip", "b", position=(2, 0, 0))
    model = b.finalize()
    with pytest.raises(
        ad.ModelError, match=r"joint 'j1', which moves frame 'tip', follows joint 'j0'"
    ):
        inverse_kinematics(model, "tip", _pose([1.0, 1.0]), np.zeros(model.n_coords), mask=XY)


def test_a_floating_model_is_refused():
    b = ad.ModelBuilder()
    b.add_body("box", 1.0, np.eye(3) * 0.01)
    b.add_free("free", "box")
    b.add_frame("c", "box")
    with pytest.raises(ad.ModelError, match=r"coordinates for .* rates"):
        inverse_kinematics(b.finalize(), "c", np.eye(4), np.zeros(7))


def test_a_zero_length_move_is_a_path_that_stays_put(ur5):
    q0 = np.array(UR5_Q0)
    path = linear_move(ur5, "tool0", q0, ad.frame_pose(ur5, q0, "tool0"))
    q, d1, d2 = path.evaluate(np.linspace(0, 1, 5))
    np.testing.assert_allclose(q, np.tile(q0, (5, 1)), atol=1e-12)
    np.testing.assert_allclose(d1, 0.0, atol=1e-12)
    np.testing.assert_allclose(d2, 0.0, atol=1e-12)
