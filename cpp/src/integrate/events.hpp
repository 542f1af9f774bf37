// SPDX-License-Identifier: BSD-3-Clause
// Event handling the integrators share (private to cpp/src/integrate): the event functions'
// signs and values over a step, the location of the earliest crossing on the step's dense output,
// and the cut of the step there.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "armdyn/integrate/integrators.hpp"

namespace armdyn::detail {

/// The event functions of a run: their signs and values at the start of the step (with their
/// rates, where the system knows them), their values and rates at its end, and the location of
/// the earliest crossing on the step's dense output. A crossing is a sign change between the
/// ends, or a dip: a function of one sign at both ends whose rates turn inside the step (a joint
/// out past its stop and back) and whose cubic Hermite model of g over the step comes closer to
/// zero than the depth of its turn below the nearer end; g is then evaluated on the dense output
/// at the model's turning point, and a value of the other sign brackets the crossing.
struct EventState {
  std::vector<int>&sgn, &crossed;
  VecX &g0, &dg0, &gend, &dg1, &gbuf, &ybuf;
  bool rates = false;  // the system knows some rates

  /// buffers: the work's slots 36..38 and 40..42, its signs and crossed lists
  EventState(OdeSystem& sys, IntegratorWork& w, long n);
  int size() const { return static_cast<int>(sgn.size()); }

  /// Values, signs (a zero takes +1) and rates at the start of a step, (t, y).
  void init(OdeSystem& sys, double t, const VecX& y);
  /// Values and rates at (t, y), the signs kept (a step cut at a crossing that changed nothing:
  /// the crossed functions keep their new signs, even where round-off of the restart flips g).
  void refresh(OdeSystem& sys, double t, const VecX& y);
  /// The end of an accepted step without events becomes the next step's start.
  void next() {
    g0 = gend;
    dg0 = dg1;
  }
  /// The event functions at the start of the next step, at the new, projected (t, y): taken
  /// afresh after an event changed the system, refreshed with their signs kept after an event
  /// cut the step, else those of the step's end.
  void after_step(OdeSystem& sys, double t, const VecX& y, bool changed, bool cut);
  /// Values and rates at the step's end (tn, y1); whether a crossing or a dip may lie inside.
  bool end(OdeSystem& sys, double tn, const VecX& y1, double h);
  /// The turning point theta in (0, 1) of a suspected dip of function i, or -1.
  double dip_theta(int i, double h) const;

  /// The theta in (0, 1] of the earliest crossing on the step [t, t + h] with dense output
  /// dense(theta, y_out) (on the side where g has its new sign), or -1; crossed lists the
  /// functions that cross there.
  template <class Dense>
  double locate(OdeSystem& sys, double t, double h, const Dense& dense) {
    double best = -1.0;
    crossed.clear();
    for (int i = 0; i < size(); ++i) {
      double b = 1.0, fb = gend[i];
      if (!(gend[i] * sgn[static_cast<size_t>(i)] < 0)) {
        const double th = dip_theta(i, h);
        if (th < 0) continue;
        dense(th, ybuf);
        sys.events(t + th * h, ybuf, gbuf.data());
        if (!(gbuf[i] * sgn[static_cast<size_t>(i)] < 0)) continue;  // no dip below zero
        b = th;
        fb = gbuf[i];
      }
      b = illinois(sys, t, h, dense, i, b, fb);
      if (best < 0 || b < best - 1e-12) {
        best = b;
        crossed.assign(1, i);
      } else if (std::abs(b - best) <= 1e-12) {
        crossed.push_back(i);
      }
    }
    return best;
  }

  /// Illinois on [0, b] for function i: g(0) of sign sgn[i], g(b) = fb of the opposite sign.
  template <class Dense>
  double illinois(OdeSystem& sys, double t, double h, const Dense& dense, int i, double b,
                  double fb) {
    const int sg = sgn[static_cast<size_t>(i)];
    double a = 0.0, fa = sg * 1e-300;
    dense(0.0, ybuf);
    sys.events(t, ybuf, gbuf.data());
    if (gbuf[i] * sg > 0) fa = gbuf[i];
    int side = 0;
    for (int it = 0; it < 100 && (b - a) * h > 1e-14 * std::max(1.0, std::abs(t)); ++it) {
      const double c = (fa == fb) ? 0.5 * (a + b) : b - fb * (b - a) / (fb - fa);
      const double cc = (c > a && c < b) ? c : 0.5 * (a + b);
      dense(cc, ybuf);
      sys.events(t + cc * h, ybuf, gbuf.data());
      const double fc = gbuf[i];
      if (fc * sg > 0) {  // still before the crossing
        a = cc;
        fa = fc;
        if (side == -1) fb *= 0.5;
        side = -1;
      } else {
        b = cc;
        fb = fc;
        if (side == 1) fa *= 0.5;
        side = 1;
      }
    }
    return b;
  }

  /// After locate returned th: when the crossing lies inside the step, ends the step there (tn
  /// and y1 from the dense output); flips the crossed functions' signs and reports them
  /// (OdeSystem::on_event).
  template <class Dense>
  void take(OdeSystem& sys, double t, double h, double th, const Dense& dense, StepStats& st,
            double& tn, VecX& y1) {
    if (th > 0 && th < 1.0) {
      tn = t + th * h;
      dense(th, y1);
    }
    for (int i : crossed) {
      sgn[i] = -sgn[i];
      sys.on_event(tn, i, sgn[i]);
      ++st.events;
    }
  }
};

}  // namespace armdyn::detail
