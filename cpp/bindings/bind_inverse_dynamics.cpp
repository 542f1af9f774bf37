// SPDX-License-Identifier: BSD-3-Clause
// Binding of driven inverse dynamics (armdyn/algorithm/driven_inverse_dynamics.hpp):
// _inverse_dynamics_driven, which armdyn.driven_inverse_dynamics calls; the GIL is released and
// Ctrl-C polled. And the private _force_element_derivatives
// (armdyn/algorithm/force_derivatives.hpp), which the tests check against finite differences of
// inverse_dynamics.
#include <pybind11/stl.h>

#include "armdyn/algorithm/driven_inverse_dynamics.hpp"
#include "armdyn/algorithm/force_derivatives.hpp"
#include "armdyn/kernels/joint_space.hpp"
#include "common.hpp"
#include "results.hpp"
#include "rows.hpp"

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

using MatrixPair = py::typing::Tuple<py::array_t<double>, py::array_t<double>>;

py::array_t<double> matrix_out(const MatX& a) {
  py::array_t<double> out({a.rows(), a.cols()});
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      out.mutable_data(), a.rows(), a.cols()) = a;
  return out;
}

// the force elements' generalised force's derivatives at one state, in the coordinates
// inverse_dynamics takes (a coupled model's independent ones: G^T dF G)
MatrixPair force_element_derivatives_py(const ModelArg& model, const ArrayLike& q,
                                        const ArrayLike& qd, const FloatArg& t) {
  constexpr const char* fn = "_force_element_derivatives";
  const CallArgs a = call_args(model, py::none(), fn);
  const Model& m = a.model();
  Data& d = a.data;
  require_joint_space(m, fn, true);
  const double tt = float_arg(t, fn, "t");
  if (!std::isfinite(tt)) throw ModelError(msg(fn, ": t is not finite"));
  const VecArg qa(q, "q", d.niq), qda(qd, "qd", d.ni);
  check_joint_vector(*qa, d.niq, fn, "q");
  check_joint_vector(*qda, d.ni, fn, "qd");
  check_base_quaternions(m, *qa, fn);
  VecX qf(d.nq), qdf(d.n);
  m.independent.expand_q((*qa).data(), qf.data());
  m.independent.expand_v((*qda).data(), qdf.data());
  MatX dq = MatX::Zero(d.n, d.n), dqd = MatX::Zero(d.n, d.n);
  {
    py::gil_scoped_release nogil;
    joint_space_kinematics(m, qf, qdf, d.kin, d.rne);
    add_force_element_derivatives(m, d, qf.data(), qdf.data(), tt, dq, dqd);
  }
  if (!dq.allFinite() || !dqd.allFinite())
    throw SolverError(msg(fn, ": non-finite derivative at t=", tt));
  if (d.ni == d.n) return py::make_tuple(matrix_out(dq), matrix_out(dqd));
  MatX rq(d.ni, d.ni), rqd(d.ni, d.ni);
  m.independent.reduce(dq, rq);
  m.independent.reduce(dqd, rqd);
  return py::make_tuple(matrix_out(rq), matrix_out(rqd));
}

}  // namespace

void bind_inverse_dynamics(py::module_& m) {
  m.def("_inverse_dynamics_driven", &inverse_dynamics_driven_py, py::arg("model"), py::arg("t"));
  m.def("_force_element_derivatives", &force_element_derivatives_py, py::arg("model"), py::arg("q"),
        py::arg("qd"), py::arg("t") = 0.0,
        "(dF_dq, dF_dqd), each (n_dofs, n_dofs): the derivatives of the generalised force F of "
        "the model's force elements (body loads, spring-dampers, coordinate forces, gear pairs; "
        "F = inverse_dynamics of the model without them - inverse_dynamics with them) at (q, "
        "qd) and time t, q-derivatives along the rates (a floating base's along qd's base-frame "
        "velocity), integral states zero (a coupled model's in its independent coordinates: "
        "G^T dF G). Private: the tests' and part deriv's check of the C++ function.");
}

}  // namespace armdyn
