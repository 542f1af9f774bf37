// SPDX-License-Identifier: BSD-3-Clause
// The dynamic-parameter regressors' cost per call in C++ (benchmarks/cpp/CMakeLists.txt; the
// C++ side of benchmarks/regressor.py): on one Data, over 256 random states of a URDF robot, the
// median per-call time of inverse_dynamics, joint_torque_regressor (into a sized Y) and
// energy_regressor (rounds interleaved, each round every state once), and the ratio
// (joint_torque_regressor / one inverse_dynamics call; target <= 3).
#include <algorithm>
#include <armdyn/armdyn.hpp>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

struct States {
  std::vector<armdyn::VecX> q, qd, qdd;
};

States random_states(const armdyn::Model& m, int count) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  States s;
  const int nq = m.independent.nq(), nv = m.independent.nv();
  for (int k = 0; k < count; ++k) {
    armdyn::VecX q(nq), qd(nv), qdd(nv);
    for (int i = 0; i < nq; ++i) q[i] = u(rng);
    for (int f = 0; f < m.n_free; ++f) q.segment<4>(7 * f + 3).normalize();
    for (int i = 0; i < nv; ++i) qd[i] = u(rng), qdd[i] = u(rng);
    s.q.push_back(q), s.qd.push_back(qd), s.qdd.push_back(qdd);
  }
  return s;
}

template <class F>
double round_us(const States& s, F&& f) {
  const auto t0 = Clock::now();
  for (std::size_t k = 0; k < s.q.size(); ++k) f(k);
  const std::chrono::duration<double, std::micro> dt = Clock::now() - t0;
  return dt.count() / static_cast<double>(s.q.size());
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

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
