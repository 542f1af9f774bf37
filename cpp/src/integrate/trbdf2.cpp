// SPDX-License-Identifier: BSD-3-Clause
// TR-BDF2: the trapezoidal rule followed by BDF2 as an L-stable, stiffly accurate ESDIRK, with
// simplified Newton on a finite-difference Jacobian (integrators.hpp). A step is a list of
// stages: guard, the two implicit stages, the error estimate, then the accepted step's events
// and outputs, the move to its end, the Jacobian's refresh and the next step size (or the
// rejection).
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "armdyn/errors.hpp"
#include "armdyn/integrate/integrators.hpp"
#include "dense_output.hpp"
#include "events.hpp"
#include "step_control.hpp"

namespace armdyn {

namespace detail {

/// One TR-BDF2 run from t0 to t1: its clock, its buffers (the work's slots 0..12 and 39, both
/// matrices and the LU), the Jacobian's state and the event functions.
class Trbdf2Run {
 public:
  Trbdf2Run(OdeSystem& sys, VecX& y, double t0, double t1, const StepOptions& opt, StepStats& st,
            IntegratorWork& wk);
  /// The projected initial state, its output, the event signs, the first step and Jacobian.
  void start();
  bool running() const { return t_ < t1_; }
  /// One attempt at a step of size h: accepted, rejected, or retried with a fresh Jacobian.
  void step();

 private:
  // ESDIRK tableau: c = (0, 2d, 1); A = [0 0 0; d d 0; w w d]; b = last row (stiffly accurate);
  // embedded order 3: bh = ((1 - w)/3, (3w + 1)/3, d/3)
  const double d = 1.0 - std::sqrt(2.0) / 2.0, w = std::sqrt(2.0) / 4.0, c2 = 2.0 * d;
  const double e1 = w - (1.0 - w) / 3.0, e2 = w - (3.0 * w + 1.0) / 3.0, e3 = d - d / 3.0;
  static constexpr double safe = 0.9, fac_min = 0.2, fac_max = 5.0;
  static constexpr int max_newton = 8;

  OdeSystem& sys_;
  VecX& y;
  const double t1_;
  const StepOptions& opt;
  StepStats& st;
  const long n;
  VecX &K1, &K2, &K3, &Y, &y1, &R, &dK, &err, &f0, &yp, &fp, &yo, &sc;
  MatX &J, &M;
  Eigen::PartialPivLU<MatX>& lu;
  std::vector<double>& touts;
  bool every_step;
  size_t ko = 1;
  const double span, hmax, hmin;
  double t_, h = 0.0;
  // right-hand sides spent beyond two Newton iterations per stage since the Jacobian was last
  // evaluated: what convergence with a stale Jacobian has cost so far
  long extra = 0;
  double h_lu = -1.0;  // step of the current factorisation
  bool slow = false;   // a Newton iteration of this step converged slowly
  bool jac_current = true;
  bool refreshed_in_step = false;  // the Jacobian went stale within the last step
  const int ne;
  EventState ev;
  VecX& yh;

