// SPDX-License-Identifier: BSD-3-Clause
// armdyn::Poll (armdyn/poll.hpp) in the stepping loops: a run with a poll that does not
// stop equals the run without one, bit for bit; a cancel flag or a callback throwing
// Interrupted stops every integrator and the kinematic path, and simulate() returns the outputs
// so far, equal to the first outputs of the uninterrupted run.
#include <atomic>
#include <cmath>
#include <string>

#include "armdyn/errors.hpp"
#include "armdyn/poll.hpp"
#include "armdyn/simulate/simulate.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

namespace {

SimOptions options(Integrator method) {
  SimOptions o;
  o.integrator = method;
  o.step.output_dt = 0.01;
  o.step.rtol = 1e-10;
  o.step.atol = 1e-10;
  if (method == Integrator::Rk4) o.step.dt = 1e-4;
  return o;
}

ModelPtr model_for(Integrator method) {
  armdyn_test::Pendulum p;
  p.phi0 = 0.7;
  ModelBuilder b = p.builder();
  if (method == Integrator::Kinematic)
    b.add_drive(
        "hinge",
        Profile::callback(
            [](double t) { return ProfileValue{std::sin(t), std::cos(t), -std::sin(t)}; }, "sin"));
  return b.finalize();
}

/// The rows of r equal the first rows of the full run (all but the last for an
/// error-controlled run, whose final step lands on its end).
void check_prefix(const SimResult& r, const SimResult& full, bool last_too) {
  CHECK(r.n > 1 && r.n < full.n);
  const long rows = last_too ? r.n : r.n - 1;
  double dq = 0.0;
  for (long i = 0; i < rows; ++i) {
    CHECK(r.t[i] == full.t[i]);
    dq = std::max(dq, std::abs(r.q[i] - full.q[i]));
  }
  CHECK(dq == 0.0);
}

const Integrator kMethods[] = {Integrator::Rk4, Integrator::Dopri5, Integrator::Dop853,
                               Integrator::Trbdf2, Integrator::Kinematic};

}  // namespace

TEST_CASE(a_poll_that_does_not_stop_changes_nothing) {
  for (Integrator method : kMethods) {
    const ModelPtr m = model_for(method);
    SimOptions o = options(method);
    const SimResult plain = simulate(*m, 5.0, o, m->u0, m->v0);
    long calls = 0;
    Poll poll(
        [&](double t, double t_end) {
          CHECK(t >= 0.0 && t <= t_end && t_end == 5.0);
          ++calls;
        },
        0.0);  // every clock read calls back
    o.step.poll = &poll;
    const SimResult polled = simulate(*m, 5.0, o, m->u0, m->v0);
    CHECK(polled.error.empty() && !polled.interrupted && !polled.exception);
    CHECK(calls > 10);
    CHECK(polled.n == plain.n);
    CHECK(polled.q == plain.q && polled.t == plain.t);
  }
}

TEST_CASE(a_cancel_flag_stops_every_loop_with_the_outputs_so_far) {
  for (Integrator method : kMethods) {
    const ModelPtr m = model_for(method);
    SimOptions o = options(method);
    const SimResult full = simulate(*m, 5.0, o, m->u0, m->v0);
    std::atomic<bool> cancel{false};
    // the flag is set once the loop passes t = 2 (another thread would set it the same way)
    Poll poll([&](double t, double) { cancel = cancel || t > 2.0; }, 0.0, &cancel);
    o.step.poll = &poll;
    const SimResult r = simulate(*m, 5.0, o, m->u0, m->v0);
    CHECK(r.interrupted && r.exception && r.error == "run cancelled");
    CHECK(r.t.back() >= 2.0 - 0.1 && r.t.back() < 5.0);
    check_prefix(r, full, method == Integrator::Rk4 || method == Integrator::Kinematic);
  }
}

TEST_CASE(a_callback_throwing_interrupted_stops_the_run) {
  for (Integrator method : kMethods) {
    const ModelPtr m = model_for(method);
    SimOptions o = options(method);
    const SimResult full = simulate(*m, 5.0, o, m->u0, m->v0);
    Poll poll(
        [](double t, double) {
          if (t > 1.0) throw Interrupted("stop at 1 s");
        },
        0.0);
    o.step.poll = &poll;
    const SimResult r = simulate(*m, 5.0, o, m->u0, m->v0);
    CHECK(r.interrupted && r.error == "stop at 1 s");
    bool rethrown = false;
    try {
      std::rethrow_exception(r.exception);
    } catch (const Interrupted&) {
      rethrown = true;
    }
    CHECK(rethrown);
    check_prefix(r, full, method == Integrator::Rk4 || method == Integrator::Kinematic);
  }
}

TEST_CASE(without_a_poll_interrupted_propagates_from_a_profile) {
  // a profile callback's Interrupted (the bindings' KeyboardInterrupt) is kept like a poll's
  armdyn_test::Pendulum p;
  p.phi0 = 0.7;
  ModelBuilder b = p.builder();
  b.add_joint_torque("hinge", Profile::callback(
                                  [](double t) {
                                    if (t > 0.5) throw Interrupted("from the profile");
                                    return ProfileValue{0.0, 0.0, 0.0};
                                  },
                                  "stop"));
  const ModelPtr m = b.finalize();
  SimOptions o = options(Integrator::Dopri5);
  o.step.max_step = 0.01;  // a step evaluating beyond 0.5 s starts at most 0.01 s before it
  const SimResult r = simulate(*m, 2.0, o, m->u0, m->v0);
  CHECK(r.interrupted && r.error == "from the profile");
  CHECK(r.t.back() >= 0.48 && r.t.back() <= 0.5);
}

ARMDYN_TEST_MAIN()
