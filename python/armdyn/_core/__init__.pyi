"""
armdyn compiled core: Cartesian Newton-Euler multibody dynamics
"""
from __future__ import annotations
import collections.abc
import numpy
import numpy.typing
import typing
from . import profiles
__all__: list[str] = ['Actuator', 'Data', 'LagrangeValidator', 'Model', 'ModelBuilder', 'ModelError', 'Motor', 'Profile', 'SolverError', 'URDF_COULOMB_SMOOTHING', 'URDF_MAX_ATTRIBUTES', 'URDF_MAX_BYTES', 'UrdfError', 'body_accelerations', 'body_forces', 'body_mass_matrix', 'dynamic_parameter_names', 'dynamic_parameters', 'dynamics_cost', 'end_effector_position', 'energy', 'energy_regressor', 'evaluate_constraints', 'forward_dynamics', 'forward_dynamics_derivatives', 'frame_jacobian', 'frame_jacobian_cartesian', 'frame_pose', 'frame_pose_cartesian', 'inverse_dynamics', 'inverse_dynamics_derivatives', 'joint_coordinates', 'joint_reactions', 'joint_torque_regressor', 'mass_matrix', 'model_with_dynamic_parameters', 'paper_3dof_torques', 'paper_5dof_end_effector', 'profiles', 'state_from_joints', 'torque_error_metrics', 'urdf_builder']
class ModelError(ValueError):
    """
    Bad input: a model, builder call, array shape or option that armdyn refuses, the message naming the culprit (the body, joint, argument and the expected shape). The model or builder is left as it was. A ValueError.
    """
class UrdfError(ModelError):
    """
    A URDF file or string that cannot be loaded: malformed XML, an unsupported element or value, a size limit exceeded; the message names the file, element and attribute. A ModelError.
    """
class SolverError(RuntimeError):
    """
    A run or solve that failed numerically: a singular constraint system, a step size underflow, too many steps, a callback (profile or progress) that raised (chained as the __cause__). The message says where (time, body, row). A RuntimeError.
    """
class Motor:
    """
    A motor's datasheet values, motor side, SI units, every one optional (None when not given): torque_constant [N m/A], resistance [ohm], voltage [V], no_load_speed [rad/s], continuous_torque [N m], peak_torque [N m], max_speed [rad/s], thermal_resistance [K/W], thermal_time_constant [s], rotor_inertia [kg m^2], mass [kg], thermal_resistance_winding [K/W], thermal_resistance_housing [K/W], thermal_time_constant_winding [s], thermal_time_constant_housing [s], max_winding_temperature [degC], brake_torque [N m], and a name. Given values must be finite and > 0 (ModelError naming the field). Attach one with ModelBuilder.add_actuator(..., motor=armdyn.Motor(...)); it does not enter the dynamics (the actuator's rotor inertia, gear ratio and friction do), the motor-side sizing reads it. Keyword-only constructor (the keywords: Motor.FIELDS and name); Motor.from_row(row) from a mapping; comparable (==) and picklable.
    """
    FIELDS: typing.ClassVar[tuple] = ('torque_constant', 'resistance', 'voltage', 'no_load_speed', 'continuous_torque', 'peak_torque', 'max_speed', 'thermal_resistance', 'thermal_time_constant', 'rotor_inertia', 'mass', 'thermal_resistance_winding', 'thermal_resistance_housing', 'thermal_time_constant_winding', 'thermal_time_constant_housing', 'max_winding_temperature', 'brake_torque')
    __hash__: typing.ClassVar[None] = None
    @staticmethod
    def from_row(row: collections.abc.Mapping[str, typing.SupportsFloat | str | None]) -> Motor:
        """
        The Motor of a catalog row: a mapping (a dict, a pandas Series) holding any of the fields in Motor.FIELDS (SI units; None, NaN or pandas' NA = not given; given ones finite and > 0, else ModelError naming the field); other keys are ignored. The name: the row's 'name' entry when given, else the Series' name when it is a str, else ''.
        """
    def __eq__(self, arg0: typing.Any) -> bool:
        ...
    def __getstate__(self) -> dict:
        ...
    def __init__(self, *, name: str = '', torque_constant: float | None = None, resistance: float | None = None, voltage: float | None = None, no_load_speed: float | None = None, continuous_torque: float | None = None, peak_torque: float | None = None, max_speed: float | None = None, thermal_resistance: float | None = None, thermal_time_constant: float | None = None, rotor_inertia: float | None = None, mass: float | None = None, thermal_resistance_winding: float | None = None, thermal_resistance_housing: float | None = None, thermal_time_constant_winding: float | None = None, thermal_time_constant_housing: float | None = None, max_winding_temperature: float | None = None, brake_torque: float | None = None) -> None:
        """
        A motor's datasheet values (every one optional, None when not given; given ones finite and > 0, else ModelError naming the field), all motor side: torque_constant [N m/A], resistance [ohm], voltage [V], no_load_speed [rad/s], continuous_torque [N m], peak_torque [N m], max_speed [rad/s], thermal_resistance [K/W], thermal_time_constant [s], rotor_inertia [kg m^2], mass [kg], thermal_resistance_winding [K/W], thermal_resistance_housing [K/W], thermal_time_constant_winding [s], thermal_time_constant_housing [s], max_winding_temperature [degC], brake_torque [N m].
        """
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: dict) -> None:
        ...
    @property
    def brake_torque(self) -> float | None:
        """
        Holding brake torque (motor side) [N m], or None.
        """
    @property
    def continuous_torque(self) -> float | None:
        """
        Rated continuous torque (motor side) [N m], or None.
        """
    @property
    def mass(self) -> float | None:
        """
        Motor mass [kg], or None.
        """
    @property
    def max_speed(self) -> float | None:
        """
        Maximum permissible speed [rad/s], or None.
        """
    @property
    def max_winding_temperature(self) -> float | None:
        """
        Maximum permissible winding temperature [degC], or None.
        """
    @property
    def name(self) -> str:
        """
        The motor's name ('' when not given).
        """
    @property
    def no_load_speed(self) -> float | None:
        """
        No-load speed at the supply voltage [rad/s], or None.
        """
    @property
    def peak_torque(self) -> float | None:
        """
        Peak torque (motor side) [N m], or None.
        """
    @property
    def resistance(self) -> float | None:
        """
        Terminal resistance [ohm], or None.
        """
    @property
    def rotor_inertia(self) -> float | None:
        """
        Rotor inertia (motor side) [kg m^2], or None.
        """
    @property
    def thermal_resistance(self) -> float | None:
        """
        Thermal resistance winding to ambient (one-node model) [K/W], or None.
        """
    @property
    def thermal_resistance_housing(self) -> float | None:
        """
        Thermal resistance housing to ambient (two-node model) [K/W], or None.
        """
    @property
    def thermal_resistance_winding(self) -> float | None:
        """
        Thermal resistance winding to housing (two-node model) [K/W], or None.
        """
    @property
    def thermal_time_constant(self) -> float | None:
        """
        Thermal time constant of the winding (one-node model) [s], or None.
        """
    @property
    def thermal_time_constant_housing(self) -> float | None:
        """
        Thermal time constant of the housing (two-node model) [s], or None.
        """
    @property
    def thermal_time_constant_winding(self) -> float | None:
        """
        Thermal time constant of the winding (two-node model) [s], or None.
        """
    @property
    def torque_constant(self) -> float | None:
        """
        Torque constant k_t (motor side) [N m/A], or None.
        """
    @property
    def voltage(self) -> float | None:
        """
        Supply voltage [V], or None.
        """
