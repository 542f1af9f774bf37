// SPDX-License-Identifier: BSD-3-Clause
// The immutable Model: bodies in Cartesian coordinates with Euler parameters, joints as
// algebraic constraints, drives as rheonomic constraints, force elements, and the topology
// analysis done once at finalize() (armdyn/builder/builder.hpp).
//
// State layout (fixed): per body i, u_i = (x_i [m], e_i) with x_i the centre of mass in world
// and e_i the scalar-first Euler parameters (body -> world); v_i = (xdot_i [m/s] in world,
// omega_i [rad/s] in the BODY frame). nq = 7 nb, nv = 6 nb. Body index -1 is ground.
#pragma once

#include <array>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "armdyn/math/types.hpp"
#include "armdyn/model/derived.hpp"
#include "armdyn/model/profile.hpp"

namespace armdyn {

constexpr int kGround = -1;

struct Body {
  std::string name;
  double mass = 0.0;  ///< [kg]
  Mat3 inertia;       ///< [kg m^2] about the centre of mass, body axes
  Vec3 position;      ///< centre of mass at assembly [m] (world)
  Vec4 orientation;   ///< Euler parameters at assembly (body -> world)
};

enum class JointType {
  Revolute,
  Prismatic,
  Spherical,
  Fixed,
  Cylindrical,
  Universal,
  Free,
  /// a point of the child stays on the parent's axis line (2 rows; Adams' "inline" primitive)
  Inline,
  /// the distance between a point of each body stays at its assembly value (1 row)
  Distance
};

const char* joint_type_name(JointType t);

/// Number of constraint rows of a joint type.
constexpr int joint_rows(JointType t) {
  switch (t) {
    case JointType::Revolute:
    case JointType::Prismatic:
      return 5;
    case JointType::Spherical:
      return 3;
    case JointType::Fixed:
      return 6;
    case JointType::Cylindrical:
    case JointType::Universal:
      return 4;
    case JointType::Free:
      return 0;
    case JointType::Inline:
      return 2;
    case JointType::Distance:
      return 1;
  }
  return 0;
}
/// Number of joint coordinates (angle and/or displacement) a joint type defines (the Cartesian
/// coordinate list Model::coords; a free joint has none there).
constexpr int joint_coords(JointType t) {
  switch (t) {
    case JointType::Revolute:
    case JointType::Prismatic:
      return 1;
    case JointType::Cylindrical:
      return 2;
    default:
      return 0;
  }
}

/// Degrees of freedom a joint type contributes to the joint-space velocity vector qd: its
/// coordinates, and 6 for a free joint (a floating base: linear and angular velocity of its frame
/// in its own axes).
constexpr int joint_dofs(JointType t) { return t == JointType::Free ? 6 : joint_coords(t); }
/// Entries a joint type contributes to the joint-space configuration q: its coordinates, and 7
/// for a free joint (position, then the scalar-first unit quaternion of its frame).
constexpr int joint_configs(JointType t) { return t == JointType::Free ? 7 : joint_coords(t); }

struct Joint {
  std::string name;
  JointType type = JointType::Revolute;
  int parent = kGround, child = kGround;  ///< body indices, kGround = -1
  /// joint point in each body's frame, relative to its centre of mass [m] (ground: world)
  Vec3 point_parent = Vec3::Zero(), point_child = Vec3::Zero();
  /// joint frame axes (columns x, y, z) in each body's frame; z is the joint axis
  Mat3 frame_parent = Mat3::Identity(), frame_child = Mat3::Identity();
  double lower = -1e300, upper = 1e300;       ///< position limits (URDF; reported, not enforced)
  double effort = 0.0, velocity_limit = 0.0;  ///< URDF limits, informative
  double length = 0.0;                        ///< distance joint: the held distance [m]
  int row0 = 0;                               ///< first constraint row
  int coord0 = -1;                            ///< first joint coordinate index, -1 if none
  /// Joint-space layout (finalize; -1 when the joint adds nothing): first entry of the joint's
  /// configuration in q and of its degrees of freedom in qd, qdd, tau and M. Free joints
  /// (floating bases) come first, 7 and 6 entries each; then the coordinates in Model::coords
  /// order (q0 = 7 n_free + coord0, dof0 = 6 n_free + coord0).
  int q0 = -1, dof0 = -1;
};

/// Prescribed joint coordinate: q_joint[coord](t) = profile(t).
struct Drive {
  std::string name;
  int joint = 0;
  int coord = 0;  ///< which coordinate of the joint (cylindrical: 0 angle, 1 displacement)
  Profile profile;
  int row = 0;  ///< its constraint row
};

/// Force and torque on a body, both in world axes; the force acts at `point` (body frame,
/// relative to the centre of mass). Scaled by `profile` when has_profile.
struct BodyLoad {
  int body = 0;
  Vec3 force = Vec3::Zero(), torque = Vec3::Zero(), point = Vec3::Zero();
  bool has_profile = false;
  Profile profile;
};

/// Point-to-point spring-damper: tension = k (L - L0) + c dL/dt.
struct SpringDamper {
  std::string name;
  int body_a = kGround, body_b = kGround;
  Vec3 point_a = Vec3::Zero(), point_b = Vec3::Zero();  ///< in body frames (ground: world)
  double stiffness = 0.0, damping = 0.0, rest_length = 0.0;
};

/// Generalised force on one joint coordinate:
///   tau = -k (q - q0) - c qdot - F_c tanh(qdot / v_s) + input(t) + motor,
///   motor = clamp(kp (q_ref - q) + kd (qd_ref - qdot) + ki z, -tau_max, tau_max),
/// z the integral of (q_ref - q): an auxiliary state of the simulation (PI(D) motors), integrated
/// only while the motor is not saturated (conditional integration, no wind-up).
/// Covers rotational/linear spring-dampers, viscous and smoothed Coulomb friction, torque/force
/// inputs and PD motors with a torque limit. The law: coord_force_value (algorithm/forces.hpp).
struct CoordForce {
  int coord = 0;
  double stiffness = 0.0, damping = 0.0, rest = 0.0;
  double coulomb = 0.0, v_smooth = 1e-3;  ///< smoothed Coulomb friction
  bool has_input = false;
  Profile input;
  bool motor = false;  ///< PD motor tracking `reference`
  Profile reference;
  double kp = 0.0, kd = 0.0, ki = 0.0, torque_limit = 1e300;
  int aux = -1;      ///< index of the integral state z (ki > 0)
  std::string name;  ///< for messages
};

/// Gear pair with backlash between the angle coordinates of two revolute joints (external
/// mesh): the mesh displacement along the line of action is s = r_a q_a + r_b q_b (zero when
/// both gears are at their assembly angles; rolling without slip keeps it constant). Inside the
/// gap |s| <= backlash/2 no force acts; beyond it the penetration d = |s| - backlash/2 gives the
/// Hunt-Crossley contact force F = k d^n (1 + alpha d'), clamped at F >= 0 (never pulling), and
/// the generalised forces tau_a = -r_a sign(s) F, tau_b = -r_b sign(s) F. q_a, q_b are tracked
/// over several turns (unwrapped). The law: gear_force (algorithm/forces.hpp).
struct GearPair {
  std::string name;
  int coord_a = 0, coord_b = 0;
  double r_a = 0.0, r_b = 0.0, backlash = 0.0;
  double stiffness = 0.0, exponent = 1.5, hc_damping = 0.0;  ///< k [N/m^n], n, alpha [s/m]
};

/// A linear coupling of two joint coordinates as one constraint row
///   r_a q_a + r_b q_b = offset
/// (multi-turn angles). Two kinds share it (and the Cartesian row, the joint-space null-space
/// reduction of TreeDynamics and the reports):
///  - an ideal gear (ModelBuilder::add_gear, no backlash): two revolute joints, the rolling
///    condition of an external mesh with pitch radii r_a, r_b > 0 and offset 0;
///  - a coupling (ModelBuilder::add_coupling, URDF <mimic>): q_follower = multiplier q_leader +
///    offset between two revolute or two prismatic joints, coord_a the follower, coord_b the
///    leader, r_a = 1, r_b = -multiplier. The follower is a dependent coordinate: the public
///    joint-space functions take the independent ones (IndependentCoords).
struct GearConstraint {
  std::string name;
  int coord_a = 0, coord_b = 0;
  double r_a = 0.0, r_b = 0.0;
  double offset = 0.0;    ///< the row's value [rad or m]
  bool coupling = false;  ///< a coupling (coord_a follows coord_b), not an ideal gear
  int row = 0;
  double multiplier() const { return -r_b / r_a; }
};

/// One joint coordinate (revolute angle, prismatic displacement, ...).
struct Coord {
  std::string name;
  int joint = 0;
  int sub = 0;  ///< 0: angle (or prismatic displacement), 1: cylindrical displacement
  bool angular = true;
};

/// The independent joint coordinates of a model with couplings (GearConstraint::coupling):
/// every coordinate c (of Model::coords) is q_c = scale_c q[source_c] + shift_c of an
/// independent coordinate (scale 1, shift 0 for the independent ones themselves; chains of
/// couplings resolved). On the joint-space vectors, whose floating bases' blocks lead (lead_q =
/// 7 n_free entries of q, lead_v = 6 n_free of qd) and pass through unchanged:
///   q_full = G q + shift,  qd_full = G qd,  qdd_full = G qdd,
/// with G one entry per row. The joint-space functions of a coupled model take q (the
/// independent coordinates, model order, followers removed), as Pinocchio's mimic=True models
/// do, and reduce forces and the mass matrix by G: tau = G^T tau_full, M = G^T M_full G.
/// Without couplings G is the identity (identity() true). The one place where full and
/// independent joint-space vectors meet.
struct IndependentCoords {
  int n = 0;                   ///< independent coordinates (of Model::coords)
  int lead_q = 0, lead_v = 0;  ///< floating bases' entries leading q and qd (passed through)
  std::vector<int> full;       ///< per independent coordinate: its index in Model::coords
  /// per coordinate: the independent coordinate it follows (its own index when independent)
  std::vector<int> source;
  std::vector<double> scale, shift;  ///< per coordinate
  bool identity() const { return n == static_cast<int>(source.size()); }
  int nq() const { return lead_q + n; }  ///< length of the independent q
  int nv() const { return lead_v + n; }  ///< length of the independent qd, qdd, tau
  /// q_full = G q + shift (joint-space configurations)
  void expand_q(const double* q, double* q_full) const;
  /// x_full = G x (rates, accelerations)
  void expand_v(const double* x, double* x_full) const;
  /// f = G^T f_full (generalised forces)
  void reduce(const double* f_full, double* f) const;
  /// Mr = G^T M G (Mr sized nv() x nv() by the caller)
  void reduce(const MatX& M, MatX& Mr) const;
  /// Each angle follower among the coordinates coord_q (Model::coords order, every one) moved
  /// by whole turns to the value nearest its coupling's, scale q_leader + shift: a follower's
  /// pose gives its angle only modulo a turn.
  void align(const std::vector<Coord>& coords, double* coord_q) const;
};

/// A motor's datasheet values, motor side, SI units; NaN = not given (every field optional).
/// Informative for the dynamics (the rotor inertia, gear ratio and friction of an Actuator are
/// what enters them); the motor-side sizing maths (Python armdyn.actuators, armdyn.sizing) reads
/// them.
struct MotorSpec {
  static constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();
  std::string name;
  double torque_constant = kUnset;                ///< [N m/A]
  double resistance = kUnset;                     ///< terminal resistance [ohm]
  double voltage = kUnset;                        ///< supply voltage [V]
  double no_load_speed = kUnset;                  ///< [rad/s]
  double continuous_torque = kUnset;              ///< rated continuous torque [N m]
  double peak_torque = kUnset;                    ///< [N m]
  double max_speed = kUnset;                      ///< [rad/s]
  double thermal_resistance = kUnset;             ///< winding to ambient [K/W] (one-node model)
  double thermal_time_constant = kUnset;          ///< winding [s] (one-node model)
  double rotor_inertia = kUnset;                  ///< [kg m^2]
  double mass = kUnset;                           ///< [kg]
  double thermal_resistance_winding = kUnset;     ///< winding to housing [K/W] (two-node model)
  double thermal_resistance_housing = kUnset;     ///< housing to ambient [K/W] (two-node model)
  double thermal_time_constant_winding = kUnset;  ///< [s] (two-node model)
  double thermal_time_constant_housing = kUnset;  ///< [s] (two-node model)
  double max_winding_temperature = kUnset;        ///< [degC]
  double brake_torque = kUnset;                   ///< holding brake, motor side [N m]
  /// The number of numeric fields (every double member above).
  static constexpr std::size_t kNumFields = 17;
  using Field = std::pair<const char*, double MotorSpec::*>;
  /// The numeric fields, in declaration order, with their names: the one list the bindings
  /// (constructor keywords, properties, repr, ==, pickling), validation and the model bytes
  /// follow. New fields go at the end (the bytes of format 2 hold the first nine).
  static const std::array<Field, kNumFields>& fields();
  /// @throws ModelError naming the field when a given value is not finite and > 0.
  void validate(const std::string& who) const;
  bool operator==(const MotorSpec& o) const;
};

/// A gearbox and motor rotor on a revolute or prismatic joint (ModelBuilder::add_actuator),
/// in the dynamics as a body of its own on a revolute joint `rotor_joint` along the actuated
/// joint's axis, coupled to it: gyroscopic false, the gear-reduced model (Pinocchio's armature):
/// `<joint>_armature` on ground with axial inertia N^2 J turning with the joint (kinetic energy
/// 1/2 N^2 J qdot^2); gyroscopic true, the rotor `<joint>_rotor` with axial inertia J on the
/// actuated joint's parent body turning at N qdot relative to it (its full kinetic energy with
/// its carrier's rotation). Motor-side friction acts on the rotor joint (reflected onto the
/// armature).
struct Actuator {
  int joint = 0;                    ///< the actuated joint
  int rotor_joint = 0;              ///< the rotor's (armature's) revolute joint, a follower
  double gear_ratio = 1.0;          ///< N: rotor speed / joint speed [1, or rad/m for prismatic]
  double rotor_inertia = 0.0;       ///< J about the rotor axis [kg m^2]
  double efficiency = 1.0;          ///< gear efficiency in (0, 1] (not in the dynamics)
  double friction_viscous = 0.0;    ///< motor side [N m s/rad]
  double friction_coulomb = 0.0;    ///< motor side [N m]
  double friction_smoothing = 0.0;  ///< motor-side tanh smoothing velocity [rad/s]
  bool gyroscopic = false;
  bool has_motor = false;
  MotorSpec motor;
};

/// A named frame rigidly attached to a body (or to ground): a URDF link, a tool flange, a sensor.
/// Its placement follows the conventions of Joint::point_parent and Joint::frame_parent: the
/// origin in the body's frame relative to its centre of mass (ground: world), and the frame's
/// axes as the columns of `rotation` in the body's axes (frame -> body).
struct NamedFrame {
  std::string name;
  int body = kGround;
  Vec3 point = Vec3::Zero();
  Mat3 rotation = Mat3::Identity();
};

/// Options of ModelBuilder::finalize(), kept with the model (the welded model simulate()
/// derives from it is assembled with the same options).
struct FinalizeOptions {
  bool mass_weighted_assembly = true;
  int max_assembly_iterations = 50;
};

class Model {
 public:
  // --- data (read-only after finalize) ---
  std::vector<Body> bodies;
  std::vector<Joint> joints;
  std::vector<Drive> drives;
  std::vector<BodyLoad> body_loads;
  std::vector<SpringDamper> springs;
  std::vector<CoordForce> coord_forces;
  std::vector<GearPair> gears;
  std::vector<GearConstraint> gear_constraints;
  std::vector<Actuator> actuators;  ///< gearboxes and rotors (ModelBuilder::add_actuator)
  std::vector<int> tracked_coords;  ///< angle coordinates unwrapped over turns (gears)
  int n_aux = 0;  ///< auxiliary states of the simulation (integral terms of PI motors)
  std::vector<Coord> coords;
  /// Joint-space sizes (finalize): nq_joint = len(q) = 7 n_free + coords, nv_joint = len(qd) =
  /// 6 n_free + coords; n_free the free joints (floating bases), whose blocks lead q and qd.
  int n_free = 0, nq_joint = 0, nv_joint = 0;
  std::vector<int> dof_joint;  ///< the joint of each joint-space degree of freedom (nv_joint)
  std::vector<std::string> q_names, dof_names;  ///< names of the entries of q and of qd
  std::vector<NamedFrame> frames;  ///< named frames (builder add_frame; every URDF link)
  /// the independent coordinates (couplings removed; finalize). n_coords of the bindings.
  IndependentCoords independent;
  Vec3 gravity = Vec3(0, 0, -9.81);

