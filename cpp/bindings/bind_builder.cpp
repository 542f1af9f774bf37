// SPDX-License-Identifier: BSD-3-Clause
// armdyn.ModelBuilder (armdyn/builder/builder.hpp): bodies, joints, frames, limits, finalize().
// Drives, loads, force elements, gears and actuators: bind_builder_forces.cpp; pickling:
// bind_pickle.cpp.
#include "armdyn/model/properties.hpp"
#include "convert_builder.hpp"

namespace armdyn {

namespace py = pybind11;
using namespace py_helpers;

namespace {

void def_builder_bodies(BuilderClass& cls) {
  cls.def_property(
         "physical_inertia", &ModelBuilder::physical_inertia,
         [](ModelBuilder& b, const BoolArg& v) {
           b.set_physical_inertia(bool_arg(v, "ModelBuilder", "physical_inertia"));
         },
         "True (default): add_body accepts physically consistent inertias only "
         "(positive semidefinite, triangle inequality). False: any positive "
         "semidefinite tensor; negative round-off moments down to -1e-12 of the "
         "largest are clamped to zero with a warning. Applies to bodies added after "
         "it is set.")
      .def(
          "add_body",
          [](ModelBuilder& b, const StrArg& name_, const FloatArg& mass, const ArrayLike& inertia,
             const ArrayLike& position, const ArrayLike& orientation) {
            const char* fn = "ModelBuilder.add_body";
            const std::string name = str_arg(name_, fn, "name");
            const double m = float_arg(mass, fn, "mass");
            const std::string who = "body '" + name + "'";
            return b.add_body(name, m, to_inertia(inertia, who + ": inertia"),
                              to_vec3(position, who + ": position"),
                              to_vec4(orientation, who + ": orientation"));
          },
          py::arg("name"), py::arg("mass"), py::arg("inertia"),
          py::arg("position") = py::make_tuple(0.0, 0.0, 0.0),
          py::arg("orientation") = py::make_tuple(1.0, 0.0, 0.0, 0.0),
          "Add a body: mass [kg], inertia (3,3) about the CoM in body axes [kg m^2] (or its (3,) "
          "diagonal), CoM position [m], orientation as unit Euler parameters [e0, e1, e2, e3].")
      .def(
          "add_frame",
          [](ModelBuilder& b, const StrArg& name_, const StrArg& body_, const ArrayLike& position,
             const ArrayLike& orientation) {
            const char* fn = "ModelBuilder.add_frame";
            const std::string name = str_arg(name_, fn, "name"), body = str_arg(body_, fn, "body");
            const std::string who = "frame '" + name + "'";
            return b.add_frame(name, body, to_vec3(position, who + ": position"),
                               to_vec4(orientation, who + ": orientation"));
          },
          py::arg("name"), py::arg("body"), py::arg("position") = py::make_tuple(0.0, 0.0, 0.0),
          py::arg("orientation") = py::make_tuple(1.0, 0.0, 0.0, 0.0),
          "Add a named frame rigidly attached to `body` (or 'ground'): its origin [m] and axes "
          "(unit Euler parameters [e0, e1, e2, e3], frame -> world), both in world at the "
          "assembly pose like every builder input. Read it back with armdyn.frame_pose and "
          "armdyn.frame_jacobian.")
      .def(
          "set_joint_limits",
          [](ModelBuilder& b, const StrArg& joint, const FloatArg& lower, const FloatArg& upper,
             const FloatArg& effort, const FloatArg& velocity) {
            const char* fn = "ModelBuilder.set_joint_limits";
            b.set_joint_limits(str_arg(joint, fn, "joint"), limit_arg(lower, fn, "lower"),
                               limit_arg(upper, fn, "upper"), limit_arg(effort, fn, "effort"),
                               limit_arg(velocity, fn, "velocity"));
          },
          py::arg("joint"), py::arg("lower"), py::arg("upper"), py::arg("effort") = 0.0,
          py::arg("velocity") = 0.0,
          "Set a joint's limits (of its first coordinate): position lower <= q <= upper [rad or "
          "m] (stops enforced by simulate(limits=True)), effort [N m or N] and velocity [rad/s "
          "or m/s] (informative, 0 = none; read by the sizing). ModelError on an unknown "
          "joint, lower > upper, NaN, or negative effort/velocity.");
}

void def_builder_joints(BuilderClass& cls) {
  cls.def(
         "add_revolute",
         [](ModelBuilder& b, const StrArg& n, const StrArg& p, const StrArg& c,
            const ArrayLike& point, const ArrayLike& axis) {
           const JointArgs a(n, p, c, &point, &axis, "ModelBuilder.add_revolute");
           return b.add_revolute(a.name, a.parent, a.child, a.point, a.axis);
         },
         py::arg("name"), py::arg("parent"), py::arg("child"), py::arg("point"), py::arg("axis"),
         "Add a revolute (hinge) joint `name` between bodies `parent` and `child` (either may be "
         "'ground'): rotation about `axis` (3,) (world axes, need not be unit) through `point` "
         "(3,) [m], both in world at the assembly pose. One coordinate q [rad], positive by the "
         "right-hand rule about axis; q = 0 at assembly. Returns the joint index. ModelError "
         "(builder unchanged) on a duplicate name, an unknown body, a zero or non-finite axis or "
         "point.")
      .def(
          "add_prismatic",
          [](ModelBuilder& b, const StrArg& n, const StrArg& p, const StrArg& c,
             const ArrayLike& point, const ArrayLike& axis) {
            const JointArgs a(n, p, c, &point, &axis, "ModelBuilder.add_prismatic");
            return b.add_prismatic(a.name, a.parent, a.child, a.point, a.axis);
          },
          py::arg("name"), py::arg("parent"), py::arg("child"), py::arg("point"), py::arg("axis"),
          "Add a prismatic (slider) joint `name` between `parent` and `child` (either may be "
          "'ground'): translation along `axis` (3,) (world axes) through `point` (3,) [m], world "
          "at assembly. One coordinate q [m] along the unit axis; q = 0 at assembly. Returns the "
          "joint index; ModelError on a duplicate name, an unknown body, a zero or non-finite axis "
          "or point.")
      .def(
          "add_cylindrical",
          [](ModelBuilder& b, const StrArg& n, const StrArg& p, const StrArg& c,
             const ArrayLike& point, const ArrayLike& axis) {
            const JointArgs a(n, p, c, &point, &axis, "ModelBuilder.add_cylindrical");
            return b.add_cylindrical(a.name, a.parent, a.child, a.point, a.axis);
          },
          py::arg("name"), py::arg("parent"), py::arg("child"), py::arg("point"), py::arg("axis"),
          "Add a cylindrical joint `name` between `parent` and `child`: rotation about and "
          "translation along `axis` (3,) through `point` (3,) [m] (world at assembly). Two "
          "coordinates: the angle [rad], then the slide [m]. Returns the joint index; ModelError "
          "on bad input.")
      .def(
          "add_inline",
          [](ModelBuilder& b, const StrArg& n, const StrArg& p, const StrArg& c,
             const ArrayLike& point, const ArrayLike& axis) {
            const JointArgs a(n, p, c, &point, &axis, "ModelBuilder.add_inline");
            return b.add_inline(a.name, a.parent, a.child, a.point, a.axis);
          },
          py::arg("name"), py::arg("parent"), py::arg("child"), py::arg("point"), py::arg("axis"),
          "Inline (point-on-line) joint, 2 rows: the child's point stays on the parent's line "
          "through `point` along `axis`. Closes a planar loop without redundant rows.");
}

void def_builder_closures(BuilderClass& cls) {
  cls.def(
         "set_independent_coordinates",
         [](ModelBuilder& b, const StrSeq& names) {
           const char* fn = "ModelBuilder.set_independent_coordinates";
           if (PyUnicode_Check(names.ptr()) || !py::isinstance<py::sequence>(names))
             throw ModelError(msg(
                 fn, ": names must be a list of joint coordinate names (str), got ", shown(names)));
           std::vector<std::string> v;
           for (const py::handle h : py::reinterpret_borrow<py::sequence>(names))
             v.push_back(str_arg(h, fn, "each name"));
           b.set_independent_coordinates(v);
         },
         py::arg("names"),
         "The independent coordinates of a model with closed loops or of a fixed-base tree "
         "with ideal gears: names from joint_coord_names, as many as the model's mobility, in "
         "the order q, qd, qdd and tau take them. finalize() checks them (ModelError naming an "
         "unknown or repeated name, a wrong count, a coordinate the others determine at the "
         "assembled state, or a tree without ideal gears or with a floating base). "
         "An empty list restores armdyn's default: the joint coordinates in model order, each "
         "taken when independent of those taken before (add the actuated joints first).")
      .def(

          "add_distance",
          [](ModelBuilder& b, const StrArg& n_, const StrArg& ba_, const ArrayLike& pa,
             const StrArg& bb_, const ArrayLike& pb) {
            const char* fn = "ModelBuilder.add_distance";
            const std::string n = str_arg(n_, fn, "name"), ba = str_arg(ba_, fn, "body_a"),
                              bb = str_arg(bb_, fn, "body_b");
            const std::string who = "joint '" + n + "'";
            return b.add_distance(n, ba, to_vec3(pa, who + ": point_a"), bb,
                                  to_vec3(pb, who + ": point_b"));
          },
          py::arg("name"), py::arg("body_a"), py::arg("point_a"), py::arg("body_b"),
          py::arg("point_b"),
          "Distance joint, 1 row: a massless rod with ball ends between point_a of body_a and "
          "point_b of body_b (world coordinates at assembly); it holds their assembly distance.")
      .def(
          "add_spherical",
          [](ModelBuilder& b, const StrArg& n, const StrArg& p, const StrArg& c,
             const ArrayLike& point) {
            const JointArgs a(n, p, c, &point, nullptr, "ModelBuilder.add_spherical");
            return b.add_spherical(a.name, a.parent, a.child, a.point);
          },
          py::arg("name"), py::arg("parent"), py::arg("child"), py::arg("point"),
          "Add a spherical (ball) joint `name` between `parent` and `child` at `point` (3,) [m], "
          "world at assembly: 3 constraint rows, 3 rotational dofs (joint space: a quaternion). "
          "Returns the joint index; ModelError on a duplicate name, an unknown body, a "
          "non-finite point.")
      .def(
          "add_fixed",
          [](ModelBuilder& b, const StrArg& n, const StrArg& p, const StrArg& c,
             const OptArrayLike& point) {
            const JointArgs a(n, p, c, nullptr, nullptr, "ModelBuilder.add_fixed");
            const auto pt = opt_vec3(point, "joint '" + a.name + "': point");
            return b.add_fixed(a.name, a.parent, a.child, ptr_or_null(pt));
          },
          py::arg("name"), py::arg("parent"), py::arg("child"), py::arg("point") = py::none(),
          "Weld `child` rigidly to `parent` (either may be 'ground'): 6 rows, no dof. `point` "
          "(3,) [m], world at assembly, only sets where the reaction is reported (default: the "
          "child's CoM, the world origin for 'ground'). Returns the joint index; ModelError on "
          "a duplicate name or an unknown body.")
      .def(
          "add_universal",
          [](ModelBuilder& b, const StrArg& n, const StrArg& p, const StrArg& c,
             const ArrayLike& point, const ArrayLike& a1, const ArrayLike& a2) {
            const JointArgs a(n, p, c, &point, nullptr, "ModelBuilder.add_universal");
            return b.add_universal(a.name, a.parent, a.child, a.point,
                                   to_vec3(a1, "joint '" + a.name + "': axis1"),
                                   to_vec3(a2, "joint '" + a.name + "': axis2"));
          },
          py::arg("name"), py::arg("parent"), py::arg("child"), py::arg("point"), py::arg("axis1"),
          py::arg("axis2"),
          "Add a universal (Cardan) joint at `point` (3,) [m]: `axis1` (3,) fixed in the parent, "
          "`axis2` (3,) fixed in the child, perpendicular, world at assembly. Two coordinates "
          "[rad] (about axis1, then axis2). Returns the joint index; ModelError on bad input "
          "(axes not perpendicular, zero, or not finite).")
      .def(
          "add_free",
          [](ModelBuilder& b, const StrArg& n_, const StrArg& c_, const OptArrayLike& origin) {
            const char* fn = "ModelBuilder.add_free";
            const std::string n = str_arg(n_, fn, "name"), c = str_arg(c_, fn, "child");
            const auto o = opt_vec3(origin, "free joint '" + n + "': origin");
            return b.add_free(n, c, ptr_or_null(o));
          },
          py::arg("name"), py::arg("child"), py::arg("origin") = py::none(),
          "Declare body `child` free (a floating base). In joint space its frame -- the body's "
          "axes at `origin` (world at assembly, m; default its centre of mass) -- takes 7 entries "
          "of q (x, y, z, then the scalar-first unit quaternion e0..e3) and 6 of qd (linear, "
          "then angular velocity, both in the frame's own axes).");
}

void def_builder_finalize(BuilderClass& cls) {
  cls.def("finalize", &finalize_model, py::arg("mass_weighted_assembly") = true,
          "Validate, analyse topology and rank, assemble; returns an immutable Model.")
      .def_property_readonly(
          "body_names", [](const ModelBuilder& b) { return names_of(b.draft().bodies); },
          "Names of the bodies added so far, in definition order (for urdf_builder: the "
          "URDF's links as the loader added them).")
      .def_property_readonly(
          "joint_names", [](const ModelBuilder& b) { return names_of(b.draft().joints); },
          "Names of the joints added so far, in definition order (for urdf_builder: the URDF's "
          "joints as the loader added them, actuator rotors and free bases included).")
      .def_property_readonly(
          "frame_names", [](const ModelBuilder& b) { return names_of(b.draft().frames); },
          "Names of the named frames added so far (add_frame; for urdf_builder its links), in "
          "definition order.");
}

}  // namespace

void bind_builder(py::module_& m) {
  BuilderClass c(m, "ModelBuilder",
                 "Build a model: bodies, joints, drives, force elements; then finalize().");
  c.def(py::init([](const ArrayLike& g, const BoolArg& physical_inertia) {
          const bool pi = bool_arg(physical_inertia, "ModelBuilder", "physical_inertia");
          return ModelBuilder(to_vec3(g, "gravity"), pi);
        }),
        py::arg("gravity") = py::make_tuple(0.0, 0.0, -9.81), py::kw_only(),
        py::arg("physical_inertia") = true,
        "An empty builder. gravity: (3,) in world axes [m/s^2]; physical_inertia: see the "
        "property of that name. ModelError if gravity is not 3 finite numbers.");
  def_builder_bodies(c);
  def_builder_joints(c);
  def_builder_closures(c);
  def_builder_finalize(c);
}

}  // namespace armdyn
