// SPDX-License-Identifier: BSD-3-Clause
// ModelBuilder: add bodies, joints, drives and force elements, then finalize() into an
// immutable Model: the topology analysis, the assembly of the initial state (the projection of
// armdyn/algorithm/projection.hpp) and the rank analysis (mobility, redundant rows). The build
// layer sits above the solver, as the URDF reader does; armdyn/model/ is the description alone.
// Every add_* call validates its input first and leaves the builder unchanged when it throws. Joint
// points and axes are given in WORLD coordinates at the assembly pose.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "armdyn/model/model.hpp"

namespace armdyn {

/// Why check_inertia refuses a tensor.
enum class InertiaProblem { None, NotPositiveSemidefinite, TriangleInequality };

/// The verdict on a (symmetric) inertia tensor under ModelBuilder::set_physical_inertia.
struct InertiaCheck {
  Vec3 moments = Vec3::Zero();                 ///< principal moments, ascending [kg m^2]
  InertiaProblem kind = InertiaProblem::None;  ///< why it is refused
  std::string problem;         ///< ... in words ("violates the triangle inequality"), or ""
  Mat3 tensor = Mat3::Zero();  ///< the tensor to use: the input, or its clamped version
  bool clamped = false;        ///< negative round-off moments were set to zero
  bool warn = false;           ///< ... and they exceed the round-off of rotating a tensor
  double smallest = 0.0;       ///< the smallest principal moment before clamping
};
/// physical = false: negative moments down to -1e-12 max(largest moment, scale) are round-off,
/// clamped (the URDF reader passes the robot's largest link moment as scale: CAD exports write
/// point masses as tensors of 1e-20 with either sign); a warning when below -64 eps of the
/// tensor's own largest moment (above it, they are the round-off of rotating the tensor).
InertiaCheck check_inertia(const Mat3& inertia, bool physical, double scale = 0.0);

class ModelBuilder {
 public:
  explicit ModelBuilder(const Vec3& gravity = Vec3(0, 0, -9.81), bool physical_inertia = true);
  /// A builder holding `draft`, as draft() returned it (a restored builder:
  /// armdyn/io/serialize.hpp).
  ModelBuilder(Model draft, bool physical_inertia);

  /// Which inertia tensors add_body() accepts (for the bodies added after the call).
  /// true (default): physically consistent ones only -- positive semidefinite (to -1e-12 of the
  /// largest coefficient) and satisfying the triangle inequality J1 + J2 >= J3 of the principal
  /// moments. false: any positive semidefinite tensor (published or identified parameter sets
  /// that violate the triangle inequality); negative principal moments down to -1e-12 of the
  /// largest moment are round-off and clamped to zero, with a warning (Model::warnings) when
  /// they lie below -64 eps of it (smaller ones are the round-off of rotating a tensor).
  void set_physical_inertia(bool physical) { physical_inertia_ = physical; }
  bool physical_inertia() const { return physical_inertia_; }

  /// Add a rigid body. inertia: 3x3 about the centre of mass in body axes [kg m^2];
  /// position: centre of mass [m] (of a massless body: any point of it, its frame origin);
  /// orientation: unit Euler parameters, scalar-first. mass may be 0 and the inertia singular
  /// (massless links between joints, point masses): finalize() then checks that every motion
  /// the joints allow still carries inertia (the joint-space mass matrix is positive definite)
  /// and names the joint and body when one does not.
  /// @throws ModelError on bad mass, inertia (see set_physical_inertia), pose or a duplicate
  ///   name.
  int add_body(const std::string& name, double mass, const Mat3& inertia, const Vec3& position,
               const Vec4& orientation);