  // --- sizes ---
  int nb = 0, nq = 0, nv = 0;
  int nc = 0;        ///< all constraint rows: joints then drives
  int nc_joint = 0;  ///< joint and ideal-gear rows (rows [0, nc_joint)), before the drives

  // --- topology analysis ---
  bool is_tree = false;  ///< every body has exactly one joint path to ground
  bool joint_space_ok =
      false;  ///< tree of revolute/prismatic/cylindrical/fixed joints, parent->child
  std::string joint_space_reason;
  /// joint_space_ok but for couplings: the public joint-space functions (forward and inverse
  /// dynamics, mass matrix, state_from_joints) take the independent coordinates
  /// (IndependentCoords); the others refuse such a model (joint_space_reason names the coupling)
  bool coupled_joint_space = false;
  /// a model with closed loops (not a tree), or a fixed-base tree with ideal gears, whose
  /// joint-level functions (forward and inverse dynamics, mass matrix, state_from_joints,
  /// joint_reactions, frame_pose, frame_jacobian) take `mobility` independent joint coordinates
  /// (Model::independent: full lists them, source -1 for the dependent ones), evaluated on the
  /// Cartesian formulation (armdyn/algorithm/loop_coordinates.hpp; finalize's
  /// choose_loop_coordinates)
  bool loop_coordinates = false;
  /// the independent coordinates the user chose (ModelBuilder::set_independent_coordinates, by
  /// name); empty: armdyn's default choice
  std::vector<std::string> independent_request;
  /// a tree of joint-coordinate joints defined parent -> child, ideal gears allowed (the
  /// joint-space path of simulate, armdyn/algorithm/tree_dynamics.hpp)
  bool joint_tree = false;
  /// Why the joint-space path (TreeDynamics) does not apply to this model -- not a joint tree,
  /// or (unless ignore_drives) a drive prescribes a coordinate -- or empty when it does.
  std::string joint_path_reason(bool ignore_drives = false) const;
  std::vector<int> tree_order;  ///< joints in parent-before-child order (if is_tree)
  int rank_joint = 0, rank_all = 0;
  int mobility = 0;         ///< nv - rank of joint rows (degrees of freedom without drives)
  int mobility_driven = 0;  ///< nv - rank of all rows (what the drives leave free)
  std::vector<std::string> redundant_rows;  ///< named redundant constraint rows
  /// what finalize() treated as exact though it holds only to round-off (the Python finalize
  /// issues each as a UserWarning)
  std::vector<std::string> warnings;
  /// rows finalize() took as dependent though they are so only to round-off (1e-12 .. 1e-6):
  /// the projection accepts their least-squares residual (up to 1e-6 l); empty for models whose
  /// dependent rows are exactly so
  std::vector<int> aligned_rows;
  bool redundant = false;
  double length_scale = 1.0;  ///< characteristic length for tolerances [m]
  /// true: the KKT solves take the dense pivoted path whatever the plan (the reference path;
  /// the Python Model.with_kkt_path("dense")). Redundant models take it anyway.
  bool force_dense_kkt = false;
  FinalizeOptions finalize_options;

  // --- assembled initial state ---
  VecX u0, v0;

  std::map<std::string, int> body_index, joint_index, drive_index;
  std::map<std::string, int> frame_index;

  /// The index of frame `name` in `frames`; throws ModelError "unknown frame 'x' (known: ...)".
  int find_frame(const std::string& name) const;

  int find_body(const std::string& name) const;   ///< -1 for "ground"; throws ModelError
  int find_joint(const std::string& name) const;  ///< throws ModelError
  std::string row_name(int row) const;            ///< e.g. "joint 'elbow' row 4 (rotation)"
  std::string body_name(int b) const { return b == kGround ? "ground" : bodies[b].name; }

  /// What the solver and analysis layers derive from this model on first use (KKT plans, the
  /// welded model): see armdyn/kernels/block_sparse.hpp kkt_plans(), armdyn/builder/weld.hpp.
  detail::DerivedCache derived;
};

using ModelPtr = std::shared_ptr<const Model>;

}  // namespace armdyn
