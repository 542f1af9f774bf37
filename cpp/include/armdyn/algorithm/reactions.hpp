// SPDX-License-Identifier: BSD-3-Clause
// Reactions stage of the Cartesian pipeline:
//  - joint_reaction: the force and torque a joint transmits to its child at the joint point, in
//    the child's joint frame, from the multipliers (data.delta) of the joint's rows at the
//    loaded kinematics: the constraint force on a body is -zeta_b^T delta;
//  - sweep_multipliers: the multipliers of chosen joints from the bodies' Newton-Euler balances
//    alone, far bodies first, for a motion whose accelerations are already known (a joint-space
//    run, the fixed joints merged into composite bodies): no KKT solve.
#pragma once

#include <utility>
#include <vector>

#include "armdyn/data.hpp"

namespace armdyn {

/// Reaction on joint j's child (on its parent, negated, when the child is ground) at the joint
/// point, in the child's joint frame. Zero for a joint without rows or with rows outside
/// data.nrows. Needs the kinematics and constraints of the evaluation that gave data.delta.
void joint_reaction(const Model& m, const Data& d, int j, Vec3& force, Vec3& torque);

/// The multipliers of the rows of the listed joints, into data.delta, from the Newton-Euler
/// balances of the bodies at accelerations vd (nv): with the residual
///   r = eta - Gamma vd - zeta^T delta   (delta of every other row as data.delta holds it),
/// each listed (joint, far body), in order, takes the rows that balance its far body,
///   zeta_far^T delta_j = r_far   (least squares: exact when vd is the model's motion),
/// and passes their force to its near body, r_near -= zeta_near^T delta_j. List a body after
/// every joint beyond it (children before parents). Needs data.ce (evaluate_constraints) and
/// data.eta (cartesian_forces) at the loaded state. O(joints); allocates nothing.
/// Returns the largest residual of the least-squares balances, |r_far - zeta_far^T delta_j|,
/// which is round-off when vd and the other multipliers are consistent with the model.
double sweep_multipliers(const Model& m, Data& d, const VecX& vd,
                         const std::vector<std::pair<int, int>>& joints);

}  // namespace armdyn
