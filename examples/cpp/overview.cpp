// SPDX-License-Identifier: BSD-3-Clause
// armdyn overview: build a three-joint arm in code, evaluate its dynamics at one state, and
// simulate it for a second. The Python twin, examples/python/overview.py, prints the same lines.
#include <armdyn/armdyn.hpp>
#include <cstdio>

namespace {

void print(const char* name, const armdyn::VecX& x) {
  std::printf("%s:", name);
  for (Eigen::Index i = 0; i < x.size(); ++i) std::printf(" %.6f", x[i]);
  std::printf("\n");
}

}  // namespace

int main() {
  using armdyn::Vec3;
  using armdyn::Vec4;
  using armdyn::VecX;

  // a shoulder turning about z, a shoulder pitching about y and an elbow about y; links along x
  armdyn::ModelBuilder b(Vec3(0.0, 0.0, -9.81));
  const Vec4 upright(1.0, 0.0, 0.0, 0.0);  // Euler parameters, scalar first
  b.add_body("base", 4.0, Vec3(0.02, 0.02, 0.01).asDiagonal(), Vec3(0.0, 0.0, 0.1), upright);
  b.add_body("upper_arm", 2.0, Vec3(0.004, 0.04, 0.04).asDiagonal(), Vec3(0.2, 0.0, 0.2), upright);
  b.add_body("forearm", 1.0, Vec3(0.002, 0.015, 0.015).asDiagonal(), Vec3(0.55, 0.0, 0.2), upright);
  b.add_revolute("yaw", "ground", "base", Vec3(0.0, 0.0, 0.0), Vec3(0.0, 0.0, 1.0));
  b.add_revolute("shoulder", "base", "upper_arm", Vec3(0.0, 0.0, 0.2), Vec3(0.0, 1.0, 0.0));
  b.add_revolute("elbow", "upper_arm", "forearm", Vec3(0.4, 0.0, 0.2), Vec3(0.0, 1.0, 0.0));
  const armdyn::ModelPtr model = b.finalize();
  std::printf("bodies %d, joint coordinates %zu, degrees of freedom %d\n", model->nb,
              model->coords.size(), model->mobility);

  // one state: joint coordinates, rates and torques
  VecX q(3), qd(3), tau(3);
  q << 0.3, -0.5, 0.8;
  qd << 0.2, 1.0, -0.4;
  tau << 0.5, 2.0, -1.0;
  armdyn::Data data(*model);
  const VecX qdd = armdyn::forward_dynamics(*model, data, q, qd, tau);
  print("forward dynamics qdd", qdd);
  print("inverse dynamics tau", armdyn::inverse_dynamics(*model, data, q, qd, qdd));
  const armdyn::MatX mass = armdyn::crba(*model, data, q);
  print("mass matrix diagonal", mass.diagonal());

  // released from the assembly pose at rest: one second of motion
  armdyn::SimOptions options;
  options.integrator = armdyn::Integrator::Dop853;
  options.step.rtol = 1e-10;
  options.step.atol = 1e-12;
  options.step.output_dt = 0.25;
  const armdyn::SimResult run = armdyn::simulate(*model, 1.0, options, model->u0, model->v0);
  if (!run.error.empty()) {
    std::printf("simulation stopped: %s\n", run.error.c_str());
    return 1;
  }
  const long n = static_cast<long>(model->coords.size());
  for (long k = 0; k < run.n; ++k) {
    char label[32];
    std::snprintf(label, sizeof label, "t = %.2f q", run.t[k]);
    print(label, Eigen::Map<const VecX>(run.q.data() + k * n, n));
  }
  std::printf("energy at t = 0 and 1: %.6f %.6f J\n",
              run.kinetic_energy.front() + run.potential_energy.front(),
              run.kinetic_energy.back() + run.potential_energy.back());
  return 0;
}
