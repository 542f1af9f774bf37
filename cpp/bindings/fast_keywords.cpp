// SPDX-License-Identifier: BSD-3-Clause
// Keyword arguments at the price of positional ones.
//
// pybind11 (3.1) matches a call's keywords by interning every parameter name from its C string
// on every call, once per positional argument (to reject a keyword that repeats one) and once per
// remaining parameter: 0.44 us per call of forward_dynamics(model, q, qd, tau,
// method="cartesian") on the UR5 (`python -m benchmarks.cartesian_fd`, keyword_us in the JSON,
// with fast_keyword not applied). Each module-level function with one overload and plain
// parameters gets, in its PyMethodDef, a function of its own in the place of pybind11's
// dispatcher: the keywords are matched against the function record's names, the gaps filled
// with the record's defaults, and the dispatcher is called with positional arguments only, so
// its argument loading, conversions, checks and error messages are its own. Anything this does not
// handle with certainty (an unknown, repeated or positional-only keyword, a gap without a default,
// more than kMaxParams parameters) goes through pybind11's own path unchanged, which raises its
// usual TypeError.
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cstring>
#include <string>

namespace py = pybind11;

namespace armdyn {

namespace fast_kw {

constexpr size_t kMaxParams = 24;

using Dispatcher = PyObject* (*)(PyObject*, PyObject* const*, size_t, PyObject*);

const py::detail::function_record* record_of(PyObject* f) {
  PyObject* self = PyCFunction_GET_SELF(f);
  if (!self || !py::detail::is_function_record_PyObject(self)) return nullptr;
  return py::detail::function_record_ptr_from_PyObject(self);
}

// the parameter a keyword names, -1 if none
long param_index(const py::detail::function_record& rec, PyObject* key) {
  Py_ssize_t len = 0;
  const char* s = PyUnicode_AsUTF8AndSize(key, &len);
  if (!s) {
    PyErr_Clear();
    return -1;
  }
  for (size_t j = 0; j < rec.args.size(); ++j) {
    const char* name = rec.args[j].name;
    // whole-string equality (a keyword may hold a NUL: its length decides, not strcmp's)
    if (name && std::strlen(name) == static_cast<size_t>(len) &&
        std::memcmp(name, s, static_cast<size_t>(len)) == 0)
      return static_cast<long>(j);
  }
  return -1;
}

// pybind11's dispatcher (one for every function), as found on the first function taken
Dispatcher dispatch = nullptr;

// in the place of the dispatcher in a function's PyMethodDef (CPython 3.11 calls builtins
// through it directly): self is the function record
PyObject* call_with_keywords(PyObject* self, PyObject* const* args, size_t nargsf, PyObject* kw) {
  const size_t n = static_cast<size_t>(PyVectorcall_NARGS(nargsf));
  const Py_ssize_t nk = kw ? PyTuple_GET_SIZE(kw) : 0;
  if (nk == 0) return dispatch(self, args, nargsf, nullptr);
  const py::detail::function_record* rec = py::detail::function_record_ptr_from_PyObject(self);
  const size_t np = rec->args.size();
  PyObject* buf[kMaxParams] = {};
  if (n > np) return dispatch(self, args, nargsf, kw);
  for (size_t i = 0; i < n; ++i) buf[i] = args[i];
  size_t used = n;
  for (Py_ssize_t i = 0; i < nk; ++i) {
    const long j = param_index(*rec, PyTuple_GET_ITEM(kw, i));
    if (j < static_cast<long>(rec->nargs_pos_only) || buf[j])  // unknown, positional-only, twice
      return dispatch(self, args, nargsf, kw);
    buf[j] = args[n + static_cast<size_t>(i)];
    used = std::max(used, static_cast<size_t>(j) + 1);
  }
  for (size_t j = n; j < used; ++j) {
    if (buf[j]) continue;
    buf[j] = rec->args[j].value.ptr();
    if (!buf[j]) return dispatch(self, args, nargsf, kw);  // a gap without a default
  }
  return dispatch(self, buf, used, nullptr);
}

// a plain pybind11 function: one overload, every parameter named and positional, no *args,
// **kwargs, keyword-only parameters or constructor
bool eligible(PyObject* f) {
  if (!f || !PyCFunction_Check(f)) return false;
  const py::detail::function_record* rec = record_of(f);
  if (!rec || rec->next || rec->has_args || rec->has_kwargs || rec->is_constructor ||
      rec->is_new_style_constructor || rec->args.size() > kMaxParams ||
      rec->nargs_pos != rec->args.size() || rec->nargs != rec->args.size())
    return false;
  for (const auto& a : rec->args)
    if (!a.name) return false;
  return (PyCFunction_GET_FLAGS(f) & (METH_FASTCALL | METH_KEYWORDS)) ==
         (METH_FASTCALL | METH_KEYWORDS);
}

}  // namespace fast_kw

void fast_keyword(PyObject* f) {
  if (!fast_kw::eligible(f)) return;
  PyMethodDef* def = reinterpret_cast<PyCFunctionObject*>(f)->m_ml;
  const auto meth =
      reinterpret_cast<fast_kw::Dispatcher>(reinterpret_cast<void (*)()>(def->ml_meth));
  if (meth == reinterpret_cast<fast_kw::Dispatcher>(fast_kw::call_with_keywords)) return;
  if (!fast_kw::dispatch) fast_kw::dispatch = meth;
  if (meth != fast_kw::dispatch) return;  // not pybind11's dispatcher
  def->ml_meth =
      reinterpret_cast<PyCFunction>(reinterpret_cast<void (*)()>(fast_kw::call_with_keywords));
}

}  // namespace armdyn
