// SPDX-License-Identifier: BSD-3-Clause
// Binding of driven inverse dynamics (armdyn/algorithm/driven_inverse_dynamics.hpp):
// _inverse_dynamics_driven, which armdyn.driven_inverse_dynamics calls; the GIL is released and
// Ctrl-C polled.
#include <pybind11/stl.h>

#include "armdyn/algorithm/driven_inverse_dynamics.hpp"
#include "common.hpp"
#include "results.hpp"

namespace armdyn {

namespace py = pybind11;
using namespace py_helpers;

namespace {

py::dict inverse_dynamics_driven_py(const Model& md, const ArrayLike& times) {
  const VecX t = to_vec(times, "t");
  const std::vector<double> tv(t.data(), t.data() + t.size());
  InverseDynamicsResult r;
  Poll poll = python_poll();  // Ctrl-C
  {
    py::gil_scoped_release nogil;
    r = inverse_dynamics_driven(md, tv, &poll);
  }
  return driven_id_result_dict(md, r);
}

}  // namespace

void bind_inverse_dynamics(py::module_& m) {
  m.def("_inverse_dynamics_driven", &inverse_dynamics_driven_py, py::arg("model"), py::arg("t"));
}

}  // namespace armdyn
