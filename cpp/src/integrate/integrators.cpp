// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/integrate/integrators.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "armdyn/errors.hpp"

namespace armdyn {

namespace {
constexpr std::pair<Integrator, const char*> kIntegratorNames[] = {
    {Integrator::Dopri5, "dopri5"},
    {Integrator::Dop853, "dop853"},
    {Integrator::Rk4, "rk4"},
    {Integrator::Trbdf2, "trbdf2"},
    {Integrator::Kinematic, "kinematic"},
    {Integrator::Auto, "auto"},
    {Integrator::Default, "default"}};

}  // namespace

const char* integrator_name(Integrator i) {
  for (const auto& [value, name] : kIntegratorNames)
    if (value == i) return name;
  return "?";
}

Integrator integrator_from_name(const std::string& name) {
  for (const auto& [value, n] : kIntegratorNames)
    if (name == n) return value;
  throw ModelError(msg("simulate: unknown integrator '", name,
                       "' (expected 'dopri5', 'dop853', 'rk4', 'trbdf2', 'kinematic' or 'auto')"));
}

void output_times(double t0, double t1, double dt, std::vector<double>& ts) {
  ts.clear();
  if (!(dt > 0)) return;
  const double eps = 1e-9 * dt;
  for (long k = 0;; ++k) {
    const double t = t0 + static_cast<double>(k) * dt;
    if (t >= t1 - eps) break;
    ts.push_back(t);
  }
  ts.push_back(t1);
}

std::vector<double> output_times(double t0, double t1, double dt) {
  std::vector<double> ts;
  output_times(t0, t1, dt, ts);
  return ts;
}

namespace {

// Scaled max-norm of the error, sc_i = atol + rtol max(|a_i|, |b_i|) (as ode45). An RMS norm
// would divide by the 13 nb Cartesian components, most of them fixed by constraints, and so
// under-estimate the error of the few free coordinates.
double err_norm(const VecX& e, const VecX& a, const VecX& b, double rtol, double atol) {
  double s = 0.0;
  const long n = e.size();
  for (long i = 0; i < n; ++i) {
    const double sc = atol + rtol * std::max(std::abs(a[i]), std::abs(b[i]));
    s = std::max(s, std::abs(e[i]) / sc);
  }
  return s;
}

// The event functions of a run: their signs and values at the start of the step (with their
// rates, where the system knows them), their values and rates at its end, and the location of
// the earliest crossing on the step's dense output. A crossing is a sign change between the
// ends, or a dip: a function of one sign at both ends whose rates turn inside the step (a joint
// out past its stop and back) and whose cubic Hermite model of g over the step comes closer to
// zero than the depth of its turn below the nearer end; g is then evaluated on the dense output
// at the model's turning point, and a value of the other sign brackets the crossing.
struct EventState {
  std::vector<int>&sgn, &crossed;
  VecX &g0, &dg0, &gend, &dg1, &gbuf, &ybuf;
  bool rates = false;  // the system knows some rates

  // buffers: the work's slots 36..38 and 40..42, its signs and crossed lists
  EventState(OdeSystem& sys, IntegratorWork& w, long n)
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
  int size() const { return static_cast<int>(sgn.size()); }

