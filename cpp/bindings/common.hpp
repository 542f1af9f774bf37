// SPDX-License-Identifier: BSD-3-Clause
// Shared helpers of the bindings: numpy <-> Eigen conversion with shape checks that raise
// armdyn.ModelError naming the argument and the expected shape.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "armdyn/errors.hpp"
#include "armdyn/math/types.hpp"
#include "armdyn/model/profile.hpp"
#include "python_run.hpp"

namespace armdyn::py_helpers {

namespace py = pybind11;

/// Arguments the bindings take as any Python object and check themselves (to_vec, to_profile, ...),
/// typed for the stubs and inspect: pybind11 prints handle_type_name<T> (below) in the
/// signatures pybind11-stubgen reads. Each accepts every object, like py::object.
inline bool accept_any(PyObject*) { return true; }
#define ARMDYN_HINTED_OBJECT(Name)                        \
  class Name : public py::object {                        \
   public:                                                \
    PYBIND11_OBJECT_DEFAULT(Name, py::object, accept_any) \
  };
ARMDYN_HINTED_OBJECT(ArrayLike)       // numpy.typing.ArrayLike
ARMDYN_HINTED_OBJECT(OptArrayLike)    // numpy.typing.ArrayLike | None
ARMDYN_HINTED_OBJECT(ProfileLike)     // Profile | float | Callable[[float], tuple[...]]
ARMDYN_HINTED_OBJECT(OptProfileLike)  // the same or None
ARMDYN_HINTED_OBJECT(OptFloat)        // float | None
ARMDYN_HINTED_OBJECT(OptStr)          // str | None
ARMDYN_HINTED_OBJECT(StrArg)          // str (checked by str_arg: a ModelError, never a cast error)
ARMDYN_HINTED_OBJECT(StrSeq)          // collections.abc.Sequence[str] (checked where it is taken)
ARMDYN_HINTED_OBJECT(FloatArg)        // a real number (checked by float_arg)
ARMDYN_HINTED_OBJECT(IntArg)          // an integer (checked by int_arg)
ARMDYN_HINTED_OBJECT(BoolArg)         // bool (checked by bool_arg)
ARMDYN_HINTED_OBJECT(ModelArg)        // armdyn._core.Model (checked where it is taken)
ARMDYN_HINTED_OBJECT(FrameRef)        // str | int (a frame's name or index)
ARMDYN_HINTED_OBJECT(OptMotor)        // Motor | None
ARMDYN_HINTED_OBJECT(OptProgress)     // Callable[[float, float], object] | None
ARMDYN_HINTED_OBJECT(FloatOrArray)    // float | numpy.typing.ArrayLike
ARMDYN_HINTED_OBJECT(OptTimes)        // float | numpy.typing.ArrayLike | None
ARMDYN_HINTED_OBJECT(OptData)         // Data | None
ARMDYN_HINTED_OBJECT(ProfileValues)   // Profile.eval's (y, yd, ydd): floats or float64 arrays
#undef ARMDYN_HINTED_OBJECT

/// Refuses values that numpy would convert to float64 with loss or by accident: complex numbers
/// (numpy drops the imaginary part with only a warning), and arrays of objects, strings or bytes.
inline void refuse_non_real(const py::handle& obj, const std::string& name) {
  if (PyComplex_Check(obj.ptr()))
    throw ModelError(name + ": must be real numbers, got a complex number");
  if (!py::isinstance<py::array>(obj)) return;
  const char kind = py::reinterpret_borrow<py::array>(obj).dtype().kind();
  if (kind == 'c') throw ModelError(name + ": must hold real numbers, got a complex array");
  if (kind == 'O' || kind == 'U' || kind == 'S' || kind == 'V')
    throw ModelError(name + ": must hold real numbers, got an array of dtype " +
                     py::str(py::reinterpret_borrow<py::array>(obj).dtype()).cast<std::string>());
}

inline py::array_t<double> as_array(const py::handle& obj, const std::string& name) {
  refuse_non_real(obj, name);
  try {
    return py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  } catch (...) {
  }
  throw ModelError(name + ": expected an array of real numbers");
}

/// The text of a str argument, or a ModelError naming it: not a str, or a str UTF-8 cannot
/// encode (a lone surrogate).
inline std::string str_arg(const py::handle& obj, const char* fn, const char* name) {
  if (!PyUnicode_Check(obj.ptr()))
    throw ModelError(msg(fn, ": ", name, " must be a str, got ",
                         py::str(py::type::of(obj).attr("__name__")).cast<std::string>()));
  Py_ssize_t size = 0;
  const char* s = PyUnicode_AsUTF8AndSize(obj.ptr(), &size);
  if (!s) {
    PyErr_Clear();
    throw ModelError(
        msg(fn, ": ", name, " must be valid Unicode text (it holds a lone surrogate)"));
  }
  return std::string(s, static_cast<size_t>(size));
}

/// A short repr of a rejected argument (at most 60 characters), for messages.
inline std::string shown(const py::handle& obj) {
  std::string r;
  try {
    r = py::repr(obj).cast<std::string>();
  } catch (const py::error_already_set&) {
    r = "<" + py::str(py::type::of(obj).attr("__name__")).cast<std::string>() + ">";
  }
  return r.size() <= 60 ? r : r.substr(0, 57) + "...";
}

/// Whether obj is a bool (Python's or numpy's).
inline bool is_bool_like(const py::handle& obj) {
  if (PyBool_Check(obj.ptr())) return true;
  const std::string tn = Py_TYPE(obj.ptr())->tp_name;
  return tn == "numpy.bool_" || tn == "numpy.bool";
}

/// Whether obj is an instance of numbers.<abc> (numpy's real and integer scalars register).
inline bool is_number_abc(const py::handle& obj, const char* abc) {
  const py::object cls = py::module_::import("numbers").attr(abc);
  const int r = PyObject_IsInstance(obj.ptr(), cls.ptr());
  if (r < 0) PyErr_Clear();
  return r == 1;
}

/// A real number argument (int, float, a numpy real scalar; not bool, str, None or complex) as a
/// double, or a ModelError naming the function and the argument. `finite`: NaN and infinities
/// refused here too (otherwise the callee's own checks, which name the element, judge the
/// value). Fast for a Python float (one type check).
inline double float_arg(const py::handle& obj, const char* fn, const char* name,
                        bool finite = false) {
  double x = 0.0;
  bool ok = false;
  if (PyFloat_Check(obj.ptr())) {
    x = PyFloat_AS_DOUBLE(obj.ptr());
    ok = true;
  } else if (!is_bool_like(obj) && !PyComplex_Check(obj.ptr()) &&
             (PyLong_Check(obj.ptr()) || is_number_abc(obj, "Real"))) {
    x = PyFloat_AsDouble(obj.ptr());  // an int beyond double's range: OverflowError
    ok = !(x == -1.0 && PyErr_Occurred());
    if (!ok) PyErr_Clear();
  }
  if (!ok || (finite && !std::isfinite(x)))
    throw ModelError(msg(fn, ": ", name, " must be a ", finite ? "finite " : "",
                         "real number, got ", shown(obj)));
  return x;
}

/// float_arg, or `none_value` for None (an optional number).
inline double opt_float_arg(const py::handle& obj, const char* fn, const char* name,
                            double none_value, bool finite = false) {
  if (obj.is_none()) return none_value;
  try {
    return float_arg(obj, fn, name, finite);
  } catch (const ModelError&) {
    throw ModelError(msg(fn, ": ", name, " must be a ", finite ? "finite " : "",
                         "real number or None, got ", shown(obj)));
  }
}

/// An integer argument (int or a numpy integer; not bool, not a float such as 1.0) that fits a C++
/// int, or a ModelError naming the function and the argument.
inline int int_arg(const py::handle& obj, const char* fn, const char* name) {
  long long k = 0;
  bool ok = false;
  if (!is_bool_like(obj) && (PyLong_Check(obj.ptr()) || is_number_abc(obj, "Integral"))) {
    const py::object idx = py::reinterpret_steal<py::object>(PyNumber_Index(obj.ptr()));
    int overflow = 0;
    if (idx) k = PyLong_AsLongLongAndOverflow(idx.ptr(), &overflow);
    ok = idx && overflow == 0 && !(k == -1 && PyErr_Occurred());
    if (!ok) PyErr_Clear();
    ok = ok && k >= std::numeric_limits<int>::min() && k <= std::numeric_limits<int>::max();
  }
  if (!ok)
    throw ModelError(msg(fn, ": ", name, " must be an integer in [",
                         std::numeric_limits<int>::min(), ", ", std::numeric_limits<int>::max(),
                         "], got ", shown(obj)));
  return static_cast<int>(k);
}

/// True or False (Python's or numpy's bool), or a ModelError naming the function and argument.
inline bool bool_arg(const py::handle& obj, const char* fn, const char* name) {
  if (!is_bool_like(obj))
    throw ModelError(msg(fn, ": ", name, " must be True or False, got ", shown(obj)));
  return PyObject_IsTrue(obj.ptr()) == 1;
}

/// str_arg, or `none_value` for None.
inline std::string opt_str_arg(const py::handle& obj, const char* fn, const char* name,
                               const std::string& none_value = "") {
  if (obj.is_none()) return none_value;
  if (!PyUnicode_Check(obj.ptr()))
    throw ModelError(msg(fn, ": ", name, " must be a str or None, got ", shown(obj)));
  return str_arg(obj, fn, name);
}

inline std::string shape_str(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t k = 0; k < a.ndim(); ++k) s += (k ? ", " : "") + std::to_string(a.shape(k));
  if (a.ndim() == 1) s += ",";
  return s + ")";
}

