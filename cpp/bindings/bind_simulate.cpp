// SPDX-License-Identifier: BSD-3-Clause
// Bindings of whole runs (armdyn/simulate/): _simulate, _rollout (a batch on C++ threads) and
// _output_row_bytes, which armdyn.simulate and armdyn.rollout call, and the result schema
// (results.hpp). The GIL is released during runs; Ctrl-C and progress callables are polled.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <chrono>

#include "armdyn/simulate/batch.hpp"
#include "armdyn/simulate/simulate.hpp"
#include "common.hpp"
#include "results.hpp"

namespace armdyn {

namespace py = pybind11;
using namespace py_helpers;

namespace {

using RowsArg = py::array_t<double, py::array::c_style>;

// The simulate options common to _simulate and _rollout (armdyn.simulation._sim_args builds
// the Python side of both).
#define ARMDYN_SIM_OPTION_ARGS                                                          \
  integrator, rtol, atol, dt, output_dt, projection, max_steps, max_step, merge_welded, \
      coordinates, limits, restitution

py::dict simulate_py(const Model& md, double t_end, const std::string& integrator, double rtol,
                     double atol, double dt, double output_dt, const OptArrayLike& u0,
                     const OptArrayLike& v0, const std::string& projection, long max_steps,
                     double max_step, bool merge_welded, const std::string& coordinates,
                     const OptArrayLike& q_start, bool limits, double restitution,
                     const OptProgress& progress) {
  // armdyn.simulate answers a model with no bodies itself (nothing to integrate)
  if (md.nb == 0) throw ModelError("_simulate: the model has no bodies (use armdyn.simulate)");
  SimulateGuard guard("simulate");
  SimOptions o = sim_options(ARMDYN_SIM_OPTION_ARGS);
  if (!q_start.is_none())
    o.q_start = q_start_from_independent(md, to_vec(q_start, "q0", md.independent.nq()));
  const VecX u = u0.is_none() ? md.u0 : to_vec(u0, "u0", md.nq);
  const VecX v = v0.is_none() ? md.v0 : to_vec(v0, "v0", md.nv);
  Poll poll = python_poll(&progress);
  o.step.poll = &poll;
  SimResult r;
  {
    py::gil_scoped_release release;
    r = simulate(md, t_end, o, u, v);
  }
  py::dict d = sim_result_dict(md, r);
  add_run_exception(r, d);
  return d;
}

/// The rows of a (runs, cols) array argument as vectors; ModelError "rollout: name must have
/// shape (runs, cols), got ..." (runs < 0: any number of rows).
std::vector<VecX> rollout_rows(const RowsArg& a, const char* name, long runs, long cols) {
  if (a.ndim() != 2 || (runs >= 0 && a.shape(0) != runs) || a.shape(1) != cols)
    throw ModelError(msg("rollout: ", name, " must have shape (",
                         runs >= 0 ? std::to_string(runs) : std::string("n_runs"), ", ", cols,
                         "), got ", shape_str(a)));
  std::vector<VecX> rows(a.shape(0));
  for (long k = 0; k < static_cast<long>(rows.size()); ++k)
    rows[k] = Eigen::Map<const VecX>(a.data(k, 0), cols);
  return rows;
}

/// The batch's wait on the caller's thread (simulate_batch): with the GIL, the signal handlers
/// (Ctrl-C) and every 0.1 s progress(done, n); a Python exception from either stops the batch
/// and is kept in `interrupt`.
BatchWait rollout_wait(const OptProgress& progress, long n, py::object& interrupt) {
  auto last_report =
      std::make_shared<std::chrono::steady_clock::time_point>(std::chrono::steady_clock::now());
  return [&progress, n, &interrupt, last_report](long done) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) {
      py::error_already_set e;  // fetches (and clears) the handler's exception
      interrupt = e.value();
      return true;
    }
    if (progress.is_none()) return false;
    const auto now = std::chrono::steady_clock::now();
    if (std::chrono::duration<double>(now - *last_report).count() < 0.1) return false;
    *last_report = now;
    try {
      progress(done, n);
    } catch (py::error_already_set& e) {
      interrupt = e.value();
      return true;
    }
    return false;
  };
}

