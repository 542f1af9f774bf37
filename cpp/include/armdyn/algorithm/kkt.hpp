// SPDX-License-Identifier: BSD-3-Clause
// KKT stage of the Cartesian pipeline: forward dynamics of the bodies' state, the constrained
// Newton-Euler equations
//   Gamma v' + zeta^T delta = eta,   zeta v' = -xi
// over the rows taking part (data.nrows), solved for the accelerations v' and the multipliers
// data.delta by the Schur complement of the KKT system (armdyn/kernels/kkt_factor.hpp), or, for the
// square zeta of a fully driven tree, by two O(n) sweeps (armdyn/kernels/tree_sweep.hpp). A
// configuration where the Jacobian has lost rank against assembly is counted and described in
// data.stats. Never silently inaccurate: a model with light bodies (kernels/kkt_factor.hpp
// light_bodies) is solved in augmented form without Gamma^-1, and a range-space solve whose
// constraint residual shows lost accuracy is redone in that form (data.stats.augmented_*).
#pragma once

#include <string>

#include "armdyn/data.hpp"

namespace armdyn {

/// v' (nv) into vdot and the multipliers into data.delta at (u, v, t): loads the kinematics,
/// evaluates the constraints (with xi) and the forces (cartesian_forces), and solves.
/// reuse_factor: the last projection factored A at this very u with the mass metric.
/// @throws SolverError when a force or the accelerations are not finite.
void body_accelerations(const Model& m, Data& d, double t, const double* u, const double* v,
                        double* vdot, bool reuse_factor = false);

/// The largest relative residual of zeta vd = -xi over rows [0, nrows), row by row:
/// |sum_j zeta_rj vd_j + xi_r| / (sum_j |zeta_rj| a + |xi_r|), a = max(max|vd|, a_scale),
/// round-off (1e-16) for an exact solve. O(rows). a_scale: the accelerations the loads alone
/// give (load_acceleration_scale): at rest vd is round-off of those, not of its own size.
double constraint_residual(const ConstraintEval& ce, int nrows, const VecX& vd,
                           double a_scale = 0.0);
/// The largest linear acceleration |f_i| / m_i the applied forces eta alone give a body (gravity
/// included): the size against which a solve's accelerations carry round-off. O(bodies).
double load_acceleration_scale(const Model& m, const VecX& eta);

/// body_accelerations at the kinematics already loaded in data.kin (load_kinematics or
/// load_joint_kinematics).
void body_accelerations_loaded(const Model& m, Data& d, double t, double* vdot,
                               bool reuse_factor = false);

/// The names of the rows the last factorisation of data.kkt found dependent, "; "-separated
/// (Model::row_name), for messages about singular configurations.
std::string dependent_row_names(const Model& m, const Data& d);

/// The constant Cartesian mass matrix Gamma = blockdiag(m_i I3, J_i) (nv, nv) of the bodies (J_i
/// about the centre of mass, body axes): the matrix of the KKT system.
MatX cartesian_mass_matrix(const Model& m);

}  // namespace armdyn