  int add_revolute(const std::string& name, const std::string& parent, const std::string& child,
                   const Vec3& point, const Vec3& axis);
  int add_prismatic(const std::string& name, const std::string& parent, const std::string& child,
                    const Vec3& point, const Vec3& axis);
  int add_cylindrical(const std::string& name, const std::string& parent, const std::string& child,
                      const Vec3& point, const Vec3& axis);
  int add_spherical(const std::string& name, const std::string& parent, const std::string& child,
                    const Vec3& point);
  /// Rigid connection; `point` only sets where reactions are reported.
  int add_fixed(const std::string& name, const std::string& parent, const std::string& child,
                const Vec3& point);
  /// add_fixed with `point` null: the reactions reported at the child's centre of mass (the
  /// world origin for "ground"). @throws ModelError on an unknown child, as add_fixed.
  int add_fixed(const std::string& name, const std::string& parent, const std::string& child,
                const Vec3* point);
  /// Universal (Cardan) joint: axis1 fixed in parent, axis2 fixed in child, perpendicular.
  int add_universal(const std::string& name, const std::string& parent, const std::string& child,
                    const Vec3& point, const Vec3& axis1, const Vec3& axis2);
  /// Inline (point-on-line) joint: the child's point stays on the line through `point` along
  /// `axis` fixed in the parent; 2 rows. Closing a planar loop with it instead of a revolute
  /// keeps the rows independent (a revolute there adds 3 rows the loop already implies).
  int add_inline(const std::string& name, const std::string& parent, const std::string& child,
                 const Vec3& point, const Vec3& axis);
  /// Distance joint (a massless rod with ball ends): |P_b - P_a| stays at its assembly value;
  /// points in world coordinates at the assembly pose; 1 row.
  int add_distance(const std::string& name, const std::string& body_a, const Vec3& point_a,
                   const std::string& body_b, const Vec3& point_b);
  /// Declares a body free (6 DOF, no constraint rows) so that it counts as connected to ground: a
  /// floating base. In joint space its frame -- the body's axes at `origin` (world at assembly;
  /// default the centre of mass) -- gives 7 entries of q (position, scalar-first unit quaternion)
  /// and 6 of qd (linear and angular velocity in the frame's own axes).
  int add_free(const std::string& name, const std::string& child, const Vec3* origin = nullptr);

  /// Add a named frame rigidly attached to `body` (or "ground"): its origin `position` [m] and
  /// axes `orientation` (unit Euler parameters, scalar first, frame -> world), both in WORLD at
  /// the assembly pose like every builder input. Stored relative to the body (NamedFrame).
  /// @throws ModelError on an empty or duplicate frame name, an unknown body, a non-finite
  /// placement or a quaternion that is not of unit norm.
  int add_frame(const std::string& name, const std::string& body, const Vec3& position,
                const Vec4& orientation);

  /// Set position limits and informative effort/velocity limits on a joint.
  void set_joint_limits(const std::string& joint, double lower, double upper, double effort,
                        double velocity);

  /// Prescribe joint coordinate `coord` of `joint` by `profile` (a rheonomic constraint).
  int add_drive(const std::string& joint, const Profile& profile, int coord = 0,
                const std::string& name = "");

