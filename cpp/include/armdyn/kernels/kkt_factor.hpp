// SPDX-License-Identifier: BSD-3-Clause
// The augmented (KKT) system of the constrained Newton-Euler equations
//   [ Gamma  zeta^T ] [ vdot  ]   [  eta ]
//   [ zeta   0      ] [ delta ] = [ -xi  ]
// solved by the range-space Schur complement A = zeta W^-1 zeta^T (W = Gamma for dynamics and the
// mass-weighted projection, W = I for the paper's unweighted projection):
//   A delta = zeta Gamma^-1 eta + xi,   vdot = Gamma^-1 (eta - zeta^T delta).
// A is assembled block by block from the bodies each row block touches. It is factored by
// Cholesky; when A is singular (redundant constraints) or nearly so, by a Cholesky factorisation
// with diagonal pivoting of the Jacobi-scaled S A S (S = diag(A)^-1/2) that stops at the
// numerical rank r,
//   P S A S P^T = [L11; L21] [L11; L21]^T,  L11 r x r,
// and the minimum-norm multipliers are the basic solution minus its component in the null space
// of A, spanned (in permuted coordinates) by Z = [-L11^-T L21^T; I] (Golub & Van Loan, 5.5.4 and
// 4.2.9). vdot and zeta^T delta are unique either way. All storage is sized once in the
// constructor, so neither path allocates per step.
//
// Models whose plan (kkt_plans(), made on first use) is not KktPath::Dense factor A with
// the block-sparse Cholesky of block_sparse.hpp instead (linear in the bodies on trees). A
// singular configuration ahead (a pivot below 1e-4 of its diagonal, in a non-redundant model,
// confirmed on the unweighted A so that mass ratios alone do not count) switches the solver,
// for the rest of its life, to the regularised A + 1e-7 diag(A) on the
// same block-sparse path, each solve refined once against A (iterated Tikhonov): the
// well-determined rows' components are exact to round-off, the nearly dependent rows' are
// damped (the constraints act as slightly compliant near the singularity, which keeps the
// motion on its branch), and the solution stays a smooth function of the state (a switch per
// evaluation would make the right-hand side jump). Only when that factor fails too
// does it fall back to the dense pivoted path, whose buffers are then sized once, on first use.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <memory>
#include <string>
#include <vector>

#include "armdyn/kernels/block_sparse.hpp"
#include "armdyn/kernels/constraint_rows.hpp"

namespace armdyn {

enum class Metric { Mass, Identity };

/// Bodies whose own inertia is tiny against the model's scale: smallest principal moment below
/// 1e-6 m l^2 (l the model's length scale; point masses have none) or mass below 1e-9 of the
/// heaviest body's. The range-space solve forms Gamma^-1 and loses about 1e-18 / ratio of
/// relative accuracy on them (the UR5 with one link's inertia scaled by 1e-8: 5e-9; by 1e-14:
/// 0.8), so the dynamics of a model with any takes the augmented solve
/// (KktSolver::accelerations_augmented) and its projections a floored metric. Derived once per
/// model (Model::derived).
struct LightBodies {
  std::vector<int> bodies;
  std::string note;  ///< names the bodies and their ratios; empty when none
  /// every light body is massless (mass 0): the dynamics takes the refined range-space solve
  /// (KktSolver::accelerations_refined) before the augmented one
  bool massless_only = false;
  /// the light bodies that matter to the joint-space mass matrix (CRBA about the world
  /// origin): all but the massless children of a revolute coupling follower (actuator rotors:
  /// zero mass adds no parallel-axis terms, and the follower is no degree of freedom), and
  /// their note
  std::vector<int> joint_space;
  std::string joint_space_note;
};
const LightBodies& light_bodies(const Model& m);

class KktSolver {
 public:
  explicit KktSolver(const Model& m);

  /// Assemble A over rows [0, nrows) with metric W and factor it.
  void factor(const ConstraintEval& ce, int nrows, Metric metric);
  /// Diagnosis: assemble A and factor it with pivoting at rank tolerance `tol` (relative to the
  /// unit diagonal of the scaled matrix); rank() and dependent_rows() then tell which rows are
  /// nearly dependent.
  void factor_pivoted_at(const ConstraintEval& ce, int nrows, Metric metric, double tol);
  /// Solve A x = b (b, x sized >= nrows; only the first nrows entries are used).
  void solve_schur(const VecX& b, VecX& x) const;
  /// x = W^-1 y (blockwise).
  void apply_winv(const VecX& y, VecX& x) const;
  /// Forward dynamics with the current factorisation (must be metric Mass).
  void accelerations(const ConstraintEval& ce, const VecX& eta, VecX& vdot, VecX& delta);

