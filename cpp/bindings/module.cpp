// SPDX-License-Identifier: BSD-3-Clause
#include <pybind11/pybind11.h>

#include "armdyn/errors.hpp"

namespace py = pybind11;

namespace armdyn {
void bind_model(py::module_& m);
void bind_dynamics(py::module_& m);
void bind_validate(py::module_& m);
void bind_algorithm(py::module_& m);
}  // namespace armdyn

PYBIND11_MODULE(_core, m) {
  m.doc() = "armdyn compiled core: Cartesian Newton-Euler multibody dynamics";
  auto model_error = py::register_exception<armdyn::ModelError>(m, "ModelError", PyExc_ValueError);
  py::register_exception<armdyn::UrdfError>(m, "UrdfError", model_error.ptr());
  py::register_exception<armdyn::SolverError>(m, "SolverError", PyExc_RuntimeError);
  armdyn::bind_model(m);
  armdyn::bind_dynamics(m);
  armdyn::bind_validate(m);
  armdyn::bind_algorithm(m);
}
