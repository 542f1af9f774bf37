// SPDX-License-Identifier: BSD-3-Clause
// armdyn.Model (armdyn/model/model.hpp): sizes, names, topology, limits, actuators, KKT path.
// What the properties derive is in armdyn/model/properties.hpp; pickling: bind_pickle.cpp.
#include "armdyn/builder/summary.hpp"
#include "armdyn/io/payload.hpp"
#include "convert_model.hpp"

namespace armdyn {

namespace py = pybind11;
using namespace py_helpers;

namespace {

void def_model_sizes(ModelClass& c) {
  c.def_readonly("nb", &Model::nb, "Number of bodies.")
      .def_readonly(
          "nq", &Model::nq,
          "Length of the Cartesian position state u: 7 per body (CoM [m], unit Euler parameters).")
      .def_readonly("nv", &Model::nv,
                    "Length of the Cartesian velocity state v: 6 per body (CoM velocity [m/s, "
                    "world], angular velocity [rad/s, body]).")
      .def_readonly(
          "nc", &Model::nc,
          "Number of constraint rows: the joints' and ideal gears' rows, then the drives'.")
      .def_readonly(
          "nc_joint", &Model::nc_joint,
          "Number of the joints' and ideal gears' constraint rows (the rows before the drives').")
      // the joint-space functions take the independent q and qd (a coupled model's followers
      // removed; all of them without couplings); simulation results report every joint's
      .def_property_readonly(
          "n_coords", [](const Model& md) { return md.independent.nq(); },
          "Length of the joint-space q: 7 per floating base (position, scalar-first quaternion), "
          "then one per independent joint coordinate (couplings' followers removed).")
      .def_property_readonly(
          "n_dofs", [](const Model& md) { return md.independent.nv(); },
          "Length of qd, qdd and tau: 6 per floating base (linear, angular velocity in the base "
          "frame), then one per independent joint coordinate (= n_coords without a floating "
          "base).")
      .def_readonly("n_free", &Model::n_free, "Free joints (floating bases) of the joint space.")
      .def_readonly("n_joint_coords", &Model::nq_joint,
                    "Columns of SimulationResult.q: n_coords with the couplings' followers.")
      .def_readonly("n_joint_dofs", &Model::nv_joint,
                    "Columns of SimulationResult.qd, qdd: n_dofs with the couplings' followers.")
      .def_readonly("joint_coord_names", &Model::q_names,
                    "Names of the columns of SimulationResult.q (every joint's coordinate).")
      .def_readonly("joint_dof_names", &Model::dof_names,
                    "Names of the columns of SimulationResult.qd and qdd.")
      .def_property_readonly("independent_coords", &independent_coord_indices,
                             "Index of each entry of q in joint_coord_names.")
      .def_property_readonly(
          "couplings", &coupling_dicts,
          "The couplings (add_coupling, URDF <mimic>): a list of dicts with 'name', 'follower' and "
          "'leader' (joint names), 'multiplier' and 'offset' [rad or m] of q_follower = multiplier "
          "* q_leader + offset.")
      .def_property_readonly(
          "actuators", &actuator_views,
          "The actuators (ModelBuilder.add_actuator), as armdyn.Actuator objects.")
      .def_property_readonly(
          "reflected_inertia", [](const Model& md) { return to_numpy(reflected_inertia(md)); },
          "(n_dofs,) the rotors' inertia reflected through their gears, N^2 J at each "
          "actuated dof and 0 elsewhere [kg m^2, or kg for a prismatic joint]: the armature of "
          "Pinocchio's model (the gear-reduced rotor model adds exactly this to the mass "
          "matrix's diagonal).")
      .def_property_readonly(
          "n_drives", [](const Model& md) { return md.drives.size(); },
          "Number of drives (prescribed joint coordinates, add_drive).");
}

void def_model_names(ModelClass& c) {
  c.def_property_readonly(
       "body_names", [](const Model& md) { return names_of(md.bodies); },
       "Names of the bodies, in the order they were added (index = body index; the URDF's links "
       "with mass or a child joint).")
      .def_property_readonly(
          "joint_names", [](const Model& md) { return names_of(md.joints); },
          "Names of the joints, in the order they were added (index = joint index).")
      .def_property_readonly(
          "joint_types", &joint_type_names,
          "Type of each joint of joint_names: 'revolute', 'prismatic', 'spherical', 'fixed', "
          "'free', ...")
      .def_property_readonly(
          "coord_names", &independent_coord_names,
          "Names of the entries of q (n_coords): a floating base's 'name:x' .. 'name:e3', then "
          "the independent joint coordinates.")
      .def_property_readonly(
          "dof_names", &independent_dof_names,
          "Names of the entries of qd, qdd and tau (n_dofs): a floating base's 'name:vx' .. "
          "'name:wz', then the independent joint coordinates.")
      .def_property_readonly(
          "frame_names", [](const Model& md) { return names_of(md.frames); },
          "Names of the named frames (add_frame, URDF links), in the order they were added.")
      .def("frame", &frame_dict, py::arg("frame"),
           "A named frame's placement on its body: 'index' (into frame_names), 'body' (or "
           "'ground'), 'point' (its origin in the body's frame, relative to the centre of mass; "
           "the world for 'ground') and 'rotation' (its axes as columns in the body's axes).")
      .def_property_readonly(
          "drive_names", [](const Model& md) { return names_of(md.drives); },
          "Names of the drives, in the order they were added (columns of "
          "SimulationResult.drive_forces).")
      .def_property_readonly(
          "drive_coords", &drive_dofs,
          "Index into the joint dofs (model.joint_dof_names) of each drive's coordinate.");
}

void def_model_bodies(ModelClass& c) {
  c.def_property_readonly(
       "gravity", [](const Model& md) { return to_numpy(VecX(md.gravity)); },
       "(3,) gravity vector in world axes [m/s^2].")
      .def_property_readonly(
          "masses", [](const Model& md) { return to_numpy(body_masses(md)); },
          "(nb,) body masses [kg], in body_names order.")
      .def_property_readonly(
          "inertias", &body_inertias,
          "(nb, 3, 3) body inertia tensors about the centre of mass in body axes [kg m^2].")
      .def_readonly("is_tree", &Model::is_tree,
                    "True when every body has exactly one joint path to ground (no closed loops).")
      .def_readonly("joint_space", &Model::joint_space_ok,
                    "True when the joint-space functions (forward_dynamics, inverse_dynamics, "
                    "mass_matrix, state_from_joints) take the model: a tree of revolute, "
                    "prismatic, cylindrical and fixed joints (a free joint from ground as a "
                    "floating base) defined parent to child.")
      // why simulate(coordinates="joint") does not take the model; empty when it does
      .def_property_readonly(
          "joint_path_reason", [](const Model& md) { return md.joint_path_reason(); },
          "Why simulate(coordinates='joint') does not take the model; '' when it does.")
      .def_readonly("mobility", &Model::mobility,
                    "Degrees of freedom of the mechanism without its drives.")
      .def_readonly("mobility_driven", &Model::mobility_driven,
                    "Degrees of freedom left with the drives (0: fully prescribed motion).")
      .def_readonly(
          "redundant_rows", &Model::redundant_rows,
          "Names of the redundant constraint rows finalize() found (empty when the rows are "
          "independent).")
      .def_property_readonly(
          "u0", [](const Model& md) { return to_numpy(md.u0); },
          "(nq,) the assembled Cartesian positions u: per body CoM [m] and unit Euler parameters.")
      .def_property_readonly(
          "v0", [](const Model& md) { return to_numpy(md.v0); },
          "(nv,) the initial Cartesian velocities v (zero unless set): per body CoM velocity [m/s] "
          "and angular velocity [rad/s].");
}

// URDF <limit> per joint coordinate: +-inf where none (the joints store +-1e300), effort and
// velocity limits inf where none or 0 (unset)
void def_model_limits(ModelClass& c) {
  c.def_property_readonly(
       "coord_lower", [](const Model& md) { return to_numpy(coord_limits(md, LimitKind::Lower)); },
       "Lower position limit of each entry of q (n_coords; URDF <limit lower>; -inf where none "
       "and on a floating base; a coupled model's independent entries).")
      .def_property_readonly(
          "coord_upper",
          [](const Model& md) { return to_numpy(coord_limits(md, LimitKind::Upper)); },
          "Upper position limit of each entry of q (n_coords; URDF <limit upper>; inf where none "
          "and on a floating base).")
      .def_property_readonly(
          "coord_effort_limit",
          [](const Model& md) { return to_numpy(coord_limits(md, LimitKind::Effort)); },
          "Effort limit of each entry of tau (n_dofs) [N m or N] (URDF <limit effort>; inf where "
          "none or 0, and on a floating base).")
      .def_property_readonly(
          "coord_velocity_limit",
          [](const Model& md) { return to_numpy(coord_limits(md, LimitKind::Velocity)); },
          "Velocity limit of each entry of qd (n_dofs) [rad/s or m/s] (URDF <limit velocity>; inf "
          "where none or 0, and on a floating base).")
      .def("joint_limits", &joint_limits_dict, py::arg("joint"),
           "A joint's limits as a dict: 'lower' and 'upper' position limits [rad or m] (+-1e300 "
           "where none), 'effort' [N m or N] and 'velocity' [rad/s or m/s] (0 where none).")
      .def("joint_frame", &joint_frame_dict, py::arg("joint"),
           "The joint's bodies and frames: 'point_parent'/'point_child' (the joint point in each "
           "body's frame, relative to its centre of mass; the world for 'ground'), "
           "'frame_parent'/'frame_child' (the joint frame's axes as columns in each body's "
           "frame; z is the joint axis) and 'coord' (its first joint coordinate, -1 if none).");
}

void def_model_solver(ModelClass& c) {
  c.def(
       "summary", [](const Model& md) { return summary(md); },
       "Readable description: sizes, topology, solver path.")
      .def_property_readonly(
          "kkt_path", [](const Model& md) { return kkt_path_name(kkt_path(md)); },
          "KKT solver path chosen at finalize(): 'tree', 'tree+loops', 'sparse', or 'dense' "
          "(redundant rows).")
      .def(
          "with_kkt_path",
          [](const Model& md, const StrArg& path) {
            return std::const_pointer_cast<const Model>(
                with_kkt_path(md, str_arg(path, "with_kkt_path", "path")));
          },
          py::arg("path"),
          "A copy of the model on another KKT path: 'dense' (the reference: one dense Cholesky "
          "of the Schur complement) or 'auto' (the plan finalize() picks).")
      .def_property_readonly(
          "kkt_plan", &kkt_plan_dict,
          "The KKT plan's statistics (path, row blocks, factor entries, fill, flops).")
      .def("__repr__", &model_repr);
}

/// A payload from with_payload's arguments (their types; with_payloads checks the values).
Payload payload_arg(const py::handle& at, const py::handle& mass, const py::handle& com,
                    const py::handle& inertia, const py::handle& name, const std::string& who) {
  Payload p;
  p.name = str_arg(name, who.c_str(), "name");
  p.at = str_arg(at, who.c_str(), "at");
  p.mass = float_arg(mass, who.c_str(), "mass");
  p.com = to_vec3(com, who + ": com");
  if (!inertia.is_none()) p.inertia = to_inertia(inertia, who + ": inertia");
  return p;
}

/// with_payloads' list: mappings with keys at, mass (required), com, inertia, name.
std::vector<Payload> payload_list(const py::handle& payloads) {
  const char* fn = "with_payloads";
  if (PyUnicode_Check(payloads.ptr()) || PyBytes_Check(payloads.ptr()) ||
      PyDict_Check(payloads.ptr()) || !py::isinstance<py::iterable>(payloads))
    throw ModelError(msg(fn,
                         ": payloads must be a list of dicts (keys at, mass, com, inertia, "
                         "name), got ",
                         shown(payloads)));
  std::vector<Payload> out;
  static const char* keys[] = {"at", "mass", "com", "inertia", "name"};
  for (const py::handle item : payloads) {
    const std::string who = msg(fn, ": payloads[", out.size(), "]");
    const py::object mapping = py::module_::import("collections.abc").attr("Mapping");
    if (!py::isinstance(item, mapping))
      throw ModelError(
          msg(who, " must be a dict (keys at, mass, com, inertia, name), got ", shown(item)));
    const py::dict d(py::reinterpret_borrow<py::object>(item));
    for (const auto& kv : d) {
      const std::string k = PyUnicode_Check(kv.first.ptr()) ? kv.first.cast<std::string>() : "";
      if (std::find_if(std::begin(keys), std::end(keys), [&](const char* x) { return k == x; }) ==
          std::end(keys))
        throw ModelError(
            msg(who, ": unknown key ", shown(kv.first), " (known: at, mass, com, inertia, name)"));
    }
    for (const char* req : {"at", "mass"})
      if (!d.contains(req)) throw ModelError(msg(who, ": needs '", req, "'"));
    auto get = [&](const char* k, py::object dflt) { return d.contains(k) ? d[k] : dflt; };
    out.push_back(payload_arg(d["at"], d["mass"], get("com", py::make_tuple(0.0, 0.0, 0.0)),
                              get("inertia", py::none()), get("name", py::str("payload")), who));
  }
  return out;
}

void def_model_payload(ModelClass& c) {
  c.def(
      "with_payload",
      [](const Model& md, const StrArg& at, const FloatArg& mass, const ArrayLike& com,
         const OptArrayLike& inertia, const StrArg& name) {
        const Payload p = payload_arg(at, mass, com, inertia, name, "with_payload");
        return with_payloads(md, {p}, "with_payload");
      },
      py::arg("at"), py::arg("mass"), py::arg("com") = py::make_tuple(0.0, 0.0, 0.0),
      py::arg("inertia") = py::none(), py::arg("name") = "payload",
      "A new finalized model with a payload (this model is unchanged): a rigid body of mass "
      "[kg] with its centre of mass at com [m] and inertia [kg m^2] (3x3 about the centre of "
      "mass, or its 3 principal moments; None: a point mass), both in the axes of `at` and from "
      "its origin, welded to `at`: a named frame of the model (e.g. a URDF link's frame or "
      "tool0); else a body (its centre of mass and axes) or 'ground'; else a joint (its point "
      "and joint frame on the parent's side, z the joint axis; welded to the parent): the first "
      "kind that has the name wins. It adds body `name`, fixed joint "
      "'<name>_mount' (reactions at at's origin) and frame `name` at the payload's centre of "
      "mass. The dynamics are those of the builder with the same body added (add_body + "
      "add_fixed). ModelError naming the culprit (at, mass, com, inertia, name) and leaving "
      "this model intact on bad input; a model holding a profile made from a Python function "
      "cannot be copied (ModelError).");
  c.def(
      "with_payloads",
      [](const Model& md, const PayloadList& payloads) {
        return with_payloads(md, payload_list(payloads), "with_payloads");
      },
      py::arg("payloads"),
      "with_payload for several payloads at once (one finalize): payloads is a list of dicts "
      "with keys at, mass (required), com, inertia, name (with_payload's arguments and "
      "defaults); each needs its own name. An empty list: a copy of the model.");
}

}  // namespace

void bind_model(py::module_& m) {
  ModelClass c(m, "Model", "Immutable multibody model (from ModelBuilder.finalize or load_urdf).");
  def_model_sizes(c);
  def_model_names(c);
  def_model_bodies(c);
  def_model_limits(c);
  def_model_solver(c);
  def_model_payload(c);
}

}  // namespace armdyn
