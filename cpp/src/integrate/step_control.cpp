// SPDX-License-Identifier: BSD-3-Clause
#include "step_control.hpp"

#include <algorithm>
#include <cmath>

namespace armdyn::detail {

double err_norm(const VecX& e, const VecX& a, const VecX& b, double rtol, double atol) {
  double s = 0.0;
  const long n = e.size();
  for (long i = 0; i < n; ++i) {
    const double sc = atol + rtol * std::max(std::abs(a[i]), std::abs(b[i]));
    s = std::max(s, std::abs(e[i]) / sc);
  }
  return s;
}

double initial_step(OdeSystem& sys, double t, const VecX& y, const VecX& f0, VecX& yt, VecX& f1,
                    const StepOptions& opt, double hmax, double hmin, int order, StepStats& st) {
  if (opt.dt > 0) return opt.dt;
  const double d0 = err_norm(y, y, y, opt.rtol, opt.atol);
  const double dd1 = err_norm(f0, y, y, opt.rtol, opt.atol);
  double h0 = (d0 < 1e-5 || dd1 < 1e-5) ? 1e-6 : 0.01 * d0 / dd1;
  h0 = std::min(h0, hmax);
  yt = y + h0 * f0;
  sys.rhs(t + h0, yt, f1);
  ++st.rhs_evals;
  yt = f1 - f0;
  const double dd2 = err_norm(yt, y, y, opt.rtol, opt.atol) / h0;
  const double dm = std::max(dd1, dd2);
  const double h1 = dm <= 1e-15 ? std::max(1e-6, h0 * 1e-3) : std::pow(0.01 / dm, 1.0 / order);
  return std::max(std::min({100 * h0, h1, hmax}), std::min(100 * hmin, hmax));
}

void guard_step(const char* name, const StepOptions& opt, const StepStats& st, double t, double t1,
                double hmin, double& h, const char* hint) {
  if (opt.poll) (*opt.poll)(t, t1);
  if (st.steps + st.rejected >= opt.max_steps)
    throw SolverError(
        msg(name, ": more than ", opt.max_steps, " steps before t=", t1, " (reached t=", t, ")"));
  if (t + 1.01 * h >= t1) h = t1 - t;
  if (h < hmin)
    throw SolverError(msg(name, ": step size underflow (h=", h, ") at t=", t, "; ", hint));
  h = representable_step(t, h);
}

}  // namespace armdyn::detail
