// SPDX-License-Identifier: BSD-3-Clause
#include <pybind11/pybind11.h>

#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "armdyn/errors.hpp"
#include "common.hpp"

namespace py = pybind11;

namespace armdyn {
void bind_motor(py::module_& m);
void bind_profile(py::module_& m);
void bind_model(py::module_& m);
void bind_builder(py::module_& m);
void bind_builder_forces(py::module_& m);
void bind_urdf(py::module_& m);
void bind_pickle(py::module_& m);
void bind_simulate(py::module_& m);
void bind_dynamics(py::module_& m);
void bind_inverse_dynamics(py::module_& m);
void bind_validate(py::module_& m);
void bind_algorithm(py::module_& m);
void bind_frames(py::module_& m);
void bind_derivatives(py::module_& m);
void bind_regressor(py::module_& m);
void bind_parameter_model(py::module_& m);
void fast_keyword(PyObject* f);  // fast_keywords.cpp: keywords matched before pybind11
}  // namespace armdyn

namespace {

// inspect.signature on the compiled functions (pybind11 sets no __text_signature__, pybind11
// issue #945): each function's PyMethodDef::ml_doc (pybind11's, malloc'ed) gets CPython's
// "name(<text signature>)\n--\n\n" prefix, derived from pybind11's own first docstring line by
// dropping the annotations. CPython then exposes __text_signature__ and strips the prefix from
// __doc__, which keeps pybind11's annotated line for pybind11-stubgen. `self` stays a plain
// parameter (not CPython's "$self"): a pybind11 function's __self__ is its function record, so
// inspect would take "$self" as already bound and drop it (and the bound method one more).

// the parameters of "name(...) -> ret" split at top-level commas; false if not of that form
bool split_params(const std::string& line, size_t open, std::vector<std::string>& out) {
  int depth = 0;
  char quote = 0;
  std::string cur;
  for (size_t i = open + 1; i < line.size(); ++i) {
    const char c = line[i];
    if (quote) {
      if (c == '\\' && i + 1 < line.size()) {
        cur += c;
        cur += line[++i];
        continue;
      }
      if (c == quote) quote = 0;
      cur += c;
      continue;
    }
    if (c == '\'' || c == '"') {
      quote = c;
    } else if (c == '(' || c == '[' || c == '{') {
      ++depth;
    } else if (c == ']' || c == '}') {
      --depth;
    } else if (c == ')') {
      if (depth == 0) {
        if (!cur.empty()) out.push_back(cur);
        return true;
      }
      --depth;
    } else if (c == ',' && depth == 0) {
      out.push_back(cur);
      cur.clear();
      continue;
    }
    cur += c;
  }
  return false;
}

std::string trim(const std::string& s) {
  const size_t b = s.find_first_not_of(' ');
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(' ') - b + 1);
}

// position of the top-level " = " (annotation = default) in one parameter, npos if none
size_t default_pos(const std::string& p) {
  int depth = 0;
  for (size_t i = 0; i + 2 < p.size(); ++i) {
    const char c = p[i];
    if (c == '(' || c == '[' || c == '{') ++depth;
    if (c == ')' || c == ']' || c == '}') --depth;
    if (depth == 0 && p.compare(i, 3, " = ") == 0) return i;
  }
  return std::string::npos;
}

// "(a, b=1, *, c=...)" of pybind11's signature line; empty if it is not one
std::string text_signature(const std::string& line, const std::string& name,
                           const py::handle& literal_eval) {
  if (line.compare(0, name.size(), name) != 0 || line.size() <= name.size() ||
      line[name.size()] != '(')
    return "";
  std::vector<std::string> params;
  if (!split_params(line, name.size(), params)) return "";
  std::string sig = "(";
  for (size_t k = 0; k < params.size(); ++k) {
    const std::string p = trim(params[k]);
    std::string item;
    if (p == "*" || p == "/") {
      item = p;
    } else {
      const size_t colon = p.find(':');
      const size_t eq = default_pos(p);
      item = trim(p.substr(0, std::min(colon, eq)));
      if (eq != std::string::npos) {
        const std::string def = trim(p.substr(eq + 3));
        bool literal = true;
        try {
          literal_eval(def);
        } catch (const py::error_already_set&) {
          literal = false;
        }
        item += "=" + (literal ? def : std::string("..."));
      }
    }
    sig += (k ? ", " : "") + item;
  }
  return sig + ")";
}

