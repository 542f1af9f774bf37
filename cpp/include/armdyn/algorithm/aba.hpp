// SPDX-License-Identifier: BSD-3-Clause
// Joint-space forward dynamics of a tree in O(n): the articulated-body algorithm (Featherstone,
// Rigid Body Dynamics Algorithms, 2008, ch. 7), in world axes about the world origin (the
// frames of crba.hpp and rne_residual: spatial vectors (angular; velocity of the point at the
// origin), no coordinate transforms between bodies).
//  - forward, parents first: each body's spatial velocity v_i = (W, xd - W x c) from the tree's
//    kinematics, and each coordinate's velocity-product term c_k = v_parent x (s_k qd_k) (every
//    joint's axis line is fixed in its parent, so s_k' = v_parent x s_k);
//  - backward, children first: the articulated inertia I^A and bias force p^A of each subtree,
//    one coordinate at a time (a cylindrical joint is a turn and a slide about one line through
//    a massless intermediate body), U = I^A s, D = s^T U, u = tau - s^T p^A,
//    I^a = I^A - U U^T / D, p^a = p^A + I^a c + U u / D, added to the parent's;
//  - forward, parents first: qdd_k = (u_k - U_k^T a') / D_k, a = a' + s_k qdd_k.
// Each body's own bias force is the Newton-Euler residual at zero spatial acceleration with the
// same applied and gyroscopic forces eta (body_forces) as joint_space_equations, and the joint
// forces are tau + Q (coordinate_forces): the same force model as the CRBA path. Gravity is in
// eta (the root's acceleration is zero).
#pragma once

#include "armdyn/data.hpp"

namespace armdyn {

/// Joint accelerations qdd (n_coords) of a joint-space tree (no ideal gears) at joint
/// coordinates q, rates qd (n each, multi-turn), auxiliary states z (model.n_aux; nullptr: all
/// zero) and time t, with extra joint forces tau (n; nullptr: none), by the articulated-body
/// algorithm: the same equations as joint_space_equations, M(q) qdd = rhs. Also leaves the
/// kinematics (data.kin), joint frames (data.rne.point, .axis), applied forces (data.eta) and
/// the joint forces tau + Q (data.rhs -- not the CRBA path's rhs) at (q, qd, t). The inputs are
/// not checked; allocates nothing. qdd may be data.qdd.
/// @throws SolverError naming the coordinate when a force is not finite, or the joint, its
///   coordinate and child body when an articulated pivot D is not positive (a massless subtree).
void aba_accelerations(const Model& m, Data& d, const double* q, const double* qd, const double* z,
                       const double* tau, double t, double* qdd);

/// Forward dynamics by the articulated-body algorithm: joint accelerations (n_coords) into
/// data.qdd for joint torques/forces tau at (q, qd), time t. Allocates nothing.
/// @throws ModelError when the model is not a joint-space tree, on wrong sizes or non-finite
///   inputs; SolverError as aba_accelerations.
const VecX& aba(const Model& m, Data& d, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                Eigen::Ref<const VecX> tau, double t = 0.0);

}  // namespace armdyn
