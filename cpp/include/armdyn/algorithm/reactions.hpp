// SPDX-License-Identifier: BSD-3-Clause
// Reactions stage of the Cartesian pipeline:
//  - joint_reaction: the force and torque a joint transmits to its child at the joint point, in
//    the child's joint frame, from the multipliers (data.delta) of the joint's rows at the
//    loaded kinematics: the constraint force on a body is -zeta_b^T delta;
//  - sweep_multipliers: the multipliers of chosen joints from the bodies' Newton-Euler balances
//    alone, far bodies first, for a motion whose accelerations are already known (a joint-space
//    run, the fixed joints merged into composite bodies): no KKT solve;
//  - load_tree_motion: the Cartesian pipeline loaded at a tree's joint-space motion and every
//    joint's multipliers swept from it (shared by the joint-space simulation's outputs and
//    joint_reactions);
//  - joint_reactions: every joint's reaction along a given joint-space motion of a tree, with
//    the inverse dynamics' joint torques (the motion exactly the one given).
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

/// The (joint, child) pairs sweep_multipliers takes for a tree: every joint with rows, children
/// before parents (the reverse of Model::tree_order).
std::vector<std::pair<int, int>> tree_sweep(const Model& m);

/// The Cartesian pipeline of d loaded at a tree's joint-space motion and the multipliers of the
/// listed joints (tree_sweep, or the joints a welded run keeps) swept from it. Needs d.kin and
/// the joint frames d.rne at (q, qd) (joint_space_kinematics, as rnea and
/// TreeDynamics::accelerations leave them); q (model.nq_joint), qd, qdd (model.nv_joint) every
/// coordinate of the model (followers of couplings included). Writes the bodies' Cartesian state
/// u, v (nq, nv) and accelerations vd (nv, from the forward sweep at qdd), sets d.track_ref to
/// q's coordinates, loads the kinematics, constraints (time t) and forces (cartesian_forces,
/// with d.aux, d.joint_torques and d.with_coordinate_forces as the caller set them), sets the
/// ideal gears' multipliers to gear_delta (one per Model::gear_constraints; nullptr: zero) and
/// every other row's to zero, then sweeps. Allocates nothing. Returns sweep_multipliers'.
double load_tree_motion(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                        Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> qdd, double t,
                        const double* gear_delta, const std::vector<std::pair<int, int>>& sweep,
                        VecX& u, VecX& v, VecX& vd);

/// Every joint's reaction (joint_reaction: on the child at the joint point, in the child's
/// joint frame; fixed joints included, zero for joints without rows) along the joint-space
/// motion (q, qd, qdd) of a tree at time t, the inputs as rnea takes them (a coupled model's
/// independent coordinates). The joint torques in the bodies' balances are the inverse
/// dynamics' (rnea's, each coordinate's total axis force), so the reactions are those of
/// exactly the given motion; the model's drives play no part. forces and torques receive
/// 3 n_joints values each (joint-major). Allocates nothing after the first call on d.
/// @throws ModelError (naming "joint_reactions" and the argument) when the model is not a
///   joint-space tree, on wrong sizes or non-finite inputs; SolverError when a force is not
///   finite.
void joint_reactions(const Model& m, Data& d, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                     Eigen::Ref<const VecX> qdd, double t, double* forces, double* torques);

}  // namespace armdyn