inline VecX to_vec(const py::handle& obj, const std::string& name, long n = -1) {
  auto a = as_array(obj, name);
  if (!a || a.ndim() != 1 || (n >= 0 && a.shape(0) != n))
    throw ModelError(msg(name, ": expected shape (", n >= 0 ? std::to_string(n) : "n", ",), got ",
                         a ? shape_str(a) : std::string("?")));
  VecX v(a.shape(0));
  for (py::ssize_t i = 0; i < a.shape(0); ++i) v[i] = a.at(i);
  return v;
}

/// A read-only vector argument: a view of a float64 C-contiguous numpy array of the right length
/// (no copy), otherwise converted (and checked) by to_vec.
class VecArg {
 public:
  VecArg(const py::handle& obj, const char* name, long n) : map_(nullptr, 0) {
    if (py::array_t<double, py::array::c_style>::check_(obj)) {
      auto a = py::reinterpret_borrow<py::array>(obj);
      if (a.ndim() == 1 && a.shape(0) == n) {
        new (&map_) Eigen::Map<const VecX>(static_cast<const double*>(a.data()), n);
        return;
      }
    }
    own_ = to_vec(obj, name, n);
    new (&map_) Eigen::Map<const VecX>(own_.data(), n);
  }
  VecArg(const VecArg&) = delete;  // map_ may point into own_
  VecArg& operator=(const VecArg&) = delete;
  const Eigen::Map<const VecX>& operator*() const { return map_; }

