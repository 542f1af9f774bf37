// SPDX-License-Identifier: BSD-3-Clause
// armdyn.Profile (armdyn/model/profile.hpp) and the built-in profiles, armdyn.profiles.*.
// Pickling: bind_pickle.cpp; a number or a Python callable as a profile: common.cpp to_profile.
#include "convert_model.hpp"

namespace armdyn {

namespace py = pybind11;
using namespace py_helpers;

void bind_profile(py::module_& m) {
  py::class_<Profile>(m, "Profile", "A time profile y(t) with derivatives, evaluated in C++.")
      .def("eval", &profile_eval, py::arg("t"),
           "The profile's value y, rate dy/dt and second derivative d2y/dt2 at time t [s]: a "
           "tuple of 3 floats for a number t; for an array t (any shape), a tuple of 3 float64 "
           "arrays of t's shape (one evaluation per element). Units follow the profile's use "
           "(rad, m, N m, N or a load scale, per s and s^2). ModelError if t is not numeric.")
      .def("__repr__", [](const Profile& p) { return "<armdyn.Profile " + p.describe() + ">"; });

  auto prof = m.def_submodule("profiles", "Built-in drive and load profiles (evaluated in C++).");
  prof.def(
      "constant",
      [](const FloatArg& value) {
        return Profile::constant(float_arg(value, "profiles.constant", "value"));
      },
      py::arg("value"), "The constant profile y(t) = value (zero derivatives).");
  prof.def(
      "cubic",
      [](const FloatArg& y0, const FloatArg& y1, const FloatArg& t0, const FloatArg& t1) {
        const char* fn = "profiles.cubic";
        return Profile::cubic(float_arg(y0, fn, "y0"), float_arg(y1, fn, "y1"),
                              float_arg(t0, fn, "t0"), float_arg(t1, fn, "t1"));
      },
      py::arg("y0"), py::arg("y1"), py::arg("t0"), py::arg("t1"),
      "Cubic rest-to-rest from y0 at t0 to y1 at t1 (3s^2 - 2s^3); constant outside.");
  prof.def(
      "quintic",
      [](const FloatArg& y0, const FloatArg& y1, const FloatArg& t0, const FloatArg& t1) {
        const char* fn = "profiles.quintic";
        return Profile::quintic(float_arg(y0, fn, "y0"), float_arg(y1, fn, "y1"),
                                float_arg(t0, fn, "t0"), float_arg(t1, fn, "t1"));
      },
      py::arg("y0"), py::arg("y1"), py::arg("t0"), py::arg("t1"),
      "Quintic rest-to-rest (zero velocity and acceleration at both ends).");
  prof.def(
      "sine",
      [](const FloatArg& amplitude, const FloatArg& frequency, const FloatArg& phase,
         const FloatArg& offset) {
        const char* fn = "profiles.sine";
        return Profile::sine(float_arg(amplitude, fn, "amplitude"),
                             float_arg(frequency, fn, "frequency"), float_arg(phase, fn, "phase"),
                             float_arg(offset, fn, "offset"));
      },
      py::arg("amplitude"), py::arg("frequency"), py::arg("phase") = 0.0, py::arg("offset") = 0.0,
      "offset + amplitude * sin(2 pi frequency t + phase); frequency in Hz.");
  prof.def(
      "spline",
      [](const ArrayLike& t, const ArrayLike& y) {
        const VecX tv = to_vec(t, "profiles.spline: t"), yv = to_vec(y, "profiles.spline: y");
        return Profile::spline(std::vector<double>(tv.data(), tv.data() + tv.size()),
                               std::vector<double>(yv.data(), yv.data() + yv.size()));
      },
      py::arg("t"), py::arg("y"),
      "Natural cubic spline through the samples (t[k], y[k]), t (n,) increasing [s], y (n,); "
      "linear extrapolation outside [t[0], t[-1]].");
}

}  // namespace armdyn
