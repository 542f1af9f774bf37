// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/kkt.hpp"

#include "armdyn/algorithm/constraints.hpp"
#include "armdyn/algorithm/forces.hpp"
#include "armdyn/algorithm/kinematics.hpp"
#include "armdyn/errors.hpp"

namespace armdyn {

std::string dependent_row_names(const Model& m, const Data& d) {
  std::string rows;
  for (int r : d.kkt.dependent_rows()) rows += (rows.empty() ? "" : "; ") + m.row_name(r);
  return rows;
}

void body_accelerations(const Model& m, Data& d, double t, const double* u, const double* v,
                        double* vdot, bool reuse_factor) {
  load_kinematics(m, d, u, v);
  body_accelerations_loaded(m, d, t, vdot, reuse_factor);
}

void body_accelerations_loaded(const Model& m, Data& d, double t, double* vdot, bool reuse_factor) {
  evaluate_constraints(m, d, t, true);
  cartesian_forces(m, d, t);
  Eigen::Map<VecX> vd(vdot, m.nv);
  const int nrows = d.nrows;
  PipelineStats& st = d.stats;
  d.swept = false;
  if (d.sweep.ok() && nrows == m.nc) {
    // square zeta of a fully driven tree: two O(n) sweeps, no KKT factorisation
    d.swept = d.sweep.solve(m, d.ce, d.eta, d.vd_work, d.delta);
    if (d.swept) {
      ++st.factorizations;
      ++st.kkt_solves;
      vd = d.vd_work;
      return;
    }
  }
  KktSolver& kkt = d.kkt;
  if (!(reuse_factor && kkt.metric() == Metric::Mass && kkt.nrows() == nrows)) {
    kkt.factor(d.ce, nrows, Metric::Mass);
    ++st.factorizations;
  }
  if (kkt.used_pseudo_inverse()) {
    const int expected = nrows == m.nc ? m.rank_all : m.rank_joint;
    if (kkt.rank() < expected) {
      if (st.singular_evaluations++ == 0) {
        st.singular_note =
            msg("singular configuration at t=", t, ": constraint rank ", kkt.rank(), " instead of ",
                expected, "; dependent rows: ", dependent_row_names(m, d));
      }
    }
  }
  kkt.accelerations(d.ce, d.eta, d.vd_work, d.delta);
  ++st.kkt_solves;
  if (!d.vd_work.allFinite())
    throw SolverError(msg("non-finite accelerations at t=", t,
                          " (singular constraint Jacobian or invalid state)"));
  vd = d.vd_work;
}

}  // namespace armdyn
