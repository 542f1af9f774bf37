"""armdyn: Cartesian Newton–Euler multibody dynamics with topological projection.

Bodies are described in Cartesian coordinates: centre-of-mass position plus Euler parameters
(unit quaternion, scalar first ``[e0, e1, e2, e3]``), angular velocity in the body frame. Joints
and drives are algebraic constraints; accelerations and Lagrange multipliers (joint reactions,
actuator efforts) come from the augmented system ``[Γ ζᵀ; ζ 0][v'; δ] = [η; −ξ]``, and a
projection keeps the constraints satisfied to round-off.
"""

from armdyn import actuators, identification, motion, scenes, validation
from armdyn._core import (
    Actuator,
    Data,
    Model,
    ModelBuilder,
    ModelError,
    Motor,
    Profile,
    SolverError,
    UrdfError,
    body_accelerations,
    body_forces,
    body_mass_matrix,
    dynamic_parameter_names,
    dynamic_parameters,
    dynamics_cost,
    energy,
    energy_regressor,
    evaluate_constraints,
    forward_dynamics,
    forward_dynamics_derivatives,
    frame_jacobian,
    frame_jacobian_cartesian,
    frame_pose,
    frame_pose_cartesian,
    inverse_dynamics,
    inverse_dynamics_derivatives,
    joint_coordinates,
    joint_reactions,
    joint_torque_regressor,
    mass_matrix,
    profiles,
    state_from_joints,
    urdf_builder,
)
from armdyn.animation import animate  # k3d and trimesh are imported when animate() runs
from armdyn.dynamics import InverseDynamicsResult, driven_inverse_dynamics
from armdyn.mjcf import load_mjcf  # mujoco is imported when load_mjcf runs
from armdyn.simulation import SimulationResult, load_urdf, rollout, simulate
from armdyn.sizing import (
    Catalog,
    DutyCycle,
    JointLoad,
    SizingReport,
    TrajectoryRun,
    duty_cycle,
    gear_ratio_sweep,
    limit_violations,
    load_catalog,
    sizing_report,
    trajectory_run,
)
from armdyn.sizing.select import DrivetrainSelection, select_drivetrain
from armdyn.sweeps import sweep  # dask and xarray are imported when sweep() runs
from armdyn.validation import LagrangeValidator
from armdyn.workprecision import WorkPrecisionResult, work_precision

__version__ = "0.1.0"

__all__ = [
    "Actuator",
    "Catalog",
    "Data",
    "DrivetrainSelection",
    "DutyCycle",
    "InverseDynamicsResult",
    "JointLoad",
    "LagrangeValidator",
    "Model",
    "ModelBuilder",
    "ModelError",
    "Motor",
    "Profile",
    "SimulationResult",
    "SizingReport",
    "SolverError",
    "TrajectoryRun",
    "UrdfError",
    "WorkPrecisionResult",
    "actuators",
    "animate",
    "body_accelerations",
    "body_forces",
    "body_mass_matrix",
    "driven_inverse_dynamics",
    "duty_cycle",
    "dynamic_parameter_names",
    "dynamic_parameters",
    "dynamics_cost",
    "energy",
    "energy_regressor",
    "evaluate_constraints",
    "forward_dynamics",
    "forward_dynamics_derivatives",
    "frame_jacobian",
    "frame_jacobian_cartesian",
    "frame_pose",
    "frame_pose_cartesian",
    "gear_ratio_sweep",
    "identification",
    "inverse_dynamics",
    "inverse_dynamics_derivatives",
    "joint_coordinates",
    "joint_reactions",
    "joint_torque_regressor",
    "limit_violations",
    "load_catalog",
    "load_mjcf",
    "load_urdf",
    "mass_matrix",
    "motion",
    "profiles",
    "rollout",
    "scenes",
    "select_drivetrain",
    "simulate",
    "sizing_report",
    "state_from_joints",
    "sweep",
    "trajectory_run",
    "urdf_builder",
    "validation",
    "work_precision",
]
