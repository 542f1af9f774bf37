// SPDX-License-Identifier: BSD-3-Clause
// Joint-space forward and inverse dynamics of a tree, by methods that give the same answer to
// round-off:
//  - forward dynamics: Crba -- the composite-rigid-body mass matrix, the recursive
//    Newton-Euler bias and a Cholesky solve (O(n^3) on a chain); Aba -- the articulated-body
//    algorithm (armdyn/algorithm/aba.hpp, O(n)); Cartesian -- the paper's constrained
//    Newton-Euler system on the bodies' Cartesian state with the joint torques as loads (KKT
//    solve for v' and the multipliers). Joint takes the cheaper of Crba and Aba, Auto the
//    cheapest of the three, both by the measured cost model of armdyn/algorithm/cost_model.hpp
//    (derived once per model).
//  - inverse dynamics: Joint (and Auto) -- recursive Newton-Euler (armdyn/algorithm/rnea.hpp);
//    Cartesian -- every joint coordinate driven to (q, qd, qdd), the torques being the drives'
//    multipliers.
// All include the model's force elements and ignore its drives. A model with couplings
// (ModelBuilder::add_coupling, URDF <mimic>) is taken in its independent coordinates
// (Model::independent: q_full = G q + shift), as Pinocchio's mimic=True models: forward
// dynamics solves (G^T M G) qdd = G^T rhs_full + tau by CRBA (or the Cartesian KKT system with
// the couplings' rows, tau on the independent coordinates); inverse dynamics returns
// G^T tau_full(q_full, G qd, G qdd); 'aba' is refused there.
#pragma once

#include "armdyn/data.hpp"

namespace armdyn {

enum class DynamicsMethod { Auto, Joint, Crba, Aba, Cartesian };

/// forward dynamics: "auto" | "joint" | "crba" | "aba" | "cartesian"; inverse dynamics
/// (forward = false): "auto" | "joint" | "cartesian". Throws ModelError naming fn for anything
/// else.
DynamicsMethod dynamics_method(const std::string& name, const char* fn, bool forward = true);

/// The joint-space equations of motion M(q) qdd = rhs of a tree at (q, qd), auxiliary states z
/// (model.n_aux; nullptr: all zero) and time t, with extra joint forces tau (nullptr: none):
/// data.M by CRBA and data.rhs = tau + Q - (b - J^T eta), the Newton-Euler residual at qdd = 0
/// (armdyn/algorithm/forces.hpp for eta and Q). The inputs are not checked; allocates nothing.
/// Shared by forward_dynamics and the joint-space simulation (TreeDynamics).
/// @throws SolverError naming the coordinate or body when a force is not finite.
void joint_space_equations(const Model& m, Data& d, const double* q, const double* qd,
                           const double* z, const double* tau, double t);

/// Joint accelerations (n_coords; a coupled model's independent ones, into
/// data.coupled.qdd_out) into data.qdd for joint torques/forces tau at (q, qd), time t.
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
