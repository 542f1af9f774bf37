// SPDX-License-Identifier: BSD-3-Clause
#include <pybind11/pybind11.h>

#include "armdyn/errors.hpp"
#include "common.hpp"

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
  // the module keeps the type alive
  static PyObject* solver_error =
      py::register_exception<armdyn::SolverError>(m, "SolverError", PyExc_RuntimeError).ptr();
  // Python exceptions carried through C++ loops (common.hpp): registered last, tried first
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (armdyn::py_helpers::PyInterrupted& e) {
      e.err.restore();
    } catch (const armdyn::SolverError& e) {
      // with the Python exception of a callback behind it: chained as the cause
      py::object cause = armdyn::py_helpers::py_cause(e);
      if (cause.is_none()) throw;
      PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(cause.ptr())), cause.ptr());
      py::raise_from(solver_error, e.what());
    } catch (const armdyn::Interrupted& e) {
      PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
    }
  });
  armdyn::bind_model(m);
  armdyn::bind_dynamics(m);
  armdyn::bind_validate(m);
  armdyn::bind_algorithm(m);
}
