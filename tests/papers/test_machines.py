"""The closed-loop machines of armdyn.scenes (issue 36): the palletizer and the delta robot
assemble with their actuated joints as the first coordinates and follow their pick-and-place
cycles (checked against their closed-form kinematics: the tool at the waypoints, the wrist
level, the plate translating)."""

import armdyn as ad
import numpy as np
import pytest
from armdyn._rotation import quat_to_rot
from armdyn.scenes import machines as mc


def _body_pose(model, u, body):
    k = model.body_names.index(body)
    return u[..., 7 * k : 7 * k + 3], u[..., 7 * k + 3 : 7 * k + 7]


def _frame_point(model, u, frame):
    """The world position of a named frame from Cartesian rows u (no armdyn kinematics call)."""
    f = model.frame(frame)
    x, e = _body_pose(model, u, f["body"])
    return np.array([xi + quat_to_rot(ei) @ f["point"] for xi, ei in zip(x, e, strict=True)])


@pytest.fixture(scope="module")
def palletizer_cycle():
    traj = mc.pick_and_place("palletizer")
    model = mc.palletizer(drives=traj)
    times = traj.info["waypoint_times"]
    grid = np.union1d(times, np.linspace(0.0, traj.duration, 61))
    return traj, model, ad.driven_inverse_dynamics(model, grid)


@pytest.fixture(scope="module")
def delta_cycle():
    traj = mc.pick_and_place("delta")
    model = mc.delta_robot(drives=traj)
    grid = np.union1d(traj.info["waypoint_times"], np.linspace(0.0, traj.duration, 41))
    return traj, model, ad.driven_inverse_dynamics(model, grid)


def test_palletizer_assembles_with_actuated_joints_first():
    for closure, redundant in (("inline", 0), ("revolute", 9)):
        model = mc.palletizer(closure=closure)
        assert model.mobility == 4
        assert tuple(model.joint_names[:4]) == mc.PALLETIZER_ACTUATED
        assert len(model.redundant_rows) == redundant
        # the assembly pose is the home of the closed-form kinematics
        tool = _frame_point(model, model.u0[None], "tool")[0]
        np.testing.assert_allclose(tool, mc.PalletizerGeometry().points()["tool"], atol=1e-14)
        np.testing.assert_allclose(mc.palletizer_ik(tool), 0.0, atol=1e-14)
    with pytest.raises(ad.ModelError, match="closure"):
        mc.palletizer(closure="weld")


def test_palletizer_cycle_reaches_waypoints_with_the_wrist_level(palletizer_cycle):
    traj, model, idr = palletizer_cycle
    assert idr.position_residual.max() < 1e-10
    np.testing.assert_allclose(idr.q[:, :4], traj.sample(t=idr.t).q, atol=1e-12)
    # the tool passes through every waypoint of the cycle (closed-form inverse kinematics)
    at = np.searchsorted(idr.t, traj.info["waypoint_times"])
    tool = _frame_point(model, idr.u[at], "tool")
    np.testing.assert_allclose(tool, traj.info["tool"], atol=1e-10)
    # the parallelograms hold the wrist level: the flange axis stays vertical along the cycle
    _, e = _body_pose(model, idr.u, "flange")
    axis = np.array([quat_to_rot(ei)[:, 2] for ei in e])
    np.testing.assert_allclose(axis, np.tile([0.0, 0.0, 1.0], (len(e), 1)), atol=1e-10)
    # and the upper arm's pitch is the elbow coordinate: the elbow parallelogram
    _, e = _body_pose(model, idr.u, "upper_arm")
    yaw = idr.q[:, 0]
    forward = np.array([quat_to_rot(ei)[:, 0] for ei in e])
    pitch = np.arctan2(-forward[:, 2], forward[:, 0] * np.cos(yaw) + forward[:, 1] * np.sin(yaw))
    np.testing.assert_allclose(pitch, idr.q[:, 2], atol=1e-10)


def test_palletizer_closures_give_the_same_torques(palletizer_cycle):
    traj, _, idr = palletizer_cycle
    redundant = mc.palletizer(drives=traj, closure="revolute")
    other = ad.driven_inverse_dynamics(redundant, idr.t[::6])
    scale = np.abs(idr.drive_forces).max()
    np.testing.assert_allclose(other.drive_forces, idr.drive_forces[::6], atol=1e-9 * scale)


def test_delta_assembles_with_the_arms_first():
    model = mc.delta_robot()
    assert model.mobility == 3
    assert tuple(model.joint_names[:3]) == mc.DELTA_ACTUATED
    assert len(model.redundant_rows) == 0
    g = mc.DeltaGeometry()
    plate, _ = _body_pose(model, model.u0, "plate")
    np.testing.assert_allclose(plate, [0.0, 0.0, g.plate_z()], atol=1e-15)
    np.testing.assert_allclose(mc.delta_ik(plate), 0.0, atol=1e-14)


