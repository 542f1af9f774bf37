// SPDX-License-Identifier: BSD-3-Clause
// Projection stage of the Cartesian pipeline: the topological projection of the bodies' state
// (u, v) onto the constraint manifold -- positions onto f(u, t) = 0 by minimum-norm Newton steps
// in the metric W (quaternions renormalised), velocities onto zeta v = rhs -- over the rows
// taking part (data.nrows); the constraint residuals; and, after a failure, the diagnosis of a
// nearly singular constraint Jacobian by its dependent rows.
#pragma once

#include <string>

#include "armdyn/data.hpp"

namespace armdyn {

/// Project u onto f(u, t) = 0 and v onto zeta v = rhs, in place. Leaves the kinematics loaded
/// at (u, v), A factored at the final u with `metric`, and the tracked angles committed.
/// @throws SolverError when the Euler parameters or the residual are not finite, or the
///   position iteration does not converge (naming the worst row).
void project(const Model& m, Data& d, double t, double* u, double* v, Metric metric);

/// ||f||_inf and ||zeta v - rhs||_inf over the rows taking part at (u, v, t).
void residuals(const Model& m, Data& d, double t, const double* u, const double* v, double& rf,
               double& rv);

/// The same from the last constraint evaluation in data.ce (at the loaded u and its t), for
/// velocities v.
void loaded_residuals(const Model& m, Data& d, const double* v, double& rf, double& rv);

/// When the constraint Jacobian at (u, v, t) is nearly singular (scaled pivots below
/// threshold), a sentence naming the nearly dependent rows; otherwise empty.
std::string diagnose_singularity(const Model& m, Data& d, double t, const double* u,
                                 const double* v, double threshold = 1e-7);

}  // namespace armdyn
