// SPDX-License-Identifier: BSD-3-Clause
// Joint-space inverse dynamics of a tree by the recursive Newton-Euler algorithm:
//   tau = M(q) qdd + b(q, qd) - J(q)^T eta - Q(q, qd, t),
// the torque/force each joint's actuator applies to its child about/along the joint axis (the
// RNEA / URDF effort convention), with gravity and every force element of the model included
// (eta: armdyn/algorithm/forces.hpp) and the model's drives ignored.
#pragma once

#include "armdyn/data.hpp"

namespace armdyn {

/// rnea() on every coordinate of the model (followers of couplings included), unchecked, into
/// data.tau.
void rnea_full(const Model& m, Data& d, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
               Eigen::Ref<const VecX> qdd, double t);

/// Joint torques/forces (n_coords: a coupled model's independent coordinates, tau = G^T
/// tau_full of Model::independent; then the result is data.coupled.tau) into data.tau at
/// (q, qd, qdd) and time t. O(n): forward,
/// parents first, the bodies' accelerations; backward, children first, each subtree's residual
/// wrench projected on its joint's axis. Allocates nothing.
/// @throws ModelError when the model is not a joint-space tree, on wrong sizes or non-finite
///   inputs; SolverError when a force is not finite.
const VecX& rnea(const Model& m, Data& d, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                 Eigen::Ref<const VecX> qdd, double t = 0.0);

}  // namespace armdyn
