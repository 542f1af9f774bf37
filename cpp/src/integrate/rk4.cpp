// SPDX-License-Identifier: BSD-3-Clause
// RK4: the classical fixed-step method, steps landing on the output times (integrators.hpp).
#include <algorithm>
#include <cmath>

#include "armdyn/errors.hpp"
#include "armdyn/integrate/integrators.hpp"
#include "dense_output.hpp"
#include "events.hpp"
#include "step_control.hpp"

namespace armdyn {

void integrate_rk4(OdeSystem& sys, VecX& y, double t0, double t1, const StepOptions& opt,
                   StepStats& st, IntegratorWork* work) {
  if (!(opt.dt > 0)) throw ModelError("rk4: dt must be positive");
  IntegratorWork local;
  IntegratorWork& w = work ? *work : local;
  const long n = y.size();
  VecX &k1 = w.vec(0, n), &k2 = w.vec(1, n), &k3 = w.vec(2, n), &k4 = w.vec(3, n),
       &yt = w.vec(4, n), &y1 = w.vec(5, n), &f1 = w.vec(6, n);
  std::vector<double>& touts = w.times;
  output_times(t0, t1, opt.output_dt, touts);
  const bool every_step = touts.empty();
  size_t ko = 1;
  double t = t0;
  sys.project_and_rhs(t, y, k1);
  ++st.rhs_evals;
  sys.output(t, y);
  // events: located on the cubic Hermite interpolant of (y, k1) and (y1, f(t + h, y1)), which
  // costs extra right-hand sides only on steps where an event function changes sign
  const int ne = sys.n_events();
  detail::EventState ev(sys, w, n);
  ev.init(sys, t, y);
  const double eps = 1e-12 * std::max(1.0, std::abs(t1));
  // a step shortened to a located crossing may end just short of it (the location came from
  // the longer step's interpolant); the next step locates it again from closer by. After a few
  // such steps in a row the event is taken at once, instead of creeping towards the crossing
  // without reaching it
  int creeps = 0;
  constexpr int kMaxCreeps = 3;
  while (t < t1 - eps) {
    if (opt.poll) (*opt.poll)(t, t1);
    if (st.steps >= opt.max_steps)
      throw SolverError(msg("rk4: more than ", opt.max_steps, " steps before t=", t1));
    // land exactly on the next output time and on t1
    double h = std::min(opt.dt, t1 - t);
    double to = t1;
    if (!every_step && ko < touts.size()) to = touts[ko];
    if (t + h > to - eps) h = to - t;
    h = detail::representable_step(t, h);
    // a step across an event is redone up to the located crossing (at most twice), so that the
    // final location uses stages on the near side of it (the Hermite interpolant of a step whose
    // end already feels, e.g., a contact force is only a first guess)
    double tn = t;
    bool changed = false;  // an event changed the state or the event functions
    bool cut = false;      // an event ended the step early
    for (int round = 0;; ++round) {
      yt = y + 0.5 * h * k1;
      sys.rhs(t + 0.5 * h, yt, k2);
      yt = y + 0.5 * h * k2;
      sys.rhs(t + 0.5 * h, yt, k3);
      yt = y + h * k3;
      sys.rhs(t + h, yt, k4);
      y1 = y + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
      tn = (std::abs(t + h - to) <= eps) ? to : t + h;
      st.rhs_evals += 3;
      if (ne == 0) break;
      if (!ev.end(sys, tn, y1, h)) {
        creeps = round > 0 ? creeps + 1 : 0;
        break;
      }
      sys.rhs(tn, y1, f1);
      ++st.rhs_evals;
      auto dense = [&](double th, VecX& out) { detail::hermite(th, h, y, k1, y1, f1, out); };
      const double th = ev.locate(sys, t, h, dense);
      if (th < 0) {  // a suspected dip that does not reach zero
        creeps = round > 0 ? creeps + 1 : 0;
        break;
      }
      if (creeps < kMaxCreeps && round < 2 && th < 1.0 - 1e-9) {
        h = detail::representable_step(t, h * th);
        continue;
      }
      ev.take(sys, t, h, th, dense, st, tn, y1);
      changed = !ev.crossed.empty() && sys.apply_events(tn, y1);
      cut = th < 1.0;
      creeps = 0;
      break;
    }
    y = y1;
    t = tn;
    sys.project_and_rhs(t, y, k1);
    ++st.rhs_evals;
    ev.after_step(sys, t, y, changed, cut);
    ++st.steps;
    if (every_step) {
      sys.output(t, y);
    } else if (ko < touts.size() && std::abs(t - touts[ko]) <= eps) {
      sys.output(t, y);
      ++ko;
    }
  }
}

}  // namespace armdyn
