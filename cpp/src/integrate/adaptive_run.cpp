// SPDX-License-Identifier: BSD-3-Clause
#include "adaptive_run.hpp"

namespace armdyn::detail {

AdaptiveRun::AdaptiveRun(const char* name_, OdeSystem& sys, const StepOptions& o, double t0,
                         double t1_, long n, IntegratorWork& w)
    : name(name_),
      opt(o),
      t1(t1_),
      t(t0),
      hmax(o.max_step > 0 ? o.max_step : t1_ - t0),
      hmin(1e-14 * std::max(1.0, std::abs(t1_))),
      touts(w.times),
      ev(sys, w, n),
      yo(w.vec(39, n)),
      sys_(sys) {
  output_times(t0, t1_, o.output_dt, touts);
  every_step = touts.empty();
}

void AdaptiveRun::start(OdeSystem& sys, VecX& y, VecX& f0, VecX& yt, VecX& f1, int order,
                        StepStats& st) {
  sys.project_and_rhs(t, y, f0);
  ++st.rhs_evals;
  sys.step_accepted();
  sys.output(t, y);
  h = initial_step(sys, t, y, f0, yt, f1, opt, hmax, hmin, order, st);
  h = std::min(h, sys.step_bound(t));  // (OdeSystem::step_bound)
  ev.init(sys, t, y);
}

}  // namespace armdyn::detail
