// SPDX-License-Identifier: BSD-3-Clause
// Inverse dynamics through driving constraints (methods.md §7.2), on the same Cartesian
// Newton-Euler/KKT path as forward dynamics:
//  - driven models (drives leave no freedom): at each time, the position problem (Newton on
//    f(u, t) = 0), the velocity problem (zeta v = rhs) and the acceleration problem
//    (zeta vdot = -xi) are solved, and the multipliers follow from Gamma vdot + zeta^T delta = eta.
//    Drive multipliers give the actuator efforts tau = -delta_drive; the others the joint
//    reactions.
//  - joint space (tree models): every joint coordinate is driven to the given (q, qd, qdd) and
//    the same KKT solve gives the joint torques/forces in the model's joint order.
// Sign: tau is the torque/force the actuator applies to the child body about/along the joint
// axis (the RNEA / URDF effort convention).
#pragma once

#include <Eigen/LU>
#include <memory>
#include <vector>

#include "armdyn/analysis/joint_space.hpp"
#include "armdyn/model/model.hpp"

namespace armdyn {

class Engine;

struct InverseDynamicsResult {
  long n = 0;
  /// row-major tables, one row per time
  std::vector<double> t, u, v, q, qd, qdd, efforts, reaction_forces, reaction_torques;
  std::vector<double> position_residual, velocity_residual;
  long newton_iterations = 0, factorizations = 0;
  double cpu_seconds = 0.0;
};

/// Inverse dynamics of a driven model at the given (increasing) times.
/// @throws ModelError when the drives leave degrees of freedom (naming the undriven
///   coordinates) or the times are invalid; SolverError when the driven constraints become
///   singular (naming the dependent drive/joint rows) or the position problem fails.
InverseDynamicsResult inverse_dynamics_driven(const Model& m, const std::vector<double>& times);

/// Joint-space inverse dynamics of a tree model; the model's own drives are ignored.
class JointSpaceInverseDynamics {
 public:
  /// @throws ModelError when the model is not a joint-space tree.
  explicit JointSpaceInverseDynamics(std::shared_ptr<const Model> m);
  ~JointSpaceInverseDynamics();
  /// Joint torques/forces for (q, qd, qdd) at time t (t matters for profiled force elements).
  VecX compute(const VecX& q, const VecX& qd, const VecX& qdd, double t = 0.0);
  /// The same into tau (n_coords), allocating nothing.
  void compute(Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> qdd,
               Eigen::Ref<VecX> tau, double t = 0.0);
  const Model& model() const { return *src_; }

 private:
  std::shared_ptr<const Model> src_;
  Model driven_;  // src_ with one drive per joint coordinate, in coordinate order
  std::unique_ptr<Engine> e_;
  VecX u_, v_, vd_, ref_;
  TreeFkWork fk_;
  // O(n) path: with every coordinate driven, each tree joint's rows plus its drive rows are six
  // rows on its child's six velocities, so zeta is square and block-triangular in tree order:
  // vdot by a forward sweep and delta by a backward sweep of 6x6 solves
  struct Sweep {
    int joint, parent, child;
    int blocks[3];  // the joint's block and its drives' blocks (-1: unused)
    int nblocks;
  };
  std::vector<Sweep> sweep_;
  std::vector<Eigen::PartialPivLU<Mat6>> lu_;
  VecX delta_, r_;
  bool sweep_ok_ = false;
  void compute_sweep(double t);
};

}  // namespace armdyn
