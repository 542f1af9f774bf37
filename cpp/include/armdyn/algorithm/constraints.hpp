// SPDX-License-Identifier: BSD-3-Clause
// Constraints stage of the Cartesian pipeline: the residuals f(u, t), the velocity-space
// Jacobian zeta, rhs (zeta v = rhs) and xi (zeta v' = -xi) of every row, at the kinematics
// loaded in data.kin, into data.ce (assembled by armdyn/kernels/constraint_rows.hpp, the ideal gear
// rows reading the coordinate jets and the tracked angles of data).
#pragma once

#include "armdyn/data.hpp"
#include "armdyn/kernels/constraint_rows.hpp"

namespace armdyn {

/// data.ce at the loaded kinematics and time t; xi only when with_xi.
inline void evaluate_constraints(const Model& m, Data& d, double t, bool with_xi) {
  eval_constraints(m, d.kin, t, with_xi, d.ce);
}

/// Every constraint row at a Cartesian state: residuals f (nc), the dense Jacobian zeta (nc, nv),
/// xi and rhs (nc), with zeta v = rhs and zeta v' = -xi.
struct ConstraintValues {
  VecX f, xi, rhs;
  MatX zeta;
};

/// The constraints at the Cartesian state (u: nq, v: nv) and time t (a Data of its own; the state
/// checked by check_cartesian_state, messages naming fn).
ConstraintValues constraint_values(const Model& m, const VecX& u, const VecX& v, double t,
                                   const char* fn);

}  // namespace armdyn
