// SPDX-License-Identifier: BSD-3-Clause
// First-order derivatives of joint-space inverse and forward dynamics of a tree, analytically, as
// recursive algorithms over (Model, Data): the derivatives of the recursive Newton-Euler
// algorithm of Carpentier & Mansard (RSS 2018, "Analytical Derivatives of Rigid Body Dynamics
// Algorithms"), in the engine's frames -- spatial vectors in world axes about one point o fixed
// in space (the world origin; with a floating base its centre of mass at this instant, for
// precision, as crba_loaded), angular part first, no coordinate transforms between bodies.
//
// With S_k each degree of freedom's world motion, V_i, A_i each body's spatial velocity and
// acceleration (A offset by gravity), Y_i its spatial inertia and f_i = Y_i A_i + V_i x* Y_i V_i:
//  - a q-derivative is taken along the coordinate's rate (a floating base's along its qd block:
//    the base frame's velocity in its own axes, Pinocchio's free-flyer convention): the subtree
//    of k's joint moves by the twist S_k, so dS_j/dq_k = S_k x S_j for j in that subtree,
//    dV_i/dq_k = S_k x V_i + u_k, dA_i/dq_k = S_k x A_i + w_k + u_k x V_i with the parent's
//    u_k = V_p x S_k, w_k = A_p x S_k + V_p x u_k; and dY_i = S_k x* Y_i - Y_i S_k x;
//  - so df_i/dq_k = S_k x* f_i + Y_i w_k + B_i u_k, with B_i u = Y_i (u x V_i) + u x* Y_i V_i +
//    V_i x* Y_i u, and df_i/dqd_k = Y_i a_k + B_i S_k with a_k = (V_p + V_c) x S_k;
//  - backward, children first, the subtree sums Yc, Bc, Fc, and tau_j = S_j . Fc_j gives
//    dtau_j/dq_k = S_j . (Yc_k w_k + Bc_k u_k) (+ S_k x* Fc_k when j's joint is a strict
//    ancestor of k's) for j at or above k, S_j . (Yc_j w_k + Bc_j u_k) for j below k; the same
//    with (a_k, S_k) for qd.
// The force elements' derivatives come from add_force_element_derivatives
// (algorithm/force_derivatives.hpp) and are subtracted (tau = ... - F). A coupled model is taken
// in its independent coordinates: G^T (d tau_full) G (Model::independent).
// Forward dynamics: qdd = M^-1 (tau - b) by CRBA and a factor of M (L^T D L without fill-in on a
// model without couplings, Featherstone's LTDL; else Cholesky), then dqdd/dq = -M^-1 dtau/dq and
// dqdd/dqd = -M^-1 dtau/dqd at that qdd, dqdd/dtau = M^-1, by the same factor.
#pragma once

#include "armdyn/data.hpp"

namespace armdyn {

/// Sizes data.deriv's buffers (once per Data: quadratic in the coordinates).
void ensure_derivatives(const Model& m, Data& d);

/// The rigid-body derivatives of tau_full (every coordinate, floating bases' blocks first) at the
/// state whose kinematics and joint frames joint_space_kinematics(..., d.kin, d.rne) loaded, for
/// the rates qd and accelerations qdd (full): into d.deriv.dq and d.deriv.dqd (n x n), gravity
/// and gyroscopic terms included, force elements not. Unchecked; allocates nothing once sized.
void rnea_derivatives_loaded(const Model& m, Data& d, Eigen::Ref<const VecX> qd,
                             Eigen::Ref<const VecX> qdd);

/// (dtau/dq, dtau/dqd) of inverse dynamics (rnea: gravity and the force elements included, drives
/// ignored) at (q, qd, qdd) and time t, into data.deriv.tau_q and data.deriv.tau_qd (n_dofs x
/// n_dofs: a coupled model's independent coordinates). Allocates nothing after its first call on
/// a Data.
/// @throws ModelError as inverse_dynamics (model, sizes, non-finite inputs, quaternions);
///   SolverError when a force element's force is not finite.
void inverse_dynamics_derivatives(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                                  Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> qdd,
                                  double t = 0.0);

/// (dqdd/dq, dqdd/dqd, dqdd/dtau) of forward dynamics at (q, qd, tau) and time t, into
/// data.deriv.qdd_q, .qdd_qd, .qdd_tau (n_dofs x n_dofs), the accelerations into data.deriv.qdd.
/// @throws ModelError as forward_dynamics, and for a model with light bodies (the mass matrix
///   about the world origin loses them); SolverError when M is not positive definite or a force
///   is not finite.
void forward_dynamics_derivatives(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                                  Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> tau,
                                  double t = 0.0);

}  // namespace armdyn
