// SPDX-License-Identifier: BSD-3-Clause
// Pickling (and copy.copy / copy.deepcopy through it) of Motor, Profile, Model and ModelBuilder:
// every field, doubles bit for bit (armdyn/io/serialize.hpp for the model and the builder's
// draft); a Python-callable profile cannot travel (ModelError naming it). The states:
// convert_model.hpp.
#include "convert_builder.hpp"
#include "convert_model.hpp"

namespace armdyn {

namespace py = pybind11;
using namespace py_helpers;

void bind_pickle(py::module_& m) {
  py::reinterpret_borrow<py::class_<MotorSpec>>(py::object(m.attr("Motor")))
      .def(py::pickle(&motor_state, &motor_from_state));
  py::reinterpret_borrow<py::class_<Profile>>(py::object(m.attr("Profile")))
      .def(py::pickle(&profile_state, &profile_from_state));
  py::reinterpret_borrow<ModelClass>(py::object(m.attr("Model")))
      .def(py::pickle(&model_state, &model_from_state));
  py::reinterpret_borrow<BuilderClass>(py::object(m.attr("ModelBuilder")))
      .def(py::pickle(&builder_state, &builder_from_state));
}

}  // namespace armdyn
