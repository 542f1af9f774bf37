// SPDX-License-Identifier: BSD-3-Clause
// armdyn.ModelBuilder's drives, loads, force elements, gears, couplings, actuators and motors
// (armdyn/builder/builder.hpp); the bodies and joints: bind_builder.cpp.
#include "convert_builder.hpp"
#include "convert_model.hpp"

namespace armdyn {

namespace py = pybind11;
using namespace py_helpers;

namespace {

void def_builder_loads(BuilderClass& cls) {
  cls.def(
         "add_drive",
         [](ModelBuilder& b, const StrArg& joint_, const ProfileLike& profile, const IntArg& coord,
            const OptStr& name) {
           const char* fn = "ModelBuilder.add_drive";
           const std::string joint = str_arg(joint_, fn, "joint");
           const int k = int_arg(coord, fn, "coord");
           const std::string nm = opt_str_arg(name, fn, "name");
           return b.add_drive(joint, to_profile(profile, "add_drive '" + joint + "': profile"), k,
                              nm);
         },
         py::arg("joint"), py::arg("profile"), py::arg("coord") = 0, py::arg("name") = py::none(),
         "Prescribe coordinate `coord` of `joint` by a profile [rad or m over t in s] "
         "(armdyn.profiles.*, a number, or a Python callable t -> (y, yd, ydd): accepted but "
         "slow, it runs Python at every evaluation): a rheonomic constraint whose multiplier is "
         "the drive's effort (SimulationResult.drive_forces). `name` defaults to the joint's. "
         "Returns the drive index; ModelError on an unknown joint or coordinate, or a bad "
         "profile.")
      .def(
          "add_body_force",
          [](ModelBuilder& b, const StrArg& body_, const ArrayLike& force, const ArrayLike& torque,
             const OptArrayLike& point, const OptProfileLike& profile) {
            const std::string body = str_arg(body_, "ModelBuilder.add_body_force", "body");
            const std::string who = "load on body '" + body + "'";
            const auto pt = opt_vec3(point, who + ": point");
            const auto pr = opt_profile(profile, who + ": profile");
            b.add_body_load(body, to_vec3(force, who + ": force"),
                            to_vec3(torque, who + ": torque"), ptr_or_null(pt), ptr_or_null(pr));
          },
          py::arg("body"), py::arg("force") = py::make_tuple(0.0, 0.0, 0.0),
          py::arg("torque") = py::make_tuple(0.0, 0.0, 0.0), py::arg("point") = py::none(),
          py::arg("profile") = py::none(),
          "Force [N] at a point (world coordinates at assembly; default the CoM) and torque "
          "[N m], both in world axes, optionally scaled by a profile.")
      .def(
          "add_spring_damper",
          [](ModelBuilder& b, const StrArg& n_, const StrArg& ba_, const ArrayLike& pa,
             const StrArg& bb_, const ArrayLike& pb, const FloatArg& k, const FloatArg& c,
             const OptFloat& rest) {
            const char* fn = "ModelBuilder.add_spring_damper";
            const std::string n = str_arg(n_, fn, "name"), ba = str_arg(ba_, fn, "body_a"),
                              bb = str_arg(bb_, fn, "body_b");
            const double kv = float_arg(k, fn, "stiffness"), cv = float_arg(c, fn, "damping");
            const double rv = rest_length_arg(rest, fn);
            const std::string who = "spring-damper '" + n + "'";
            b.add_spring_damper(n, ba, to_vec3(pa, who + ": point_a"), bb,
                                to_vec3(pb, who + ": point_b"), kv, cv, rv);
          },
          py::arg("name"), py::arg("body_a"), py::arg("point_a"), py::arg("body_b"),
          py::arg("point_b"), py::arg("stiffness"), py::arg("damping") = 0.0,
          py::arg("rest_length") = py::none(),
          "Point-to-point spring-damper `name` between point_a (3,) of body_a and point_b (3,) of "
          "body_b (world coordinates at assembly [m]; a body may be 'ground'): force "
          "stiffness [N/m] * (length - rest_length) + damping [N s/m] * length rate along the "
          "line; rest_length [m] defaults to the assembly distance. ModelError on an unknown "
          "body, coincident points, non-finite input, negative stiffness or damping.")
      .def(
          "add_joint_spring_damper",
          [](ModelBuilder& b, const StrArg& joint, const FloatArg& k, const FloatArg& c,
             const FloatArg& rest, const IntArg& coord) {
            const char* fn = "ModelBuilder.add_joint_spring_damper";
            b.add_joint_spring_damper(str_arg(joint, fn, "joint"), float_arg(k, fn, "stiffness"),
                                      float_arg(c, fn, "damping"), float_arg(rest, fn, "rest"),
                                      int_arg(coord, fn, "coord"));
          },
          py::arg("joint"), py::arg("stiffness") = 0.0, py::arg("damping") = 0.0,
          py::arg("rest") = 0.0, py::arg("coord") = 0,
          "Spring-damper on coordinate `coord` of `joint`: tau = -stiffness (q - rest) - "
          "damping qdot, stiffness [N m/rad or N/m], damping [N m s/rad or N s/m], rest [rad "
          "or m]. ModelError on an unknown joint or coordinate, negative stiffness/damping.")
      .def(
          "add_joint_friction",
          [](ModelBuilder& b, const StrArg& joint, const FloatArg& viscous, const FloatArg& coulomb,
             const FloatArg& smoothing_velocity, const IntArg& coord) {
            const char* fn = "ModelBuilder.add_joint_friction";
            b.add_joint_friction(str_arg(joint, fn, "joint"), float_arg(viscous, fn, "viscous"),
                                 float_arg(coulomb, fn, "coulomb"),
                                 float_arg(smoothing_velocity, fn, "smoothing_velocity"),
                                 int_arg(coord, fn, "coord"));
          },
          py::arg("joint"), py::arg("viscous") = 0.0, py::arg("coulomb") = 0.0,
          py::arg("smoothing_velocity") = 1e-3, py::arg("coord") = 0,
          "Joint friction: tau = -viscous * qdot - coulomb * tanh(qdot / smoothing_velocity).");
}

void def_builder_gears(BuilderClass& cls) {
  cls.def(
         "add_gear",
         [](ModelBuilder& b, const StrArg& name, const StrArg& ja, const StrArg& jb,
            const FloatArg& ra, const FloatArg& rb) {
           const char* fn = "ModelBuilder.add_gear";
           b.add_gear(str_arg(name, fn, "name"), str_arg(ja, fn, "joint_a"),
                      str_arg(jb, fn, "joint_b"), float_arg(ra, fn, "r_a"),
                      float_arg(rb, fn, "r_b"));
         },
         py::arg("name"), py::arg("joint_a"), py::arg("joint_b"), py::arg("r_a"), py::arg("r_b"),
         "Ideal gear (no backlash) between two revolute joints: the rolling constraint "
         "r_a q_a + r_b q_b = 0 (external mesh, multi-turn angles).")
      .def(
          "add_coupling",
          [](ModelBuilder& b, const StrArg& name, const StrArg& follower, const StrArg& leader,
             const FloatArg& multiplier, const FloatArg& offset) {
            const char* fn = "ModelBuilder.add_coupling";
            b.add_coupling(str_arg(name, fn, "name"), str_arg(follower, fn, "follower"),
                           str_arg(leader, fn, "leader"), float_arg(multiplier, fn, "multiplier"),
                           float_arg(offset, fn, "offset"));
          },
          py::arg("name"), py::arg("follower"), py::arg("leader"), py::arg("multiplier"),
          py::arg("offset") = 0.0,
          "Coupling q_follower = multiplier * q_leader + offset [rad or m] between two revolute "
          "(continuous) or two prismatic joints (URDF <mimic>): one constraint row; the "
          "follower becomes a dependent coordinate, and forward_dynamics, inverse_dynamics, "
          "mass_matrix, state_from_joints and simulate(q0=...) take the independent ones "
          "(model.coord_names). Chains allowed; cycles, a follower coupled twice, joints of "
          "different types and a zero or non-finite multiplier are refused (ModelError).")
      .def(
          "add_actuator",
          [](ModelBuilder& b, const StrArg& joint_, const FloatArg& gear_ratio,
             const FloatArg& rotor_inertia, const FloatArg& efficiency,
             const FloatArg& friction_viscous, const FloatArg& friction_coulomb,
             const OptMotor& motor, const BoolArg& gyroscopic, const OptFloat& friction_smoothing) {
            const char* fn = "ModelBuilder.add_actuator";
            const std::string joint = str_arg(joint_, fn, "joint");
            const double n = float_arg(gear_ratio, fn, "gear_ratio");
            const double j = float_arg(rotor_inertia, fn, "rotor_inertia");
            const double eff = float_arg(efficiency, fn, "efficiency");
            const double fv = float_arg(friction_viscous, fn, "friction_viscous");
            const double fc = float_arg(friction_coulomb, fn, "friction_coulomb");
            const bool gyro = bool_arg(gyroscopic, fn, "gyroscopic");
            const auto spec = opt_motor_arg(motor, fn, joint);
            const double vs = friction_smoothing_arg(friction_smoothing, fn, joint);
            b.add_actuator(joint, n, j, eff, fv, fc, ptr_or_null(spec), gyro, vs);
          },
          py::arg("joint"), py::arg("gear_ratio"), py::arg("rotor_inertia"),
          py::arg("efficiency") = 1.0, py::arg("friction_viscous") = 0.0,
          py::arg("friction_coulomb") = 0.0, py::arg("motor") = py::none(),
          py::arg("gyroscopic") = false, py::arg("friction_smoothing") = py::none(),
          "A gearbox and motor rotor on a revolute (continuous) or prismatic joint. "
          "gear_ratio N = rotor speed / joint speed (negative reverses the rotor; rad/m for a "
          "prismatic joint, a ball screw); rotor_inertia J [kg m^2] about the rotor axis; "
          "efficiency in (0, 1] (stored for the motor-side maths, not in the dynamics); "
          "friction_viscous [N m s/rad] and friction_coulomb [N m] on the motor side "
          "(reflected as N^2 b and |N| c), Coulomb smoothed by tanh(omega / friction_smoothing), "
          "friction_smoothing [rad/s, motor side] default 1e-3 |N|; motor: an armdyn.Motor or "
          "None. Adds a body, a revolute joint and a coupling (zero mass, thin-disc inertia) "
          "along the joint axis through its origin: by default (gyroscopic=False) "
          "'<joint>_armature' on ground, axial inertia N^2 J, turning with the joint (at qdot: "
          "the gear-reduced model, Pinocchio's armature N^2 J exactly); with gyroscopic=True "
          "'<joint>_rotor' on the joint's parent body, axial inertia J, turning at N qdot "
          "relative to it (the rotor's full kinetic energy, with its carrier's rotation). "
          "ModelError, builder unchanged, on an unknown joint, a joint not "
          "revolute or prismatic, a second actuator, gear_ratio zero or not finite, "
          "rotor_inertia < 0, efficiency outside (0, 1], negative frictions.")
      .def(
          "add_gear_pair",
          [](ModelBuilder& b, const StrArg& name, const StrArg& ja, const StrArg& jb,
             const FloatArg& ra, const FloatArg& rb, const FloatArg& backlash,
             const FloatArg& stiffness, const FloatArg& exponent, const FloatArg& hc_damping) {
            const char* fn = "ModelBuilder.add_gear_pair";
            b.add_gear_pair(
                str_arg(name, fn, "name"), str_arg(ja, fn, "joint_a"), str_arg(jb, fn, "joint_b"),
                float_arg(ra, fn, "r_a"), float_arg(rb, fn, "r_b"),
                float_arg(backlash, fn, "backlash"), float_arg(stiffness, fn, "stiffness"),
                float_arg(exponent, fn, "exponent"), float_arg(hc_damping, fn, "hc_damping"));
          },
          py::arg("name"), py::arg("joint_a"), py::arg("joint_b"), py::arg("r_a"), py::arg("r_b"),
          py::arg("backlash") = 0.0, py::arg("stiffness") = 1e8, py::arg("exponent") = 1.5,
          py::arg("hc_damping") = 0.0,
          "Gear pair with backlash between two revolute joints (external mesh): mesh "
          "displacement s = r_a q_a + r_b q_b, dead zone |s| <= backlash/2, Hunt-Crossley "
          "contact force F = k d^n (1 + hc_damping d') >= 0 beyond it. Contact onset and "
          "separation are located as events (result.events).")
      .def(
          "add_motor",
          [](ModelBuilder& b, const StrArg& joint_, const ProfileLike& reference,
             const FloatArg& kp_, const FloatArg& kd_, const FloatArg& torque_limit_,
             const OptProfileLike& feedforward, const IntArg& coord_, const FloatArg& ki_) {
            const char* fn = "ModelBuilder.add_motor";
            const std::string joint = str_arg(joint_, fn, "joint");
            const double kp = float_arg(kp_, fn, "kp"), kd = float_arg(kd_, fn, "kd");
            const double torque_limit = float_arg(torque_limit_, fn, "torque_limit");
            const int coord = int_arg(coord_, fn, "coord");
            const double ki = float_arg(ki_, fn, "ki");
            const std::string who = "add_motor '" + joint + "'";
            const Profile ref = to_profile(reference, who + ": reference");
            const auto ff = opt_profile(feedforward, who + ": feedforward");
            b.add_motor(joint, ref, kp, kd, torque_limit, ptr_or_null(ff), coord, ki);
          },
          py::arg("joint"), py::arg("reference"), py::arg("kp"), py::arg("kd"),
          py::arg("torque_limit") = 1e300, py::arg("feedforward") = py::none(),
          py::arg("coord") = 0, py::arg("ki") = 0.0,
          "PD or PID motor on a joint coordinate: tau = clamp(kp (q_ref - q) + kd (qd_ref - qd) "
          "+ ki z, +-torque_limit) + feedforward(t), z the integral of q_ref - q (an auxiliary "
          "state, not integrated while saturated); the reference is a profile (armdyn.profiles.*, "
          "a "
          "number, or a callable).")
      .def(
          "add_joint_torque",
          [](ModelBuilder& b, const StrArg& joint_, const ProfileLike& profile,
             const IntArg& coord) {
            const char* fn = "ModelBuilder.add_joint_torque";
            const std::string joint = str_arg(joint_, fn, "joint");
            const int k = int_arg(coord, fn, "coord");
            b.add_joint_torque(joint, to_profile(profile, "joint torque on '" + joint + "'"), k);
          },
          py::arg("joint"), py::arg("profile"), py::arg("coord") = 0,
          "Apply a torque [N m] (revolute) or force [N] (prismatic) on coordinate `coord` of "
          "`joint`, given by a profile of t [s] (armdyn.profiles.*, a number, or a callable t "
          "-> (y, yd, ydd)): acts on the child about/along the joint axis and the opposite on "
          "the parent; reported in SimulationResult.joint_torques. ModelError on an unknown "
          "joint or coordinate, or a bad profile.");
}

}  // namespace

void bind_builder_forces(py::module_& m) {
  auto c = py::reinterpret_borrow<BuilderClass>(py::object(m.attr("ModelBuilder")));
  def_builder_loads(c);
  def_builder_gears(c);
}

}  // namespace armdyn
