// SPDX-License-Identifier: BSD-3-Clause
// The dynamic-parameter regressors' cost per call in C++ (benchmarks/cpp/CMakeLists.txt; the
// C++ side of benchmarks/regressor.py): on one Data, over 256 random states of a URDF robot, the
// median per-call CPU time of inverse_dynamics, joint_torque_regressor (into a sized Y) and
// energy_regressor (rounds interleaved, each round every state once), and the ratio
// (joint_torque_regressor / one inverse_dynamics call; target <= 3).
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
    std::fprintf(stderr, "usage: regressor_cost ROBOT.urdf [--floating] [--mimic] [--rounds N]\n");
    return 2;
  }
  bool floating = false, mimic = false;
  int rounds = 200;
  for (int i = 2; i < argc; ++i) {
    if (std::strcmp(argv[i], "--floating") == 0) floating = true;
    if (std::strcmp(argv[i], "--mimic") == 0) mimic = true;
    if (std::strcmp(argv[i], "--rounds") == 0 && i + 1 < argc) rounds = std::atoi(argv[++i]);
  }
  const armdyn::ModelPtr model =
      armdyn::urdf_builder(argv[1], !floating, armdyn::Vec3(0.0, 0.0, -9.81), true, mimic)
          .finalize();
  const armdyn::Model& m = *model;
  armdyn::Data d(m);
  const States s = random_states(m, 256);
  armdyn::MatX Y;
  armdyn::VecX h;
  double sink = 0.0;
  std::vector<double> id, reg, en;
  for (int r = 0; r < rounds; ++r) {
    id.push_back(round_us(s, [&](std::size_t k) {
      sink += armdyn::inverse_dynamics(m, d, s.q[k], s.qd[k], s.qdd[k])[0];
    }));
    reg.push_back(round_us(s, [&](std::size_t k) {
      armdyn::joint_torque_regressor(m, d, s.q[k], s.qd[k], s.qdd[k], Y);
      sink += Y(0, 0);
    }));
    en.push_back(round_us(s, [&](std::size_t k) {
      armdyn::energy_regressor(m, d, s.q[k], s.qd[k], h);
      sink += h[0];
    }));
  }
  const double t_id = median(id), t_reg = median(reg), t_en = median(en);
  std::printf(
      "%s%s n_dofs=%d n_params=%ld: inverse_dynamics %.3f us, joint_torque_regressor %.3f us "
      "(%.2fx inverse_dynamics), energy_regressor %.3f us (%.2fx inverse_dynamics)%s\n",
      argv[1], floating ? " (floating)" : "", m.independent.nv(), static_cast<long>(Y.cols()), t_id,
      t_reg, t_reg / t_id, t_en, t_en / t_id, sink == 0.123 ? " " : "");
  return 0;
}
