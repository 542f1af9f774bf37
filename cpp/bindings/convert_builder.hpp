// SPDX-License-Identifier: BSD-3-Clause
// Argument conversions of the ModelBuilder and URDF bindings (bind_builder, bind_builder_forces,
// bind_urdf): Python arguments checked and turned into the C++ builder's (a ModelError naming
// the function and argument), None into the builder's "not given", and the run of a loader or
// finalize under the Python poll (Ctrl-C) with its warnings issued as Python UserWarnings.
#pragma once

#include <pybind11/stl.h>

#include <optional>
#include <string>
#include <vector>

#include "armdyn/builder/builder.hpp"
#include "common.hpp"

namespace armdyn::py_helpers {

using BuilderClass = py::class_<ModelBuilder>;

/// A joint's name, bodies, point and axis from Python, checked: a ModelError naming the argument
/// (point or axis null: the method takes none).
struct JointArgs {
  std::string name, parent, child;
  Vec3 point = Vec3::Zero(), axis = Vec3::Zero();
  JointArgs(const py::handle& n, const py::handle& p, const py::handle& c, const py::handle* pt,
            const py::handle* ax, const char* fn)
      : name(str_arg(n, fn, "name")),
        parent(str_arg(p, fn, "parent")),
        child(str_arg(c, fn, "child")) {
    const std::string who = "joint '" + name + "'";
    if (pt) point = to_vec3(*pt, who + ": point");
    if (ax) axis = to_vec3(*ax, who + ": axis");
  }
};

/// An optional (3,) vector argument: None, or to_vec3's.
inline std::optional<Vec3> opt_vec3(const py::handle& obj, const std::string& name) {
  if (obj.is_none()) return std::nullopt;
  return to_vec3(obj, name);
}

/// An optional profile argument: None, or to_profile's.
inline std::optional<Profile> opt_profile(const py::handle& obj, const std::string& name) {
  if (obj.is_none()) return std::nullopt;
  return to_profile(obj, name);
}

/// The pointer the builder takes for an optional value (null: not given).
template <class T>
const T* ptr_or_null(const std::optional<T>& v) {
  return v ? &*v : nullptr;
}

/// A joint limit: a real number, infinities meaning no limit; NaN refused naming the argument.
inline double limit_arg(const py::handle& v, const char* fn, const char* name) {
  const double x = float_arg(v, fn, name);
  if (std::isnan(x))
    throw ModelError(msg(fn, ": ", name, " must be a real number (inf: no limit), got nan"));
  return x;
}

/// A spring's rest length: >= 0, or None for the builder's -1 (the assembly distance).
inline double rest_length_arg(const OptFloat& rest, const char* fn) {
  const double rv = opt_float_arg(rest, fn, "rest_length", -1.0);
  if (!rest.is_none() && rv < 0.0)
    throw ModelError(msg(fn, ": rest_length must be >= 0 or None, got ", rv));
  return rv;
}

/// An actuator's friction smoothing: > 0, or None for the builder's 0 (its default).
inline double friction_smoothing_arg(const OptFloat& v, const char* fn, const std::string& joint) {
  const double vs = opt_float_arg(v, fn, "friction_smoothing", 0.0);
  if (!v.is_none() && !(vs > 0.0))
    throw ModelError(
        msg("add_actuator on joint '", joint, "': friction_smoothing must be positive, got ", vs));
  return vs;
}

/// f() run under the Python poll: Ctrl-C stops the long loops of a large model's analysis or a
/// URDF's links and joints.
template <class F>
auto with_python_poll(F&& f) {
  Poll poll = python_poll();
  ScopedThreadPoll scope(&poll);
  return f();
}

/// Each of a model's warnings issued as a Python UserWarning ("armdyn: ...").
inline void warn_all(const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings)
    if (PyErr_WarnEx(PyExc_UserWarning, ("armdyn: " + w).c_str(), 1) != 0)
      throw py::error_already_set();
}

/// ModelBuilder.finalize: the model, its warnings issued.
inline std::shared_ptr<Model> finalize_model(const ModelBuilder& b, const BoolArg& mass_weighted) {
  FinalizeOptions o;
  o.mass_weighted_assembly =
      bool_arg(mass_weighted, "ModelBuilder.finalize", "mass_weighted_assembly");
  ModelPtr m = with_python_poll([&] { return b.finalize(o); });
  warn_all(m->warnings);
  return std::const_pointer_cast<Model>(m);
}

/// urdf_builder's source: a str (UTF-8) or bytes as they are (the loader checks names are UTF-8).
inline std::string urdf_source_arg(const StrArg& src, const char* fn) {
  if (!py::isinstance<py::bytes>(src) && !py::isinstance<py::str>(src))
    throw ModelError(msg(fn, ": path_or_xml must be a str or bytes, got ", shown(src)));
  return py::isinstance<py::bytes>(src) ? src.cast<std::string>() : str_arg(src, fn, "path_or_xml");
}

/// f() with a UrdfError's message made valid UTF-8 (the loader escapes what it quotes; this
/// keeps any message valid regardless).
template <class F>
auto urdf_utf8_errors(F&& f) {
  try {
    return f();
  } catch (const UrdfError& e) {
    const std::string text = e.what();
    throw UrdfError(
        py::bytes(text).attr("decode")("utf-8", "backslashreplace").cast<std::string>());
  }
}

}  // namespace armdyn::py_helpers
