// SPDX-License-Identifier: BSD-3-Clause
// The dynamics' derivatives (armdyn/algorithm/derivatives.hpp) from C++: against central
// differences of rnea and forward_dynamics on a spatial arm (revolute and prismatic joints,
// gravity off the axes), and without a heap allocation after the first call on a Data.
#include <atomic>
#include <cstdlib>

#include "alloc_counter.hpp"
#include "armdyn/algorithm/crba.hpp"
#include "armdyn/algorithm/derivatives.hpp"
#include "armdyn/algorithm/dynamics.hpp"
#include "armdyn/algorithm/rnea.hpp"
#include "armdyn/builder/builder.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

namespace {

struct State {
  VecX q, qd, x;
};

State state(int n) {
  State s{VecX(n), VecX(n), VecX(n)};
  for (int k = 0; k < n; ++k) {
    s.q[k] = 0.3 + 0.17 * k;
    s.qd[k] = 0.5 - 0.23 * k;
    s.x[k] = -0.4 + 0.31 * k;
  }
  return s;
}

// central differences (Richardson-extrapolated, h and h/2) of f(q, qd) along q and along qd
template <class F>
void differences(int n, const State& s, F&& f, MatX& dq, MatX& dqd) {
  dq.resize(n, n);
  dqd.resize(n, n);
  auto central = [&](int k, double h, bool rates) {
    VecX a = rates ? s.qd : s.q, b = a;
    a[k] += h;
    b[k] -= h;
    return VecX(((rates ? f(s.q, a) : f(a, s.qd)) - (rates ? f(s.q, b) : f(b, s.qd))) / (2 * h));
  };
  const double h = 1e-3;
  for (int k = 0; k < n; ++k) {
    dq.col(k) = (4 * central(k, h / 2, false) - central(k, h, false)) / 3;
    dqd.col(k) = (4 * central(k, h / 2, true) - central(k, h, true)) / 3;
  }
}

double rel(const MatX& a, const MatX& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

}  // namespace

TEST_CASE(inverse_dynamics_derivatives_equal_central_differences) {
  const ModelPtr mp = armdyn_test::spatial_arm_builder().finalize();
  const Model& m = *mp;
  Data d(m), work(m);
  const int n = d.n;
  const State s = state(n);
  inverse_dynamics_derivatives(m, d, s.q, s.qd, s.x);
  MatX dq, dqd;
  differences(
      n, s, [&](const VecX& q, const VecX& qd) { return VecX(rnea(m, work, q, qd, s.x)); }, dq,
      dqd);
  CHECK(rel(d.deriv.tau_q, dq) <= 1e-9);
  CHECK(rel(d.deriv.tau_qd, dqd) <= 1e-9);
}

TEST_CASE(forward_dynamics_derivatives_equal_central_differences) {
  const ModelPtr mp = armdyn_test::spatial_arm_builder().finalize();
  const Model& m = *mp;
  Data d(m), work(m);
  const int n = d.n;
  const State s = state(n);
  forward_dynamics_derivatives(m, d, s.q, s.qd, s.x);
  CHECK_MAT_NEAR(d.deriv.qdd, forward_dynamics(m, work, s.q, s.qd, s.x), 1e-12);
  MatX dq, dqd;
  differences(
      n, s,
      [&](const VecX& q, const VecX& qd) { return VecX(forward_dynamics(m, work, q, qd, s.x)); },
      dq, dqd);
  CHECK(rel(d.deriv.qdd_q, dq) <= 1e-9);
  CHECK(rel(d.deriv.qdd_qd, dqd) <= 1e-9);
  const MatX& M = crba(m, work, s.q);
  CHECK_MAT_NEAR(MatX(d.deriv.qdd_tau * M), MatX::Identity(n, n), 1e-12);
}

TEST_CASE(derivatives_allocate_nothing_after_the_first_call) {
  const ModelPtr mp = armdyn_test::spatial_arm_builder().finalize();
  const Model& m = *mp;
  Data d(m);
  const State s = state(d.n);
  inverse_dynamics_derivatives(m, d, s.q, s.qd, s.x);
  forward_dynamics_derivatives(m, d, s.q, s.qd, s.x);
  const long before = g_allocations.load();
  for (int i = 0; i < 3; ++i) {
    inverse_dynamics_derivatives(m, d, s.q, s.qd, s.x);
    forward_dynamics_derivatives(m, d, s.q, s.qd, s.x);
  }
  CHECK(g_allocations.load() == before);
}

ARMDYN_TEST_MAIN()
