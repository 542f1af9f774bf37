// SPDX-License-Identifier: BSD-3-Clause
// Binding of model_with_dynamic_parameters (armdyn/io/parameter_model.hpp): the model of an
// identified parameter vector (armdyn.identification.with_parameters calls it).
#include "armdyn/algorithm/regressor.hpp"
#include "armdyn/io/parameter_model.hpp"
#include "common.hpp"
#include "rows.hpp"

namespace armdyn {

namespace py = pybind11;
using namespace py_helpers;

void bind_parameter_model(py::module_& m) {
  m.def(
      "model_with_dynamic_parameters",
      [](const ModelArg& model, const ArrayLike& pi, const BoolArg& physical_inertia) {
        constexpr const char* fn = "model_with_dynamic_parameters";
        const ModelHolder md = model_of(model, fn);
        const bool physical = bool_arg(physical_inertia, fn, "physical_inertia");
        const long n = dynamic_parameter_layout(*md).n_params;
        const VecX p = to_vec(pi, msg(fn, ": pi (dynamic_parameter_names(model), ", n, ")"), n);
        return std::const_pointer_cast<Model>(model_with_dynamic_parameters(*md, p, physical));
      },
      py::arg("model"), py::arg("pi"), py::arg("physical_inertia") = true,
      "A new model (this one unchanged) whose dynamic_parameters equal pi (n_params,), offsets "
      "aside (measurement biases, not dynamics: ignored): each body's mass, centre of mass and "
      "inertia from its 10 numbers (the body frame's origin moves with the centre of mass, every "
      "attachment point with it: the geometry is unchanged; a body without a frame of its name "
      "gets one at its old centre of mass, pi's parameter frame), each coordinate's friction "
      "sources "
      "scaled to fv, fc (created on its joint when it has none), its actuators' rotor inertias "
      "scaled to Ia (an actuator of gear ratio 1 added when it has none), then finalized again. "
      "physical_inertia=True: each body's parameters physically consistent (pseudo-inertia "
      "positive semidefinite); False: the inertia about the centre of mass positive "
      "semidefinite only (the triangle inequality not required). ModelError naming the entry "
      "or body on a wrong length, a non-finite entry, a negative mass, friction or Ia, an "
      "inertia outside those limits.");
}

}  // namespace armdyn
