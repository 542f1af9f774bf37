// SPDX-License-Identifier: BSD-3-Clause
// Bindings of the joint-space algorithms (armdyn/algorithm/): armdyn.Data, forward_dynamics,
// inverse_dynamics, joint_reactions, mass_matrix and dynamics_cost. One state (1-D arrays) or one
// state per row (2-D arrays, evaluated in one C++ loop without the GIL). Without data=, each thread
// keeps one Data per model, so repeated calls allocate nothing but their output array (rows.hpp).
#include <pybind11/stl.h>

#include "armdyn/algorithm/cost_model.hpp"
#include "armdyn/algorithm/crba.hpp"
#include "armdyn/algorithm/dynamics.hpp"
#include "armdyn/algorithm/reactions.hpp"
#include "common.hpp"
#include "rows.hpp"

namespace armdyn {

namespace py = pybind11;
using namespace py_helpers;

namespace {

std::unique_ptr<DataPy> data_new(const ModelArg& model) {
  return std::make_unique<DataPy>(model_of(model, "Data"));
}

py::array_t<double> forward_dynamics_py(const ModelArg& model, const ArrayLike& q,
                                        const ArrayLike& qd, const ArrayLike& tau,
                                        const FloatOrArray& t, const StrArg& method,
                                        const OptData& data) {
  constexpr const char* fn = "forward_dynamics";
  const CallArgs a = call_args(model, data, fn);
  Data& d = a.data;
  const DynamicsMethod mth = dynamics_method(str_arg(method, fn, "method"), fn);
  // one state: f(q, qd, tau, t) with the checks of a call from outside
  auto one = [&](const auto& qi, const auto& qdi, const auto& ti, double tt) -> const VecX& {
    const auto in = {named_input("q", qi), named_input("qd", qdi), named_input("tau", ti)};
    const VecX& r = naming_huge_inputs(fn, in, [&]() -> const VecX& {
      return forward_dynamics(a.model(), d, qi, qdi, ti, tt, mth);
    });
    check_finite_output(fn, "qdd", r.data(), d.ni, in);
    return r;
  };
  if (is_batch(q))
    return batch(fn, d.niq, d.ni, q, qd, "qd", tau, "tau", t, {d.ni},
                 [&](auto qi, auto qdi, auto ti, double tt, double* out) {
                   const VecX& r = one(qi, qdi, ti, tt);
                   std::copy(r.data(), r.data() + d.ni, out);
                 });
  const VecArg qa(q, "q", d.niq), qda(qd, "qd", d.ni), ta(tau, "tau", d.ni);
  return vector_out(one(*qa, *qda, *ta, scalar_time(t, fn)));
}

py::array_t<double> inverse_dynamics_py(const ModelArg& model, const ArrayLike& q,
                                        const ArrayLike& qd, const ArrayLike& qdd,
                                        const FloatOrArray& t, const StrArg& method,
                                        const OptData& data) {
  constexpr const char* fn = "inverse_dynamics";
  const CallArgs a = call_args(model, data, fn);
  Data& d = a.data;
  const DynamicsMethod mth = dynamics_method(str_arg(method, fn, "method"), fn, false);
  auto one = [&](const auto& qi, const auto& qdi, const auto& ai, double tt) -> const VecX& {
    const VecX& r = inverse_dynamics(a.model(), d, qi, qdi, ai, tt, mth);
    check_finite_output(fn, "tau", r.data(), d.ni,
                        {named_input("q", qi), named_input("qd", qdi), named_input("qdd", ai)});
    return r;
  };
  if (is_batch(q))
    return batch(fn, d.niq, d.ni, q, qd, "qd", qdd, "qdd", t, {d.ni},
                 [&](auto qi, auto qdi, auto ai, double tt, double* out) {
                   const VecX& r = one(qi, qdi, ai, tt);
                   std::copy(r.data(), r.data() + d.ni, out);
                 });
  const VecArg qa(q, "q", d.niq), qda(qd, "qd", d.ni), aa(qdd, "qdd", d.ni);
  return vector_out(one(*qa, *qda, *aa, scalar_time(t, fn)));
}

// (forces, torques) from the reactions of one state (2, n_joints, 3) or of each row (rows, 2,
// n_joints, 3), batch: the latter
using ArrayPair = py::typing::Tuple<py::array_t<double>, py::array_t<double>>;

ArrayPair split_reactions(const py::array_t<double>& both, bool batch) {
  const long rows = batch ? static_cast<long>(both.shape(0)) : 1;
  const auto nj = static_cast<py::ssize_t>(both.shape(batch ? 2 : 1));
  std::vector<py::ssize_t> shape{nj, 3};
  if (batch) shape.insert(shape.begin(), rows);
  py::array_t<double> forces(shape), torques(shape);
  const long block = 3 * static_cast<long>(nj);
  const double* src = both.data();
  double *fo = forces.mutable_data(), *to = torques.mutable_data();
  for (long i = 0; i < rows; ++i) {
    std::copy(src + 2 * i * block, src + (2 * i + 1) * block, fo + i * block);
    std::copy(src + (2 * i + 1) * block, src + (2 * i + 2) * block, to + i * block);
  }
  return py::make_tuple(forces, torques);
}

ArrayPair joint_reactions_py(const ModelArg& model, const ArrayLike& q, const ArrayLike& qd,
                             const ArrayLike& qdd, const OptTimes& t, const OptData& data) {
  constexpr const char* fn = "joint_reactions";
  const CallArgs a = call_args(model, data, fn);
  Data& d = a.data;
  const auto nj = static_cast<py::ssize_t>(a.model().joints.size());
  const py::object tt = t.is_none() ? py::object(py::float_(0.0)) : py::object(t);
  // forces then torques of one state, each (n_joints, 3) row-major
  auto one = [&](const auto& qi, const auto& qdi, const auto& ai, double ti, double* out) {
    const auto in = {named_input("q", qi), named_input("qd", qdi), named_input("qdd", ai)};
    naming_huge_inputs(fn, in, [&]() {
      joint_reactions(a.model(), d, qi, qdi, ai, ti, out, out + 3 * nj);
      return 0;
    });
    check_finite_output(fn, "the reactions", out, 6 * nj, in);
  };
  if (is_batch(q)) {
    try {
      return split_reactions(batch(fn, d.niq, d.ni, q, qd, "qd", qdd, "qdd", tt, {2, nj, 3}, one),
                             true);
    } catch (PyInterrupted& e) {
      // Ctrl-C: the rows done, as (forces, torques) too
      const py::object err = e.err.value();
      err.attr("result") = split_reactions(err.attr("result").cast<py::array_t<double>>(), true);
      throw;
    }
  }
  const VecArg qa(q, "q", d.niq), qda(qd, "qd", d.ni), aa(qdd, "qdd", d.ni);
  py::array_t<double> both(std::vector<py::ssize_t>{2, nj, 3});
  one(*qa, *qda, *aa, scalar_time(tt, fn), both.mutable_data());
  return split_reactions(both, false);
}

py::array_t<double> mass_matrix_py(const ModelArg& model, const ArrayLike& q, const OptData& data) {
  constexpr const char* fn = "mass_matrix";
  const CallArgs a = call_args(model, data, fn);
  Data& d = a.data;
  const long n = d.ni;
  VecX q0;  // q with the floating bases moved to the origin (bases_at_origin)
  // M is symmetric: its column-major storage is also its row-major one
  auto one = [&](const auto& qi) -> const MatX& {
    const MatX& M = crba(a.model(), d, bases_at_origin(a.model(), qi, q0));
    check_finite_output(fn, "M (column-major)", M.data(), n * n, {named_input("q", qi)});
    return M;
  };
  if (is_batch(q))
    return batch(fn, d.niq, d.niq, q, q, "q", q, "q", py::float_(0.0), {n, n},
                 [&](auto qi, auto, auto, double, double* out) {
                   const MatX& M = one(qi);
                   std::copy(M.data(), M.data() + n * n, out);
                 });
  const VecArg qa(q, "q", d.niq);
  const MatX& M = one(*qa);
  py::array_t<double> out({n, n});
  std::copy(M.data(), M.data() + n * n, out.mutable_data());
  return out;
}

py::dict dynamics_cost_py(const ModelArg& model) {
  const DynamicsCost& c = dynamics_cost(*model_of(model, "dynamics_cost"));
  py::dict r;
  r["nb"] = c.nb;
  r["n"] = c.n;
  r["path"] = c.path;
  r["crba_us"] = c.crba;
  r["aba_us"] = c.aba;
  r["cartesian_us"] = c.cartesian;
  r["joint"] = method_key(c.joint);
  r["light"] = c.light;
  r["auto"] = method_key(c.best);
  r["joint_rhs_us"] = c.joint_rhs;
  r["cartesian_rhs_us"] = c.cartesian_rhs;
  r["simulate"] = c.joint_rhs_cheaper ? "joint" : "cartesian";
  return r;
}

}  // namespace

void bind_algorithm(py::module_& m) {
  py::class_<DataPy>(m, "Data",
                     "Workspace of one model's evaluations: every buffer forward_dynamics, "
                     "inverse_dynamics and mass_matrix write. One per thread; pass it as data= "
                     "to choose it explicitly (otherwise each thread keeps one per model).")
      .def(py::init(&data_new), py::arg("model"),
           "A workspace for `model` (an armdyn.Model); ModelError if model is None.")
      .def_property_readonly(
          "model", [](const DataPy& d) { return d.model; }, "The model this workspace serves.");

  m.def("forward_dynamics", &forward_dynamics_py, py::arg("model"), py::arg("q"), py::arg("qd"),
        py::arg("tau"), py::arg("t") = 0.0, py::arg("method") = "auto",
        py::arg("data") = py::none(),
        "Joint accelerations qdd of a tree for joint torques/forces tau at (q, qd) and time t "
        "[s] (q: n_coords, the others n_dofs; a coupled model's independent coordinates, "
        "followers of couplings removed, as Pinocchio's mimic=True models; 2-D: one state per "
        "row). method: 'crba' (CRBA mass matrix, recursive Newton-Euler bias, Cholesky), 'aba' "
        "(articulated-body algorithm, O(n)), 'cartesian' (the constrained Newton-Euler KKT "
        "system of the bodies), 'joint' (the cheaper of crba and aba for this model), 'auto' "
        "(the cheapest of the three); the choice comes from a measured cost model "
        "(dynamics_cost). The model's force elements act; drives are ignored. A model with closed "
        "loops or a fixed-base tree with ideal gears: its independent coordinates "
        "(model.coord_names), on the Cartesian formulation (method 'auto' or 'cartesian').");

  m.def("dynamics_cost", &dynamics_cost_py, py::arg("model"),
        "The measured cost model's prediction for a model (derived once per model): microseconds "
        "per forward_dynamics call by 'crba', 'aba' and 'cartesian', the algorithms "
        "method='joint' and method='auto' take, and the microseconds per right-hand side of "
        "simulate in joint space and in Cartesian coordinates with the formulation "
        "coordinates='auto' takes where both apply.");

  m.def("inverse_dynamics", &inverse_dynamics_py, py::arg("model"), py::arg("q"), py::arg("qd"),
        py::arg("qdd"), py::arg("t") = 0.0, py::arg("method") = "auto",
        py::arg("data") = py::none(),
        "Joint torques/forces tau realising qdd at (q, qd) and time t [s] (q: n_coords, the "
        "others n_dofs; a coupled model's independent coordinates, tau = G^T tau_full; 2-D: one "
        "state per row): what each joint's actuator applies to its child about/along the joint "
        "axis, gravity and the model's force elements included, drives ignored. method: 'joint' "
        "(recursive Newton-Euler), 'cartesian' (every coordinate driven, the drives' KKT "
        "multipliers), 'auto' (joint). A model with closed loops or a fixed-base tree with ideal "
        "gears: the torques on its independent "
        "coordinates (model.coord_names), driven_inverse_dynamics' drive forces with them driven "
        "(method 'auto' or 'cartesian').");

  m.def("joint_reactions", &joint_reactions_py, py::arg("model"), py::arg("q"), py::arg("qd"),
        py::arg("qdd"), py::arg("t") = py::none(), py::arg("data") = py::none(),
        "Every joint's reaction along a joint-space motion of a tree: (forces, torques), each "
        "(n_joints, 3) for one state (q: n_coords, qd and qdd: n_dofs; a coupled model's "
        "independent coordinates, as inverse_dynamics takes them) or (rows, n_joints, 3) for one "
        "state per row; t [s] a number, one per row, or None (0). The same quantity as "
        "SimulationResult.reaction_forces/reaction_torques: what the joint's constraint applies "
        "to its child at the joint point, in the child's joint frame, for every joint of the "
        "model (fixed joints included; zero for floating bases); the components about/along a "
        "joint's free axes are zero (the actuator's torque there is inverse_dynamics'). The "
        "joint torques are the inverse dynamics' (the motion is exactly the one given); gravity "
        "and the force elements act, drives are ignored.");

  m.def("mass_matrix", &mass_matrix_py, py::arg("model"), py::arg("q"),
        py::arg("data") = py::none(),
        "The joint-space mass matrix M(q) (n_dofs, n_dofs) of a tree, by the "
        "composite-rigid-body algorithm (a coupled model's in its independent coordinates, "
        "G^T M G; a model with closed loops' or a fixed-base tree with ideal gears' in its "
        "independent coordinates, T^T Gamma T with T the velocity map); 2-D q (one state per row) "
        "gives (rows, n, n).");
}

}  // namespace armdyn
