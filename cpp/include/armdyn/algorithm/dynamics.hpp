// SPDX-License-Identifier: BSD-3-Clause
// Joint-space forward and inverse dynamics of a tree, each by two methods that give the same
// answer to round-off:
//  - Joint: the recursive joint-space algorithms: forward dynamics by CRBA (mass matrix), the
//    recursive Newton-Euler bias and a Cholesky solve; inverse dynamics by recursive
//    Newton-Euler (armdyn/algorithm/rnea.hpp).
//  - Cartesian: the paper's constrained Newton-Euler system on the bodies' Cartesian state:
//    forward dynamics with the joint torques as loads (KKT solve for v' and the multipliers);
//    inverse dynamics with every joint coordinate driven to (q, qd, qdd), the torques being the
//    drives' multipliers.
// Auto takes Joint, the faster of the two for every model these functions accept. Both include
// the model's force elements and ignore its drives.
#pragma once

#include "armdyn/data.hpp"

namespace armdyn {

enum class DynamicsMethod { Auto, Joint, Cartesian };

/// "auto" | "joint" | "cartesian"; throws ModelError naming fn for anything else.
DynamicsMethod dynamics_method(const std::string& name, const char* fn);

/// The joint-space equations of motion M(q) qdd = rhs of a tree at (q, qd), auxiliary states z
/// (model.n_aux; nullptr: all zero) and time t, with extra joint forces tau (nullptr: none):
/// data.M by CRBA and data.rhs = tau + Q - (b - J^T eta), the Newton-Euler residual at qdd = 0
/// (armdyn/algorithm/forces.hpp for eta and Q). The inputs are not checked; allocates nothing.
/// Shared by forward_dynamics and the joint-space simulation (TreeDynamics).
/// @throws SolverError naming the coordinate or body when a force is not finite.
void joint_space_equations(const Model& m, Data& d, const double* q, const double* qd,
                           const double* z, const double* tau, double t);

/// Joint accelerations (n_coords) into data.qdd for joint torques/forces tau at (q, qd), time t.
/// Allocates nothing. The Cartesian method runs the pipeline of data on the joint rows
/// (data.nrows = nc_joint, the torques as data.joint_torques) and restores its defaults.
/// @throws ModelError when the model is not a joint-space tree, on wrong sizes or non-finite
///   inputs; SolverError when a force is not finite or the mass matrix is not positive definite.
const VecX& forward_dynamics(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                             Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> tau, double t = 0.0,
                             DynamicsMethod method = DynamicsMethod::Auto);

/// Joint torques/forces (n_coords) into data.tau realising qdd at (q, qd), time t.
/// Allocates nothing after the first Cartesian call (which makes data.driven and
/// data.driven_data).
/// @throws as forward_dynamics.
const VecX& inverse_dynamics(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                             Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> qdd, double t = 0.0,
                             DynamicsMethod method = DynamicsMethod::Auto);

}  // namespace armdyn
