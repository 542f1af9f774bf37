// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/solver/kkt.hpp"

#include <Eigen/LU>
#include <cmath>
#include <utility>

#include "armdyn/errors.hpp"

namespace armdyn {

KktSolver::KktSolver(const Model& m)
    : m_(m),
      A_(MatX::Zero(m.nc, m.nc)),
      llt_(m.nc),
      perm_(Eigen::VectorXi::Zero(m.nc)),
      M_(MatX::Zero(m.nc, m.nc)),
      G_(MatX::Zero(m.nc, m.nc)),
      tmp_nv_(VecX::Zero(m.nv)),
      tmp_nc_(VecX::Zero(m.nc)),
      b_(VecX::Zero(m.nc)),
      w_(VecX::Zero(m.nc)) {
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
  bool pivoted = m_.redundant;
  if (!pivoted) {
    llt_.compute(A);
    if (llt_.info() != Eigen::Success) {
      pivoted = true;
    } else {
      const double maxd = A.diagonal().cwiseAbs().maxCoeff();
      const double minl = llt_.matrixLLT().diagonal().cwiseAbs2().minCoeff();
      if (!(minl > 1e-12 * maxd)) pivoted = true;
    }
  }
  if (pivoted) factor_pivoted(nrows);
}

void KktSolver::factor_pivoted(int n) {
  // Right-looking Cholesky with diagonal pivoting on the full symmetric matrix (the trailing block
  // is kept symmetric so that row/column swaps stay simple); stops when the largest remaining
  // pivot is below tol * max diag(A), the numerical rank.
  auto A = A_.topLeftCorner(n, n);
  pinv_ = true;
  for (int i = 0; i < n; ++i) perm_[i] = i;
  const double maxd = A.diagonal().maxCoeff();
  const double tol = 1e-10 * (maxd > 0.0 ? maxd : 1.0);
  int r = 0;
  for (int k = 0; k < n; ++k) {
    int j = 0;
    const double d = A.diagonal().segment(k, n - k).maxCoeff(&j);
    j += k;
    if (!(d > tol)) break;
    if (j != k) {
      A.row(k).swap(A.row(j));
      A.col(k).swap(A.col(j));
      std::swap(perm_[k], perm_[j]);
    }
    const double lkk = std::sqrt(A(k, k));
    A(k, k) = lkk;
    const int t = n - k - 1;
    if (t > 0) {
      A.col(k).tail(t) /= lkk;
      A.bottomRightCorner(t, t).noalias() -= A.col(k).tail(t) * A.col(k).tail(t).transpose();
    }
    r = k + 1;
  }
  rank_ = r;
  const int z = n - r;
  if (z == 0) return;
  // M = L11^-T L21^T  (r x z);  G = I + M^T M = Z^T Z, factored in place
  auto M = M_.topLeftCorner(r, z);
  M = A.bottomLeftCorner(z, r).transpose();
  A.topLeftCorner(r, r).triangularView<Eigen::Lower>().adjoint().solveInPlace(M);
  auto G = G_.topLeftCorner(z, z);
  G.noalias() = M.transpose() * M;
  G.diagonal().array() += 1.0;
  Eigen::LLT<Eigen::Ref<MatX>> gfac(G);  // in place: G now holds its lower factor
}

void KktSolver::solve_pivoted(const VecX& b, VecX& x) const {
  const int n = nrows_, r = rank_, z = n - r;
  auto A = A_.topLeftCorner(n, n);
  // basic solution in permuted coordinates: x1 = L11^-T L11^-1 (P b)_1, x2 = 0
  auto c = tmp_nc_.head(n);
  for (int i = 0; i < n; ++i) c[i] = b[perm_[i]];
  auto c1 = c.head(r);
  A.topLeftCorner(r, r).triangularView<Eigen::Lower>().solveInPlace(c1);
  A.topLeftCorner(r, r).triangularView<Eigen::Lower>().adjoint().solveInPlace(c1);
  c.tail(z).setZero();
  if (z > 0) {
    // remove the null-space component: x <- x - Z G^-1 Z^T x with Z = [-M; I], Z^T x = -M^T x1
    auto w = w_.head(z);
    w.noalias() = -M_.topLeftCorner(r, z).transpose() * c1;
    const auto G = G_.topLeftCorner(z, z);
    G.triangularView<Eigen::Lower>().solveInPlace(w);
    G.triangularView<Eigen::Lower>().adjoint().solveInPlace(w);
    c1.noalias() += M_.topLeftCorner(r, z) * w;
    c.tail(z) = -w;
  }
  for (int i = 0; i < n; ++i) x[perm_[i]] = c[i];
}

void KktSolver::solve_schur(const VecX& b, VecX& x) const {
  if (nrows_ == 0) return;
  if (pinv_) {
    solve_pivoted(b, x);
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
