// SPDX-License-Identifier: BSD-3-Clause
// The per-call timing harness of the C++ cost benchmarks (derivatives_cost, regressor_cost):
// random states of a model, rounds timed on the thread's CPU clock, the median.
#pragma once

#include <algorithm>
#include <armdyn/armdyn.hpp>
#include <ctime>
#include <random>
#include <vector>

namespace cost_harness {

// the thread's CPU clock (as the Python benchmarks' process CPU clock): on the shared machine a
// round of 256 calls is often descheduled, which a wall clock would count
inline double cpu_us() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e6 * static_cast<double>(ts.tv_sec) + 1e-3 * static_cast<double>(ts.tv_nsec);
}

struct States {
  std::vector<armdyn::VecX> q, qd, qdd, tau;
};

// count states, every entry uniform in [-1, 1] (floating bases' quaternions normalised)
inline States random_states(const armdyn::Model& m, int count) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  States s;
  const int nq = m.independent.nq(), nv = m.independent.nv();
  for (int k = 0; k < count; ++k) {
    armdyn::VecX q(nq), qd(nv), qdd(nv), tau(nv);
    for (int i = 0; i < nq; ++i) q[i] = u(rng);
    for (int f = 0; f < m.n_free; ++f) q.segment<4>(7 * f + 3).normalize();
    for (int i = 0; i < nv; ++i) qd[i] = u(rng), qdd[i] = u(rng), tau[i] = u(rng);
    s.q.push_back(q), s.qd.push_back(qd), s.qdd.push_back(qdd), s.tau.push_back(tau);
  }
  return s;
}

// one round: f(k) for every state k; CPU microseconds per call
template <class F>
double round_us(const States& s, F&& f) {
  const double t0 = cpu_us();
  for (std::size_t k = 0; k < s.q.size(); ++k) f(k);
  return (cpu_us() - t0) / static_cast<double>(s.q.size());
}

inline double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace cost_harness
