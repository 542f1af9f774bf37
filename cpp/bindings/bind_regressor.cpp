// SPDX-License-Identifier: BSD-3-Clause
// Bindings of the dynamic-parameter regressor (armdyn/algorithm/regressor.hpp):
// joint_torque_regressor (one state, or one state per row of 2-D arrays in one C++ loop without
// the GIL), dynamic_parameters and dynamic_parameter_names.
#include <pybind11/stl.h>

#include "armdyn/algorithm/regressor.hpp"
#include "common.hpp"
#include "rows.hpp"

namespace armdyn {

namespace py = pybind11;
using namespace py_helpers;

namespace {

py::array_t<double> joint_torque_regressor_py(const ModelArg& model, const ArrayLike& q,
                                              const ArrayLike& qd, const ArrayLike& qdd,
                                              const OptData& data) {
  constexpr const char* fn = "joint_torque_regressor";
  const CallArgs a = call_args(model, data, fn);
  Data& d = a.data;
  const long n = d.ni;
  const long p = dynamic_parameter_layout(a.model()).n_params;
  MatX Y(n, p);
  if (!is_batch(q)) {
    const VecArg qa(q, "q", d.niq), va(qd, "qd", n), aa(qdd, "qdd", n);
    joint_torque_regressor(a.model(), d, *qa, *va, *aa, Y);
    return to_numpy(Y);
  }
  return batch(fn, d.niq, n, q, qd, "qd", qdd, "qdd", py::float_(0.0), {n, p},
               [&](auto qi, auto vi, auto ai, double, double* out) {
                 joint_torque_regressor(a.model(), d, qi, vi, ai, Y);
                 copy_row_major(Y, out);
               });
}

}  // namespace

void bind_regressor(py::module_& m) {
  m.def("joint_torque_regressor", &joint_torque_regressor_py, py::arg("model"), py::arg("q"),
        py::arg("qd"), py::arg("qdd"), py::arg("data") = py::none(),
        "The joint torque regressor Y (n_dofs, n_params) at (q, qd, qdd): inverse_dynamics(model, "
        "q, qd, qdd) = Y @ dynamic_parameters(model), linear in the model's dynamic parameters "
        "(per body: m, m c, the inertia about its parameter frame -- its URDF link frame; per "
        "joint coordinate: viscous and Coulomb friction, a torque offset, the rotor's reflected "
        "inertia; dynamic_parameter_names names them). q: n_coords, qd and qdd: n_dofs (a "
        "coupled model's independent coordinates); 2-D arrays (one state per row) give (rows, "
        "n_dofs, n_params). ModelError for a model with a force element that is not a "
        "parameter (springs, loads, inputs, motors), named.");
  m.def(
      "dynamic_parameters",
      [](const ModelArg& model) {
        return to_numpy(dynamic_parameters(*model_of(model, "dynamic_parameters")));
      },
      py::arg("model"),
      "The model's dynamic parameters pi (n_params,) in joint_torque_regressor's order "
      "(dynamic_parameter_names): per body m, m c_x, m c_y, m c_z, I_xx, I_xy, I_yy, I_xz, I_yz, "
      "I_zz about its parameter frame (Pinocchio's order), then per joint coordinate fv, fc, "
      "offset (0), Ia.");
  m.def(
      "dynamic_parameter_names",
      [](const ModelArg& model) {
        return dynamic_parameter_names(*model_of(model, "dynamic_parameter_names"));
      },
      py::arg("model"),
      "The names of dynamic_parameters(model)' entries: '<body>.m', '<body>.mcx', ..., "
      "'<body>.Izz', then '<coordinate>.fv', '.fc', '.offset', '.Ia'.");
}

}  // namespace armdyn
