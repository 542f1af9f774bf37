// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/projection.hpp"

#include <cmath>
#include <cstdio>

#include "armdyn/algorithm/constraints.hpp"
#include "armdyn/algorithm/kinematics.hpp"
#include "armdyn/algorithm/kkt.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/math/quaternion.hpp"

namespace armdyn {

namespace {
std::string short_number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", x);
  return buf;
}
}  // namespace

namespace {
// the residual left by rows aligned to 1e-6 (finalize's rank threshold) over a length scale
constexpr double kAlignedResidual = 1e-6;
}  // namespace

void project(const Model& m, Data& d, double t, double* u, double* v, Metric metric) {
  Eigen::Map<VecX> um(u, m.nq), vm(v, m.nv);
  const int nrows = d.nrows;
  ConstraintEval& ce = d.ce;
  KktSolver& kkt = d.kkt;
  PipelineStats& st = d.stats;
  // quaternions onto the unit sphere (the normalisation rows are not part of zeta)
  for (int i = 0; i < m.nb; ++i) {
    auto e = um.segment<4>(7 * i + 3);
    const double n = e.norm();
    if (!(n > 0.0) || !std::isfinite(n))
      throw SolverError(msg("invalid Euler parameters of body '", m.bodies[i].name, "' at t=", t));
    e /= n;
  }
  // (a run in time: the angles' references moved on by their rates first)
  advance_tracking(m, d, t);
  load_kinematics(m, d, u, nullptr);
  evaluate_constraints(m, d, t, false);
  double rf = nrows ? ce.f.head(nrows).cwiseAbs().maxCoeff() : 0.0;
  if (!std::isfinite(rf)) throw SolverError(msg("non-finite constraint residual at t=", t));
  if (rf > d.tol_f) {
    // simplified Newton: minimum-norm steps w = -W^-1 zeta^T A^-1 f, Jacobian refreshed when slow
    ++st.position_projections;
    kkt.factor(ce, nrows, metric);
    ++st.factorizations;
    double rprev = rf;
    int it = 0;
    for (; it < 30 && rf > d.tol_f; ++it) {
      kkt.solve_schur(ce.f, d.mu);
      zeta_transpose_times(ce, nrows, d.mu, d.tmp_nv);
      kkt.apply_winv(d.tmp_nv, d.vd_work);
      for (int i = 0; i < m.nb; ++i) {
        um.segment<3>(7 * i) -= d.vd_work.segment<3>(6 * i);
        const Vec4 e = um.segment<4>(7 * i + 3);
        um.segment<4>(7 * i + 3) =
            quat_mul(e, quat_exp(-d.vd_work.segment<3>(6 * i + 3))).normalized();
      }
      load_kinematics(m, d, u, nullptr);
      evaluate_constraints(m, d, t, false);
      rf = ce.f.head(nrows).cwiseAbs().maxCoeff();
      ++st.newton_iterations;
      if (!std::isfinite(rf)) break;
      // rows that finalize() took as dependent though they agree only to round-off (axes
      // aligned to 1e-6, builder/finalize.cpp) cannot all hold: the minimum-norm step then
      // vanishes at their least-squares point, whose residual is that misalignment
      if (!m.aligned_rows.empty() &&
          d.vd_work.cwiseAbs().maxCoeff() < 1e-12 * std::max(1.0, m.length_scale) &&
          rf < kAlignedResidual * std::max(1.0, m.length_scale))
        break;
      if (rf > 0.25 * rprev) {
        // slow contraction: stop when it stagnates at round-off, otherwise refresh the Jacobian
        if (rf >= rprev && rf < 1e-10 * std::max(1.0, m.length_scale)) break;
        kkt.factor(ce, nrows, metric);
        ++st.factorizations;
      }
      rprev = rf;
    }
    const double accept = m.aligned_rows.empty() ? 1e-9 : kAlignedResidual;
    if (!(rf < accept * std::max(1.0, m.length_scale))) {
      int worst = 0;
      ce.f.head(nrows).cwiseAbs().maxCoeff(&worst);
      throw SolverError(msg("position projection did not converge at t=", t, ": |f| = ", rf,
                            ", largest at ", m.row_name(worst)));
    }
  }
  // velocities onto zeta v = rhs, with A at the final u
  load_kinematics(m, d, u, v);
  commit_tracking(m, d, t);
  if (nrows == 0) return;
  kkt.factor(ce, nrows, metric);
  ++st.factorizations;
  zeta_times(ce, nrows, vm, d.tmp_nc);
  d.tmp_nc.head(nrows) -= ce.rhs.head(nrows);
  kkt.solve_schur(d.tmp_nc, d.mu);
  zeta_transpose_times(ce, nrows, d.mu, d.tmp_nv);
  kkt.apply_winv(d.tmp_nv, d.vd_work);
  vm -= d.vd_work;
  ++st.velocity_projections;
}

void residuals(const Model& m, Data& d, double t, const double* u, const double* v, double& rf,
               double& rv) {
  load_kinematics(m, d, u, v);
  evaluate_constraints(m, d, t, false);
  loaded_residuals(m, d, v, rf, rv);
}

void loaded_residuals(const Model& m, Data& d, const double* v, double& rf, double& rv) {
  const int nrows = d.nrows;
  if (nrows == 0) {
    rf = rv = 0.0;
    return;
  }
  rf = d.ce.f.head(nrows).cwiseAbs().maxCoeff();
  Eigen::Map<const VecX> vm(v, m.nv);
  zeta_times(d.ce, nrows, vm, d.tmp_nc);
  rv = (d.tmp_nc.head(nrows) - d.ce.rhs.head(nrows)).cwiseAbs().maxCoeff();
}

std::string diagnose_singularity(const Model& m, Data& d, double t, const double* u,
                                 const double* v, double threshold) {
  load_kinematics(m, d, u, v);
  evaluate_constraints(m, d, t, false);
  KktSolver& kkt = d.kkt;
  kkt.factor_pivoted_at(d.ce, d.nrows, Metric::Mass, threshold);
  const int expected = d.nrows == m.nc ? m.rank_all : m.rank_joint;
  if (kkt.rank() >= expected) return "";
  return msg("the constraint Jacobian is nearly singular at t=", t, " (rank ", kkt.rank(), " of ",
             expected, " at a ", short_number(threshold),
             " threshold); nearly dependent rows: ", dependent_row_names(m, d));
}

}  // namespace armdyn