// a pybind11 function (a PyCFunction over a pybind11 function record): its text signature set
void add_text_signature(PyObject* f, const py::handle& literal_eval) {
  if (!f || !PyCFunction_Check(f)) return;
  PyObject* self = PyCFunction_GET_SELF(f);
  if (!self || !py::detail::is_function_record_PyObject(self)) return;
  PyMethodDef* def = reinterpret_cast<PyCFunctionObject*>(f)->m_ml;
  if (!def->ml_doc || !def->ml_name) return;
  const std::string doc = def->ml_doc, name = def->ml_name;
  if (doc.find(")\n--\n\n") != std::string::npos) return;  // done already
  const std::string sig = text_signature(doc.substr(0, doc.find('\n')), name, literal_eval);
  if (sig.empty()) return;
  const std::string full = name + sig + "\n--\n\n" + doc;
  char* copy = static_cast<char*>(std::malloc(full.size() + 1));
  if (!copy) throw std::bad_alloc();
  std::memcpy(copy, full.c_str(), full.size() + 1);
  std::free(const_cast<char*>(def->ml_doc));  // pybind11 frees it with std::free too
  def->ml_doc = copy;
}

// every compiled function of m and its submodules: its text signature; the module-level ones
// also their keywords matched by armdyn (fast_keywords.cpp)
void finish_functions(const py::module_& m, const py::handle& literal_eval) {
  const std::string mod = m.attr("__name__").cast<std::string>();
  for (auto item : m.attr("__dict__").cast<py::dict>()) {
    py::handle v = item.second;
    if (PyModule_Check(v.ptr())) {
      if (v.attr("__name__").cast<std::string>().rfind(mod + ".", 0) == 0)
        finish_functions(py::reinterpret_borrow<py::module_>(v), literal_eval);
    } else if (PyType_Check(v.ptr())) {
      if (!py::hasattr(v, "__module__") || v.attr("__module__").cast<std::string>() != mod)
        continue;
      for (auto member : v.attr("__dict__").cast<py::dict>()) {
        PyObject* f = member.second.ptr();
        if (PyInstanceMethod_Check(f)) {
          add_text_signature(PyInstanceMethod_GET_FUNCTION(f), literal_eval);
        } else if (py::isinstance<py::staticmethod>(member.second)) {
          add_text_signature(member.second.attr("__func__").ptr(), literal_eval);
        } else {
          add_text_signature(f, literal_eval);
        }
      }
    } else {
      add_text_signature(v.ptr(), literal_eval);
      armdyn::fast_keyword(v.ptr());
    }
  }
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "armdyn compiled core: Cartesian Newton-Euler multibody dynamics";
  auto model_error = py::register_exception<armdyn::ModelError>(m, "ModelError", PyExc_ValueError);
  model_error.attr("__doc__") =
      "Bad input: a model, builder call, array shape or option that armdyn refuses, the "
      "message naming the culprit (the body, joint, argument and the expected shape). The "
      "model or builder is left as it was. A ValueError.";
  auto urdf_error = py::register_exception<armdyn::UrdfError>(m, "UrdfError", model_error.ptr());
  urdf_error.attr("__doc__") =
      "A URDF file or string that cannot be loaded: malformed XML, an unsupported element or "
      "value, a size limit exceeded; the message names the file, element and attribute. A "
      "ModelError.";
  // the module keeps the type alive
  static PyObject* solver_error =
      py::register_exception<armdyn::SolverError>(m, "SolverError", PyExc_RuntimeError).ptr();
  py::handle(solver_error).attr("__doc__") =
      "A run or solve that failed numerically: a singular constraint system, a step size "
      "underflow, too many steps, a callback (profile or progress) that raised (chained as the "
      "__cause__). The message says where (time, body, row). A RuntimeError.";
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
  armdyn::bind_motor(m);
  armdyn::bind_profile(m);
  armdyn::bind_model(m);
  armdyn::bind_builder(m);
  armdyn::bind_builder_forces(m);
  armdyn::bind_urdf(m);
  armdyn::bind_pickle(m);
  armdyn::bind_simulate(m);
  armdyn::bind_dynamics(m);
  armdyn::bind_inverse_dynamics(m);
  armdyn::bind_validate(m);
  armdyn::bind_algorithm(m);
  armdyn::bind_frames(m);
  armdyn::bind_derivatives(m);
  armdyn::bind_regressor(m);
  armdyn::bind_parameter_model(m);
  finish_functions(m, py::module_::import("ast").attr("literal_eval"));
}
