// SPDX-License-Identifier: BSD-3-Clause
// The analytical derivatives' cost per call in C++ (benchmarks/cpp/CMakeLists.txt): on one Data,
// over 256 random states of a URDF robot, the median per-call CPU time of inverse_dynamics,
// forward_dynamics (method auto, as Python's), inverse_dynamics_derivatives and
// forward_dynamics_derivatives (rounds interleaved, each round every state once), and the
// ratios the issue names (derivatives / one inverse_dynamics call).
#include <algorithm>
#include <armdyn/armdyn.hpp>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <random>
#include <string>
#include <vector>

namespace {

// the thread's CPU clock (as benchmarks/derivatives.py's process CPU clock): on the shared
// machine a round of 256 calls is often descheduled, which a wall clock would count
double cpu_us() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e6 * static_cast<double>(ts.tv_sec) + 1e-3 * static_cast<double>(ts.tv_nsec);
}

struct States {
  std::vector<armdyn::VecX> q, qd, qdd, tau;
};

States random_states(const armdyn::Model& m, int count) {
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

template <class F>
double round_us(const States& s, F&& f) {
  const double t0 = cpu_us();
  for (std::size_t k = 0; k < s.q.size(); ++k) f(k);
  return (cpu_us() - t0) / static_cast<double>(s.q.size());
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: derivatives_cost ROBOT.urdf [--floating] [--rounds N]\n");
    return 2;
  }
  bool floating = false;
  int rounds = 200;
  for (int i = 2; i < argc; ++i) {
    if (std::strcmp(argv[i], "--floating") == 0) floating = true;
    if (std::strcmp(argv[i], "--rounds") == 0 && i + 1 < argc) rounds = std::atoi(argv[++i]);
  }
  const armdyn::ModelPtr model =
      armdyn::urdf_builder(argv[1], !floating, armdyn::Vec3(0.0, 0.0, -9.81)).finalize();
  const armdyn::Model& m = *model;
  armdyn::Data d(m);
  const States s = random_states(m, 256);
  double sink = 0.0;
  std::vector<double> id, fd, idd, fdd;
  for (int r = 0; r < rounds; ++r) {
    id.push_back(round_us(s, [&](std::size_t k) {
      sink += armdyn::inverse_dynamics(m, d, s.q[k], s.qd[k], s.qdd[k])[0];
    }));
    fd.push_back(round_us(s, [&](std::size_t k) {
      sink += armdyn::forward_dynamics(m, d, s.q[k], s.qd[k], s.tau[k])[0];
    }));
    idd.push_back(round_us(s, [&](std::size_t k) {
      armdyn::inverse_dynamics_derivatives(m, d, s.q[k], s.qd[k], s.qdd[k]);
      sink += d.deriv.tau_q(0, 0);
    }));
    fdd.push_back(round_us(s, [&](std::size_t k) {
      armdyn::forward_dynamics_derivatives(m, d, s.q[k], s.qd[k], s.tau[k]);
      sink += d.deriv.qdd_q(0, 0);
    }));
  }
  const double t_id = median(id), t_fd = median(fd), t_idd = median(idd), t_fdd = median(fdd);
  std::printf(
      "%s%s n_dofs=%d: inverse_dynamics %.3f us, forward_dynamics %.3f us, "
      "inverse_dynamics_derivatives %.3f us (%.2fx inverse_dynamics), "
      "forward_dynamics_derivatives %.3f us (%.2fx inverse_dynamics, %.2fx forward_dynamics)%s\n",
      argv[1], floating ? " (floating)" : "", m.independent.nv(), t_id, t_fd, t_idd, t_idd / t_id,
      t_fdd, t_fdd / t_id, t_fdd / t_fd, sink == 0.123 ? " " : "");
  return 0;
}
