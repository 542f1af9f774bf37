// SPDX-License-Identifier: BSD-3-Clause
// The step-size control the integrators share (private to cpp/src/integrate): the error norm,
// the first step, the checks before each step, representable steps, and the rejection of a step
// whose evaluations fail.
#pragma once

#include "armdyn/errors.hpp"
#include "armdyn/integrate/integrators.hpp"

namespace armdyn::detail {

/// Scaled max-norm of the error, sc_i = atol + rtol max(|a_i|, |b_i|) (as ode45). An RMS norm
/// would divide by the 13 nb Cartesian components, most of them fixed by constraints, and so
/// under-estimate the error of the few free coordinates.
double err_norm(const VecX& e, const VecX& a, const VecX& b, double rtol, double atol);

/// The step actually taken from t: fl(t + h) - t. Advancing the state by h while the clock
/// advances by fl(t + h) lets the two drift apart by up to half an ulp of t per step; over
/// millions of steps (IFToMM A01: 2000 s) that is 1e-7 s of phase, 5e-7 m of position.
inline double representable_step(double t, double h) { return (t + h) - t; }

/// Hairer's hinit: the first step from the size of y, f(t, y) and a difference quotient of f,
/// for a method whose local error is O(h^order). Uses yt and f1 as scratch. Not below 100 hmin:
/// hinit's bound 100 h0 (h0 moving y by 1 % of its size) collapses when y is round-off above
/// zero (joint angles of 1e-16 from an assembled state, atol 1e-12 gives h0 ~ 1e-20); the
/// controller grows a small first step by up to 10x per step, and rejects one too large.
double initial_step(OdeSystem& sys, double t, const VecX& y, const VecX& f0, VecX& yt, VecX& f1,
                    const StepOptions& opt, double hmax, double hmin, int order, StepStats& st);

/// The checks before each step of an error-controlled method: the poll, the step budget,
/// landing on t1, step-size underflow (the message ends with `hint`); then h is made a
/// representable step from t.
void guard_step(const char* name, const StepOptions& opt, const StepStats& st, double t, double t1,
                double hmin, double& h,
                const char* hint = "the problem may be stiff or singular there");

/// Runs the evaluations f of a step. A SolverError from them (a stage off the constraint
/// manifold where the accelerations are not finite, e.g. at a large step near a singular
/// position; a projection that does not converge) returns false, so that the step is rejected
/// and retried smaller; once h * fac would fall below hmin, the error itself propagates.
template <class F>
bool evaluates(F&& f, double h, double fac, double hmin) {
  try {
    f();
    return true;
  } catch (const SolverError&) {
    if (!(h * fac >= hmin)) throw;
    return false;
  }
}

}  // namespace armdyn::detail