  /// Values, signs (a zero takes +1) and rates at the start of a step, (t, y).
  void init(OdeSystem& sys, double t, const VecX& y) {
    if (sgn.empty()) return;
    sys.events(t, y, g0.data());
    for (size_t i = 0; i < sgn.size(); ++i) sgn[i] = g0[static_cast<long>(i)] < 0 ? -1 : 1;
    rates = sys.event_rates(t, y, dg0.data());
  }
  /// Values and rates at (t, y), the signs kept (a step cut at a crossing that changed nothing:
  /// the crossed functions keep their new signs, even where round-off of the restart flips g).
  void refresh(OdeSystem& sys, double t, const VecX& y) {
    if (sgn.empty()) return;
    sys.events(t, y, g0.data());
    rates = sys.event_rates(t, y, dg0.data());
  }
  /// The end of an accepted step without events becomes the next step's start.
  void next() {
    g0 = gend;
    dg0 = dg1;
  }
  /// The event functions at the start of the next step, at the new, projected (t, y): taken
  /// afresh after an event changed the system, refreshed with their signs kept after an event
  /// cut the step, else those of the step's end.
  void after_step(OdeSystem& sys, double t, const VecX& y, bool changed, bool cut) {
    if (changed)
      init(sys, t, y);
    else if (cut)
      refresh(sys, t, y);
    else if (!sgn.empty())
      next();
  }
  /// Values and rates at the step's end (tn, y1); whether a crossing or a dip may lie inside.
  bool end(OdeSystem& sys, double tn, const VecX& y1, double h) {
    if (sgn.empty()) return false;
    sys.events(tn, y1, gend.data());
    if (rates) sys.event_rates(tn, y1, dg1.data());
    for (int i = 0; i < size(); ++i)
      if (gend[i] * sgn[i] < 0 || dip_theta(i, h) >= 0) return true;
    return false;
  }

  /// The turning point theta in (0, 1) of a suspected dip of function i, or -1.
  double dip_theta(int i, double h) const {
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

  // Illinois on [0, b] for function i: g(0) of sign sgn[i], g(b) = fb of the opposite sign.
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
};

// After locate_events returned th: when the crossing lies inside the step, end the step there
// (tn and y1 from the dense output); flip the crossed functions' signs and report them.
template <class Dense>
void take_events(OdeSystem& sys, double t, double h, double th, const Dense& dense,
                 const std::vector<int>& crossed, std::vector<int>& sgn, StepStats& st, double& tn,
                 VecX& y1) {
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

// The step actually taken from t: fl(t + h) - t. Advancing the state by h while the clock
// advances by fl(t + h) lets the two drift apart by up to half an ulp of t per step; over
// millions of steps (IFToMM A01: 2000 s) that is 1e-7 s of phase, 5e-7 m of position.
inline double representable_step(double t, double h) { return (t + h) - t; }

// Cubic Hermite interpolant on [t, t + h] through (y0, f0) and (y1, f1), at theta. The
// expression is coefficient-wise, so out may be y1 itself.
inline void hermite(double th, double h, const VecX& y0, const VecX& f0, const VecX& y1,
                    const VecX& f1, VecX& out) {
  const double h00 = (1 + 2 * th) * (1 - th) * (1 - th), h10 = th * (1 - th) * (1 - th);
  const double h01 = th * th * (3 - 2 * th), h11 = th * th * (th - 1);
  out = h00 * y0 + (h10 * h) * f0 + h01 * y1 + (h11 * h) * f1;
}

// Hairer's hinit: the first step from the size of y, f(t, y) and a difference quotient of f,
// for a method whose local error is O(h^order). Uses yt and f1 as scratch. Not below 100 hmin:
// hinit's bound 100 h0 (h0 moving y by 1 % of its size) collapses when y is round-off above
// zero (joint angles of 1e-16 from an assembled state, atol 1e-12 gives h0 ~ 1e-20); the
// controller grows a small first step by up to 10x per step, and rejects one too large.
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

// The checks before each step of an error-controlled method: the step budget, landing on t1,
// step-size underflow; then h is made a representable step from t.
void guard_step(const char* name, const StepOptions& opt, const StepStats& st, double t, double t1,
                double hmin, double& h) {
  if (opt.poll) (*opt.poll)(t, t1);
  if (st.steps + st.rejected >= opt.max_steps)
    throw SolverError(
        msg(name, ": more than ", opt.max_steps, " steps before t=", t1, " (reached t=", t, ")"));
  if (t + 1.01 * h >= t1) h = t1 - t;
  if (h < hmin)
    throw SolverError(msg(name, ": step size underflow (h=", h, ") at t=", t,
                          "; the problem may be stiff or singular there"));
  h = representable_step(t, h);
}

// Runs the evaluations f of a step. A SolverError from them (a stage off the constraint
// manifold where the accelerations are not finite, e.g. at a large step near a singular
// position; a projection that does not converge) returns false, so that the step is rejected
// and retried smaller; once h * fac would fall below hmin, the error itself propagates.
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

// Output times in (t, tn] from the dense output of the step [t, t + h]
template <class Dense>
void serve_outputs(OdeSystem& sys, const std::vector<double>& touts, size_t& ko, double t, double h,
                   double tn, const Dense& dense, VecX& yo) {
  for (; ko < touts.size() && touts[ko] <= tn; ++ko) {
    dense((touts[ko] - t) / h, yo);
    sys.output(touts[ko], yo);
  }
}

// The bookkeeping DOPRI5 and DOP853 share: the output times, the step bounds, the clock (t, h),
// the rejection state and the event signs with their scratch. Each method keeps its stages, its
// error estimate, its step-size controller and its dense output.
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

  // its buffers: the work's slots 36..42, output times and event signs
  AdaptiveRun(const char* name_, OdeSystem& sys, const StepOptions& o, double t0, double t1_,
              long n, IntegratorWork& w)
      : name(name_),
        opt(o),
        t1(t1_),
        t(t0),
        hmax(o.max_step > 0 ? o.max_step : t1_ - t0),
        hmin(1e-14 * std::max(1.0, std::abs(t1_))),
        touts(w.times),
        ev(sys, w, n),
        yo(w.vec(39, n)) {
    output_times(t0, t1_, o.output_dt, touts);
    every_step = touts.empty();
  }

  /// f0 = f(t0, y) at the projected y; the output at t0, the event signs and the first step
  /// for a method of the given order (yt, f1: scratch).
  void start(OdeSystem& sys, VecX& y, VecX& f0, VecX& yt, VecX& f1, int order, StepStats& st) {
    sys.project_and_rhs(t, y, f0);
    ++st.rhs_evals;
    sys.output(t, y);
    h = initial_step(sys, t, y, f0, yt, f1, opt, hmax, hmin, order, st);
    ev.init(sys, t, y);
  }
  void guard(const StepStats& st) { guard_step(name, opt, st, t, t1, hmin, h); }
  /// Rejects the step; the next attempt takes h_retry.
  void reject(double h_retry, StepStats& st) {
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
      take_events(sys, t, h, th, dense, ev.crossed, ev.sgn, st, tn, y1);
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
    if (every_step) sys.output(t, y);
    h = hnew;
    last_rejected = false;
  }
};

}  // namespace

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
  AdaptiveRun run("dopri5", sys, opt, t0, t1, n, w);
  double &t = run.t, &h = run.h;
  run.start(sys, y, k1, yt, k2, 5, st);
  double facold = 1e-4;

