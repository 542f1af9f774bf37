// SPDX-License-Identifier: BSD-3-Clause
// The joint-space mass matrix of a tree by the composite-rigid-body algorithm in world axes
// (Featherstone, Rigid Body Dynamics Algorithms, 2008, ch. 6): each subtree's spatial inertia
// about the world origin, and M_jk = S_j . (I_subtree(k) S_k) for j on the path from k to ground.
#pragma once

#include "armdyn/data.hpp"

namespace armdyn {

/// M(q) (n_coords x n_coords) into data.M; a coupled model's in its independent coordinates,
/// G^T M G (Model::independent), into data.coupled.M. Allocates nothing after its first call on
/// a Data (ensure_mass_matrix).
/// @throws ModelError when the model is not a joint-space tree, on a wrong size or non-finite q.
const MatX& crba(const Model& m, Data& d, Eigen::Ref<const VecX> q);

/// Allocates (zeroed) data.M and data.L, n x n, and a coupled model's data.coupled.M and L,
/// unless they exist: a Data makes them on its first mass-matrix evaluation (never per step
/// after it). They are quadratic in the coordinates, so a Data that never forms M (the
/// Cartesian, ABA and Newton-Euler paths, finalize) stays linear in the model's size.
void ensure_mass_matrix(Data& d);

/// crba() without the checks, for callers that checked the model and q themselves (the
/// joint-space simulation of a tree with ideal gears, which crba() refuses).
const MatX& mass_matrix_at(const Model& m, Data& d, Eigen::Ref<const VecX> q);

/// data.M from the kinematics in data.kin and the joint frames (data.rne.point, data.rne.axis)
/// that joint_space_kinematics(..., frames) placed there; no checks. The step shared by crba() and
/// forward dynamics.
void crba_loaded(const Model& m, Data& d);

/// q with every floating base's position set to zero (kept in buf): the mass matrix does not
/// depend on where a floating base is, and the CRBA's world-frame products lose precision
/// with the square of its distance from the origin (1e-3 relative at 1e6 m, overflow past
/// 1e154 m). q itself when the model has no floating base.
Eigen::Ref<const VecX> bases_at_origin(const Model& m, Eigen::Ref<const VecX> q, VecX& buf);

}  // namespace armdyn
