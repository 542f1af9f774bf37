// SPDX-License-Identifier: BSD-3-Clause
// Joint-space forward dynamics of a tree with ideal gears, in minimal coordinates q (the
// joint angles and displacements, multi-turn):
//   M(q) qdd + b(q, qd) - J^T eta = Q(q, qd, t) + G^T lambda,   G qdd = 0,
// with
//  - M by the composite-rigid-body algorithm in world axes (Featherstone, Rigid Body Dynamics
//    Algorithms, 2008, ch. 6): each subtree's spatial inertia about the world origin, and
//    M_jk = S_j . (I_subtree(k) S_k) for j on the path from k to the root;
//  - b - J^T eta the recursive Newton-Euler residual at qdd = 0 (rne_residual): velocity
//    products, gravity, body loads and spring-dampers (eta of body_forces);
//  - Q the joint-coordinate forces (springs, dampers, friction, inputs, PD/PI motors) and the
//    gear pairs' contact forces, straight from the unwrapped coordinates;
//  - G the ideal gears' rows (r_a, r_b in their coordinates' columns; constant), eliminated by
//    an orthonormal basis T of their null space (a QR of G^T at construction):
//    qdd = T (T^T M T)^-1 T^T (Q - b + J^T eta).
// The rows are linear in q, so every Runge-Kutta method keeps G q = 0 and G qd = 0 exactly up to
// round-off; project() removes that round-off. Without ideal gears, accelerations() takes the
// articulated-body algorithm (armdyn/algorithm/aba.hpp, O(n)) where the measured cost model
// (armdyn/algorithm/cost_model.hpp) predicts it cheaper than CRBA + Cholesky. The Cartesian path
// (algorithm/kkt.hpp) remains the reference: tests compare the two.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "armdyn/data.hpp"

namespace armdyn {

/// The ideal gears' rows of a model, G (ng x n, constant), by an orthonormal basis T of their
/// null space and one of their range, and the pseudo-inverse of G^T: derived once per model
/// (Model::derived) by gear_space().
struct GearSpace {
  int rank = 0;
  MatX T, range, Gt_pinv;
  /// range^T q on the rows' solution set G q = offsets (couplings' offsets; 0 for gears)
  VecX range_value;
};
const GearSpace& gear_space(const Model& m);
/// Why TreeDynamics refuses m although it is a joint tree: ideal gears (which need the
/// mass matrix by CRBA, about the world origin) together with light bodies
/// (kernels/kkt_factor.hpp), whose accelerations that loses; empty otherwise.
std::string geared_light_reason(const Model& m);

class TreeDynamics {
 public:
  /// On a Data of m (its kinematics, forces, Newton-Euler, CRBA and tree buffers).
  /// ignore_drives: the model's drives play no part (joint-space forward dynamics for given
  /// joint forces); otherwise a model with drives is refused.
  /// @throws ModelError (Model::joint_path_reason) when the path does not apply, or when d was
  ///   made for another model.
  TreeDynamics(const Model& m, Data& d, bool ignore_drives = false);
  /// The same on a Data of its own.
  explicit TreeDynamics(const Model& m, bool ignore_drives = false);
  TreeDynamics(const TreeDynamics&) = delete;
  TreeDynamics& operator=(const TreeDynamics&) = delete;

  int n() const { return n_; }      ///< joint coordinates
  int dof() const { return dof_; }  ///< independent coordinates (n - rank of the gear rows)
  std::string description() const;  ///< one line for the run's statistics
  /// accelerations() runs the articulated-body algorithm (no ideal gears, and the cost model
  /// predicts it cheaper than CRBA + Cholesky)
  bool uses_aba() const { return aba_; }
  const Model& model() const { return m_; }

  /// Accelerations qdd (n) at (q, qd) (n each), auxiliary states z (model.n_aux; may be nullptr
  /// when there are none) and time t; tau: extra joint forces (n) or nullptr. Allocates nothing.
  /// @throws SolverError naming the culprit when a force is not finite or M is not positive
  ///   definite.
  void accelerations(double t, const double* q, const double* qd, const double* z,
                     const double* tau, double* qdd);
  /// Rates of the auxiliary states (PI motors' integral terms) at (q, qd, z, t).
  void aux_rates(double t, const double* q, const double* qd, const double* z, double* zdot) const;
  /// Gear pair g's mesh displacement s, rate and penetration |s| - backlash/2.
  void gear_mesh(int g, const double* q, const double* qd, double& s, double& sd,
                 double& penetration) const;
  /// Remove the round-off from G q = offsets and G qd = 0 (Euclidean projection onto their
  /// solution sets).
  void project(double* q, double* qd);
  /// The joint-space mass matrix at q (n x n), by the composite-rigid-body algorithm.
  const MatX& mass_matrix(const double* q);
  /// The mass matrix of the last mass_matrix() call, or of the last accelerations() call when
  /// it took CRBA (uses_aba() false).
  const MatX& last_mass_matrix() const { return d_.M; }
  /// The ideal gears' multipliers (one per gear, the Cartesian rows' convention
  /// M qdd = rhs - G^T delta) of the last accelerations() call, whose result is qdd: the
  /// least-squares solution of G^T delta = rhs - M qdd (the minimum-norm one for redundant
  /// gears). Empty without ideal gears. Allocates nothing.
  const VecX& gear_multipliers(const double* qdd);
  /// The evaluation behind the last accelerations() call: the tree's kinematics (data().kin),
  /// joint frames (data().rne) and applied forces (data().eta) at its (q, qd, t).
  const Data& data() const { return d_; }

 private:
  void init(bool ignore_drives);
  std::unique_ptr<Data> own_;  // the standalone constructor's Data
  const Model& m_;
  Data& d_;
  const GearSpace& gs_;
  int n_ = 0, dof_ = 0, rank_ = 0;
  bool aba_ = false;  // accelerations by the articulated-body algorithm (no ideal gears)
};

/// td.accelerations for a caller outside a run (the Python binding): q (model.nq_joint), qd and
/// tau (td.n()) checked finite, the floating bases' quaternions unit, t finite and the model
/// without integral states; ModelError "TreeDynamics: ..." otherwise.
void checked_accelerations(TreeDynamics& td, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                           Eigen::Ref<const VecX> tau, double t, double* qdd);
/// td.mass_matrix at q (model.nq_joint) checked as checked_accelerations checks it.
const MatX& checked_mass_matrix(TreeDynamics& td, Eigen::Ref<const VecX> q);

}  // namespace armdyn