def test_delta_cycle_translates_the_plate_through_the_waypoints(delta_cycle):
    traj, model, idr = delta_cycle
    assert idr.position_residual.max() < 1e-10
    np.testing.assert_allclose(idr.q[:, :3], traj.sample(t=idr.t).q, atol=1e-12)
    at = np.searchsorted(idr.t, traj.info["waypoint_times"])
    plate, e = _body_pose(model, idr.u, "plate")
    np.testing.assert_allclose(plate[at], traj.info["tool"], atol=1e-10)
    np.testing.assert_allclose(np.abs(e[:, 0]), 1.0, atol=1e-12)  # the plate never turns
    # the closed-form inverse kinematics along the whole cycle
    np.testing.assert_allclose(mc.delta_ik(plate), idr.q[:, :3], atol=1e-10)


def test_machines_refuse_bad_inputs():
    with pytest.raises(ad.ModelError, match="not an actuated joint"):
        mc.delta_robot(drives={"rod1a": 0.0})
    with pytest.raises(ad.ModelError, match="3 actuated joints"):
        mc.delta_robot(drives=mc.pick_and_place("palletizer"))
    with pytest.raises(ad.ModelError, match="torques must be"):
        mc.delta_robot(torques=[1.0, 2.0, 3.0])
    with pytest.raises(ad.ModelError, match="machine must be"):
        mc.pick_and_place("scara")
    with pytest.raises(ad.ModelError, match="max_velocity"):
        mc.pick_and_place("delta", max_velocity=-1.0)
    with pytest.raises(ad.ModelError, match="dwell"):
        mc.pick_and_place("delta", dwell=float("nan"))
    with pytest.raises(ad.ModelError, match="dt"):
        mc.pick_and_place("delta", dt=1e-12)
    with pytest.raises(ad.ModelError, match="payload"):
        mc.palletizer(payload=-2.0)
    with pytest.raises(ad.ModelError, match=r"geometry\.upper"):
        mc.palletizer(geometry=mc.PalletizerGeometry(upper=float("inf")))
    with pytest.raises(ad.ModelError, match=r"masses\.turret"):
        mc.palletizer(masses=mc.PalletizerMasses(turret=0.0))
    with pytest.raises(ad.ModelError, match=r"geometry\.rod"):
        mc.delta_robot(geometry=mc.DeltaGeometry(rod=0.3))
    with pytest.raises(ad.ModelError, match="tool"):
        mc.palletizer_ik([np.nan, 0.0, 1.0])
    with pytest.raises(ad.ModelError, match="plate"):
        mc.delta_ik([0.0, 0.0])
    with pytest.raises(ad.SolverError, match="tool point 1"):
        mc.palletizer_ik([[1.3, 0.0, 0.6], [5.0, 0.0, 0.6]])
    with pytest.raises(ad.SolverError, match=r"position 0 .* arm1"):
        mc.delta_ik([0.0, 0.0, -3.0])


@pytest.mark.parametrize("machine", ["palletizer", "delta"])
def test_cycle_profiles_are_the_exact_motion(machine):
    """The C++ splines the drives run equal the cycle's closed form (and its derivatives equal
    finite differences of its positions), within the per-joint limits, at rest at both ends."""
    traj = mc.pick_and_place(machine)
    t = np.linspace(0.0, traj.duration, 20001)
    q, qd, qdd = traj.sample(t=t).q, traj.sample(t=t).qd, traj.sample(t=t).qdd
    for i, name in enumerate(traj.names):
        y, yd, ydd = traj.info["profiles"][name].eval(t)
        np.testing.assert_allclose(y, q[:, i], atol=1e-13)
        np.testing.assert_allclose(yd, qd[:, i], atol=1e-12)
        np.testing.assert_allclose(ydd, qdd[:, i], atol=1e-10)
    h, inner = 1e-6, t[1:-1]  # truncation: jerk h²/6 < 1e-9
    fd = (traj.sample(t=inner + h).q - traj.sample(t=inner - h).q) / (2 * h)
    np.testing.assert_allclose(fd, traj.sample(t=inner).qd, atol=1e-8)
    v, a, _ = traj.info["limits"]
    assert np.abs(qd).max() <= v * (1 + 1e-12) and np.abs(qdd).max() <= a * (1 + 1e-12)
    np.testing.assert_allclose(q[[0, -1]], 0.0, atol=1e-15)
    np.testing.assert_allclose(qd[[0, -1]], 0.0, atol=1e-15)


def test_delta_geometry_moments_are_the_models():
    """DeltaGeometry.arm_inertia / arm_moment (the reference's I and S) equal the model's upper
    arms' inertia about their pivot axes and first moment, from the model's own bodies."""
    g = mc.DeltaGeometry()
    model = mc.delta_robot()
    radial, axis = g.directions()
    for i in range(3):
        k = model.body_names.index(f"upper_arm{i + 1}")
        x, e = _body_pose(model, model.u0, f"upper_arm{i + 1}")
        r = x - g.base * radial[i]
        rot = quat_to_rot(e)
        inertia = rot @ model.inertias[k] @ rot.T + model.masses[k] * (
            r @ r * np.eye(3) - np.outer(r, r)
        )
        assert axis[i] @ inertia @ axis[i] == pytest.approx(g.arm_inertia(), rel=1e-14)
        assert model.masses[k] * np.linalg.norm(r) == pytest.approx(g.arm_moment(), rel=1e-14)
