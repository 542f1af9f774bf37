// SPDX-License-Identifier: BSD-3-Clause
// armdyn.Motor (a motor's datasheet, armdyn/model/model.hpp MotorSpec) and armdyn.Actuator (a
// gearbox and rotor as Model.actuators lists it). Pickling: bind_pickle.cpp.
#include <stdexcept>
#include <string>
#include <utility>

#include "convert_model.hpp"

namespace armdyn {

namespace py = pybind11;
using namespace py_helpers;

namespace {

template <std::size_t>
using MotorFieldArg = OptFloat;

/// armdyn.Motor(*, name="", <every MotorSpec::fields() entry>=None): one keyword per field.
template <std::size_t... I>
void def_motor_init(py::class_<MotorSpec>& c, std::index_sequence<I...>) {
  const std::string doc =
      "A motor's datasheet values (every one optional, None when not given; given ones finite "
      "and > 0, else ModelError naming the field), all motor side: " +
      motor_fields_with_units() + ".";
  c.def(py::init([](const StrArg& name, const MotorFieldArg<I>&... v) {
          return motor_from_args(name, {v...});
        }),
        py::kw_only(), py::arg("name") = "",
        (py::arg(MotorSpec::fields()[I].first) = py::none())..., doc.c_str());
}

/// The docstrings' table follows MotorSpec::fields() (an import error otherwise: a field added
/// without its unit and description).
void check_motor_field_docs() {
  for (std::size_t k = 0; k < MotorSpec::kNumFields; ++k)
    if (std::string(motor_field_docs()[k].name) != MotorSpec::fields()[k].first)
      throw std::logic_error(msg("armdyn.Motor: the docstring table's field ", k, " is '",
                                 motor_field_docs()[k].name, "', MotorSpec::fields() has '",
                                 MotorSpec::fields()[k].first, "'"));
}

}  // namespace

void bind_motor(py::module_& m) {
  check_motor_field_docs();
  const std::string class_doc =
      "A motor's datasheet values, motor side, SI units, every one optional (None when not "
      "given): " +
      motor_fields_with_units() +
      ", and a name. Given values must be finite and > 0 (ModelError naming the field). "
      "Attach one with ModelBuilder.add_actuator(..., motor=armdyn.Motor(...)); it does not "
      "enter the dynamics (the actuator's rotor inertia, gear ratio and friction do), the "
      "motor-side sizing reads it. Keyword-only constructor (the keywords: Motor.FIELDS and "
      "name); Motor.from_row(row) from a mapping; comparable (==) and picklable.";
  py::class_<MotorSpec> motor(m, "Motor", class_doc.c_str());
  def_motor_init(motor, std::make_index_sequence<MotorSpec::kNumFields>());
  py::list names;
  for (const auto& [n, p] : MotorSpec::fields()) names.append(n);
  motor.attr("FIELDS") = py::tuple(names);
  motor.def_static(
      "from_row", &motor_from_row, py::arg("row"),
      "The Motor of a catalog row: a mapping (a dict, a pandas Series) holding any of the "
      "fields in Motor.FIELDS (SI units; None, NaN or pandas' NA = not given; given ones finite "
      "and > 0, else ModelError naming the field); other keys are ignored. The name: the row's "
      "'name' entry when given, else the Series' name when it is a str, else ''.");
  motor.def_readonly("name", &MotorSpec::name, "The motor's name ('' when not given).");
  // one read-only property per datasheet field, in MotorSpec::fields() order
  for (const auto& [n, p] : MotorSpec::fields())
    motor.def_property_readonly(
        n, [p = p](const MotorSpec& s) { return motor_get(s, p); }, motor_field_doc(n).c_str());
  motor.def("__repr__", &motor_repr);
  motor.def("__eq__", &motor_equals);
  motor.attr("__hash__") = py::none();

  py::class_<ActuatorView>(
      m, "Actuator",
      "A gearbox and motor rotor on a joint (ModelBuilder.add_actuator), as Model.actuators "
      "lists it: joint (the actuated joint's name), rotor_joint (the rotor's revolute joint and "
      "body, a coupling follower: '<joint>_armature' turning with the joint, qdot, with inertia "
      "N^2 J by default (gyroscopic=False), '<joint>_rotor' turning at gear_ratio * qdot with "
      "gyroscopic=True), dof (the "
      "index into the independent qd / model.dof_names the actuator moves), gear_ratio, "
      "rotor_inertia [kg m^2], efficiency, friction_viscous [N m s/rad, motor side], "
      "friction_coulomb [N m, motor side], friction_smoothing [rad/s, motor side], gyroscopic, "
      "motor (armdyn.Motor or None).")
      .def_readonly("joint", &ActuatorView::joint, "Name of the actuated joint.")
      .def_readonly("rotor_joint", &ActuatorView::rotor_joint,
                    "Name of the rotor's revolute joint and body: '<joint>_armature' "
                    "(gyroscopic=False, the default) or '<joint>_rotor' (gyroscopic=True).")
      .def_readonly(
          "dof", &ActuatorView::dof,
          "Index into the independent qd / model.dof_names of the dof the actuator moves.")
      .def_readonly("gear_ratio", &ActuatorView::gear_ratio,
                    "Gear ratio N = rotor speed / joint speed (negative: reversed rotor; rad/m for "
                    "a prismatic joint).")
      .def_readonly("rotor_inertia", &ActuatorView::rotor_inertia,
                    "Rotor inertia J about its axis [kg m^2].")
      .def_readonly("efficiency", &ActuatorView::efficiency,
                    "Gearbox efficiency in (0, 1] (motor-side maths only, not in the dynamics).")
      .def_readonly("friction_viscous", &ActuatorView::friction_viscous,
                    "Viscous friction [N m s/rad], motor side (reflected as N^2 b).")
      .def_readonly("friction_coulomb", &ActuatorView::friction_coulomb,
                    "Coulomb friction [N m], motor side (reflected as |N| c).")
      .def_readonly(
          "friction_smoothing", &ActuatorView::friction_smoothing,
          "Coulomb smoothing velocity [rad/s], motor side: tanh(omega / friction_smoothing).")
      .def_readonly("gyroscopic", &ActuatorView::gyroscopic,
                    "True: the rotor turns on the joint's parent body (full kinetic energy); "
                    "False: the gear-reduced (armature) model.")
      .def_readonly("motor", &ActuatorView::motor, "The attached armdyn.Motor, or None.")
      .def("__repr__", &actuator_repr);
}

}  // namespace armdyn
