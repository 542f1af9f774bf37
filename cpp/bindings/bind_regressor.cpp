// SPDX-License-Identifier: BSD-3-Clause
// Bindings of the dynamic-parameter regressor (armdyn/algorithm/regressor.hpp):
// joint_torque_regressor and energy_regressor (one state, or one state per row of 2-D arrays in
// one C++ loop without the GIL, each row written straight into the output, Ctrl-C answered),
// dynamic_parameters and dynamic_parameter_names.
#include <pybind11/stl.h>

#include <cmath>

#include "armdyn/algorithm/regressor.hpp"
#include "common.hpp"
#include "rows.hpp"

namespace armdyn {

namespace py = pybind11;
using namespace py_helpers;

namespace {

// the model's parameter count (its layout, kept with the model and by the Data)
long n_params_of(const Model& m, Data& d) {
  if (!d.parameter_layout) d.parameter_layout = &cached_parameter_layout(m);
  return d.parameter_layout->n_params;
}

// out (size entries) finite, else a SolverError naming the entry and the largest input: first
// the vectorised sum of out * 0 (NaN exactly when an entry is inf or NaN; Eigen's allFinite
// tests entry by entry, a quarter of a batch row's time on solo12), the element-wise pass only
// on failure
void check_out(const char* fn, const char* name, const double* out, long size,
               std::initializer_list<NamedInput> in) {
  if (!std::isfinite((Eigen::Map<const VecX>(out, size).array() * 0.0).sum()))
    check_finite_output(fn, name, out, size, in);
}

py::array_t<double> joint_torque_regressor_py(const ModelArg& model, const ArrayLike& q,
                                              const ArrayLike& qd, const ArrayLike& qdd,
                                              const OptData& data) {
  constexpr const char* fn = "joint_torque_regressor";
  const CallArgs a = call_args(model, data, fn);
  Data& d = a.data;
  const long n = d.ni, p = n_params_of(a.model(), d);
  // each state's Y row-major straight into the output (its row of a batch)
  auto one = [&](const auto& qi, const auto& vi, const auto& ai, double* out) {
    joint_torque_regressor_into(a.model(), d, qi, vi, ai, out);
    check_out(fn, "Y (row-major)", out, n * p,
              {named_input("q", qi), named_input("qd", vi), named_input("qdd", ai)});
  };
  if (!is_batch(q)) {
    const VecArg qa(q, "q", d.niq), va(qd, "qd", n), aa(qdd, "qdd", n);
    py::array_t<double> out({n, p});
    one(*qa, *va, *aa, out.mutable_data());
    return out;
  }
  return batch(fn, d.niq, n, q, qd, "qd", qdd, "qdd", py::float_(0.0), {n, p},
               [&](auto qi, auto vi, auto ai, double, double* out) { one(qi, vi, ai, out); });
}

py::array_t<double> energy_regressor_py(const ModelArg& model, const ArrayLike& q,
                                        const ArrayLike& qd, const OptData& data) {
  constexpr const char* fn = "energy_regressor";
  const CallArgs a = call_args(model, data, fn);
  Data& d = a.data;
  const long n = d.ni, p = n_params_of(a.model(), d);
  auto one = [&](const auto& qi, const auto& vi, double* out) {
    energy_regressor_into(a.model(), d, qi, vi, out);
    check_out(fn, "h", out, p, {named_input("q", qi), named_input("qd", vi)});
  };
  if (!is_batch(q)) {
    const VecArg qa(q, "q", d.niq), va(qd, "qd", n);
    py::array_t<double> out(p);
    one(*qa, *va, out.mutable_data());
    return out;
  }
  // (batch's third array: qd again, checked twice, read once)
  return batch(fn, d.niq, n, q, qd, "qd", qd, "qd", py::float_(0.0), {p},
               [&](auto qi, auto vi, auto, double, double* out) { one(qi, vi, out); });
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
        "coupled model's independent coordinates, Y = G^T Y_full); 2-D arrays (one state per "
        "row) give (rows, n_dofs, n_params), computed in C++ without the GIL. A floating base's "
        "six rows come first: the force on the base frame, then the moment about its origin, in "
        "its axes (as inverse_dynamics). By the recursive Newton-Euler algorithm: per body its "
        "6 x 10 unit-wrench block F in its parameter frame, then one row block S^T F per degree "
        "of freedom on its path to the root. Pinocchio's computeJointTorqueRegressor is the same "
        "matrix reordered: rows by joint name (a free flyer's six first), body B's 10 columns "
        "those of the joint whose child link is B (Pinocchio's joint frame is the URDF link "
        "frame), armdyn's friction, offset and rotor columns added. ModelError for a model with "
        "a force element that is not a parameter (springs, loads, inputs, motors), named; "
        "SolverError when finite inputs overflow.");
  m.def("energy_regressor", &energy_regressor_py, py::arg("model"), py::arg("q"), py::arg("qd"),
        py::arg("data") = py::none(),
        "The energy regressor h (n_params,) at (q, qd): the kinetic plus potential energy of the "
        "model's bodies and actuator rotors is h @ dynamic_parameters(model) (potential -m g . c "
        "about the world origin, as energy(); the friction and offset entries are 0). "
        "Identification from energy needs no accelerations: h(t1) - h(t0) is the integral of "
        "(tau - friction) . qd dt along a motion. q: n_coords, qd: n_dofs; 2-D arrays (one state "
        "per row) give (rows, n_params). ModelError as joint_torque_regressor.");
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
