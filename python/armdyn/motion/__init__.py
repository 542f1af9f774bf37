"""Motion for design: joint trajectories (point-to-point and through waypoints, trapezoidal,
jerk-limited and spline), Cartesian moves by inverse kinematics, the time-optimal timing of a
path under joint, torque and motor limits (and the shortest repeated cycle within the motors'
thermal limits), and the least-energy motion. Every planner returns a :class:`Trajectory`
(``t, q, qd, qdd``: what ``armdyn.trajectory_run``, ``duty_cycle`` and ``select_drivetrain``
take) or a :class:`Path` (geometric, timed by :func:`time_optimal`).
"""

from armdyn.motion.energy import least_energy
from armdyn.motion.profiles import (
    drive_profile,
    point_to_point,
    spline,
    through_waypoints,
    waypoint_path,
)
from armdyn.motion.trajectory import Path, Trajectory

__all__ = [
    "Path",
    "Trajectory",
    "drive_profile",
    "least_energy",
    "point_to_point",
    "spline",
    "through_waypoints",
    "waypoint_path",
]
