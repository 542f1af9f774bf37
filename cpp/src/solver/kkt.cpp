// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/solver/kkt.hpp"

#include <Eigen/LU>

#include "armdyn/errors.hpp"

namespace armdyn {

KktSolver::KktSolver(const Model& m)
    : m_(m),
      A_(MatX::Zero(m.nc, m.nc)),
      llt_(m.nc),
      cod_(m.nc, m.nc),
      tmp_nv_(VecX::Zero(m.nv)),
      tmp_nc_(VecX::Zero(m.nc)),
      b_(VecX::Zero(m.nc)) {
  minv_.resize(m.nb);
  for (int i = 0; i < m.nb; ++i) {
    minv_[i].setZero();
    minv_[i].topLeftCorner<3, 3>() = Mat3::Identity() / m.bodies[i].mass;
    minv_[i].bottomRightCorner<3, 3>() = m.bodies[i].inertia.inverse();
  }
}

void KktSolver::factor(const ConstraintEval& ce, int nrows, Metric metric) {
  nrows_ = nrows;
  metric_ = metric;
  pinv_ = false;
  rank_ = nrows;
  if (nrows == 0) return;
  auto A = A_.topLeftCorner(nrows, nrows);
  A.setZero();
  // A = sum over bodies of zeta_b W_b^-1 zeta_b^T, only between row blocks sharing a body
  Eigen::Matrix<double, 6, 6> w;
  Eigen::Matrix<double, Eigen::Dynamic, 6, 0, 6, 6> jw;
  for (int b = 0; b < m_.nb; ++b) {
    const auto& list = ce.body_blocks[b];
    if (metric == Metric::Mass) w = minv_[b];
    for (const auto& [g, sg] : list) {
      const ConstraintBlock& bg = ce.blocks[g];
      if (bg.row0 >= nrows) continue;
      if (metric == Metric::Mass)
        jw.noalias() = bg.J.middleCols<6>(6 * sg) * w;
      else
        jw = bg.J.middleCols<6>(6 * sg);
      for (const auto& [h, sh] : list) {
        const ConstraintBlock& bh = ce.blocks[h];
        if (bh.row0 >= nrows) continue;
        A.block(bg.row0, bh.row0, bg.nrows, bh.nrows).noalias() +=
            jw * bh.J.middleCols<6>(6 * sh).transpose();
      }
    }
  }
  // Cholesky unless the model is known redundant or the factor shows a (near-)zero pivot
  bool use_cod = m_.redundant;
  if (!use_cod) {
    llt_.compute(A);
    if (llt_.info() != Eigen::Success) {
      use_cod = true;
    } else {
      const double maxd = A.diagonal().cwiseAbs().maxCoeff();
      const double minl = llt_.matrixLLT().diagonal().cwiseAbs2().minCoeff();
      if (!(minl > 1e-12 * maxd)) use_cod = true;
    }
  }
  if (use_cod) {
    cod_.setThreshold(1e-10);
    cod_.compute(A);
    pinv_ = true;
    rank_ = static_cast<int>(cod_.rank());
  }
}

void KktSolver::solve_schur(const VecX& b, VecX& x) const {
  if (nrows_ == 0) return;
  if (pinv_) {
    x.head(nrows_) = cod_.solve(b.head(nrows_));
  } else {
    // in place, so that the Cholesky path allocates nothing
    auto xh = x.head(nrows_);
    xh = b.head(nrows_);
    llt_.solveInPlace(xh);
  }
}

void KktSolver::apply_winv(const VecX& y, VecX& x) const {
  if (metric_ == Metric::Identity) {
    x = y;
    return;
  }
  for (int b = 0; b < m_.nb; ++b) x.segment<6>(6 * b).noalias() = minv_[b] * y.segment<6>(6 * b);
}

void KktSolver::accelerations(const ConstraintEval& ce, const VecX& eta, VecX& vdot, VecX& delta) {
  // a = Gamma^-1 eta; delta = A^-1 (zeta a + xi); vdot = a - Gamma^-1 zeta^T delta
  for (int b = 0; b < m_.nb; ++b)
    vdot.segment<6>(6 * b).noalias() = minv_[b] * eta.segment<6>(6 * b);
  delta.setZero();
  if (nrows_ == 0) return;
  zeta_times(ce, nrows_, vdot, b_);
  b_.head(nrows_) += ce.xi.head(nrows_);
  solve_schur(b_, delta);
  zeta_transpose_times(ce, nrows_, delta, tmp_nv_);
  for (int b = 0; b < m_.nb; ++b)
    vdot.segment<6>(6 * b).noalias() -= minv_[b] * tmp_nv_.segment<6>(6 * b);
}

}  // namespace armdyn