class Actuator:
    """
    A gearbox and motor rotor on a joint (ModelBuilder.add_actuator), as Model.actuators lists it: joint (the actuated joint's name), rotor_joint (the rotor's revolute joint and body, a coupling follower: '<joint>_armature' turning with the joint, qdot, with inertia N^2 J by default (gyroscopic=False), '<joint>_rotor' turning at gear_ratio * qdot with gyroscopic=True), dof (the index into the independent qd / model.dof_names the actuator moves), gear_ratio, rotor_inertia [kg m^2], efficiency, friction_viscous [N m s/rad, motor side], friction_coulomb [N m, motor side], friction_smoothing [rad/s, motor side], gyroscopic, motor (armdyn.Motor or None).
    """
    def __repr__(self) -> str:
        ...
    @property
    def dof(self) -> int:
        """
        Index into the independent qd / model.dof_names of the dof the actuator moves.
        """
    @property
    def efficiency(self) -> float:
        """
        Gearbox efficiency in (0, 1] (motor-side maths only, not in the dynamics).
        """
    @property
    def friction_coulomb(self) -> float:
        """
        Coulomb friction [N m], motor side (reflected as |N| c).
        """
    @property
    def friction_smoothing(self) -> float:
        """
        Coulomb smoothing velocity [rad/s], motor side: tanh(omega / friction_smoothing).
        """
    @property
    def friction_viscous(self) -> float:
        """
        Viscous friction [N m s/rad], motor side (reflected as N^2 b).
        """
    @property
    def gear_ratio(self) -> float:
        """
        Gear ratio N = rotor speed / joint speed (negative: reversed rotor; rad/m for a prismatic joint).
        """
    @property
    def gyroscopic(self) -> bool:
        """
        True: the rotor turns on the joint's parent body (full kinetic energy); False: the gear-reduced (armature) model.
        """
    @property
    def joint(self) -> str:
        """
        Name of the actuated joint.
        """
    @property
    def motor(self) -> Motor | None:
        """
        The attached armdyn.Motor, or None.
        """
    @property
    def rotor_inertia(self) -> float:
        """
        Rotor inertia J about its axis [kg m^2].
        """
    @property
    def rotor_joint(self) -> str:
        """
        Name of the rotor's revolute joint and body: '<joint>_armature' (gyroscopic=False, the default) or '<joint>_rotor' (gyroscopic=True).
        """
class Profile:
    """
    A time profile y(t) with derivatives, evaluated in C++.
    """
    def __getstate__(self) -> tuple[int, int, tuple[float, float, float, float], list[float], list[float], list[float], str]:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def eval(self, t: float | numpy.typing.ArrayLike) -> tuple[float, float, float] | tuple[numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64]]:
        """
        The profile's value y, rate dy/dt and second derivative d2y/dt2 at time t [s]: a tuple of 3 floats for a number t; for an array t (any shape), a tuple of 3 float64 arrays of t's shape (one evaluation per element). Units follow the profile's use (rad, m, N m, N or a load scale, per s and s^2). ModelError if t is not numeric.
        """
