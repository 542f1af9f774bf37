// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/kernels/kkt_factor.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <utility>

#include "armdyn/errors.hpp"

namespace armdyn {

const LightBodies& light_bodies(const Model& m) {
  return m.derived.get<LightBodies>([&] {
    LightBodies lb;
    double mmax = 0.0;
    for (const Body& b : m.bodies) mmax = std::max(mmax, b.mass);
    const double l2 = m.length_scale * m.length_scale;
    // massless children of revolute coupling followers (actuator rotors) are exact in CRBA
    std::vector<char> follower(m.coords.size(), 0), rotor(m.nb, 0);
    for (const GearConstraint& g : m.gear_constraints)
      if (g.coupling) follower[g.coord_a] = 1;
    for (const Joint& j : m.joints)
      if (j.child != kGround && j.type == JointType::Revolute && follower[j.coord0] &&
          !(m.bodies[j.child].mass > 0.0))
        rotor[j.child] = 1;
    for (int i = 0; i < m.nb; ++i) {
      const Body& b = m.bodies[i];
      const double jmin = Eigen::SelfAdjointEigenSolver<Mat3>(b.inertia).eigenvalues()[0];
      // a massless body (mass 0: finalize checked that its motions carry inertia) is as light
      // as a body gets (jmin / 0 would be NaN and pass every test)
      const double ratio = b.mass > 0.0 ? std::min(jmin / (b.mass * l2), b.mass / mmax * 1e3) : 0.0;
      if (ratio < 1e-6) {
        lb.bodies.push_back(i);
        lb.note += msg(lb.note.empty() ? "" : ", ", "'", b.name, "' (", ratio, ")");
        if (!rotor[i]) {
          lb.joint_space.push_back(i);
          lb.joint_space_note +=
              msg(lb.joint_space_note.empty() ? "" : ", ", "'", b.name, "' (", ratio, ")");
        }
      }
    }
    lb.massless_only = !lb.bodies.empty();
    for (int i : lb.bodies) lb.massless_only = lb.massless_only && !(m.bodies[i].mass > 0.0);
    if (!lb.bodies.empty())
      lb.note =
          msg("light bodies (smallest principal moment / (m l^2), or 1e3 mass / heaviest, "
              "below 1e-6): ",
              lb.note,
              lb.massless_only
                  ? "; the dynamics is solved by the range-space factor with a floored Gamma, "
                    "refined against the exact system (the augmented LU of [Gamma zeta^T; zeta "
                    "0] where that does not converge)"
                  : "; the dynamics is solved in augmented form (LU of [Gamma zeta^T; zeta 0]), "
                    "without Gamma^-1");
    return lb;
  });
}

KktSolver::KktSolver(const Model& m)
    : m_(m),
      tmp_nv_(VecX::Zero(m.nv)),
      b_(VecX::Zero(m.nc)),
      tmp_nc_(VecX::Zero(m.nc)),
      w_(VecX::Zero(m.nc)),
      tmp2_(VecX::Zero(m.nc)),
      ref_r_(VecX::Zero(m.nc)),
      ref_d_(VecX::Zero(m.nc)),
      ref_nv_(VecX::Zero(m.nv)),
      ref_nv2_(VecX::Zero(m.nv)),
      rf_r1_(VecX::Zero(m.nv)),
      rf_r2_(VecX::Zero(m.nc)),
      rf_dv_(VecX::Zero(m.nv)),
      rf_dd_(VecX::Zero(m.nc)) {
  minv_.resize(m.nb);
  for (int i = 0; i < m.nb; ++i) {
    minv_[i].setZero();
    minv_[i].topLeftCorner<3, 3>() = Mat3::Identity() / m.bodies[i].mass;
    minv_[i].bottomRightCorner<3, 3>() = m.bodies[i].inertia.inverse();
  }
  // light bodies: the mass-weighted metric of the projections floored at 1e-6 m l^2 (their
  // dynamics never uses Gamma^-1: accelerations_augmented), so that a correction is not carried
  // by an almost free rotation of a nearly inertia-less body
  double mmax = 0.0;
  for (const Body& b : m.bodies) mmax = std::max(mmax, b.mass);
  // A massless body (mass 0: a "virtual" link between joints) has no mass to weight by at all:
  // its metric is a thousandth of the heaviest body's, and its inertia floor a thousandth of
  // that times l^2, which keeps the projections' Schur complement conditioned like a model of
  // ordinary links (the 1e-9 and 1e-6 floors of light bodies made it ~1e15 there, and the
  // position projection of a falling human.urdf stalled at 1e-9)
  for (int i : light_bodies(m).bodies) {
    const bool massless = !(m.bodies[i].mass > 0.0);
    double mass = massless ? 1e-3 * mmax : std::max(m.bodies[i].mass, 1e-9 * mmax);
    if (!(mass > 0.0)) mass = 1.0;  // no body has mass (finalize refuses it after assembly)
    const double floor = (massless ? 1e-3 : 1e-6) * mass * m.length_scale * m.length_scale;
    minv_[i].topLeftCorner<3, 3>() = Mat3::Identity() / mass;
    minv_[i].bottomRightCorner<3, 3>() = (m.bodies[i].inertia + floor * Mat3::Identity()).inverse();
  }
  // the block-sparse plans unless the model is redundant or forced onto the dense path
  const bool sparse = !m.redundant && !m.force_dense_kkt && m.nc > 0;
  const KktPlans* plans = sparse ? &kkt_plans(m) : nullptr;
  const bool sparse_all = plans && plans->all.path != KktPath::Dense;
  if (sparse_all) sp_all_ = std::make_unique<BlockSparseSchur>(m, plans->all);
  if (plans && m.nc_joint != m.nc && plans->joint.path != KktPath::None &&
      plans->joint.path != KktPath::Dense)
    sp_joint_ = std::make_unique<BlockSparseSchur>(m, plans->joint);
  if (!sparse_all) ensure_dense();
}

void KktSolver::ensure_dense() {
  const int n = m_.nc;
  if (A_.rows() == n) return;
  A_ = MatX::Zero(n, n);
  llt_ = Eigen::LLT<MatX>(n);
  perm_ = Eigen::VectorXi::Zero(n);
  M_ = MatX::Zero(n, n);
  G_ = MatX::Zero(n, n);
  scale_ = VecX::Zero(n);
  DM_ = MatX::Zero(n, n);
}

void KktSolver::factor_pivoted_at(const ConstraintEval& ce, int nrows, Metric metric, double tol) {
  ++factor_count_;
  stale_ = false;
  ensure_dense();
  assemble(ce, nrows, metric);
  if (nrows > 0) factor_pivoted(nrows, tol);
}

void KktSolver::assemble(const ConstraintEval& ce, int nrows, Metric metric) {
  nrows_ = nrows;
  metric_ = metric;
  pinv_ = false;
  sparse_ = false;
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
}

void KktSolver::factor(const ConstraintEval& ce, int nrows, Metric metric) {
  ++factor_count_;
  stale_ = false;
  BlockSparseSchur* sp = nullptr;
  if (nrows == m_.nc && sp_all_)
    sp = sp_all_.get();
  else if (nrows == m_.nc_joint && sp_joint_)
    sp = sp_joint_.get();
  regularized_ = false;
  if (sp && nrows > 0) {
    const std::vector<Mat6>* winv = metric == Metric::Mass ? &minv_ : nullptr;
    // the plain factor until a singular configuration is ahead; from then on, for this
    // solver's lifetime, the regularised one, so that the solution stays a smooth function of
    // the state for the step-size control (the switch itself changes it by about
    // (kShift / kTrigger)^2 relatively, after the refinement)
    if (!singular_met_ && sp->factor(ce, winv)) {
      // a pivot below kTrigger of its diagonal: a singular configuration ahead, or only mass
      // ratios (a light body between heavy ones gives small pivots in the mass metric). The
      // unweighted A tells them apart; after a check that found the geometry sound, the next
      // one waits until the pivot has fallen tenfold more.
      const double p = sp->min_relative_pivot();
      bool plain = p >= kTrigger || p >= 0.1 * mass_floor_;
      if (!plain && metric == Metric::Mass) {
        plain = sp->factor(ce, nullptr) && sp->min_relative_pivot() >= kTrigger;
        if (plain) {
          mass_floor_ = p;
          sp->factor(ce, winv);
        }
      }
      if (plain) {
        nrows_ = nrows;
        metric_ = metric;
        pinv_ = false;
        rank_ = nrows;
        sparse_ = true;
        sp_ = sp;
        return;
      }
    }
    singular_met_ = true;
    if (sp->factor(ce, winv, kShift)) {
      nrows_ = nrows;
      metric_ = metric;
      sparse_ = true;
      sp_ = sp;
      regularized_ = true;
      ce_ = &ce;
      rank_ = nrows - static_cast<int>(sp->weak_rows().size());
      pinv_ = rank_ < nrows;
      return;
    }
  }
  ensure_dense();
  assemble(ce, nrows, metric);
  if (nrows == 0) return;
  auto A = A_.topLeftCorner(nrows, nrows);
  // Cholesky unless the model is known redundant or the factor shows a (near-)zero pivot
  bool pivoted = m_.redundant;
  if (!pivoted) {
    llt_.compute(A);
    if (llt_.info() != Eigen::Success) {
      pivoted = true;
    } else {
      // each pivot against its own row's diagonal: invariant to the scale of the rows (bodies
      // of very different masses give diagonals many decades apart)
      double minrel = 1.0;
      for (int i = 0; i < nrows; ++i) {
        const double l = llt_.matrixLLT()(i, i);
        minrel = std::min(minrel, l * l / A(i, i));
      }
      if (!(minrel > 1e-12)) pivoted = true;
    }
  }
  if (pivoted) factor_pivoted(nrows);
}

void KktSolver::factor_pivoted(int n, double tol) {
  // Right-looking Cholesky with diagonal pivoting of the Jacobi-scaled matrix S A S,
  // S = diag(A)^-1/2 (unit diagonal, so that the rank decision does not depend on how far apart
  // the bodies' masses are), on the full symmetric matrix (the trailing block is kept symmetric
  // so that row/column swaps stay simple); stops when the largest remaining pivot is below
  // 1e-10, the numerical rank.
  auto A = A_.topLeftCorner(n, n);
  pinv_ = true;
  for (int i = 0; i < n; ++i) {
    perm_[i] = i;
    const double d = A(i, i);
    scale_[i] = d > 0.0 ? 1.0 / std::sqrt(d) : 1.0;
  }
  for (int j = 0; j < n; ++j) A.col(j) *= scale_[j];
  for (int i = 0; i < n; ++i) A.row(i) *= scale_[i];
  int r = 0;
  for (int k = 0; k < n; ++k) {
    // joint (and gear) rows pivot before drive rows, so that when the constraints lose rank
    // the rows left over name the drives whenever the joints alone are still independent
    int j = -1;
    double d = 0.0;
    for (int pass = 0; pass < 2 && !(d > tol); ++pass) {
      for (int i = k; i < n; ++i)
        if ((pass == 1 || perm_[i] < m_.nc_joint) && A(i, i) > d) {
          d = A(i, i);
          j = i;
        }
    }
    if (!(d > tol)) break;
    if (j != k) {
      A.row(k).swap(A.row(j));
      A.col(k).swap(A.col(j));
      std::swap(perm_[k], perm_[j]);
      std::swap(scale_[k], scale_[j]);
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
  // scaled, permuted null space Z_y = [-M; I] with M = L11^-T L21^T (r x z); in the original
  // variables Z = S Z_y, so the Gram matrix of the minimum-norm correction is
  //   G = Z^T Z = M^T S1^2 M + S2^2, factored in place
  auto M = M_.topLeftCorner(r, z);
  M = A.bottomLeftCorner(z, r).transpose();
  A.topLeftCorner(r, r).triangularView<Eigen::Lower>().adjoint().solveInPlace(M);
  auto G = G_.topLeftCorner(z, z);
  auto DM = DM_.topLeftCorner(r, z);
  DM = scale_.head(r).cwiseAbs2().asDiagonal() * M;
  G.noalias() = M.transpose() * DM;
  G.diagonal() += scale_.segment(r, z).cwiseAbs2();
  Eigen::LLT<Eigen::Ref<MatX>> gfac(G);  // in place: G now holds its lower factor
}

void KktSolver::solve_pivoted(const VecX& b, VecX& x) const {
  const int n = nrows_, r = rank_, z = n - r;
  auto A = A_.topLeftCorner(n, n);
  // basic solution of the scaled system (S A S) y = S b in permuted coordinates:
  // y1 = L11^-T L11^-1 (P S b)_1, y2 = 0; then x = S y
  auto c = tmp_nc_.head(n);
  for (int i = 0; i < n; ++i) c[i] = scale_[i] * b[perm_[i]];
  auto c1 = c.head(r);
  A.topLeftCorner(r, r).triangularView<Eigen::Lower>().solveInPlace(c1);
  A.topLeftCorner(r, r).triangularView<Eigen::Lower>().adjoint().solveInPlace(c1);
  c1.array() *= scale_.head(r).array();  // x1 = S1 y1
  c.tail(z).setZero();
  if (z > 0) {
    // remove the null-space component (Euclidean): x <- x - Z G^-1 Z^T x with Z = [-S1 M; S2],
    // Z^T x = -M^T S1 x1
    auto w = w_.head(z);
    auto t1 = tmp2_.head(r);
    t1 = scale_.head(r).cwiseProduct(c1);
    w.noalias() = -M_.topLeftCorner(r, z).transpose() * t1;
    const auto G = G_.topLeftCorner(z, z);
    G.triangularView<Eigen::Lower>().solveInPlace(w);
    G.triangularView<Eigen::Lower>().adjoint().solveInPlace(w);
    t1.noalias() = M_.topLeftCorner(r, z) * w;
    c1 += scale_.head(r).cwiseProduct(t1);
    c.tail(z) = -scale_.segment(r, z).cwiseProduct(w);
  }
  for (int i = 0; i < n; ++i) x[perm_[i]] = c[i];
}

void KktSolver::apply_a(const VecX& x, VecX& y) const {
  zeta_transpose_times(*ce_, nrows_, x, ref_nv_);
  apply_winv(ref_nv_, ref_nv2_);
  zeta_times(*ce_, nrows_, ref_nv2_, y);
}

void KktSolver::solve_schur(const VecX& b, VecX& x) const {
  if (nrows_ == 0) return;
  if (sparse_) {
    auto xh = x.head(nrows_);
    xh = b.head(nrows_);
    sp_->solve_in_place(x);
    if (regularized_) {
      // one step of iterated Tikhonov (a smooth function of b and A):
      // x += (A + e D)^-1 (b - A x); a component of relative eigenvalue lambda keeps the
      // relative error (e / (lambda + e))^2, so the well-determined rows are exact to round-off
      // and the nearly dependent ones are damped: near a singular configuration the constraints
      // act as slightly compliant ones (compliance e), which keeps the motion on its branch
      // (IFToMM A02). More refinement steps let the bifurcation modes in: measured on A02 (20 s,
      // DOPRI5 rtol 1e-8), the B0 error is 3e-6 with one step and 8e-4 with four.
      apply_a(x, ref_r_);
      auto r = ref_d_.head(nrows_);
      r = b.head(nrows_) - ref_r_.head(nrows_);
      sp_->solve_in_place(ref_d_);
      xh += r;
    }
  } else if (pinv_) {
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
  for (int b = 0; b < m_.nb; ++b) apply_minv(b, y.segment<6>(6 * b), x.segment<6>(6 * b));
}

void KktSolver::accelerations(const ConstraintEval& ce, const VecX& eta, VecX& vdot, VecX& delta) {
  // a = Gamma^-1 eta; delta = A^-1 (zeta a + xi); vdot = a - Gamma^-1 zeta^T delta
  for (int b = 0; b < m_.nb; ++b) apply_minv(b, eta.segment<6>(6 * b), vdot.segment<6>(6 * b));
  delta.setZero();
  if (nrows_ == 0) return;
  zeta_times(ce, nrows_, vdot, b_);
  b_.head(nrows_) += ce.xi.head(nrows_);
  solve_schur(b_, delta);
  zeta_transpose_times(ce, nrows_, delta, tmp_nv_);
  for (int b = 0; b < m_.nb; ++b) {
    vdot.segment<3>(6 * b) -= minv_[b](0, 0) * tmp_nv_.segment<3>(6 * b);
    vdot.segment<3>(6 * b + 3).noalias() -=
        minv_[b].bottomRightCorner<3, 3>() * tmp_nv_.segment<3>(6 * b + 3);
  }
}

bool KktSolver::accelerations_refined(const ConstraintEval& ce, int nrows, const VecX& eta,
                                      VecX& vdot, VecX& delta, int max_iter, int& iterations) {
  iterations = 0;
  // the preconditioned first solution: K_f x = (eta, -xi), K_f with the floored Gamma_f
  accelerations(ce, eta, vdot, delta);
  if (!vdot.allFinite() || !delta.allFinite()) return false;
  for (int it = 1; it <= max_iter; ++it) {
    iterations = it;
    // residual of the exact system: r1 = eta - Gamma vdot - zeta^T delta, r2 = -xi - zeta vdot
    zeta_transpose_times(ce, nrows, delta, rf_r1_);
    for (int b = 0; b < m_.nb; ++b) {
      const Body& bd = m_.bodies[b];
      rf_r1_.segment<3>(6 * b) += bd.mass * vdot.segment<3>(6 * b);
      rf_r1_.segment<3>(6 * b + 3).noalias() += bd.inertia * vdot.segment<3>(6 * b + 3);
    }
    rf_r1_ = eta - rf_r1_;
    if (nrows > 0) {
      zeta_times(ce, nrows, vdot, rf_r2_);
      rf_r2_.head(nrows) = -ce.xi.head(nrows) - rf_r2_.head(nrows);
    }
    // the correction K_f (dv, dd) = (r1, r2): a = Gamma_f^-1 r1, A dd = zeta a - r2,
    // dv = a - Gamma_f^-1 zeta^T dd
    for (int b = 0; b < m_.nb; ++b)
      apply_minv(b, rf_r1_.segment<6>(6 * b), rf_dv_.segment<6>(6 * b));
    rf_dd_.setZero();
    if (nrows > 0) {
      zeta_times(ce, nrows, rf_dv_, b_);
      b_.head(nrows) -= rf_r2_.head(nrows);
      solve_schur(b_, rf_dd_);
      zeta_transpose_times(ce, nrows, rf_dd_, tmp_nv_);
      for (int b = 0; b < m_.nb; ++b) {
        rf_dv_.segment<3>(6 * b) -= minv_[b](0, 0) * tmp_nv_.segment<3>(6 * b);
        rf_dv_.segment<3>(6 * b + 3).noalias() -=
            minv_[b].bottomRightCorner<3, 3>() * tmp_nv_.segment<3>(6 * b + 3);
      }
    }
    vdot += rf_dv_;
    delta.head(nrows) += rf_dd_.head(nrows);
    if (!vdot.allFinite() || !delta.allFinite()) return false;
    const double dv = rf_dv_.cwiseAbs().maxCoeff(), v = vdot.cwiseAbs().maxCoeff();
    const double dd = nrows > 0 ? rf_dd_.head(nrows).cwiseAbs().maxCoeff() : 0.0;
    const double d = nrows > 0 ? delta.head(nrows).cwiseAbs().maxCoeff() : 0.0;
    // (redundant rows: the multipliers are the minimum-norm ones, only vdot is unique)
    if (dv <= 1e-13 * v && (pinv_ || dd <= 1e-13 * d)) return true;
  }
  return false;
}

bool KktSolver::accelerations_augmented(const ConstraintEval& ce, int nrows, const VecX& eta,
                                        VecX& vdot, VecX& delta) {
  const int nv = m_.nv, n = nv + nrows;
  if (aug_.rows() != n) {
    aug_ = MatX::Zero(n, n);
    aug_b_ = VecX::Zero(n);
    aug_x_ = VecX::Zero(n);
    aug_lu_ = Eigen::PartialPivLU<MatX>(n);
  }
  aug_.setZero();
  for (int b = 0; b < m_.nb; ++b) {
    const Body& bd = m_.bodies[b];
    aug_.block<3, 3>(6 * b, 6 * b).diagonal().setConstant(bd.mass);
    aug_.block<3, 3>(6 * b + 3, 6 * b + 3) = bd.inertia;
  }
  for (const ConstraintBlock& blk : ce.blocks) {
    if (blk.row0 >= nrows) continue;
    for (int k = 0; k < blk.nbody; ++k) {
      const int body = blk.body[k];
      if (body == kGround) continue;
      const auto Z = blk.J.block(0, 6 * k, blk.nrows, 6);
      aug_.block(nv + blk.row0, 6 * body, blk.nrows, 6) += Z;
      aug_.block(6 * body, nv + blk.row0, 6, blk.nrows) += Z.transpose();
    }
  }
  aug_b_.head(nv) = eta;
  aug_b_.tail(nrows) = -ce.xi.head(nrows);
  aug_lu_.compute(aug_);
  aug_x_ = aug_lu_.solve(aug_b_);
  if (!aug_x_.allFinite()) return false;
  vdot = aug_x_.head(nv);
  delta.setZero();
  delta.head(nrows) = aug_x_.tail(nrows);
  return true;
}

}  // namespace armdyn
