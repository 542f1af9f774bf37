"""Motion for design: joint trajectories (point-to-point and through waypoints, trapezoidal,
jerk-limited and spline), Cartesian moves by inverse kinematics, the time-optimal timing of a
path under joint, torque and motor limits (and the shortest repeated cycle within the motors'
thermal limits), and the least-energy motion. Every planner returns a :class:`Trajectory`
(``t, q, qd, qdd``: what ``armdyn.trajectory_run``, ``duty_cycle`` and ``select_drivetrain``
take) or a :class:`Path` (geometric, timed by :func:`time_optimal`).
"""

from armdyn.motion.cartesian import CartesianPath, arc_move, linear_move
from armdyn.motion.energy import least_energy
from armdyn.motion.ik import IKResult, inverse_kinematics, manipulability
from armdyn.motion.profiles import (
    drive_profile,
    point_to_point,
    spline,
    through_waypoints,
    waypoint_path,
)
from armdyn.motion.timing import shortest_cycle, time_optimal
from armdyn.motion.trajectory import Path, Trajectory

__all__ = [
    "CartesianPath",
    "IKResult",
    "Path",
    "Trajectory",
    "arc_move",
    "drive_profile",
    "inverse_kinematics",
    "least_energy",
    "linear_move",
    "manipulability",
    "point_to_point",
    "shortest_cycle",
    "spline",
    "through_waypoints",
    "time_optimal",
    "waypoint_path",
]