  /// Force (world) at a body point (world coordinates at assembly; default centre of mass) and
  /// torque (world), optionally scaled by a profile.
  void add_body_load(const std::string& body, const Vec3& force, const Vec3& torque,
                     const Vec3* point_world, const Profile* profile);
  /// Point-to-point spring-damper between two points given in world coordinates at assembly.
  /// rest_length < 0 means "the assembly distance".
  void add_spring_damper(const std::string& name, const std::string& body_a, const Vec3& point_a,
                         const std::string& body_b, const Vec3& point_b, double stiffness,
                         double damping, double rest_length);
  /// Spring-damper and/or viscous friction on a joint coordinate.
  void add_joint_spring_damper(const std::string& joint, double stiffness, double damping,
                               double rest, int coord = 0);
  /// Torque (force for prismatic) input on a joint coordinate, from a profile.
  void add_joint_torque(const std::string& joint, const Profile& profile, int coord = 0);
  /// Viscous plus smoothed Coulomb friction: tau = -viscous qdot - coulomb tanh(qdot / v_s).
  void add_joint_friction(const std::string& joint, double viscous, double coulomb,
                          double smoothing_velocity, int coord = 0);
  /// Ideal gear between two revolute joints: the constraint r_a q_a + r_b q_b = 0.
  void add_gear(const std::string& name, const std::string& joint_a, const std::string& joint_b,
                double r_a, double r_b);
  /// Coupling q_follower = multiplier q_leader + offset [rad or m] between two revolute (or
  /// continuous) or two prismatic joints (URDF <mimic>): one constraint row; the follower is a
  /// dependent coordinate (Model::independent). Chains (a leader that follows another) are
  /// allowed, cycles are not.
  /// @throws ModelError (naming the coupling and the culprit) on a duplicate name, an unknown
  ///   joint, the same joint twice, a joint without exactly one coordinate, joints of different
  ///   types, a non-finite or zero multiplier, a non-finite offset, a follower coupled twice or
  ///   a cycle of couplings.
  /// The independent coordinates of a model with closed loops (by name, from
  /// joint_coord_names; as many as its mobility, each independent of the others at the assembled
  /// state), checked by finalize (Model::loop_coordinates). An empty list: armdyn's default.
  void set_independent_coordinates(const std::vector<std::string>& names) {
    m_.independent_request = names;
  }
  void add_coupling(const std::string& name, const std::string& follower, const std::string& leader,
                    double multiplier, double offset = 0.0);
  /// A gearbox and motor rotor on revolute or prismatic joint `joint` (see Actuator), as a
  /// body of zero mass and thin-disc inertia (axial I, transverse I / 2) on a revolute joint
  /// along the joint's axis through its origin, coupled to the joint:
  ///  - gyroscopic false (the gear-reduced model, Pinocchio's armature): body and joint
  ///    `<joint>_armature` on ground, I = N^2 rotor_inertia, turning with the joint (coupling
  ///    multiplier 1): kinetic energy 1/2 N^2 J qdot^2, exactly the rotor's at N qdot, without a
  ///    body spinning N times faster for the Cartesian error control;
  ///  - gyroscopic true: the rotor itself, `<joint>_rotor`, I = rotor_inertia, on the joint's
  ///    parent body, turning at q_rotor = gear_ratio q_joint relative to it (its full kinetic
  ///    energy, gyroscopic terms included).
  /// A prismatic joint's ratio is in rad/m. Motor-side viscous b [N m s/rad] and Coulomb c
  /// [N m] friction (smoothing velocity friction_smoothing [rad/s] motor side; <= 0:
  /// 1e-3 |gear_ratio|, i.e. 1e-3 joint side) act on the rotor joint, reaching the joint as
  /// N^2 b and |N| c (on the armature directly so). efficiency and motor are stored
  /// (Model::actuators), not in the dynamics.
  /// @throws ModelError naming the joint and the culprit on an unknown joint, a joint that is
  ///   not revolute or prismatic, a second actuator on the joint, a zero or non-finite
  ///   gear_ratio, a negative or non-finite rotor_inertia, an efficiency outside (0, 1],
  ///   negative or non-finite frictions, an invalid motor, or the rotor's name taken.
  void add_actuator(const std::string& joint, double gear_ratio, double rotor_inertia,
                    double efficiency = 1.0, double friction_viscous = 0.0,
                    double friction_coulomb = 0.0, const MotorSpec* motor = nullptr,
                    bool gyroscopic = false, double friction_smoothing = 0.0);
  /// Gear pair with backlash between two revolute joints (see GearPair).
  void add_gear_pair(const std::string& name, const std::string& joint_a,
                     const std::string& joint_b, double r_a, double r_b, double backlash,
                     double stiffness, double exponent, double hc_damping);
  /// PD motor on a joint coordinate tracking `reference` (angles wrapped), torque limited to
  /// +-torque_limit, plus an optional feed-forward profile.
  void add_motor(const std::string& joint, const Profile& reference, double kp, double kd,
                 double torque_limit, const Profile* feedforward, int coord = 0, double ki = 0.0);

  /// Validate, analyse the topology and assemble the initial state. The builder is unchanged
  /// and may be finalized again.
  /// @throws ModelError on invalid or disconnected models, or when assembly fails.
  ModelPtr finalize(const FinalizeOptions& options = FinalizeOptions()) const;

  const Model& draft() const { return m_; }

  /// A note finalize() passes on in Model::warnings (the URDF reader's clamped inertias).
  void add_warning(const std::string& text) { m_.warnings.push_back(text); }

 private:
  /// The joint named `joint`, checked to have coordinate `coord` (messages name `who`).
  const Joint& coord_joint(const std::string& who, const std::string& joint, int coord) const;
  /// Coordinates of the two revolute joints of a gear, with the checks common to both gear
  /// kinds (named `who` in the messages).
  std::pair<int, int> gear_coords(const std::string& who, const std::string& joint_a,
                                  const std::string& joint_b, double r_a, double r_b) const;

  /// add_coupling; mixed: a revolute follower may follow a prismatic leader (actuator rotors)
  void add_coupling_impl(const std::string& name, const std::string& follower,
                         const std::string& leader, double multiplier, double offset, bool mixed);
  int add_joint(const std::string& name, JointType type, const std::string& parent,
                const std::string& child, const Vec3& point, const Vec3& axis, const Vec3* axis2,
                const Vec3* point_child = nullptr);
  int resolve_body(const std::string& name, const std::string& context) const;
  Model m_;
  bool physical_inertia_ = true;
};

namespace detail {
/// finalize() of a draft model (what a builder holds): sizes, rows, topology, assembly, rank.
std::shared_ptr<Model> finalize_draft(const Model& draft, const FinalizeOptions& options);
}  // namespace detail

}  // namespace armdyn
