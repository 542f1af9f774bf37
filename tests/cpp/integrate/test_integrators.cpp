// SPDX-License-Identifier: BSD-3-Clause
// The integrators (armdyn/integrate/integrators.hpp) on ODEs with closed-form solutions: the
// harmonic oscillator (accuracy, RK4's fourth order, event location) and a stiff relaxation
// towards cos t (TR-BDF2).
#include <cmath>
#include <vector>

#include "armdyn/integrate/integrators.hpp"
#include "check.hpp"

using namespace armdyn;

namespace {

/// y'' = -y: y = (cos t, -sin t) from (1, 0); one event, y0 = 0 (at pi/2, 3 pi/2, ...).
struct Oscillator : OdeSystem {
  std::vector<double> out_t, event_t;
  std::vector<int> event_dir;
  bool with_events = true;
  void rhs(double, const VecX& y, VecX& dy) override {
    dy.resize(2);
    dy << y[1], -y[0];
  }
  void project_and_rhs(double t, VecX& y, VecX& dy) override { rhs(t, y, dy); }
  void output(double t, const VecX&) override { out_t.push_back(t); }
  int n_events() const override { return with_events ? 1 : 0; }
  void events(double, const VecX& y, double* g) override { g[0] = y[0]; }
  void on_event(double t, int, int direction) override {
    event_t.push_back(t);
    event_dir.push_back(direction);
  }
};

/// y' = -lambda (y - cos t) - sin t: y = cos t from y(0) = 1, stiff for large lambda.
struct Stiff : OdeSystem {
  double lambda = 1e5;
  void rhs(double t, const VecX& y, VecX& dy) override {
    dy.resize(1);
    dy[0] = -lambda * (y[0] - std::cos(t)) - std::sin(t);
  }
  void project_and_rhs(double t, VecX& y, VecX& dy) override { rhs(t, y, dy); }
  void output(double, const VecX&) override {}
};

VecX start() { return (VecX(2) << 1.0, 0.0).finished(); }

}  // namespace

TEST_CASE(output_grid) {
  const std::vector<double> ts = output_times(0.0, 1.0, 0.3);
  CHECK(ts.size() == 5);
  CHECK_NEAR(ts[3], 0.9, 1e-15);
  CHECK(ts.back() == 1.0);
  CHECK(output_times(0.0, 1.0, 0.0).empty());
  // 1.0 is reached by the grid within round-off: not repeated
  CHECK(output_times(0.0, 1.0, 0.1).size() == 11);
}

TEST_CASE(dopri5_and_dop853_reach_the_closed_form) {
  const double t1 = 5.0;
  for (int method = 0; method < 2; ++method) {
    Oscillator sys;
    VecX y = start();
    StepOptions opt;
    opt.rtol = 1e-10;
    opt.atol = 1e-12;
    opt.output_dt = 0.5;
    StepStats st;
    if (method == 0)
      integrate_dopri5(sys, y, 0.0, t1, opt, st);
    else
      integrate_dop853(sys, y, 0.0, t1, opt, st);
    CHECK_NEAR(y[0], std::cos(t1), 1e-8);
    CHECK_NEAR(y[1], -std::sin(t1), 1e-8);
    CHECK(st.steps > 0 && st.rhs_evals > st.steps);
    // outputs on the grid, and the zero crossings of cos t located on the dense output
    CHECK(sys.out_t.size() >= 11);
    CHECK(sys.event_t.size() == 2);
    if (sys.event_t.size() == 2) {
      CHECK_NEAR(sys.event_t[0], 0.5 * M_PI, 1e-8);
      CHECK_NEAR(sys.event_t[1], 1.5 * M_PI, 1e-8);
      CHECK(sys.event_dir[0] == -1 && sys.event_dir[1] == +1);
    }
  }
}

TEST_CASE(rk4_is_fourth_order) {
  double err[2];
  for (int k = 0; k < 2; ++k) {
    Oscillator sys;
    sys.with_events = false;
    VecX y = start();
    StepOptions opt;
    opt.dt = k == 0 ? 0.1 : 0.05;
    StepStats st;
    integrate_rk4(sys, y, 0.0, 2.0, opt, st);
    err[k] = std::abs(y[0] - std::cos(2.0));
    CHECK(st.steps == (k == 0 ? 20 : 40));
  }
  // halving the step divides the error by 2^4
  CHECK_NEAR(err[0] / err[1], 16.0, 0.5);
}

TEST_CASE(rk4_locates_events) {
  // every step size, including those whose shortened step ends just short of the crossing
  // (dt = 0.05 once crept towards it without reaching it until max_steps)
  for (const double dt : {0.01, 0.02, 0.05, 0.1, 0.13}) {
    Oscillator sys;
    VecX y = start();
    StepOptions opt;
    opt.dt = dt;
    opt.max_steps = 100000;
    StepStats st;
    integrate_rk4(sys, y, 0.0, 2.0, opt, st);
    CHECK(sys.event_t.size() == 1);
    CHECK(st.steps < 2.0 / dt + 10);
    // RK4's global error ~ dt^4 / 100 on this problem
    const double tol = std::max(1e-8, std::pow(dt, 4));
    if (!sys.event_t.empty()) {
      CHECK_NEAR(sys.event_t[0], 0.5 * M_PI, tol);
      CHECK(sys.event_dir[0] == -1);
    }
    CHECK_NEAR(y[0], std::cos(2.0), tol);
  }
}

TEST_CASE(trbdf2_is_stable_on_a_stiff_problem) {
  Stiff sys;
  VecX y = VecX::Constant(1, 1.0);
  StepOptions opt;
  opt.rtol = 1e-6;
  opt.atol = 1e-8;
  StepStats st;
  integrate_trbdf2(sys, y, 0.0, 2.0, opt, st);
  CHECK_NEAR(y[0], std::cos(2.0), 1e-5);
  // an explicit method needs ~lambda t / 3.3 = 60000 steps for stability; TR-BDF2 follows the
  // smooth solution
  CHECK(st.steps < 2000);
  CHECK(st.jacobians >= 1);
}

/// y'' = a: y = a t^2 / 2 from y(0) = y0 (a polynomial every Runge-Kutta pair integrates exactly).
struct Falling : OdeSystem {
  double a = 30.0;
  void rhs(double, const VecX& y, VecX& dy) override {
    dy.resize(2);
    dy << y[1], a;
  }
  void project_and_rhs(double t, VecX& y, VecX& dy) override { rhs(t, y, dy); }
  void output(double, const VecX&) override {}
};

TEST_CASE(first_step_from_a_round_off_start_does_not_underflow) {
  // a joint angle of 1e-16 (an assembled state's round-off) with atol 1e-12: Hairer's hinit alone
  // proposes h ~ 1e-20, below the step floor; the first step is held at 100 hmin
  for (const bool dop853 : {false, true}) {
    Falling sys;
    VecX y = (VecX(2) << 1e-16, 0.0).finished();
    StepOptions opt;
    opt.rtol = 1e-11;
    opt.atol = 1e-12;
    StepStats st;
    if (dop853)
      integrate_dop853(sys, y, 0.0, 1.0, opt, st);
    else
      integrate_dopri5(sys, y, 0.0, 1.0, opt, st);
    CHECK_NEAR(y[0], 15.0, 1e-10);
    CHECK_NEAR(y[1], 30.0, 1e-10);
    CHECK(st.steps < 40);  // from 1e-12 growing up to 10x per step
  }
}

ARMDYN_TEST_MAIN()
