// SPDX-License-Identifier: BSD-3-Clause
// The bookkeeping DOPRI5 and DOP853 share (private to cpp/src/integrate): the output times, the
// step bounds, the clock (t, h), the rejection state and the event signs with their scratch.
// Each method keeps its stages, its error estimate, its step-size controller and its dense
// output.
#pragma once

#include <algorithm>
#include <vector>

#include "dense_output.hpp"
#include "events.hpp"
#include "step_control.hpp"

namespace armdyn::detail {

struct AdaptiveRun {
  const char* name;
  const StepOptions& opt;
  double t1, t, h = 0.0, hmax, hmin;
  std::vector<double>& touts;
  bool every_step;
  size_t ko = 1;
  bool last_rejected = false;
  bool resign = false;  // an event changed the system: take the signs afresh
  bool cut = false;     // an event ended the step early
  EventState ev;
  VecX& yo;
  OdeSystem& sys_;

  /// its buffers: the work's slots 36..42, output times and event signs
  AdaptiveRun(const char* name_, OdeSystem& sys, const StepOptions& o, double t0, double t1_,
              long n, IntegratorWork& w);

  /// f0 = f(t0, y) at the projected y; the output at t0, the event signs and the first step
  /// for a method of the given order (yt, f1: scratch).
  void start(OdeSystem& sys, VecX& y, VecX& f0, VecX& yt, VecX& f1, int order, StepStats& st);
  void guard(const StepStats& st) { guard_step(name, opt, st, t, t1, hmin, h); }
  /// Rejects the step; the next attempt takes h_retry.
  void reject(double h_retry, StepStats& st) {
    sys_.step_rejected();
    h = h_retry;
    ++st.rejected;
    last_rejected = true;
  }
  /// The end of the step from t (t1 itself when within round-off of it).
  double step_end() const {
    return (t + h >= t1 - 1e-14 * std::max(1.0, std::abs(t1))) ? t1 : t + h;
  }
  /// An output time lies in (t, tn].
  bool output_inside(double tn) const {
    return !every_step && ko < touts.size() && touts[ko] <= tn;
  }
  /// Whether an event function may cross zero between t and (tn, y1) (EventState::end).
  bool sign_change(OdeSystem& sys, double tn, const VecX& y1) { return ev.end(sys, tn, y1, h); }
  /// An accepted step with its dense output: ends it at the earliest event crossing (when
  /// events), serves the output times in (t, tn] and sets y = y1. Returns whether an event cut
  /// the step (tn and y1 then moved, and f must be evaluated afresh at them).
  template <class Dense>
  bool accept(OdeSystem& sys, double& tn, const Dense& dense, bool events, VecX& y, VecX& y1,
              StepStats& st) {
    const double t_end_step = tn;
    ev.crossed.clear();
    if (events) {
      const double th = ev.locate(sys, t, h, dense);
      ev.take(sys, t, h, th, dense, st, tn, y1);
    }
    serve_outputs(sys, touts, ko, t, h, tn, dense, yo);
    resign = !ev.crossed.empty() && sys.apply_events(tn, y1);
    cut = tn != t_end_step;
    y = y1;
    return cut || resign;
  }
  /// The event functions at the start of the next step: taken afresh at the new, projected y
  /// after an event cut the step or changed the system, else those of the step's end.
  void signs_after_events(OdeSystem& sys, double tn, const VecX& y) {
    ev.after_step(sys, tn, y, resign, cut);
    resign = cut = false;
  }
  /// The clock moves to tn (y and the first stage there in place); the next step is hnew.
  void advance(OdeSystem& sys, double tn, const VecX& y, double hnew, StepStats& st) {
    t = tn;
    ++st.steps;
    sys.step_accepted();
    if (every_step) sys.output(t, y);
    h = std::min(hnew, sys.step_bound(t));  // (OdeSystem::step_bound)
    last_rejected = false;
  }
};

}  // namespace armdyn::detail