class Model:
    """
    Immutable multibody model (from ModelBuilder.finalize or load_urdf).
    """
    def __getstate__(self) -> tuple[bytes]:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def frame(self, frame: str) -> dict:
        """
        A named frame's placement on its body: 'index' (into frame_names), 'body' (or 'ground'), 'point' (its origin in the body's frame, relative to the centre of mass; the world for 'ground') and 'rotation' (its axes as columns in the body's axes).
        """
    def joint_frame(self, joint: str) -> dict:
        """
        The joint's bodies and frames: 'point_parent'/'point_child' (the joint point in each body's frame, relative to its centre of mass; the world for 'ground'), 'frame_parent'/'frame_child' (the joint frame's axes as columns in each body's frame; z is the joint axis) and 'coord' (its first joint coordinate, -1 if none).
        """
    def joint_limits(self, joint: str) -> dict:
        """
        A joint's limits as a dict: 'lower' and 'upper' position limits [rad or m] (+-1e300 where none), 'effort' [N m or N] and 'velocity' [rad/s or m/s] (0 where none).
        """
    def summary(self) -> str:
        """
        Readable description: sizes, topology, solver path.
        """
    def with_kkt_path(self, path: str) -> Model:
        """
        A copy of the model on another KKT path: 'dense' (the reference: one dense Cholesky of the Schur complement) or 'auto' (the plan finalize() picks).
        """
    def with_payload(self, at: str, mass: typing.SupportsFloat | typing.SupportsIndex, com: numpy.typing.ArrayLike = (0.0, 0.0, 0.0), inertia: numpy.typing.ArrayLike | None = None, name: str = 'payload') -> Model:
        """
        A new finalized model with a payload (this model is unchanged): a rigid body of mass [kg] with its centre of mass at com [m] and inertia [kg m^2] (3x3 about the centre of mass, or its 3 principal moments; None: a point mass), both in the axes of `at` and from its origin, welded to `at`: a named frame of the model (e.g. a URDF link's frame or tool0); else a body (its centre of mass and axes) or 'ground'; else a joint (its point and joint frame on the parent's side, z the joint axis; welded to the parent): the first kind that has the name wins. It adds body `name`, fixed joint '<name>_mount' (reactions at at's origin) and frame `name` at the payload's centre of mass. The dynamics are those of the builder with the same body added (add_body + add_fixed). ModelError naming the culprit (at, mass, com, inertia, name) and leaving this model intact on bad input; a model holding a profile made from a Python function cannot be copied (ModelError).
        """
    def with_payloads(self, payloads: collections.abc.Iterable[collections.abc.Mapping[str, numpy.typing.ArrayLike | None]]) -> Model:
        """
        with_payload for several payloads at once (one finalize): payloads is a list of dicts with keys at, mass (required), com, inertia, name (with_payload's arguments and defaults); each needs its own name. An empty list: a copy of the model.
        """
    @property
    def actuators(self) -> list[Actuator]:
        """
        The actuators (ModelBuilder.add_actuator), as armdyn.Actuator objects.
        """
    @property
    def body_names(self) -> list[str]:
        """
        Names of the bodies, in the order they were added (index = body index; the URDF's links with mass or a child joint).
        """
    @property
    def coord_effort_limit(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        Effort limit of each entry of tau (n_dofs) [N m or N] (URDF <limit effort>; inf where none or 0, and on a floating base).
        """
    @property
    def coord_lower(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        Lower position limit of each entry of q (n_coords; URDF <limit lower>; -inf where none and on a floating base; a coupled model's independent entries).
        """
    @property
    def coord_names(self) -> list[str]:
        """
        Names of the entries of q (n_coords): a floating base's 'name:x' .. 'name:e3', then the independent joint coordinates.
        """
    @property
    def coord_upper(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        Upper position limit of each entry of q (n_coords; URDF <limit upper>; inf where none and on a floating base).
        """
    @property
    def coord_velocity_limit(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        Velocity limit of each entry of qd (n_dofs) [rad/s or m/s] (URDF <limit velocity>; inf where none or 0, and on a floating base).
        """
    @property
    def couplings(self) -> list:
        """
        The couplings (add_coupling, URDF <mimic>): a list of dicts with 'name', 'follower' and 'leader' (joint names), 'multiplier' and 'offset' [rad or m] of q_follower = multiplier * q_leader + offset.
        """
    @property
    def dof_names(self) -> list[str]:
        """
        Names of the entries of qd, qdd and tau (n_dofs): a floating base's 'name:vx' .. 'name:wz', then the independent joint coordinates.
        """
    @property
    def drive_coords(self) -> list[int]:
        """
        Index into the joint dofs (model.joint_dof_names) of each drive's coordinate.
        """
    @property
    def drive_names(self) -> list[str]:
        """
        Names of the drives, in the order they were added (columns of SimulationResult.drive_forces).
        """
    @property
    def frame_names(self) -> list[str]:
        """
        Names of the named frames (add_frame, URDF links), in the order they were added.
        """
    @property
    def gravity(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        (3,) gravity vector in world axes [m/s^2].
        """
    @property
    def independent_coords(self) -> list[int]:
        """
        Index of each entry of q in joint_coord_names.
        """
    @property
    def inertias(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        (nb, 3, 3) body inertia tensors about the centre of mass in body axes [kg m^2].
        """
    @property
    def is_tree(self) -> bool:
        """
        True when every body has exactly one joint path to ground (no closed loops).
        """
    @property
    def joint_coord_names(self) -> list[str]:
        """
        Names of the columns of SimulationResult.q (every joint's coordinate).
        """
    @property
    def joint_dof_names(self) -> list[str]:
        """
        Names of the columns of SimulationResult.qd and qdd.
        """
    @property
    def joint_names(self) -> list[str]:
        """
        Names of the joints, in the order they were added (index = joint index).
        """
    @property
    def joint_path_reason(self) -> str:
        """
        Why simulate(coordinates='joint') does not take the model; '' when it does.
        """
    @property
    def joint_space(self) -> bool:
        """
        True when the joint-space functions (forward_dynamics, inverse_dynamics, mass_matrix, state_from_joints) take the model: a tree of revolute, prismatic, cylindrical and fixed joints (a free joint from ground as a floating base) defined parent to child.
        """
    @property
    def joint_types(self) -> list[str]:
        """
        Type of each joint of joint_names: 'revolute', 'prismatic', 'spherical', 'fixed', 'free', ...
        """
    @property
    def kkt_path(self) -> str:
        """
        KKT solver path chosen at finalize(): 'tree', 'tree+loops', 'sparse', or 'dense' (redundant rows).
        """
    @property
    def kkt_plan(self) -> dict:
        """
        The KKT plan's statistics (path, row blocks, factor entries, fill, flops).
        """
    @property
    def masses(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        (nb,) body masses [kg], in body_names order.
        """
    @property
    def mobility(self) -> int:
        """
        Degrees of freedom of the mechanism without its drives.
        """
    @property
    def mobility_driven(self) -> int:
        """
        Degrees of freedom left with the drives (0: fully prescribed motion).
        """
    @property
    def n_coords(self) -> int:
        """
        Length of the joint-space q: 7 per floating base (position, scalar-first quaternion), then one per independent joint coordinate (couplings' followers removed).
        """
    @property
    def n_dofs(self) -> int:
        """
        Length of qd, qdd and tau: 6 per floating base (linear, angular velocity in the base frame), then one per independent joint coordinate (= n_coords without a floating base).
        """
    @property
    def n_drives(self) -> int:
        """
        Number of drives (prescribed joint coordinates, add_drive).
        """
    @property
    def n_free(self) -> int:
        """
        Free joints (floating bases) of the joint space.
        """
    @property
    def n_joint_coords(self) -> int:
        """
        Columns of SimulationResult.q: n_coords with the couplings' followers.
        """
    @property
    def n_joint_dofs(self) -> int:
        """
        Columns of SimulationResult.qd, qdd: n_dofs with the couplings' followers.
        """
    @property
    def nb(self) -> int:
        """
        Number of bodies.
        """
    @property
    def nc(self) -> int:
        """
        Number of constraint rows: the joints' and ideal gears' rows, then the drives'.
        """
    @property
    def nc_joint(self) -> int:
        """
        Number of the joints' and ideal gears' constraint rows (the rows before the drives').
        """
    @property
    def nq(self) -> int:
        """
        Length of the Cartesian position state u: 7 per body (CoM [m], unit Euler parameters).
        """
    @property
    def nv(self) -> int:
        """
        Length of the Cartesian velocity state v: 6 per body (CoM velocity [m/s, world], angular velocity [rad/s, body]).
        """
    @property
    def redundant_rows(self) -> list[str]:
        """
        Names of the redundant constraint rows finalize() found (empty when the rows are independent).
        """
    @property
    def reflected_inertia(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        (n_dofs,) the rotors' inertia reflected through their gears, N^2 J at each actuated dof and 0 elsewhere [kg m^2, or kg for a prismatic joint]: the armature of Pinocchio's model (the gear-reduced rotor model adds exactly this to the mass matrix's diagonal).
        """
    @property
    def u0(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        (nq,) the assembled Cartesian positions u: per body CoM [m] and unit Euler parameters.
        """
    @property
    def v0(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        (nv,) the initial Cartesian velocities v (zero unless set): per body CoM velocity [m/s] and angular velocity [rad/s].
        """
class ModelBuilder:
    """
    Build a model: bodies, joints, drives, force elements; then finalize().
    """
    def __getstate__(self) -> tuple[bytes, bool]:
        ...
    def __init__(self, gravity: numpy.typing.ArrayLike = (0.0, 0.0, -9.81), *, physical_inertia: bool = True) -> None:
        """
        An empty builder. gravity: (3,) in world axes [m/s^2]; physical_inertia: see the property of that name. ModelError if gravity is not 3 finite numbers.
        """
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def add_actuator(self, joint: str, gear_ratio: typing.SupportsFloat | typing.SupportsIndex, rotor_inertia: typing.SupportsFloat | typing.SupportsIndex, efficiency: typing.SupportsFloat | typing.SupportsIndex = 1.0, friction_viscous: typing.SupportsFloat | typing.SupportsIndex = 0.0, friction_coulomb: typing.SupportsFloat | typing.SupportsIndex = 0.0, motor: Motor | None = None, gyroscopic: bool = False, friction_smoothing: float | None = None) -> None:
        """
        A gearbox and motor rotor on a revolute (continuous) or prismatic joint. gear_ratio N = rotor speed / joint speed (negative reverses the rotor; rad/m for a prismatic joint, a ball screw); rotor_inertia J [kg m^2] about the rotor axis; efficiency in (0, 1] (stored for the motor-side maths, not in the dynamics); friction_viscous [N m s/rad] and friction_coulomb [N m] on the motor side (reflected as N^2 b and |N| c), Coulomb smoothed by tanh(omega / friction_smoothing), friction_smoothing [rad/s, motor side] default 1e-3 |N|; motor: an armdyn.Motor or None. Adds a body, a revolute joint and a coupling (zero mass, thin-disc inertia) along the joint axis through its origin: by default (gyroscopic=False) '<joint>_armature' on ground, axial inertia N^2 J, turning with the joint (at qdot: the gear-reduced model, Pinocchio's armature N^2 J exactly); with gyroscopic=True '<joint>_rotor' on the joint's parent body, axial inertia J, turning at N qdot relative to it (the rotor's full kinetic energy, with its carrier's rotation). ModelError, builder unchanged, on an unknown joint, a joint not revolute or prismatic, a second actuator, gear_ratio zero or not finite, rotor_inertia < 0, efficiency outside (0, 1], negative frictions.
        """
    def add_body(self, name: str, mass: typing.SupportsFloat | typing.SupportsIndex, inertia: numpy.typing.ArrayLike, position: numpy.typing.ArrayLike = (0.0, 0.0, 0.0), orientation: numpy.typing.ArrayLike = (1.0, 0.0, 0.0, 0.0)) -> int:
        """
        Add a body: mass [kg], inertia (3,3) about the CoM in body axes [kg m^2] (or its (3,) diagonal), CoM position [m], orientation as unit Euler parameters [e0, e1, e2, e3].
        """
    def add_body_force(self, body: str, force: numpy.typing.ArrayLike = (0.0, 0.0, 0.0), torque: numpy.typing.ArrayLike = (0.0, 0.0, 0.0), point: numpy.typing.ArrayLike | None = None, profile: Profile | float | collections.abc.Callable[[float], tuple[float, float, float]] | None = None) -> None:
        """
        Force [N] at a point (world coordinates at assembly; default the CoM) and torque [N m], both in world axes, optionally scaled by a profile.
        """
    def add_coupling(self, name: str, follower: str, leader: str, multiplier: typing.SupportsFloat | typing.SupportsIndex, offset: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        """
        Coupling q_follower = multiplier * q_leader + offset [rad or m] between two revolute (continuous) or two prismatic joints (URDF <mimic>): one constraint row; the follower becomes a dependent coordinate, and forward_dynamics, inverse_dynamics, mass_matrix, state_from_joints and simulate(q0=...) take the independent ones (model.coord_names). Chains allowed; cycles, a follower coupled twice, joints of different types and a zero or non-finite multiplier are refused (ModelError).
        """
    def add_cylindrical(self, name: str, parent: str, child: str, point: numpy.typing.ArrayLike, axis: numpy.typing.ArrayLike) -> int:
        """
        Add a cylindrical joint `name` between `parent` and `child`: rotation about and translation along `axis` (3,) through `point` (3,) [m] (world at assembly). Two coordinates: the angle [rad], then the slide [m]. Returns the joint index; ModelError on bad input.
        """
    def add_distance(self, name: str, body_a: str, point_a: numpy.typing.ArrayLike, body_b: str, point_b: numpy.typing.ArrayLike) -> int:
        """
        Distance joint, 1 row: a massless rod with ball ends between point_a of body_a and point_b of body_b (world coordinates at assembly); it holds their assembly distance.
        """
    def add_drive(self, joint: str, profile: Profile | float | collections.abc.Callable[[float], tuple[float, float, float]], coord: typing.SupportsInt | typing.SupportsIndex = 0, name: str | None = None) -> int:
        """
        Prescribe coordinate `coord` of `joint` by a profile [rad or m over t in s] (armdyn.profiles.*, a number, or a Python callable t -> (y, yd, ydd): accepted but slow, it runs Python at every evaluation): a rheonomic constraint whose multiplier is the drive's effort (SimulationResult.drive_forces). `name` defaults to the joint's. Returns the drive index; ModelError on an unknown joint or coordinate, or a bad profile.
        """
    def add_fixed(self, name: str, parent: str, child: str, point: numpy.typing.ArrayLike | None = None) -> int:
        """
        Weld `child` rigidly to `parent` (either may be 'ground'): 6 rows, no dof. `point` (3,) [m], world at assembly, only sets where the reaction is reported (default: the child's CoM, the world origin for 'ground'). Returns the joint index; ModelError on a duplicate name or an unknown body.
        """
    def add_frame(self, name: str, body: str, position: numpy.typing.ArrayLike = (0.0, 0.0, 0.0), orientation: numpy.typing.ArrayLike = (1.0, 0.0, 0.0, 0.0)) -> int:
        """
        Add a named frame rigidly attached to `body` (or 'ground'): its origin [m] and axes (unit Euler parameters [e0, e1, e2, e3], frame -> world), both in world at the assembly pose like every builder input. Read it back with armdyn.frame_pose and armdyn.frame_jacobian.
        """
    def add_free(self, name: str, child: str, origin: numpy.typing.ArrayLike | None = None) -> int:
        """
        Declare body `child` free (a floating base). In joint space its frame -- the body's axes at `origin` (world at assembly, m; default its centre of mass) -- takes 7 entries of q (x, y, z, then the scalar-first unit quaternion e0..e3) and 6 of qd (linear, then angular velocity, both in the frame's own axes).
        """
    def add_gear(self, name: str, joint_a: str, joint_b: str, r_a: typing.SupportsFloat | typing.SupportsIndex, r_b: typing.SupportsFloat | typing.SupportsIndex) -> None:
        """
        Ideal gear (no backlash) between two revolute joints: the rolling constraint r_a q_a + r_b q_b = 0 (external mesh, multi-turn angles).
        """
    def add_gear_pair(self, name: str, joint_a: str, joint_b: str, r_a: typing.SupportsFloat | typing.SupportsIndex, r_b: typing.SupportsFloat | typing.SupportsIndex, backlash: typing.SupportsFloat | typing.SupportsIndex = 0.0, stiffness: typing.SupportsFloat | typing.SupportsIndex = 100000000.0, exponent: typing.SupportsFloat | typing.SupportsIndex = 1.5, hc_damping: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        """
        Gear pair with backlash between two revolute joints (external mesh): mesh displacement s = r_a q_a + r_b q_b, dead zone |s| <= backlash/2, Hunt-Crossley contact force F = k d^n (1 + hc_damping d') >= 0 beyond it. Contact onset and separation are located as events (result.events).
        """
    def add_inline(self, name: str, parent: str, child: str, point: numpy.typing.ArrayLike, axis: numpy.typing.ArrayLike) -> int:
        """
        Inline (point-on-line) joint, 2 rows: the child's point stays on the parent's line through `point` along `axis`. Closes a planar loop without redundant rows.
        """
    def add_joint_friction(self, joint: str, viscous: typing.SupportsFloat | typing.SupportsIndex = 0.0, coulomb: typing.SupportsFloat | typing.SupportsIndex = 0.0, smoothing_velocity: typing.SupportsFloat | typing.SupportsIndex = 0.001, coord: typing.SupportsInt | typing.SupportsIndex = 0) -> None:
        """
        Joint friction: tau = -viscous * qdot - coulomb * tanh(qdot / smoothing_velocity).
        """
    def add_joint_spring_damper(self, joint: str, stiffness: typing.SupportsFloat | typing.SupportsIndex = 0.0, damping: typing.SupportsFloat | typing.SupportsIndex = 0.0, rest: typing.SupportsFloat | typing.SupportsIndex = 0.0, coord: typing.SupportsInt | typing.SupportsIndex = 0) -> None:
        """
        Spring-damper on coordinate `coord` of `joint`: tau = -stiffness (q - rest) - damping qdot, stiffness [N m/rad or N/m], damping [N m s/rad or N s/m], rest [rad or m]. ModelError on an unknown joint or coordinate, negative stiffness/damping.
        """
    def add_joint_torque(self, joint: str, profile: Profile | float | collections.abc.Callable[[float], tuple[float, float, float]], coord: typing.SupportsInt | typing.SupportsIndex = 0) -> None:
        """
        Apply a torque [N m] (revolute) or force [N] (prismatic) on coordinate `coord` of `joint`, given by a profile of t [s] (armdyn.profiles.*, a number, or a callable t -> (y, yd, ydd)): acts on the child about/along the joint axis and the opposite on the parent; reported in SimulationResult.joint_torques. ModelError on an unknown joint or coordinate, or a bad profile.
        """
    def add_motor(self, joint: str, reference: Profile | float | collections.abc.Callable[[float], tuple[float, float, float]], kp: typing.SupportsFloat | typing.SupportsIndex, kd: typing.SupportsFloat | typing.SupportsIndex, torque_limit: typing.SupportsFloat | typing.SupportsIndex = 1e+300, feedforward: Profile | float | collections.abc.Callable[[float], tuple[float, float, float]] | None = None, coord: typing.SupportsInt | typing.SupportsIndex = 0, ki: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        """
        PD or PID motor on a joint coordinate: tau = clamp(kp (q_ref - q) + kd (qd_ref - qd) + ki z, +-torque_limit) + feedforward(t), z the integral of q_ref - q (an auxiliary state, not integrated while saturated); the reference is a profile (armdyn.profiles.*, a number, or a callable).
        """
    def add_prismatic(self, name: str, parent: str, child: str, point: numpy.typing.ArrayLike, axis: numpy.typing.ArrayLike) -> int:
        """
        Add a prismatic (slider) joint `name` between `parent` and `child` (either may be 'ground'): translation along `axis` (3,) (world axes) through `point` (3,) [m], world at assembly. One coordinate q [m] along the unit axis; q = 0 at assembly. Returns the joint index; ModelError on a duplicate name, an unknown body, a zero or non-finite axis or point.
        """
    def add_revolute(self, name: str, parent: str, child: str, point: numpy.typing.ArrayLike, axis: numpy.typing.ArrayLike) -> int:
        """
        Add a revolute (hinge) joint `name` between bodies `parent` and `child` (either may be 'ground'): rotation about `axis` (3,) (world axes, need not be unit) through `point` (3,) [m], both in world at the assembly pose. One coordinate q [rad], positive by the right-hand rule about axis; q = 0 at assembly. Returns the joint index. ModelError (builder unchanged) on a duplicate name, an unknown body, a zero or non-finite axis or point.
        """
    def add_spherical(self, name: str, parent: str, child: str, point: numpy.typing.ArrayLike) -> int:
        """
        Add a spherical (ball) joint `name` between `parent` and `child` at `point` (3,) [m], world at assembly: 3 constraint rows, 3 rotational dofs (joint space: a quaternion). Returns the joint index; ModelError on a duplicate name, an unknown body, a non-finite point.
        """
    def add_spring_damper(self, name: str, body_a: str, point_a: numpy.typing.ArrayLike, body_b: str, point_b: numpy.typing.ArrayLike, stiffness: typing.SupportsFloat | typing.SupportsIndex, damping: typing.SupportsFloat | typing.SupportsIndex = 0.0, rest_length: float | None = None) -> None:
        """
        Point-to-point spring-damper `name` between point_a (3,) of body_a and point_b (3,) of body_b (world coordinates at assembly [m]; a body may be 'ground'): force stiffness [N/m] * (length - rest_length) + damping [N s/m] * length rate along the line; rest_length [m] defaults to the assembly distance. ModelError on an unknown body, coincident points, non-finite input, negative stiffness or damping.
        """
    def add_universal(self, name: str, parent: str, child: str, point: numpy.typing.ArrayLike, axis1: numpy.typing.ArrayLike, axis2: numpy.typing.ArrayLike) -> int:
        """
        Add a universal (Cardan) joint at `point` (3,) [m]: `axis1` (3,) fixed in the parent, `axis2` (3,) fixed in the child, perpendicular, world at assembly. Two coordinates [rad] (about axis1, then axis2). Returns the joint index; ModelError on bad input (axes not perpendicular, zero, or not finite).
        """
    def finalize(self, mass_weighted_assembly: bool = True) -> Model:
        """
        Validate, analyse topology and rank, assemble; returns an immutable Model.
        """
    def set_independent_coordinates(self, names: collections.abc.Sequence[str]) -> None:
        """
        The independent coordinates of a model with closed loops or of a fixed-base tree with ideal gears: names from joint_coord_names, as many as the model's mobility, in the order q, qd, qdd and tau take them. finalize() checks them (ModelError naming an unknown or repeated name, a wrong count, a coordinate the others determine at the assembled state, or a tree without ideal gears or with a floating base). An empty list restores armdyn's default: the joint coordinates in model order, each taken when independent of those taken before (add the actuated joints first).
        """
    def set_joint_limits(self, joint: str, lower: typing.SupportsFloat | typing.SupportsIndex, upper: typing.SupportsFloat | typing.SupportsIndex, effort: typing.SupportsFloat | typing.SupportsIndex = 0.0, velocity: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        """
        Set a joint's limits (of its first coordinate): position lower <= q <= upper [rad or m] (stops enforced by simulate(limits=True)), effort [N m or N] and velocity [rad/s or m/s] (informative, 0 = none; read by the sizing). ModelError on an unknown joint, lower > upper, NaN, or negative effort/velocity.
        """
    @property
    def body_names(self) -> list[str]:
        """
        Names of the bodies added so far, in definition order (for urdf_builder: the URDF's links as the loader added them).
        """
    @property
    def frame_names(self) -> list[str]:
        """
        Names of the named frames added so far (add_frame; for urdf_builder its links), in definition order.
        """
    @property
    def joint_names(self) -> list[str]:
        """
        Names of the joints added so far, in definition order (for urdf_builder: the URDF's joints as the loader added them, actuator rotors and free bases included).
        """
    @property
    def physical_inertia(self) -> bool:
        """
        True (default): add_body accepts physically consistent inertias only (positive semidefinite, triangle inequality). False: any positive semidefinite tensor; negative round-off moments down to -1e-12 of the largest are clamped to zero with a warning. Applies to bodies added after it is set.
        """
    @physical_inertia.setter
    def physical_inertia(self, arg1: bool) -> None:
        ...
class _TreeDynamics:
    """
    Joint-space forward dynamics of a tree without drives, ideal gears allowed (the path of simulate(coordinates='joint')): the mass matrix by the composite-rigid-body algorithm, bias and applied forces by recursive Newton-Euler, gears eliminated by their null space. Keeps its workspace between calls.
    """
    def __call__(self, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike, tau: numpy.typing.ArrayLike, t: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> numpy.typing.NDArray[numpy.float64]:
        """
        Joint accelerations for joint forces tau at (q, qd, t); the model's coordinate forces and gear contacts are included, the ideal gears' rows are held.
        """
    def __init__(self, model: Model) -> None:
        ...
    def mass_matrix(self, q: numpy.typing.ArrayLike) -> numpy.typing.NDArray[numpy.float64]:
        """
        The joint-space mass matrix M(q) (n_coords x n_coords).
        """
    @property
    def description(self) -> str:
        ...
    @property
    def dof(self) -> int:
        ...
class LagrangeValidator:
    """
    Complete Euler-Lagrange equations of a tree model in its joint coordinates, derived from joint-space kinematics by automatic differentiation, independently of the Newton-Euler/KKT path.
    """
    def __init__(self, model: Model, rotational_inertia: bool = True) -> None:
        """
        The Euler-Lagrange equations of a tree `model` (rotational_inertia=False: the bodies as point masses).
        """
    def mass_matrix(self, q: numpy.typing.ArrayLike) -> numpy.typing.NDArray[numpy.float64]:
        """
        The joint-space mass matrix M(q) (n_dofs, n_dofs) [kg m^2, kg] of the Lagrangian at q (n_coords,).
        """
    def torques(self, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike, qdd: numpy.typing.ArrayLike, t: numpy.typing.ArrayLike | None = None) -> numpy.typing.NDArray[numpy.float64]:
        """
        Torques for one sample (1-D inputs) or many (rows); t a scalar or one per row.
        """
    @property
    def rotational_inertia(self) -> bool:
        """
        False when the bodies count as point masses.
        """
class Data:
    """
    Workspace of one model's evaluations: every buffer forward_dynamics, inverse_dynamics and mass_matrix write. One per thread; pass it as data= to choose it explicitly (otherwise each thread keeps one per model).
    """
    def __init__(self, model: Model) -> None:
        """
        A workspace for `model` (an armdyn.Model); ModelError if model is None.
        """
    @property
    def model(self) -> Model:
        """
        The model this workspace serves.
        """
def _force_element_derivatives(model: Model, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike, t: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> tuple[numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64]]:
    """
    (dF_dq, dF_dqd), each (n_dofs, n_dofs): the derivatives of the generalised force F of the model's force elements (body loads, spring-dampers, coordinate forces, gear pairs; F = inverse_dynamics of the model without them - inverse_dynamics with them) at (q, qd) and time t, q-derivatives along the rates (a floating base's along qd's base-frame velocity), integral states zero (a coupled model's in its independent coordinates: G^T dF G). Private: the tests' and part deriv's check of the C++ function.
    """
def _inverse_dynamics_driven(model: Model, t: numpy.typing.ArrayLike) -> dict:
    ...
def _output_row_bytes(model: Model) -> int:
    """
    Bytes of one output time of simulate (every table's row, the limit forces counted for every joint): the bound armdyn.simulate checks an output_dt run against.
    """
def _rollout(model: Model, t_end: typing.SupportsFloat | typing.SupportsIndex, integrator: str, rtol: typing.SupportsFloat | typing.SupportsIndex, atol: typing.SupportsFloat | typing.SupportsIndex, dt: typing.SupportsFloat | typing.SupportsIndex, output_dt: typing.SupportsFloat | typing.SupportsIndex, u0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], v0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], projection: str, max_steps: typing.SupportsInt | typing.SupportsIndex, max_step: typing.SupportsFloat | typing.SupportsIndex, merge_welded: bool, coordinates: str, q_start: numpy.typing.ArrayLike | None, limits: bool, restitution: typing.SupportsFloat | typing.SupportsIndex, errors: collections.abc.Sequence[str], threads: typing.SupportsInt | typing.SupportsIndex, progress: collections.abc.Callable[[float, float], typing.Any] | None = None) -> tuple[list, typing.Any]:
    """
    Runs of simulate from each row of u0/v0 (q_start: the joint-space q0 rows, or None) on `threads` C++ threads, the GIL released; (list of result dicts, the interrupting exception or None). A run whose `errors` entry is non-empty is not run; a run that raises has its message in its dict's 'error'.
    """
def _simulate(model: Model, t_end: typing.SupportsFloat | typing.SupportsIndex, integrator: str, rtol: typing.SupportsFloat | typing.SupportsIndex, atol: typing.SupportsFloat | typing.SupportsIndex, dt: typing.SupportsFloat | typing.SupportsIndex, output_dt: typing.SupportsFloat | typing.SupportsIndex, u0: numpy.typing.ArrayLike | None, v0: numpy.typing.ArrayLike | None, projection: str, max_steps: typing.SupportsInt | typing.SupportsIndex, max_step: typing.SupportsFloat | typing.SupportsIndex = 0.0, merge_welded: bool = True, coordinates: str = 'cartesian', q_start: numpy.typing.ArrayLike | None = None, limits: bool = True, restitution: typing.SupportsFloat | typing.SupportsIndex = 0.0, progress: collections.abc.Callable[[float, float], typing.Any] | None = None) -> dict:
    ...
def body_accelerations(model: Model, u: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, t: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> tuple[numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64]]:
    """
    Solve the KKT system at the Cartesian state u (nq,), v (nv,) and time t [s]: returns (v' (nv,) the bodies' accelerations [m/s^2, rad/s^2], delta (nc,) the Lagrange multipliers [N, N m]). ModelError on wrong shapes, SolverError on a singular system.
    """
def body_forces(model: Model, u: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, t: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> numpy.typing.NDArray[numpy.float64]:
    """
    The applied Cartesian forces eta (nv,) at the state u (nq,), v (nv,) and time t [s]: per body the force [N, world] and torque [N m, body axes] of gravity, the gyroscopic -w x Jw, loads, springs and joint forces. ModelError on wrong shapes.
    """
def body_mass_matrix(model: Model) -> numpy.typing.NDArray[numpy.float64]:
    """
    The constant Cartesian mass matrix Gamma = blockdiag(m_i I3, J_i) (nv, nv) [kg, kg m^2] of the bodies (J_i about the CoM in body axes).
    """
def dynamic_parameter_names(model: Model) -> list[str]:
    """
    The names of dynamic_parameters(model)' entries: '<body>.m', '<body>.mcx', ..., '<body>.Izz', then '<coordinate>.fv', '.fc', '.offset', '.Ia'.
    """
def dynamic_parameters(model: Model) -> numpy.typing.NDArray[numpy.float64]:
    """
    The model's dynamic parameters pi (n_params,) in joint_torque_regressor's order (dynamic_parameter_names): per body m, m c_x, m c_y, m c_z, I_xx, I_xy, I_yy, I_xz, I_yz, I_zz about its parameter frame (Pinocchio's order), then per joint coordinate fv, fc, offset (0), Ia.
    """
def dynamics_cost(model: Model) -> dict:
    """
    The measured cost model's prediction for a model (derived once per model): microseconds per forward_dynamics call by 'crba', 'aba' and 'cartesian', the algorithms method='joint' and method='auto' take, and the microseconds per right-hand side of simulate in joint space and in Cartesian coordinates with the formulation coordinates='auto' takes where both apply.
    """
def end_effector_position(model: Model, body: str, point: numpy.typing.ArrayLike, q: numpy.typing.ArrayLike) -> numpy.typing.NDArray[numpy.float64]:
    ...
def energy(model: Model, u: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike) -> tuple[float, float]:
    """
    (kinetic, potential) energy [J] at the Cartesian state u (nq,), v (nv,); the potential includes gravity and springs. ModelError on wrong shapes.
    """
def energy_regressor(model: Model, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike, data: Data | None = None) -> numpy.typing.NDArray[numpy.float64]:
    """
    The energy regressor h (n_params,) at (q, qd): the kinetic plus potential energy of the model's bodies and actuator rotors is h @ dynamic_parameters(model) (potential -m g . c about the world origin, as energy(); the friction and offset entries are 0). Identification from energy needs no accelerations: h(t1) - h(t0) is the integral of (tau - friction) . qd dt along a motion. q: n_coords, qd: n_dofs; 2-D arrays (one state per row) give (rows, n_params). ModelError as joint_torque_regressor.
    """
def evaluate_constraints(model: Model, u: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike, t: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> dict:
    """
    The constraints at the Cartesian state u (nq,), v (nv,) and time t [s]: a dict of float64 arrays f (nc,) (the residuals, [m or rad]), zeta (nc, nv) (the Jacobian), xi (nc,) and rhs (nc,), with zeta v = rhs and zeta v' = -xi. ModelError on wrong shapes.
    """
def forward_dynamics(model: Model, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike, tau: numpy.typing.ArrayLike, t: float | numpy.typing.ArrayLike = 0.0, method: str = 'auto', data: Data | None = None) -> numpy.typing.NDArray[numpy.float64]:
    """
    Joint accelerations qdd of a tree for joint torques/forces tau at (q, qd) and time t [s] (q: n_coords, the others n_dofs; a coupled model's independent coordinates, followers of couplings removed, as Pinocchio's mimic=True models; 2-D: one state per row). method: 'crba' (CRBA mass matrix, recursive Newton-Euler bias, Cholesky), 'aba' (articulated-body algorithm, O(n)), 'cartesian' (the constrained Newton-Euler KKT system of the bodies), 'joint' (the cheaper of crba and aba for this model), 'auto' (the cheapest of the three); the choice comes from a measured cost model (dynamics_cost). The model's force elements act; drives are ignored. A model with closed loops or a fixed-base tree with ideal gears: its independent coordinates (model.coord_names), on the Cartesian formulation (method 'auto' or 'cartesian').
    """
def forward_dynamics_derivatives(model: Model, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike, tau: numpy.typing.ArrayLike, t: float | numpy.typing.ArrayLike = 0.0, data: Data | None = None) -> tuple[numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64]]:
    """
    The first-order derivatives (dqdd_dq, dqdd_dqd, dqdd_dtau) of forward_dynamics at (q, qd, tau) and time t [s], each (n_dofs, n_dofs) for one state or (rows, n_dofs, n_dofs) for one state per row, as inverse_dynamics_derivatives takes them: qdd = M^-1 (tau - b) by the composite-rigid-body mass matrix and a factor of it (L^T D L without fill-in on a model without couplings, else Cholesky), then dqdd_dq = -M^-1 dtau_dq and dqdd_dqd = -M^-1 dtau_dqd at that qdd, dqdd_dtau = M^-1 (q-derivatives along the coordinates' rates, a floating base's along its qd block). ModelError for a model with light bodies, whose mass matrix about the world origin loses them.
    """
def frame_jacobian(model: Model, q: numpy.typing.ArrayLike, frame: str | int, data: Data | None = None) -> numpy.typing.NDArray[numpy.float64]:
    """
    The Jacobian (6, n_dofs) of a named frame at joint-space q (n_coords): linear rows then angular rows, world axes, at the frame's origin (Pinocchio's LOCAL_WORLD_ALIGNED), so that [v; omega] of the frame = J qd (a floating base's six columns first; a coupled model's independent coordinates, J G). 2-D q gives (rows, 6, n_dofs).
    """
def frame_jacobian_cartesian(model: Model, u: numpy.typing.ArrayLike, frame: str | int, data: Data | None = None) -> numpy.typing.NDArray[numpy.float64]:
    """
    The Jacobian (6, nv) of a named frame with respect to the bodies' velocities v of the Cartesian state (any model): linear rows then angular rows, world axes, at the frame's origin, so that [v; omega] of the frame = J v. 2-D u gives (rows, 6, nv).
    """
def frame_pose(model: Model, q: numpy.typing.ArrayLike, frame: str | int, data: Data | None = None) -> numpy.typing.NDArray[numpy.float64]:
    """
    The world pose of a named frame (a name of model.frame_names or its index) at joint coordinates q: the 4x4 homogeneous transform [R p; 0 1], R the frame's axes in world (frame -> world) and p its origin [m]; 2-D q (one state per row) gives (rows, 4, 4).
    """
def frame_pose_cartesian(model: Model, u: numpy.typing.ArrayLike, frame: str | int, data: Data | None = None) -> numpy.typing.NDArray[numpy.float64]:
    """
    frame_pose from the Cartesian state u (nq; any model, loops included): the 4x4 world pose of a named frame; 2-D u gives (rows, 4, 4).
    """
def inverse_dynamics(model: Model, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike, qdd: numpy.typing.ArrayLike, t: float | numpy.typing.ArrayLike = 0.0, method: str = 'auto', data: Data | None = None) -> numpy.typing.NDArray[numpy.float64]:
    """
    Joint torques/forces tau realising qdd at (q, qd) and time t [s] (q: n_coords, the others n_dofs; a coupled model's independent coordinates, tau = G^T tau_full; 2-D: one state per row): what each joint's actuator applies to its child about/along the joint axis, gravity and the model's force elements included, drives ignored. method: 'joint' (recursive Newton-Euler), 'cartesian' (every coordinate driven, the drives' KKT multipliers), 'auto' (joint). A model with closed loops or a fixed-base tree with ideal gears: the torques on its independent coordinates (model.coord_names), driven_inverse_dynamics' drive forces with them driven (method 'auto' or 'cartesian').
    """
def inverse_dynamics_derivatives(model: Model, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike, qdd: numpy.typing.ArrayLike, t: float | numpy.typing.ArrayLike = 0.0, data: Data | None = None) -> tuple[numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64]]:
    """
    The first-order derivatives (dtau_dq, dtau_dqd) of inverse_dynamics at (q, qd, qdd) and time t [s], each (n_dofs, n_dofs) for one state (q: n_coords, qd and qdd: n_dofs; a coupled model's independent coordinates) or (rows, n_dofs, n_dofs) for one state per row (2-D arrays; t a number or one per row). Analytical (the recursive Newton-Euler derivatives of Carpentier & Mansard 2018), gravity, gyroscopic terms and the model's force elements included, drives ignored. q-derivatives are taken along the coordinates' rates: column k of dtau_dq is d tau(q + eps e_k) / d eps for a joint coordinate, and for a floating base's six columns the derivative along its qd block (the base frame moved by its own linear and angular velocity in its axes, Pinocchio's free-flyer convention). dtau/dqdd is mass_matrix(model, q).
    """
def joint_coordinates(model: Model, u: numpy.typing.ArrayLike, v: numpy.typing.ArrayLike) -> tuple[numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64]]:
    """
    Joint-space q (n_coords: floating bases' poses, then joint coordinates with angles in (-pi, pi]) and qd (n_dofs) at the Cartesian state (u, v): a coupled model's independent coordinates, as state_from_joints takes.
    """
def joint_reactions(model: Model, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike, qdd: numpy.typing.ArrayLike, t: float | numpy.typing.ArrayLike | None = None, data: Data | None = None) -> tuple[numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64]]:
    """
    Every joint's reaction along a joint-space motion of a tree: (forces, torques), each (n_joints, 3) for one state (q: n_coords, qd and qdd: n_dofs; a coupled model's independent coordinates, as inverse_dynamics takes them) or (rows, n_joints, 3) for one state per row; t [s] a number, one per row, or None (0). The same quantity as SimulationResult.reaction_forces/reaction_torques: what the joint's constraint applies to its child at the joint point, in the child's joint frame, for every joint of the model (fixed joints included; zero for floating bases); the components about/along a joint's free axes are zero (the actuator's torque there is inverse_dynamics'). The joint torques are the inverse dynamics' (the motion is exactly the one given); gravity and the force elements act, drives are ignored.
    """
def joint_torque_regressor(model: Model, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike, qdd: numpy.typing.ArrayLike, data: Data | None = None) -> numpy.typing.NDArray[numpy.float64]:
    """
    The joint torque regressor Y (n_dofs, n_params) at (q, qd, qdd): inverse_dynamics(model, q, qd, qdd) = Y @ dynamic_parameters(model), linear in the model's dynamic parameters (per body: m, m c, the inertia about its parameter frame -- its URDF link frame; per joint coordinate: viscous and Coulomb friction, a torque offset, the rotor's reflected inertia; dynamic_parameter_names names them). q: n_coords, qd and qdd: n_dofs (a coupled model's independent coordinates, Y = G^T Y_full); 2-D arrays (one state per row) give (rows, n_dofs, n_params), computed in C++ without the GIL. A floating base's six rows come first: the force on the base frame, then the moment about its origin, in its axes (as inverse_dynamics). By the recursive Newton-Euler algorithm: per body its 6 x 10 unit-wrench block F in its parameter frame, then one row block S^T F per degree of freedom on its path to the root. Pinocchio's computeJointTorqueRegressor is the same matrix reordered: rows by joint name (a free flyer's six first), body B's 10 columns those of the joint whose child link is B (Pinocchio's joint frame is the URDF link frame), armdyn's friction, offset and rotor columns added. ModelError for a model with a force element that is not a parameter (springs, loads, inputs, motors), named; SolverError when finite inputs overflow.
    """
def mass_matrix(model: Model, q: numpy.typing.ArrayLike, data: Data | None = None) -> numpy.typing.NDArray[numpy.float64]:
    """
    The joint-space mass matrix M(q) (n_dofs, n_dofs) of a tree, by the composite-rigid-body algorithm (a coupled model's in its independent coordinates, G^T M G; a model with closed loops' or a fixed-base tree with ideal gears' in its independent coordinates, T^T Gamma T with T the velocity map); 2-D q (one state per row) gives (rows, n, n).
    """
def model_with_dynamic_parameters(model: Model, pi: numpy.typing.ArrayLike, physical_inertia: bool = True) -> Model:
    """
    A new model (this one unchanged) whose dynamic_parameters equal pi (n_params,), offsets aside (measurement biases, not dynamics: ignored): each body's mass, centre of mass and inertia from its 10 numbers (the body frame's origin moves with the centre of mass, every attachment point with it: the geometry is unchanged; a body without a frame of its name gets one at its old centre of mass, pi's parameter frame), each coordinate's friction sources scaled to fv, fc (created on its joint when it has none), its actuators' rotor inertias scaled to Ia (an actuator of gear ratio 1 added when it has none), then finalized again. physical_inertia=True: each body's parameters physically consistent (pseudo-inertia positive semidefinite); False: the inertia about the centre of mass positive semidefinite only (the triangle inequality not required). ModelError naming the entry or body on a wrong length, a non-finite entry, a negative mass, friction or Ia, an inertia outside those limits.
    """
def paper_3dof_torques(L: numpy.typing.ArrayLike, M: numpy.typing.ArrayLike, g: typing.SupportsFloat | typing.SupportsIndex, theta: numpy.typing.ArrayLike, thetad: numpy.typing.ArrayLike) -> numpy.typing.NDArray[numpy.float64]:
    ...
def paper_5dof_end_effector(h: typing.SupportsFloat | typing.SupportsIndex, L1: typing.SupportsFloat | typing.SupportsIndex, L2: typing.SupportsFloat | typing.SupportsIndex, L34: typing.SupportsFloat | typing.SupportsIndex, theta: numpy.typing.ArrayLike) -> numpy.typing.NDArray[numpy.float64]:
    ...
def state_from_joints(model: Model, q: numpy.typing.ArrayLike, qd: numpy.typing.ArrayLike | None = None, data: Data | None = None) -> tuple[numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64]]:
    """
    Cartesian state (u, v) of a joint-space tree model from joint-space q (n_coords) and qd (n_dofs; default zero): a coupled model's independent coordinates, the followers set by their couplings. Returns (u (nq,), v (nv,)) float64 arrays: per body CoM [m] and unit Euler parameters; CoM velocity [m/s, world] and angular velocity [rad/s, body]. ModelError on a model without a joint space or wrong shapes. A model with closed loops or a fixed-base tree with ideal gears: its independent coordinates (model.coord_names), the others solved from the loop and gear constraints (continuation from the last solution of data, an armdyn.Data, or this thread's when None: the assembly branch and the gears' turns kept; SolverError at a singular configuration).
    """
def torque_error_metrics(a: numpy.typing.ArrayLike, ref: numpy.typing.ArrayLike) -> dict:
    ...
def urdf_builder(path_or_xml: str, fixed_base: bool = True, gravity: numpy.typing.ArrayLike = (0.0, 0.0, -9.81), *, physical_inertia: bool = True, mimic: bool = True) -> ModelBuilder:
    """
    A ModelBuilder holding a URDF robot (add drives or loads, then finalize()): path_or_xml is a file path or the XML text; fixed_base=False adds a free joint (a floating base) on the root link; gravity (3,) [m/s^2] in world axes; physical_inertia as ModelBuilder's; mimic=True turns <mimic> joints into couplings. UrdfError naming the element on a malformed or unsupported file.
    """
URDF_COULOMB_SMOOTHING: float = 0.001
URDF_MAX_ATTRIBUTES: int = 1000
URDF_MAX_BYTES: int = 67108864
_DRIVEN_ID_FIELDS: tuple = (('t', '(n,) times [s]'), ('u', '(n, nq) Cartesian positions solving the driven constraints'), ('v', '(n, nv) Cartesian velocities solving the driven constraints'), ('q', '(n, n_coords) joint coordinates'), ('qd', '(n, n_coords) joint rates'), ('qdd', '(n, n_coords) joint accelerations'), ('drive_forces', '(n, n_drives) actuator torque/force of each drive, tau = -delta_drive [N m or N]'), ('reaction_forces', '(n, n_joints, 3) joint reaction force on the child [N]'), ('reaction_torques', '(n, n_joints, 3) joint reaction torque on the child [N m]'), ('position_residual', '(n,) max |f| of the constraints [m or rad]'), ('velocity_residual', '(n,) max |zeta v - rhs|'), ('stats', 'counters and CPU time (ARMDYN_DRIVEN_ID_STATS)'))
_DRIVEN_ID_STATS: tuple = (('newton_iterations', 'Newton iterations of the position problems'), ('factorizations', 'KKT factorizations'), ('seconds', 'CPU time [s]'))
_SIM_FIELDS: tuple = (('t', '(n,) output times [s]'), ('u', '(n, nq) positions: per body CoM and Euler parameters (scalar first)'), ('v', '(n, nv) velocities: per body CoM velocity (world) and angular velocity (body)'), ('q', '(n, n_joint_coords) joint-space coordinates (angles unwrapped along the run)'), ('qd', '(n, n_joint_dofs) joint-space rates'), ('qdd', '(n, n_joint_dofs) joint-space accelerations'), ('drive_forces', '(n, n_drives) actuator torque/force of each drive [N m or N]'), ('joint_torques', "(n, n_joint_dofs) applied generalised force on every joint dof (Model::dof_names; floating bases' zero), joint side: drive efforts + torque inputs + motor torques (after their torque limits); springs, dampers and friction excluded [N m or N]"), ('reaction_forces', '(n, n_joints, 3) joint reaction force on the child [N]'), ('reaction_torques', '(n, n_joints, 3) joint reaction torque on the child [N m]'), ('position_residual', '(n,) max |f| of the constraints [m or rad]'), ('velocity_residual', '(n,) max |zeta v - rhs|'), ('kinetic_energy', '(n,) kinetic energy [J]'), ('potential_energy', '(n,) potential energy, gravity and springs [J]'), ('gear_forces', 'mesh force along the line of action of every gear pair, then every ideal gear [N] (positive when s > 0: pushes q_a and q_b back)'), ('limit_forces', "the stops' torque/force on each joint held by one (limit_joints), positive along the coordinate (a lower stop pushes up) [N m or N]"), ('stats', "the run's counters, notes and CPU time (ARMDYN_SIM_STATS)"), ('events', "located events: gear contact onset and separation, the joint stops' events"), ('error', 'why the run stopped early (empty: a complete run)'))
_SIM_STATS: tuple = (('steps', 'accepted steps'), ('rejected', 'rejected steps'), ('rhs_evals', 'right-hand side evaluations'), ('kkt_solves', 'KKT systems solved'), ('factorizations', 'KKT factorizations'), ('articulated_solves', 'KKT systems of a tree solved by the articulated-body recursion (no factorization)'), ('position_projections', 'position projections'), ('newton_iterations', 'Newton iterations of the projections'), ('seconds', 'CPU time of the run [s]'), ('jacobians', 'Jacobians of the implicit integrator'), ('lu_factorizations', 'LU factorizations of the implicit integrator'), ('newton_iterations_implicit', 'Newton iterations of the implicit integrator'), ('newton_failures', 'failed Newton solves of the implicit integrator'), ('events', 'located events'), ('singular_evaluations', 'evaluations at a kinematically singular state'), ('singular_note', 'where the first singular evaluation was'), ('augmented_solves', 'accelerations solved in augmented form (light bodies, or lost accuracy)'), ('augmented_note', 'why accelerations were solved augmented'), ('integrator', 'the integrator used'), ('integrator_reason', "why (for integrator 'auto')"), ('solver_bodies', 'bodies of the model integrated'), ('solver_rows', 'constraint rows of the model integrated'), ('formulation', 'the coordinates integrated and the solver path, one line'))