auto rollout_py(const Model& md, double t_end, const std::string& integrator, double rtol,
                double atol, double dt, double output_dt, const RowsArg& u0, const RowsArg& v0,
                const std::string& projection, long max_steps, double max_step, bool merge_welded,
                const std::string& coordinates, const OptArrayLike& q_start, bool limits,
                double restitution, std::vector<std::string> errors, int threads,
                const OptProgress& progress) {
  if (md.nb == 0) throw ModelError("_rollout: the model has no bodies (use armdyn.rollout)");
  const SimOptions base = sim_options(ARMDYN_SIM_OPTION_ARGS);
  BatchRuns runs;
  runs.u0 = rollout_rows(u0, "u0", -1, md.nq);
  const long n = static_cast<long>(runs.u0.size());
  runs.v0 = rollout_rows(v0, "v0", n, md.nv);
  if (static_cast<long>(errors.size()) != n)
    throw ModelError(msg("rollout: ", errors.size(), " error entries for ", n, " runs"));
  if (threads < 1) throw ModelError(msg("rollout: threads must be >= 1, got ", threads));
  if (!q_start.is_none())
    runs.q_start = rollout_rows(q_start.cast<RowsArg>(), "q0", n, md.independent.nq());
  runs.errors = std::move(errors);
  py::object interrupt = py::none();
  const BatchWait wait = rollout_wait(progress, n, interrupt);
  std::vector<SimResult> results;
  {
    py::gil_scoped_release release;
    results = simulate_batch(md, t_end, base, std::move(runs), threads, wait);
  }
  py::list out;
  for (const SimResult& r : results) out.append(sim_result_dict(md, r));
  return py::make_tuple(out, interrupt);
}

#undef ARMDYN_SIM_OPTION_ARGS

}  // namespace

void bind_simulate(py::module_& m) {
  m.def("_simulate", &simulate_py, py::arg("model"), py::arg("t_end"), py::arg("integrator"),
        py::arg("rtol"), py::arg("atol"), py::arg("dt"), py::arg("output_dt"), py::arg("u0"),
        py::arg("v0"), py::arg("projection"), py::arg("max_steps"), py::arg("max_step") = 0.0,
        py::arg("merge_welded") = true, py::arg("coordinates") = "cartesian",
        py::arg("q_start") = py::none(), py::arg("limits") = true, py::arg("restitution") = 0.0,
        py::arg("progress") = py::none());

  m.def("_output_row_bytes", &output_row_bytes, py::arg("model"),
        "Bytes of one output time of simulate (every table's row, the limit forces counted for "
        "every joint): the bound armdyn.simulate checks an output_dt run against.");

  m.def("_rollout", &rollout_py, py::arg("model"), py::arg("t_end"), py::arg("integrator"),
        py::arg("rtol"), py::arg("atol"), py::arg("dt"), py::arg("output_dt"), py::arg("u0"),
        py::arg("v0"), py::arg("projection"), py::arg("max_steps"), py::arg("max_step"),
        py::arg("merge_welded"), py::arg("coordinates"), py::arg("q_start"), py::arg("limits"),
        py::arg("restitution"), py::arg("errors"), py::arg("threads"),
        py::arg("progress") = py::none(),
        "Runs of simulate from each row of u0/v0 (q_start: the joint-space q0 rows, or None) on "
        "`threads` C++ threads, the GIL released; (list of result dicts, the interrupting "
        "exception or None). A run whose `errors` entry is non-empty is not run; a run that "
        "raises has its message in its dict's 'error'.");

  add_result_schema(m);
}

}  // namespace armdyn