  while (t < t1) {
    run.guard(st);
    // stages; one that cannot be evaluated rejects the step (evaluates)
    const bool stages_ok = evaluates(
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
    const bool last_ok = evaluates(
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
    const double en = err_norm(err, y, y1, opt.rtol, opt.atol);
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

namespace {

// DOP853 coefficients (Hairer, Norsett & Wanner, Solving ODEs I, II.10; the tables of Hairer's
// dop853.f: 12 stages, the step's end f(t + h, y1) as stage 13 and three stages more for the
// 7th-order dense output). b = a[12][0..11]; e5 and e3 give the 5th- and 3rd-order error
// estimates; d the dense-output rows beyond the first three.
namespace dop853 {
constexpr double c[16] = {0,
                          0.05260015195876773,
                          0.0789002279381516,
                          0.1183503419072274,
                          0.2816496580927726,
                          0.3333333333333333,
                          0.25,
                          0.3076923076923077,
                          0.6512820512820513,
                          0.6,
                          0.8571428571428571,
                          1.0,
                          1.0,
                          0.1,
                          0.2,
                          0.7777777777777778};
constexpr double a[16][16] = {
    {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {0.05260015195876773, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {0.0197250569845379, 0.0591751709536137, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {0.02958758547680685, 0, 0.08876275643042054, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {0.2413651341592667, 0, -0.8845494793282861, 0.924834003261792, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
     0},
    {0.037037037037037035, 0, 0, 0.17082860872947386, 0.12546768756682242, 0, 0, 0, 0, 0, 0, 0, 0,
     0, 0, 0},
    {0.037109375, 0, 0, 0.17025221101954405, 0.06021653898045596, -0.017578125, 0, 0, 0, 0, 0, 0, 0,
     0, 0, 0},
    {0.03709200011850479, 0, 0, 0.17038392571223998, 0.10726203044637328, -0.015319437748624402,
     0.008273789163814023, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {0.6241109587160757, 0, 0, -3.3608926294469414, -0.868219346841726, 27.59209969944671,
     20.154067550477894, -43.48988418106996, 0, 0, 0, 0, 0, 0, 0, 0},
    {0.47766253643826434, 0, 0, -2.4881146199716677, -0.590290826836843, 21.230051448181193,
     15.279233632882423, -33.28821096898486, -0.020331201708508627, 0, 0, 0, 0, 0, 0, 0},
    {-0.9371424300859873, 0, 0, 5.186372428844064, 1.0914373489967295, -8.149787010746927,
     -18.52006565999696, 22.739487099350505, 2.4936055526796523, -3.0467644718982196, 0, 0, 0, 0, 0,
     0},
    {2.273310147516538, 0, 0, -10.53449546673725, -2.0008720582248625, -17.9589318631188,
     27.94888452941996, -2.8589982771350235, -8.87285693353063, 12.360567175794303,
     0.6433927460157636, 0, 0, 0, 0, 0},
    {0.054293734116568765, 0, 0, 0, 0, 4.450312892752409, 1.8915178993145003, -5.801203960010585,
     0.3111643669578199, -0.1521609496625161, 0.20136540080403034, 0.04471061572777259, 0, 0, 0, 0},
    {0.056167502283047954, 0, 0, 0, 0, 0, 0.25350021021662483, -0.2462390374708025,
     -0.12419142326381637, 0.15329179827876568, 0.00820105229563469, 0.007567897660545699,
     -0.008298, 0, 0, 0},
    {0.03183464816350214, 0, 0, 0, 0, 0.028300909672366776, 0.053541988307438566,
     -0.05492374857139099, 0, 0, -0.00010834732869724932, 0.0003825710908356584,
     -0.00034046500868740456, 0.1413124436746325, 0, 0},
    {-0.42889630158379194, 0, 0, 0, 0, -4.697621415361164, 7.683421196062599, 4.06898981839711,
     0.3567271874552811, 0, 0, 0, -0.0013990241651590145, 2.9475147891527724, -9.15095847217987, 0},
};
constexpr double e5[12] = {0.01312004499419488,
                           0,
                           0,
                           0,
                           0,
                           -1.2251564463762044,
                           -0.4957589496572502,
                           1.6643771824549864,
                           -0.35032884874997366,
                           0.3341791187130175,
                           0.08192320648511571,
                           -0.022355307863886294};
constexpr double e3[12] = {-0.18980075407240762,
                           0,
                           0,
                           0,
                           0,
                           4.450312892752409,
                           1.8915178993145003,
                           -5.801203960010585,
                           -0.4226823213237919,
                           -0.1521609496625161,
                           0.20136540080403034,
                           0.02265179219836082};
constexpr double d[4][16] = {
    {-8.428938276109013, 0, 0, 0, 0, 0.5667149535193777, -3.0689499459498917, 2.38466765651207,
     2.117034582445028, -0.871391583777973, 2.2404374302607883, 0.6315787787694688,
     -0.08899033645133331, 18.148505520854727, -9.194632392478356, -4.436036387594894},
    {10.427508642579134, 0, 0, 0, 0, 242.28349177525817, 165.20045171727028, -374.5467547226902,
     -22.113666853125306, 7.733432668472264, -30.674084731089398, -9.332130526430229,
     15.697238121770845, -31.139403219565178, -9.35292435884448, 35.81684148639408},
    {19.985053242002433, 0, 0, 0, 0, -387.0373087493518, -189.17813819516758, 527.8081592054236,
     -11.57390253995963, 6.8812326946963, -1.0006050966910838, 0.7777137798053443,
     -2.778205752353508, -60.19669523126412, 84.32040550667716, 11.99229113618279},
    {-25.69393346270375, 0, 0, 0, 0, -154.18974869023643, -231.5293791760455, 357.6391179106141,
     93.40532418362432, -37.45832313645163, 104.0996495089623, 29.8402934266605, -43.53345659001114,
     96.32455395918828, -39.17726167561544, -149.72683625798564},
};
}  // namespace dop853

// out = y + h sum_{j < s} w[j] k[j]
inline void stage_point(VecX& out, const VecX& y, double h, const double* w, int s,
                        const std::array<VecX, 16>& k) {
  out = y;
  for (int j = 0; j < s; ++j)
    if (w[j] != 0.0) out += (h * w[j]) * k[j];
}

}  // namespace

void integrate_dop853(OdeSystem& sys, VecX& y, double t0, double t1, const StepOptions& opt,
                      StepStats& st, IntegratorWork* work) {
  IntegratorWork local;
  IntegratorWork& w = work ? *work : local;
  namespace C = dop853;
  // step-size control: Hairer's dop853 defaults (no PI term)
  constexpr double safe = 0.9, fac_min = 0.333, fac_max = 6.0, expo = 1.0 / 8.0;
  const long n = y.size();
  std::array<VecX, 16>& k = w.stages;
  for (VecX& ki : k)
    if (ki.size() != n) ki.resize(n);
  std::array<VecX, 7>& r = w.dense;  // y(t + th h) = y + th (r0 + (1-th)(r1 + th(r2 + ...)))
  for (VecX& ri : r)
    if (ri.size() != n) ri.resize(n);
  VecX &yt = w.vec(23, n), &y1 = w.vec(24, n), &yp = w.vec(25, n);
  AdaptiveRun run("dop853", sys, opt, t0, t1, n, w);
  double &t = run.t, &h = run.h;
  run.start(sys, y, k[0], yt, k[1], 8, st);
  auto stages = [&](int from, int to) {
    for (int s = from; s < to; ++s) {
      stage_point(yt, y, h, C::a[s], s, k);
      sys.rhs(t + C::c[s] * h, yt, k[s]);
    }
  };

  while (t < t1) {
    run.guard(st);
    const bool stages_ok = evaluates([&] { stages(1, 12); }, h, fac_min, run.hmin);
    st.rhs_evals += 11;
    if (!stages_ok) {
      run.reject(h * fac_min, st);
      continue;
    }
    stage_point(y1, y, h, C::a[12], 12, k);
    // error: the 5th-order estimate, damped by the 3rd-order one where the latter is much
    // larger (Hairer's err^2 / sqrt(err^2 + 0.01 err3^2)), in the scaled max-norm of err_norm
    double n5 = 0.0, n3 = 0.0;
    for (long i = 0; i < n; ++i) {
      double s5 = 0.0, s3 = 0.0;
      for (int j = 0; j < 12; ++j) {
        s5 += C::e5[j] * k[j][i];
        s3 += C::e3[j] * k[j][i];
      }
      const double sc = opt.atol + opt.rtol * std::max(std::abs(y[i]), std::abs(y1[i]));
      n5 = std::max(n5, std::abs(h * s5) / sc);
      n3 = std::max(n3, std::abs(h * s3) / sc);
    }
    const double deno = n5 * n5 + 0.01 * n3 * n3;
    const double en = deno > 0 ? n5 * n5 / std::sqrt(deno) : 0.0;
    if (!std::isfinite(en)) throw SolverError(msg("dop853: non-finite error estimate at t=", t));
    const double fac11 = std::pow(en, expo);
    if (en > 1.0) {
      run.reject(h / std::min(1.0 / fac_min, fac11 / safe), st);
      continue;
    }
    // accepted: project the end point and evaluate there (stage 13, the next step's first); a
    // projection that fails rejects the step
    yp = y1;
    if (!evaluates([&] { sys.project_and_rhs(t + h, yp, k[12]); }, h, fac_min, run.hmin)) {
      run.reject(h * fac_min, st);
      continue;
    }
    ++st.rhs_evals;
    y1 = yp;  // the dense output ends where the next step starts
    const double fac = std::clamp(fac11 / safe, 1.0 / fac_max, 1.0 / fac_min);
    double hnew = std::min(h / fac, run.hmax);
    if (run.last_rejected) hnew = std::min(hnew, h);
    double tn = run.step_end();
    // dense output only where it is used: an output time inside the step or a sign change of
    // an event function (three more right-hand sides)
    const bool events = run.sign_change(sys, tn, y1);
    if (events || run.output_inside(tn)) {
      const bool dense_ok = evaluates([&] { stages(13, 16); }, h, fac_min, run.hmin);
      st.rhs_evals += 3;
      if (!dense_ok) {  // nothing of the step is kept: y, t and k[0] are unchanged
        run.reject(h * fac_min, st);
        continue;
      }
      r[0] = y1 - y;
      r[1] = h * k[0] - r[0];
      r[2] = 2.0 * r[0] - h * (k[12] + k[0]);
      for (int row = 0; row < 4; ++row) {
        VecX& rr = r[3 + row];
        rr.setZero();
        for (int j = 0; j < 16; ++j)
          if (C::d[row][j] != 0.0) rr += (h * C::d[row][j]) * k[j];
      }
    }
    auto dense = [&](double th, VecX& out) {
      const double th1 = 1.0 - th;
      out =
          y +
          th * (r[0] +
                th1 * (r[1] + th * (r[2] + th1 * (r[3] + th * (r[4] + th1 * (r[5] + th * r[6]))))));
    };
    if (run.accept(sys, tn, dense, events, y, y1, st)) {  // an event cut the step
      sys.project_and_rhs(tn, y, k[0]);
      ++st.rhs_evals;
    } else {
      std::swap(k[0], k[12]);
    }
    run.signs_after_events(sys, tn, y);
    run.advance(sys, tn, y, hnew, st);
  }
}

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
  EventState ev(sys, w, n);
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
    h = representable_step(t, h);
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
      auto dense = [&](double th, VecX& out) { hermite(th, h, y, k1, y1, f1, out); };
      const double th = ev.locate(sys, t, h, dense);
      if (th < 0) {  // a suspected dip that does not reach zero
        creeps = round > 0 ? creeps + 1 : 0;
        break;
      }
      if (creeps < kMaxCreeps && round < 2 && th < 1.0 - 1e-9) {
        h = representable_step(t, h * th);
        continue;
      }
      take_events(sys, t, h, th, dense, ev.crossed, ev.sgn, st, tn, y1);
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

namespace armdyn {

void integrate_trbdf2(OdeSystem& sys, VecX& y, double t0, double t1, const StepOptions& opt,
                      StepStats& st, IntegratorWork* work) {
  IntegratorWork local;
  IntegratorWork& wk = work ? *work : local;
  // ESDIRK tableau: c = (0, 2d, 1); A = [0 0 0; d d 0; w w d]; b = last row (stiffly accurate);
  // embedded order 3: bh = ((1 - w)/3, (3w + 1)/3, d/3)
  const double d = 1.0 - std::sqrt(2.0) / 2.0, w = std::sqrt(2.0) / 4.0, c2 = 2.0 * d;
  const double e1 = w - (1.0 - w) / 3.0, e2 = w - (3.0 * w + 1.0) / 3.0, e3 = d - d / 3.0;
  constexpr double safe = 0.9, fac_min = 0.2, fac_max = 5.0;
  constexpr int max_newton = 8;

  const long n = y.size();
  VecX &K1 = wk.vec(0, n), &K2 = wk.vec(1, n), &K3 = wk.vec(2, n), &Y = wk.vec(3, n),
       &y1 = wk.vec(4, n), &R = wk.vec(5, n), &dK = wk.vec(6, n), &err = wk.vec(7, n),
       &f0 = wk.vec(8, n), &yp = wk.vec(9, n), &fp = wk.vec(10, n), &yo = wk.vec(11, n),
       &sc = wk.vec(12, n);
  MatX &J = wk.mat(0, n), &M = wk.mat(1, n);
  Eigen::PartialPivLU<MatX>& lu = wk.lu;
  std::vector<double>& touts = wk.times;
  output_times(t0, t1, opt.output_dt, touts);
  const bool every_step = touts.empty();
  size_t ko = 1;
  const double span = t1 - t0;
  const double hmax = opt.max_step > 0 ? opt.max_step : span;
  const double hmin = 1e-14 * std::max(1.0, std::abs(t1));

  double t = t0;
  sys.project_and_rhs(t, y, K1);
  ++st.rhs_evals;
  sys.output(t, y);

  auto weights = [&](const VecX& a) {
    for (long i = 0; i < n; ++i) sc[i] = opt.atol + opt.rtol * std::abs(a[i]);
  };
  auto wnorm = [&](const VecX& e) {
    double s = 0.0;
    for (long i = 0; i < n; ++i) s = std::max(s, std::abs(e[i]) / sc[i]);
    return s;
  };
  // right-hand sides spent beyond two Newton iterations per stage since the Jacobian was last
  // evaluated: what convergence with a stale Jacobian has cost so far
  long extra = 0;
  // finite-difference Jacobian of f at (t, y), with f(t, y) = K1
  auto jacobian = [&]() {
    const double eps = std::sqrt(std::numeric_limits<double>::epsilon());
    yp = y;
    for (long j = 0; j < n; ++j) {
      const double delta = eps * std::max(std::abs(y[j]), 1e-3 * sc[j] / opt.rtol + 1e-8);
      yp[j] = y[j] + delta;
      sys.rhs(t, yp, fp);
      J.col(j) = (fp - K1) / delta;
      yp[j] = y[j];
    }
    st.rhs_evals += n;
    ++st.jacobians;
    extra = 0;
  };
  double h_lu = -1.0;  // step of the current factorisation
  auto factor = [&](double h) {
    M = -h * d * J;
    M.diagonal().array() += 1.0;
    lu.compute(M);
    h_lu = h;
    ++st.lu_factorizations;
  };
  // stage K solving K = f(tc, base + h d K) by simplified Newton; returns false on divergence
  bool slow = false;
  auto stage = [&](double tc, const VecX& base, double h, VecX& K) {
    double prev = 0.0;
    for (int it = 0; it < max_newton; ++it) {
      Y = base + h * d * K;
      sys.rhs(tc, Y, R);
      ++st.rhs_evals;
      ++st.newton_iterations;
      if (it >= 2) ++extra;
      R = K - R;
      dK = lu.solve(R);
      K -= dK;
      const double nrm = h * wnorm(dK);
      if (!std::isfinite(nrm)) return false;
      if (it > 0) {
        const double theta = nrm / prev;
        if (theta > 0.9) return false;
        if (theta > 0.3) slow = true;
        // converged when the estimated remaining error is well below the tolerance
        if (theta / (1.0 - theta) * nrm <= 0.05) return true;
      } else if (nrm <= 1e-3) {
        return true;
      }
      prev = nrm;
    }
    return false;
  };

  const int ne = sys.n_events();
  EventState ev(sys, wk, n);
  VecX& yh = wk.vec(39, n);
  ev.init(sys, t, y);
  weights(y);
  // initial step: a fraction of the span, limited by the first derivative
  double h = opt.dt > 0
                 ? opt.dt
                 : std::min(hmax, 0.01 * std::max(wnorm(K1) > 0 ? 1.0 / wnorm(K1) : span, 1e-6));
  h = std::min(h, hmax);
  jacobian();
  bool jac_current = true;
  bool refreshed_in_step = false;  // the Jacobian went stale within the last step

  while (t < t1) {
    if (opt.poll) (*opt.poll)(t, t1);
    if (st.steps + st.rejected >= opt.max_steps)
      throw SolverError(
          msg("trbdf2: more than ", opt.max_steps, " steps before t=", t1, " (reached t=", t, ")"));
    if (t + 1.01 * h >= t1) h = t1 - t;
    if (h < hmin)
      throw SolverError(msg("trbdf2: step size underflow (h=", h, ") at t=", t,
                            "; the problem may be singular there"));
    h = representable_step(t, h);
    weights(y);
    if (h != h_lu) factor(h);
    slow = false;
    // stage 2 at t + 2 d h (trapezoidal), stage 3 at t + h (BDF2); predictors from K1
    K2 = K1;
    bool ok = stage(t + c2 * h, f0 = y + h * d * K1, h, K2);
    if (ok) {
      K3 = K2;
      ok = stage(t + h, f0 = y + h * w * (K1 + K2), h, K3);
    }
    if (!ok) {
      ++st.newton_failures;
      if (!jac_current) {
        jacobian();  // retry the same step with a fresh Jacobian
        jac_current = true;
        refreshed_in_step = true;
        h_lu = -1.0;
      } else {
        h *= 0.25;
        ++st.rejected;
      }
      continue;
    }
    y1 = y + h * (w * (K1 + K2) + d * K3);
    // embedded estimate, filtered through the iteration matrix for stiff components
    R = h * (e1 * K1 + e2 * K2 + e3 * K3);
    err = lu.solve(R);
    weights(y1);
    const double en = wnorm(err);
    if (!std::isfinite(en)) throw SolverError(msg("trbdf2: non-finite error estimate at t=", t));
    double fac = std::clamp(safe * std::pow(std::max(en, 1e-10), -1.0 / 3.0), fac_min, fac_max);
    if (en <= 1.0) {
      double tn = (t + h >= t1 - 1e-14 * std::max(1.0, std::abs(t1))) ? t1 : t + h;
      // dense output: cubic Hermite between (y, K1) and (y1, K3); on a copy of y1, which an
      // event cut overwrites before the outputs inside the step are served
      yh = y1;
      auto dense = [&](double th, VecX& out) { hermite(th, h, y, K1, yh, K3, out); };
      bool changed = false;  // an event changed the state or the event functions
      bool cut = false;      // an event ended the step early
      ev.crossed.clear();
      if (ne > 0 && ev.end(sys, tn, y1, h)) {
        const double th = ev.locate(sys, t, h, dense);
        take_events(sys, t, h, th, dense, ev.crossed, ev.sgn, st, tn, y1);
        cut = th > 0 && th < 1.0;
      }
      for (; !every_step && ko < touts.size() && touts[ko] <= tn; ++ko) {
        dense((touts[ko] - t) / h, yo);
        sys.output(touts[ko], yo);
      }
      if (ne > 0 && !ev.crossed.empty()) changed = sys.apply_events(tn, y1);
      y = y1;
      sys.project_and_rhs(tn, y, K1);
      ++st.rhs_evals;
      ev.after_step(sys, tn, y, changed, cut);
      t = tn;
      ++st.steps;
      if (every_step) sys.output(t, y);
      jac_current = false;
      // a fresh Jacobian costs n right-hand sides: re-evaluate it after slow convergence only
      // once the extra iterations have cost half of that (the squeezer's 91 states: 46 extra
      // iterations; the geared arm's 234: 117, where a Jacobian per step would cost about 40
      // times the step itself). A Newton failure still refreshes it at once.
      if ((slow || refreshed_in_step) && 2 * extra >= n) {
        refreshed_in_step = false;
        weights(y);
        jacobian();
        jac_current = true;
        h_lu = -1.0;
      }
      // keep the factorisation when the step would change only a little
      const double hnew = std::min(h * fac, hmax);
      if (!(hnew >= h && hnew <= 1.2 * h && h_lu > 0)) h = hnew;
    } else {
      h *= std::max(fac, fac_min);
      ++st.rejected;
    }
  }
}

}  // namespace armdyn
