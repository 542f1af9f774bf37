// SPDX-License-Identifier: BSD-3-Clause
// Shared helpers of the bindings: numpy <-> Eigen conversion with shape checks that raise
// armdyn.ModelError naming the argument and the expected shape.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "armdyn/errors.hpp"
#include "armdyn/math/types.hpp"
#include "armdyn/model/profile.hpp"

namespace armdyn::py_helpers {

namespace py = pybind11;

inline py::array_t<double> as_array(const py::handle& obj, const std::string& name) {
  try {
    return py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  } catch (...) {
  }
  throw ModelError(name + ": expected an array of numbers");
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