  void weights(const VecX& a);
  double wnorm(const VecX& e) const;
  void jacobian();
  void factor(double hf);
  bool newton(double tc, const VecX& base, VecX& K);
  bool solve_stages();
  void newton_failed();
  double error_estimate();
  void accept(double fac);
  bool events_and_outputs(double& tn, bool& cut);
  void refresh_jacobian();
};

Trbdf2Run::Trbdf2Run(OdeSystem& sys, VecX& y_, double t0, double t1, const StepOptions& opt_,
                     StepStats& st_, IntegratorWork& wk)
    : sys_(sys),
      y(y_),
      t1_(t1),
      opt(opt_),
      st(st_),
      n(y_.size()),
      K1(wk.vec(0, n)),
      K2(wk.vec(1, n)),
      K3(wk.vec(2, n)),
      Y(wk.vec(3, n)),
      y1(wk.vec(4, n)),
      R(wk.vec(5, n)),
      dK(wk.vec(6, n)),
      err(wk.vec(7, n)),
      f0(wk.vec(8, n)),
      yp(wk.vec(9, n)),
      fp(wk.vec(10, n)),
      yo(wk.vec(11, n)),
      sc(wk.vec(12, n)),
      J(wk.mat(0, n)),
      M(wk.mat(1, n)),
      lu(wk.lu),
      touts(wk.times),
      span(t1 - t0),
      hmax(opt_.max_step > 0 ? opt_.max_step : span),
      hmin(1e-14 * std::max(1.0, std::abs(t1))),
      t_(t0),
      ne(sys.n_events()),
      ev(sys, wk, n),
      yh(wk.vec(39, n)) {
  output_times(t0, t1, opt.output_dt, touts);
  every_step = touts.empty();
}

void Trbdf2Run::start() {
  sys_.project_and_rhs(t_, y, K1);
  ++st.rhs_evals;
  sys_.output(t_, y);
  ev.init(sys_, t_, y);
  weights(y);
  // initial step: a fraction of the span, limited by the first derivative
  h = opt.dt > 0 ? opt.dt
                 : std::min(hmax, 0.01 * std::max(wnorm(K1) > 0 ? 1.0 / wnorm(K1) : span, 1e-6));
  h = std::min({h, hmax, sys_.step_bound(t_)});  // (OdeSystem::step_bound)
  jacobian();
  jac_current = true;
  refreshed_in_step = false;
}

void Trbdf2Run::weights(const VecX& a) {
  for (long i = 0; i < n; ++i) sc[i] = opt.atol + opt.rtol * std::abs(a[i]);
}

double Trbdf2Run::wnorm(const VecX& e) const {
  double s = 0.0;
  for (long i = 0; i < n; ++i) s = std::max(s, std::abs(e[i]) / sc[i]);
  return s;
}

// finite-difference Jacobian of f at (t, y), with f(t, y) = K1
void Trbdf2Run::jacobian() {
  const double eps = std::sqrt(std::numeric_limits<double>::epsilon());
  yp = y;
  for (long j = 0; j < n; ++j) {
    const double delta = eps * std::max(std::abs(y[j]), 1e-3 * sc[j] / opt.rtol + 1e-8);
    yp[j] = y[j] + delta;
    sys_.rhs(t_, yp, fp);
    J.col(j) = (fp - K1) / delta;
    yp[j] = y[j];
  }
  st.rhs_evals += n;
  ++st.jacobians;
  extra = 0;
}

// the iteration matrix I - h d J, factorised
void Trbdf2Run::factor(double hf) {
  M = -hf * d * J;
  M.diagonal().array() += 1.0;
  lu.compute(M);
  h_lu = hf;
  ++st.lu_factorizations;
}

// stage K solving K = f(tc, base + h d K) by simplified Newton; returns false on divergence
bool Trbdf2Run::newton(double tc, const VecX& base, VecX& K) {
  double prev = 0.0;
  for (int it = 0; it < max_newton; ++it) {
    Y = base + h * d * K;
    sys_.rhs(tc, Y, R);
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
}

// stage 2 at t + 2 d h (trapezoidal), stage 3 at t + h (BDF2); predictors from K1
bool Trbdf2Run::solve_stages() {
  K2 = K1;
  if (!newton(t_ + c2 * h, f0 = y + h * d * K1, K2)) return false;
  K3 = K2;
  return newton(t_ + h, f0 = y + h * w * (K1 + K2), K3);
}

// Newton failed: retry the same step with a fresh Jacobian, or a quarter of the step when the
// Jacobian was fresh
void Trbdf2Run::newton_failed() {
  ++st.newton_failures;
  if (!jac_current) {
    jacobian();
    jac_current = true;
    refreshed_in_step = true;
    h_lu = -1.0;
  } else {
    h *= 0.25;
    ++st.rejected;
  }
}

// the embedded estimate, filtered through the iteration matrix for stiff components, in the
// weights of the step's end
double Trbdf2Run::error_estimate() {
  R = h * (e1 * K1 + e2 * K2 + e3 * K3);
  err = lu.solve(R);
  weights(y1);
  const double en = wnorm(err);
  if (!std::isfinite(en)) throw SolverError(msg("trbdf2: non-finite error estimate at t=", t_));
  return en;
}

void Trbdf2Run::step() {
  guard_step("trbdf2", opt, st, t_, t1_, hmin, h, "the problem may be singular there");
  weights(y);
  if (h != h_lu) factor(h);
  slow = false;
  if (!solve_stages()) {
    newton_failed();
    return;
  }
  y1 = y + h * (w * (K1 + K2) + d * K3);
  const double en = error_estimate();
  const double fac = std::clamp(safe * std::pow(std::max(en, 1e-10), -1.0 / 3.0), fac_min, fac_max);
  if (en <= 1.0) {
    accept(fac);
  } else {
    h *= std::max(fac, fac_min);
    ++st.rejected;
  }
}

// The accepted step's events (the step cut at the earliest crossing: tn and y1 moved) and the
// output times inside it, from its dense output: cubic Hermite between (y, K1) and (y1, K3), on
// a copy of y1, which an event cut overwrites before the outputs are served. Returns whether an
// event changed the state or the event functions.
bool Trbdf2Run::events_and_outputs(double& tn, bool& cut) {
  yh = y1;
  auto dense = [&](double th, VecX& out) { hermite(th, h, y, K1, yh, K3, out); };
  ev.crossed.clear();
  if (ne > 0 && ev.end(sys_, tn, y1, h)) {
    const double th = ev.locate(sys_, t_, h, dense);
    ev.take(sys_, t_, h, th, dense, st, tn, y1);
    cut = th > 0 && th < 1.0;
  }
  serve_outputs(sys_, touts, ko, t_, h, tn, dense, yo);
  return ne > 0 && !ev.crossed.empty() && sys_.apply_events(tn, y1);
}

// A fresh Jacobian costs n right-hand sides: re-evaluate it after slow convergence only once
// the extra iterations have cost half of that (the squeezer's 91 states: 46 extra iterations;
// the geared arm's 234: 117, where a Jacobian per step would cost about 40 times the step
// itself). A Newton failure still refreshes it at once.
void Trbdf2Run::refresh_jacobian() {
  jac_current = false;
  if ((slow || refreshed_in_step) && 2 * extra >= n) {
    refreshed_in_step = false;
    weights(y);
    jacobian();
    jac_current = true;
    h_lu = -1.0;
  }
}

// the accepted step: events and outputs, the projected end point and its right-hand side, the
// Jacobian, and the next step (the factorisation kept when the step would change only a little)
void Trbdf2Run::accept(double fac) {
  double tn = (t_ + h >= t1_ - 1e-14 * std::max(1.0, std::abs(t1_))) ? t1_ : t_ + h;
  bool cut = false;  // an event ended the step early
  const bool changed = events_and_outputs(tn, cut);
  y = y1;
  sys_.project_and_rhs(tn, y, K1);
  ++st.rhs_evals;
  ev.after_step(sys_, tn, y, changed, cut);
  t_ = tn;
  ++st.steps;
  if (every_step) sys_.output(t_, y);
  refresh_jacobian();
  const double hnew = std::min({h * fac, hmax, sys_.step_bound(t_)});  // (OdeSystem::step_bound)
  if (!(hnew >= h && hnew <= 1.2 * h && h_lu > 0)) h = hnew;
}

}  // namespace detail

void integrate_trbdf2(OdeSystem& sys, VecX& y, double t0, double t1, const StepOptions& opt,
                      StepStats& st, IntegratorWork* work) {
  IntegratorWork local;
  detail::Trbdf2Run run(sys, y, t0, t1, opt, st, work ? *work : local);
  run.start();
  while (run.running()) run.step();
}

}  // namespace armdyn
