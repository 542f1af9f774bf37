// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/kkt.hpp"

#include <algorithm>
#include <cmath>

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

double constraint_residual(const ConstraintEval& ce, int nrows, const VecX& vd, double a_scale) {
  const double vmax = std::max(vd.cwiseAbs().maxCoeff(), a_scale);
  double worst = 0.0;
  for (const ConstraintBlock& blk : ce.blocks) {
    if (blk.row0 >= nrows) continue;
    for (int r = 0; r < blk.nrows; ++r) {
      const double xi = ce.xi[blk.row0 + r];
      double sum = xi, zsum = 0.0;
      for (int k = 0; k < blk.nbody; ++k) {
        if (blk.body[k] == kGround) continue;
        for (int c = 0; c < 6; ++c) {
          const double z = blk.J(r, 6 * k + c);
          sum += z * vd[6 * blk.body[k] + c];
          zsum += std::abs(z);
        }
      }
      const double size = zsum * vmax + std::abs(xi);
      if (size > 0.0) worst = std::max(worst, std::abs(sum) / size);
    }
  }
  return worst;
}

double load_acceleration_scale(const Model& m, const VecX& eta) {
  double a = 0.0;
  for (int i = 0; i < m.nb; ++i) {
    const double mass = m.bodies[i].mass;
    if (mass > 0.0) a = std::max(a, eta.segment<3>(6 * i).norm() / mass);
  }
  return std::isfinite(a) ? a : 0.0;
}

namespace {

// The augmented solve of d's loaded system (rows [0, nrows)), with a SolverError when it has no
// finite solution; the first one of a Data says why in the stats.
void solve_augmented(const Model& m, Data& d, double t, int nrows, const std::string& why) {
  PipelineStats& st = d.stats;
  if (!d.kkt.accelerations_augmented(d.ce, nrows, d.eta, d.vd_work, d.delta))
    throw SolverError(
        msg("the augmented constraint system is singular at t=", t,
            " (the joint-space mass matrix is not positive definite: a massless "
            "or inertia-less subtree?",
            light_bodies(m).bodies.empty() ? std::string(")") : "; " + light_bodies(m).note + ")"));
  if (st.augmented_solves++ == 0) st.augmented_note = why;
  ++st.factorizations;
  ++st.kkt_solves;
}

}  // namespace

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
  const LightBodies& light = *d.light;
  if (!light.bodies.empty() && !d.augmented && light.massless_only) {
    // massless bodies only ("virtual" links between joints): the floored range-space factor
    // refined against the exact system, O(n) per step; the augmented LU when it does not
    // converge (then for the rest of this Data's life)
    KktSolver& kkt = d.kkt;
    if (!(reuse_factor && kkt.reusable(nrows))) {
      kkt.factor(d.ce, nrows, Metric::Mass);
      ++st.factorizations;
    }
    int iterations = 0;
    if (kkt.accelerations_refined(d.ce, nrows, d.eta, d.vd_work, d.delta, 30, iterations)) {
      ++st.kkt_solves;
      vd = d.vd_work;
      return;
    }
    d.augmented = true;
    solve_augmented(
        m, d, t, nrows,
        msg("at t=", t,
            " the refined range-space solve of the massless bodies did not "
            "converge in ",
            iterations, " steps (", light.note, "): solved in augmented form from there on"));
    vd = d.vd_work;
    return;
  }
  if (!light.bodies.empty() || d.augmented) {
    // no Gamma^-1: light bodies (known from the model), or a range-space solve on this Data
    // that lost accuracy
    solve_augmented(m, d, t, nrows, light.bodies.empty() ? st.augmented_note : light.note);
    vd = d.vd_work;
    return;
  }
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
  const bool kkt_current = reuse_factor && kkt.reusable(nrows);
  if (!kkt_current && d.artic.ok()) {
    // a tree (ideal gears, couplings and a few drives as extra rows): the articulated-body
    // recursions over the Cartesian coordinates, O(n), no KKT factorisation
    const bool reuse = reuse_factor && d.artic.factored(nrows, kkt.factor_count());
    if (d.artic.solve(m, d.kin, d.ce, nrows, d.eta, d.vd_work, d.delta, reuse, kkt.factor_count(),
                      d.multipliers)) {
      ++st.kkt_solves;
      ++st.articulated_solves;
      d.swept = true;
      kkt.mark_stale();
      vd = d.vd_work;
      return;
    }
  }
  if (!kkt_current) {
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
  // never silently wrong: the range-space solve forms Gamma^-1, and a body whose inertia is small
  // against the constraint forces on it costs accuracy that shows in zeta vdot = -xi (exact
  // arithmetic holds it; round-off leaves 1e-16 of the terms' sizes; mass and gear ratios a few
  // digits more: the geared arm reaches 2e-10 at gear contact). Beyond 1e-8 the
  // augmented solve takes over for the rest of this Data's life. (Not near a singular
  // configuration, where the regularised factor leaves a residual on purpose.)
  if (!kkt.near_singular() && !kkt.used_pseudo_inverse()) {
    // (against the loads' accelerations too: at rest, under gravity, the solve's accelerations
    // are round-off of g's, and relative to their own size that read as a lost solve)
    const double res =
        constraint_residual(d.ce, nrows, d.vd_work, load_acceleration_scale(m, d.eta));
    if (res > 1e-8) {
      d.augmented = true;
      solve_augmented(
          m, d, t, nrows,
          msg("at t=", t, " the range-space solve left a relative constraint residual ", res,
              " (bodies light against their constraint forces): solved in "
              "augmented form (LU of [Gamma zeta^T; zeta 0]) from there on"));
    }
  }
  vd = d.vd_work;
}

MatX cartesian_mass_matrix(const Model& m) {
  MatX g = MatX::Zero(m.nv, m.nv);
  for (int i = 0; i < m.nb; ++i) {
    g.block<3, 3>(6 * i, 6 * i) = m.bodies[i].mass * Mat3::Identity();
    g.block<3, 3>(6 * i + 3, 6 * i + 3) = m.bodies[i].inertia;
  }
  return g;
}

}  // namespace armdyn
