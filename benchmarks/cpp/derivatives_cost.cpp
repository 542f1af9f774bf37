// SPDX-License-Identifier: BSD-3-Clause
// The analytical derivatives' cost per call in C++ (benchmarks/cpp/CMakeLists.txt): on one Data,
// over 256 random states of a URDF robot, the median per-call CPU time of inverse_dynamics,
// forward_dynamics (method auto, as Python's), inverse_dynamics_derivatives and
// forward_dynamics_derivatives (rounds interleaved, each round every state once), and the
// ratios the issue names (derivatives / one inverse_dynamics call).
#include <armdyn/armdyn.hpp>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "cost_harness.hpp"

using namespace cost_harness;

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
