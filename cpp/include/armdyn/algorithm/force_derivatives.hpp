// SPDX-License-Identifier: BSD-3-Clause
// Analytical derivatives of the model's force elements, as joint-space generalised forces: the
// part of inverse dynamics' tau = M qdd + b - J^T eta - Q that the rigid-body recursion does not
// cover (body loads and point-to-point spring-dampers in eta; coordinate forces and gear pairs in
// Q). Gravity and the gyroscopic terms are the rigid-body recursion's own
// (algorithm/derivatives.hpp).
#pragma once

#include "armdyn/data.hpp"

namespace armdyn {

/// Adds the derivatives of the force elements' generalised force F(q, qd, t) = J^T eta_elements +
/// Q (every coordinate, followers of couplings included: the full joint-space layout, floating
/// bases' blocks first) to dF_dq and dF_dqd (nv_joint x nv_joint, not zeroed here): q-derivatives
/// along the rates (a floating base's along its qd block, Pinocchio's convention), at time t and
/// auxiliary states zero (as inverse_dynamics). Needs data.kin and data.rne at (q, qd)
/// (joint_space_kinematics). Allocates nothing once the first call on the Data has sized its
/// scratch (Data::force_deriv). Cost: per body load O(d^2), per spring-damper O((d_a + d_b)^2) (d:
/// the degrees of freedom on a body's chain), per coordinate force and gear pair O(1). Where a law
/// is not differentiable, the derivative is that of the branch the law evaluates at that state: a
/// PD/PI motor's limit (std::clamp) is the identity on the closed band |u| <= limit (the
/// unsaturated slopes -kp, -kd at |u| = limit); a gear pair exerts no force while its penetration
/// is <= 0 (zero slopes at the backlash edge) and its Hunt-Crossley force k d^n (1 + alpha d') is
/// clamped only below 0 (the contact slopes where it is exactly 0); an angle difference's wrap at
/// +-pi is ignored (slope 1). The smoothed Coulomb friction is smooth (slope -F_c / v_s at qd = 0).
/// @throws SolverError naming the element when a profile or force is not finite, or a
///   spring-damper's length is zero.
void add_force_element_derivatives(const Model& m, Data& d, const double* q, const double* qd,
                                   double t, Eigen::Ref<MatX> dF_dq, Eigen::Ref<MatX> dF_dqd);

/// True when the model has force elements (body loads, spring-dampers, coordinate forces, gear
/// pairs): add_force_element_derivatives has something to add.
bool has_force_elements(const Model& m);

}  // namespace armdyn