  int nrows() const { return nrows_; }
  Metric metric() const { return metric_; }
  /// Factorisations so far (factor and factor_pivoted_at): tells another solver's cached factor
  /// whether the pose may have changed under it.
  long factor_count() const { return factor_count_; }
  /// The factor is of rows [0, nrows) with the mass metric, and no other solve of a later pose
  /// (mark_stale) has come since: body_accelerations may reuse it at the same pose.
  bool reusable(int nrows) const { return !stale_ && metric_ == Metric::Mass && nrows_ == nrows; }
  /// Another solver answered at a pose this factor may not be of (the articulated sweep).
  void mark_stale() { stale_ = true; }
  /// The last factorisation used the block-sparse path.
  bool used_sparse() const { return sparse_; }
  bool used_pseudo_inverse() const { return pinv_; }
  int rank() const { return rank_; }
  /// Rows left out of the pivoted factor (dependent at this configuration); empty on the
  /// Cholesky path.
  std::vector<int> dependent_rows() const {
    std::vector<int> r;
    if (pinv_ && regularized_) return sp_->weak_rows();
    if (pinv_)
      for (int i = rank_; i < nrows_; ++i) r.push_back(perm_[i]);
    return r;
  }
  /// A singular configuration was met: the solver runs regularised from then on.
  bool near_singular() const { return singular_met_; }
  /// The accelerations from the whole augmented system [Gamma zeta^T; zeta 0] over rows
  /// [0, nrows), factored densely (LU, partial pivoting) without forming Gamma^-1: accurate
  /// whatever the inertias of single bodies, down to point masses, while the joint-space mass
  /// matrix is positive definite. O((nv + nrows)^3); its buffers are sized on first use.
  /// Returns false when the augmented matrix is singular (no finite solution).
  bool accelerations_augmented(const ConstraintEval& ce, int nrows, const VecX& eta, VecX& vdot,
                               VecX& delta);
  /// The accelerations of a model whose light bodies are all massless (mass 0), without the
  /// augmented LU: the current factor (metric Mass, whose Gamma is floored on those bodies) as
  /// the preconditioner of iterative refinement against the exact system [Gamma zeta^T; zeta 0]
  /// over rows [0, nrows). A mode moving a massless body carries the inertia of the bodies it
  /// moves (finalize checked it), so each step shrinks the error by about floor / (floor +
  /// that inertia). Returns false when the corrections have not fallen below 1e-13 of the
  /// solution within max_iter steps (the caller then takes the augmented solve); `iterations`
  /// receives the steps taken. O(n) per step on the block-sparse paths, nothing allocated.
  bool accelerations_refined(const ConstraintEval& ce, int nrows, const VecX& eta, VecX& vdot,
                             VecX& delta, int max_iter, int& iterations);
  /// Forget what earlier solves learnt (the sticky regularisation and its pivot level), as a
  /// new solver would start: a new run on a reused Data.
  void reset() {
    singular_met_ = false;
    regularized_ = false;
    mass_floor_ = 10.0 * kTrigger;
  }

 private:
  const Model& m_;
  std::vector<Mat6> minv_;  // per-body Gamma^-1 blocks: diag((1/m) I, I^-1)
  template <class In, class Out>
  void apply_minv(int b, const In& y, Out&& x) const {
    x.template head<3>() = minv_[b](0, 0) * y.template head<3>();
    x.template tail<3>().noalias() =
        minv_[b].template bottomRightCorner<3, 3>() * y.template tail<3>();
  }
  std::unique_ptr<BlockSparseSchur> sp_all_, sp_joint_;
  const BlockSparseSchur* sp_ = nullptr;  // the factor in use when sparse_
  bool sparse_ = false;
  bool regularized_ = false;   // the factor in use is the regularised one (solves refine)
  bool singular_met_ = false;  // sticky: every factor is regularised from then on
  static constexpr double kShift = 1e-7;
  static constexpr double kTrigger = 1e-4;
  double mass_floor_ = 10.0 * kTrigger;  // pivot level whose geometry was last found sound
  const ConstraintEval* ce_ = nullptr;   // the evaluation A was assembled from (refinement)
  void ensure_dense();
  /// y = A x over the factor's rows, with the current evaluation
  void apply_a(const VecX& x, VecX& y) const;
  MatX A_;
  Eigen::LLT<MatX> llt_;
  void assemble(const ConstraintEval& ce, int nrows, Metric metric);
  MatX aug_;  // the augmented matrix and its LU (accelerations_augmented), sized on first use
  Eigen::PartialPivLU<MatX> aug_lu_;
  VecX aug_b_, aug_x_;
  void factor_pivoted(int n, double tol = 1e-10);
  void solve_pivoted(const VecX& b, VecX& x) const;
  // pivoted path: factor of P A P^T in A_ (lower), permutation, M = L11^-T L21^T and the
  // Cholesky factor of G = I + M^T M
  Eigen::VectorXi perm_;
  MatX M_, G_;
  VecX tmp_nv_, b_;
  mutable VecX tmp_nc_, w_;  // scratch of the const solves
  VecX scale_;               // Jacobi scaling diag(A)^-1/2, in pivot order
  mutable VecX tmp2_, ref_r_, ref_d_;
  mutable VecX ref_nv_, ref_nv2_;
  VecX rf_r1_, rf_r2_, rf_dv_, rf_dd_;  // accelerations_refined: residuals and corrections
  MatX DM_;                             // S1^2 M
  int nrows_ = 0, rank_ = 0;
  long factor_count_ = 0;
  bool stale_ = false;
  Metric metric_ = Metric::Mass;
  bool pinv_ = false;
};

}  // namespace armdyn
