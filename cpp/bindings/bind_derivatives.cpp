// SPDX-License-Identifier: BSD-3-Clause
// Bindings of the dynamics' first-order derivatives (armdyn/algorithm/derivatives.hpp):
// inverse_dynamics_derivatives and forward_dynamics_derivatives, one state (1-D arrays) or one
// state per row (2-D arrays, one C++ loop without the GIL), as inverse_dynamics and
// forward_dynamics take them (rows.hpp).
#include <pybind11/stl.h>

#include <array>
#include <cstdlib>
#include <new>
#include <vector>

#include "armdyn/algorithm/derivatives.hpp"
#include "common.hpp"
#include "output_pool.hpp"
#include "rows.hpp"

namespace armdyn {

namespace py = pybind11;
using namespace py_helpers;

namespace {

using ArrayPair = py::typing::Tuple<py::array_t<double>, py::array_t<double>>;
using ArrayTriple =
    py::typing::Tuple<py::array_t<double>, py::array_t<double>, py::array_t<double>>;

// k matrices row-major into out[j] + offset, each checked finite (vectorised; the element-wise
// check names the entry)
void write_matrices(const char* fn, std::initializer_list<std::pair<const char*, const MatX*>> ms,
                    std::initializer_list<NamedInput> in, double* const* out, long offset) {
  for (const auto& [name, x] : ms) {
    if (!x->allFinite()) check_finite_output(fn, name, x->data(), x->size(), in);
    copy_row_major(*x, *out++ + offset);
  }
}

// the k matrices (n, n) of one state, or (rows, n, n) each of one state per row, from
// one(q_i, a_i, b_i, t_i, outputs, offset of row i): written straight into their arrays (batch()
// then makes no output of its own); a Ctrl-C's partial result is the rows done
template <class Fn>
py::tuple matrices_call(const char* fn, Data& d, int k, const py::handle& q, const py::handle& a,
                        const char* an, const py::handle& b, const char* bn, const py::handle& t,
                        Fn&& one) {
  const long n = d.ni;
  // (at most 3 outputs: no vectors of them to allocate per call)
  std::array<py::object, 3> outs;  // (py::object: no empty array made first)
  std::array<double*, 3> ptrs{};
  const bool rows_given = is_batch(q);
  const long rows =
      rows_given ? static_cast<long>(py::reinterpret_borrow<py::array>(q).shape(0)) : 1;
  const std::vector<py::ssize_t> shape =
      rows_given ? std::vector<py::ssize_t>{rows, n, n} : std::vector<py::ssize_t>{n, n};
  for (int j = 0; j < k; ++j) {
    py::array_t<double> out = OutputPool::get().array(shape);
    ptrs[j] = out.mutable_data();
    outs[j] = std::move(out);
  }
  auto result = [&](long done) {
    py::tuple r(k);
    for (int j = 0; j < k; ++j)
      r[j] = rows_given && done < rows ? py::object(outs[j][py::slice(0, done, 1)])
                                       : py::object(outs[j]);
    return r;
  };
  if (!rows_given) {
    const VecArg qa(q, "q", d.niq), aa(a, an, n), ba(b, bn, n);
    one(*qa, *aa, *ba, scalar_time(t, fn), ptrs.data(), 0);
    return result(1);
  }
  long row = 0;
  try {
    batch(fn, d.niq, n, q, a, an, b, bn, t, {0},
          [&](auto qi, auto ai, auto bi, double tt, double*) {
            one(qi, ai, bi, tt, ptrs.data(), row * n * n);
            ++row;
          });
  } catch (PyInterrupted& e) {
    e.err.value().attr("result") = result(row);
    throw;
  }
  return result(rows);
}

ArrayPair inverse_dynamics_derivatives_py(const ModelArg& model, const ArrayLike& q,
                                          const ArrayLike& qd, const ArrayLike& qdd,
                                          const FloatOrArray& t, const OptData& data) {
  constexpr const char* fn = "inverse_dynamics_derivatives";
  const CallArgs a = call_args(model, data, fn);
  Data& d = a.data;
  auto one = [&](const auto& qi, const auto& qdi, const auto& ai, double tt, double* const* out,
                 long offset) {
    const auto in = {named_input("q", qi), named_input("qd", qdi), named_input("qdd", ai)};
    naming_huge_inputs(fn, in, [&]() {
      inverse_dynamics_derivatives(a.model(), d, qi, qdi, ai, tt);
      return 0;
    });
    write_matrices(
        fn,
        {{"dtau_dq (column-major)", &d.deriv.tau_q}, {"dtau_dqd (column-major)", &d.deriv.tau_qd}},
        in, out, offset);
  };
  return matrices_call(fn, d, 2, q, qd, "qd", qdd, "qdd", t, one);
}

ArrayTriple forward_dynamics_derivatives_py(const ModelArg& model, const ArrayLike& q,
                                            const ArrayLike& qd, const ArrayLike& tau,
                                            const FloatOrArray& t, const OptData& data) {
  constexpr const char* fn = "forward_dynamics_derivatives";
  const CallArgs a = call_args(model, data, fn);
  Data& d = a.data;
  auto one = [&](const auto& qi, const auto& qdi, const auto& ti, double tt, double* const* out,
                 long offset) {
    const auto in = {named_input("q", qi), named_input("qd", qdi), named_input("tau", ti)};
    naming_huge_inputs(fn, in, [&]() {
      forward_dynamics_derivatives(a.model(), d, qi, qdi, ti, tt);
      return 0;
    });
    write_matrices(fn,
                   {{"dqdd_dq (column-major)", &d.deriv.qdd_q},
                    {"dqdd_dqd (column-major)", &d.deriv.qdd_qd},
                    {"dqdd_dtau (column-major)", &d.deriv.qdd_tau}},
                   in, out, offset);
  };
  return matrices_call(fn, d, 3, q, qd, "qd", tau, "tau", t, one);
}

}  // namespace

void bind_derivatives(py::module_& m) {
  m.def("inverse_dynamics_derivatives", &inverse_dynamics_derivatives_py, py::arg("model"),
        py::arg("q"), py::arg("qd"), py::arg("qdd"), py::arg("t") = 0.0,
        py::arg("data") = py::none(),
        "The first-order derivatives (dtau_dq, dtau_dqd) of inverse_dynamics at (q, qd, qdd) and "
        "time t [s], each (n_dofs, n_dofs) for one state (q: n_coords, qd and qdd: n_dofs; a "
        "coupled model's independent coordinates) or (rows, n_dofs, n_dofs) for one state per "
        "row (2-D arrays; t a number or one per row). Analytical (the recursive Newton-Euler "
        "derivatives of Carpentier & Mansard 2018), gravity, gyroscopic terms and the model's "
        "force elements included, drives ignored. q-derivatives are taken along the "
        "coordinates' rates: column k of dtau_dq is d tau(q + eps e_k) / d eps for a joint "
        "coordinate, and for a floating base's six columns the derivative along its qd block "
        "(the base frame moved by its own linear and angular velocity in its axes, Pinocchio's "
        "free-flyer convention). dtau/dqdd is mass_matrix(model, q).");
  m.def("forward_dynamics_derivatives", &forward_dynamics_derivatives_py, py::arg("model"),
        py::arg("q"), py::arg("qd"), py::arg("tau"), py::arg("t") = 0.0,
        py::arg("data") = py::none(),
        "The first-order derivatives (dqdd_dq, dqdd_dqd, dqdd_dtau) of forward_dynamics at (q, "
        "qd, tau) and time t [s], each (n_dofs, n_dofs) for one state or (rows, n_dofs, n_dofs) "
        "for one state per row, as inverse_dynamics_derivatives takes them: qdd = "
        "M^-1 (tau - b) by the composite-rigid-body mass matrix and a factor of it (L^T D L "
        "without fill-in on a model without couplings, else Cholesky), then "
        "dqdd_dq = -M^-1 dtau_dq and dqdd_dqd = -M^-1 dtau_dqd at that qdd, dqdd_dtau = M^-1 "
        "(q-derivatives along the coordinates' rates, a floating base's along its qd block). "
        "ModelError for a model with light bodies, whose mass matrix about the world origin "
        "loses them.");
}

}  // namespace armdyn