 private:
  VecX own_;
  Eigen::Map<const VecX> map_;
};

inline Vec3 to_vec3(const py::handle& obj, const std::string& name) { return to_vec(obj, name, 3); }

inline Vec4 to_vec4(const py::handle& obj, const std::string& name) { return to_vec(obj, name, 4); }

/// 3x3 matrix, or a length-3 vector taken as a diagonal.
inline Mat3 to_inertia(const py::handle& obj, const std::string& name) {
  auto a = as_array(obj, name);
  Mat3 m = Mat3::Zero();
  if (a.ndim() == 1 && a.shape(0) == 3) {
    for (int i = 0; i < 3; ++i) m(i, i) = a.at(i);
    return m;
  }
  if (a.ndim() != 2 || a.shape(0) != 3 || a.shape(1) != 3)
    throw ModelError(msg(name, ": expected shape (3, 3) or (3,), got ", shape_str(a)));
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = a.at(i, j);
  return m;
}

inline py::array_t<double> to_numpy(const double* data, std::vector<py::ssize_t> shape) {
  py::array_t<double> a(shape);
  py::ssize_t n = 1;
  for (auto s : shape) n *= s;
  std::copy(data, data + n, a.mutable_data());
  return a;
}

inline py::array_t<double> to_numpy(const VecX& v) { return to_numpy(v.data(), {v.size()}); }

