// SPDX-License-Identifier: BSD-3-Clause
// DOPRI5: Dormand-Prince 5(4) with PI step control and 4th-order dense output (integrators.hpp).
#include <algorithm>
#include <cmath>

#include "adaptive_run.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/integrate/integrators.hpp"

namespace armdyn {

void integrate_dopri5(OdeSystem& sys, VecX& y, double t0, double t1, const StepOptions& opt,
                      StepStats& st, IntegratorWork* work) {
  IntegratorWork local;
  IntegratorWork& w = work ? *work : local;
  // Dormand-Prince coefficients
  constexpr double c2 = 1.0 / 5, c3 = 3.0 / 10, c4 = 4.0 / 5, c5 = 8.0 / 9;
  constexpr double a21 = 1.0 / 5;
  constexpr double a31 = 3.0 / 40, a32 = 9.0 / 40;
  constexpr double a41 = 44.0 / 45, a42 = -56.0 / 15, a43 = 32.0 / 9;
  constexpr double a51 = 19372.0 / 6561, a52 = -25360.0 / 2187, a53 = 64448.0 / 6561,
                   a54 = -212.0 / 729;
  constexpr double a61 = 9017.0 / 3168, a62 = -355.0 / 33, a63 = 46732.0 / 5247, a64 = 49.0 / 176,
                   a65 = -5103.0 / 18656;
  constexpr double a71 = 35.0 / 384, a73 = 500.0 / 1113, a74 = 125.0 / 192, a75 = -2187.0 / 6784,
                   a76 = 11.0 / 84;
  constexpr double e1 = 71.0 / 57600, e3 = -71.0 / 16695, e4 = 71.0 / 1920, e5 = -17253.0 / 339200,
                   e6 = 22.0 / 525, e7 = -1.0 / 40;
  constexpr double d1 = -12715105075.0 / 11282082432.0, d3 = 87487479700.0 / 32700410799.0,
                   d4 = -10690763975.0 / 1880347072.0, d5 = 701980252875.0 / 199316789632.0,
                   d6 = -1453857185.0 / 822651844.0, d7 = 69997945.0 / 29380423.0;
  // PI controller (Hairer's DOPRI5 defaults)
  constexpr double safe = 0.9, fac_min = 0.2, fac_max = 10.0, beta = 0.04;
  const double expo1 = 0.2 - beta * 0.75;

  const long n = y.size();
  VecX &k1 = w.vec(0, n), &k2 = w.vec(1, n), &k3 = w.vec(2, n), &k4 = w.vec(3, n),
       &k5 = w.vec(4, n), &k6 = w.vec(5, n), &k7 = w.vec(6, n), &yt = w.vec(7, n),
       &y1 = w.vec(8, n), &err = w.vec(9, n);
  VecX &r1 = w.vec(10, n), &r2 = w.vec(11, n), &r3 = w.vec(12, n), &r4 = w.vec(13, n),
       &r5 = w.vec(14, n), &yp = w.vec(15, n);
  detail::AdaptiveRun run("dopri5", sys, opt, t0, t1, n, w);
  double &t = run.t, &h = run.h;
  run.start(sys, y, k1, yt, k2, 5, st);
  double facold = 1e-4;

  while (t < t1) {
    run.guard(st);
    // stages; one that cannot be evaluated rejects the step (evaluates)
    const bool stages_ok = detail::evaluates(
        [&] {
          yt = y + h * a21 * k1;
          sys.rhs(t + c2 * h, yt, k2);
          yt = y + h * (a31 * k1 + a32 * k2);
          sys.rhs(t + c3 * h, yt, k3);
          yt = y + h * (a41 * k1 + a42 * k2 + a43 * k3);
          sys.rhs(t + c4 * h, yt, k4);
          yt = y + h * (a51 * k1 + a52 * k2 + a53 * k3 + a54 * k4);
          sys.rhs(t + c5 * h, yt, k5);
          yt = y + h * (a61 * k1 + a62 * k2 + a63 * k3 + a64 * k4 + a65 * k5);
          sys.rhs(t + h, yt, k6);
        },
        h, fac_min, run.hmin);
    if (!stages_ok) {
      run.reject(h * fac_min, st);
      continue;
    }
    y1 = y + h * (a71 * k1 + a73 * k3 + a74 * k4 + a75 * k5 + a76 * k6);
    // the last stage at the projected y1: FSAL with the projection folded in, so that an
    // accepted step needs no re-evaluation at its projected end point (the projection moves y1
    // by the order of the local error, which changes the estimate below by O(h) of that). A
    // projection or evaluation that fails rejects the step.
    const bool fsal_projected = sys.project_last_stage();
    yp = y1;
    const bool last_ok = detail::evaluates(
        [&] {
          if (fsal_projected)
            sys.project_and_rhs(t + h, yp, k7);
          else
            sys.rhs(t + h, y1, k7);
        },
        h, fac_min, run.hmin);
    st.rhs_evals += 6;
    if (!last_ok) {
      run.reject(h * fac_min, st);
      continue;
    }
    err = h * (e1 * k1 + e3 * k3 + e4 * k4 + e5 * k5 + e6 * k6 + e7 * k7);
    const double en = detail::err_norm(err, y, y1, opt.rtol, opt.atol);
    if (!std::isfinite(en)) throw SolverError(msg("dopri5: non-finite error estimate at t=", t));
    const double fac11 = std::pow(en, expo1);
    if (en <= 1.0) {
      // accepted: dense output coefficients, outputs inside (t, t + h], projection
      double fac = fac11 / std::pow(facold, beta);
      fac = std::clamp(fac / safe, 1.0 / fac_max, 1.0 / fac_min);
      double hnew = std::min(h / fac, run.hmax);
      if (run.last_rejected) hnew = std::min(hnew, h);
      facold = std::max(en, 1e-4);
      double tn = run.step_end();
      if (fsal_projected) y1 = yp;  // the dense output ends where the next step starts
      const bool events = run.sign_change(sys, tn, y1);
      if (events || run.output_inside(tn)) {
        r1 = y;
        r2 = y1 - y;
        r3 = h * k1 - r2;
        r4 = r2 - h * k7 - r3;
        r5 = h * (d1 * k1 + d3 * k3 + d4 * k4 + d5 * k5 + d6 * k6 + d7 * k7);
      }
      auto dense = [&](double th, VecX& out) {
        const double th1 = 1.0 - th;
        out = r1 + th * (r2 + th1 * (r3 + th * (r4 + th1 * r5)));
      };
      // an event cut moved y1: project and evaluate there; otherwise k7 is already f(tn, y1)
      if (run.accept(sys, tn, dense, events, y, y1, st) || !fsal_projected) {
        sys.project_and_rhs(tn, y, k1);
        ++st.rhs_evals;
      } else {
        k1 = k7;
      }
      run.signs_after_events(sys, tn, y);
      run.advance(sys, tn, y, hnew, st);
    } else {
      run.reject(h / std::min(1.0 / fac_min, fac11 / safe), st);
    }
  }
}

}  // namespace armdyn
