// SPDX-License-Identifier: BSD-3-Clause
#include "events.hpp"

namespace armdyn::detail {

EventState::EventState(OdeSystem& sys, IntegratorWork& w, long n)
    : sgn(w.signs),
      crossed(w.crossed),
      g0(w.vec(40, sys.n_events())),
      dg0(w.vec(41, sys.n_events())),
      gend(w.vec(36, sys.n_events())),
      dg1(w.vec(42, sys.n_events())),
      gbuf(w.vec(37, sys.n_events())),
      ybuf(w.vec(38, n)) {
  sgn.assign(static_cast<size_t>(sys.n_events()), 1);
}

void EventState::init(OdeSystem& sys, double t, const VecX& y) {
  if (sgn.empty()) return;
  sys.events(t, y, g0.data());
  for (size_t i = 0; i < sgn.size(); ++i) sgn[i] = g0[static_cast<long>(i)] < 0 ? -1 : 1;
  rates = sys.event_rates(t, y, dg0.data());
}

void EventState::refresh(OdeSystem& sys, double t, const VecX& y) {
  if (sgn.empty()) return;
  sys.events(t, y, g0.data());
  rates = sys.event_rates(t, y, dg0.data());
}

void EventState::after_step(OdeSystem& sys, double t, const VecX& y, bool changed, bool cut) {
  if (changed)
    init(sys, t, y);
  else if (cut)
    refresh(sys, t, y);
  else if (!sgn.empty())
    next();
}

bool EventState::end(OdeSystem& sys, double tn, const VecX& y1, double h) {
  if (sgn.empty()) return false;
  sys.events(tn, y1, gend.data());
  if (rates) sys.event_rates(tn, y1, dg1.data());
  for (int i = 0; i < size(); ++i)
    if (gend[i] * sgn[i] < 0 || dip_theta(i, h) >= 0) return true;
  return false;
}

double EventState::dip_theta(int i, double h) const {
  if (!rates) return -1.0;
  const double s = sgn[static_cast<size_t>(i)];
  const double a0 = s * g0[i], a1 = s * gend[i], d0 = s * h * dg0[i], d1 = s * h * dg1[i];
  if (!(a0 >= 0 && a1 >= 0 && d0 < 0 && d1 > 0)) return -1.0;  // (NaN rates: never)
  // the cubic Hermite p(th) of g over the step; p' = 3 c3 th^2 + 2 c2 th + d0 turns in (0, 1)
  const double c3 = 2 * (a0 - a1) + d0 + d1, c2 = 3 * (a1 - a0) - 2 * d0 - d1;
  double lo = 0.0, hi = 1.0;
  for (int it = 0; it < 60; ++it) {
    const double m = 0.5 * (lo + hi);
    ((3 * c3 * m + 2 * c2) * m + d0 < 0 ? lo : hi) = m;
  }
  const double th = 0.5 * (lo + hi);
  const double pmin = ((c3 * th + c2) * th + d0) * th + a0;
  return pmin < std::min(a0, a1) - pmin ? th : -1.0;
}

}  // namespace armdyn::detail