inline py::array_t<double> to_numpy(const MatX& m) {
  py::array_t<double> a({m.rows(), m.cols()});
  for (long i = 0; i < m.rows(); ++i)
    for (long j = 0; j < m.cols(); ++j) a.mutable_at(i, j) = m(i, j);
  return a;
}

/// A Profile from a Profile object, a number (constant) or a callable t -> (y, yd, ydd).
Profile to_profile(const py::handle& obj, const std::string& name);

}  // namespace armdyn::py_helpers

namespace pybind11::detail {
#define ARMDYN_TYPE_HINT(Name, Hint)                  \
  template <>                                         \
  struct handle_type_name<armdyn::py_helpers::Name> { \
    static constexpr auto name = const_name(Hint);    \
  };
ARMDYN_TYPE_HINT(ArrayLike, "numpy.typing.ArrayLike")
ARMDYN_TYPE_HINT(OptArrayLike, "numpy.typing.ArrayLike | None")
#define ARMDYN_PROFILE_HINT \
  "armdyn._core.Profile | float | collections.abc.Callable[[float], tuple[float, float, float]]"
ARMDYN_TYPE_HINT(ProfileLike, ARMDYN_PROFILE_HINT)
ARMDYN_TYPE_HINT(OptProfileLike, ARMDYN_PROFILE_HINT " | None")
#undef ARMDYN_PROFILE_HINT
ARMDYN_TYPE_HINT(OptFloat, "float | None")
ARMDYN_TYPE_HINT(OptStr, "str | None")
ARMDYN_TYPE_HINT(StrArg, "str")
ARMDYN_TYPE_HINT(StrSeq, "collections.abc.Sequence[str]")
// the hints pybind11 prints for double and int arguments (the stubs unchanged)
ARMDYN_TYPE_HINT(FloatArg, "typing.SupportsFloat | typing.SupportsIndex")
ARMDYN_TYPE_HINT(IntArg, "typing.SupportsInt | typing.SupportsIndex")
ARMDYN_TYPE_HINT(BoolArg, "bool")
ARMDYN_TYPE_HINT(ModelArg, "armdyn._core.Model")
ARMDYN_TYPE_HINT(FrameRef, "str | int")
ARMDYN_TYPE_HINT(OptMotor, "armdyn._core.Motor | None")
ARMDYN_TYPE_HINT(OptProgress, "collections.abc.Callable[[float, float], object] | None")
ARMDYN_TYPE_HINT(FloatOrArray, "float | numpy.typing.ArrayLike")
ARMDYN_TYPE_HINT(OptTimes, "float | numpy.typing.ArrayLike | None")
ARMDYN_TYPE_HINT(OptData, "armdyn._core.Data | None")
ARMDYN_TYPE_HINT(ProfileValues,
                 "tuple[float, float, float] | tuple[numpy.typing.NDArray[numpy.float64], "
                 "numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64]]")
#undef ARMDYN_TYPE_HINT
}  // namespace pybind11::detail
