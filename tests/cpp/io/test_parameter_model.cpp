// SPDX-License-Identifier: BSD-3-Clause
// model_with_dynamic_parameters (armdyn/io/parameter_model.hpp) on a builder's spatial arm with
// rotated body frames, a prismatic joint, joint friction and a gyroscopic actuator: the result's
// dynamic_parameters are pi, its inverse dynamics Y(model) pi; bad vectors name the culprit.
#include <cmath>
#include <random>
#include <string>

#include "armdyn/algorithm/dynamics.hpp"
#include "armdyn/algorithm/regressor.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/io/parameter_model.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

namespace {

ModelPtr arm() {
  ModelBuilder b = armdyn_test::spatial_arm_builder();
  b.add_joint_friction("reach", 0.4, 0.6, 0.02);
  b.add_actuator("pitch", 30.0, 2e-4, 1.0, 1e-3, 0.01, nullptr, true);
  return b.finalize();
}

/// pi far from the model's: a point mass added to each body at c, friction, offsets, Ia.
VecX identified(const Model& m) {
  VecX pi = dynamic_parameters(m);
  const ParameterLayout L = dynamic_parameter_layout(m);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  for (int i = 0; i < static_cast<int>(L.bodies.size()); ++i) {
    const double mass = 0.5 + u(rng);
    const Vec3 c(u(rng), u(rng), u(rng));
    const Mat3 I = mass * (c.squaredNorm() * Mat3::Identity() - c * c.transpose());
    Eigen::Matrix<double, 10, 1> p;
    p << mass, mass * c, I(0, 0), I(0, 1), I(1, 1), I(0, 2), I(1, 2), I(2, 2);
    pi.segment<10>(L.body_offset(i)) += p;
  }
  for (int k = 0; k < m.independent.n; ++k)
    pi.segment<4>(L.coord_offset(k)) << 0.3 + u(rng), 0.2 + u(rng), 5.0, 0.1 + u(rng);
  return pi;
}

}  // namespace

TEST_CASE(parameters_and_inverse_dynamics) {
  const ModelPtr m = arm();
  const VecX before = dynamic_parameters(*m);
  const VecX pi = identified(*m);
  const ModelPtr out = model_with_dynamic_parameters(*m, pi);
  VecX expected = pi;
  const ParameterLayout L = dynamic_parameter_layout(*m);
  for (int k = 0; k < m->independent.n; ++k) expected[L.coord_offset(k) + 2] = 0.0;  // offsets
  CHECK_MAT_NEAR(dynamic_parameters(*out), expected, 1e-12 * expected.cwiseAbs().maxCoeff());
  CHECK((dynamic_parameters(*m) - before).cwiseAbs().maxCoeff() == 0.0);  // m unchanged
  Data dm(*m), dout(*out);
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  MatX Y;
  for (int s = 0; s < 5; ++s) {
    VecX q(m->independent.nq()), qd(m->independent.nv()), qdd(m->independent.nv());
    for (int i = 0; i < q.size(); ++i) q[i] = 0.5 * n(rng), qd[i] = n(rng), qdd[i] = n(rng);
    joint_torque_regressor(*m, dm, q, qd, qdd, Y);
    const VecX tau = inverse_dynamics(*out, dout, q, qd, qdd);
    CHECK_MAT_NEAR(tau, Y * expected, 1e-12 * tau.cwiseAbs().maxCoeff());
  }
}

TEST_CASE(bad_vectors_name_the_culprit) {
  const ModelPtr m = arm();
  const VecX pi = dynamic_parameters(*m);
  const std::vector<std::string> names = dynamic_parameter_names(*m);
  auto with = [&](int i, double v) {
    VecX p = pi;
    p[i] = v;
    return p;
  };
  auto message = [&](const VecX& p) {
    return THROWN_MESSAGE(model_with_dynamic_parameters(*m, p), ModelError);
  };
  CHECK(message(pi.head(pi.size() - 1)).find("pi must have") != std::string::npos);
  CHECK(message(with(3, NAN)).find("('" + names[3] + "') must be finite") != std::string::npos);
  CHECK(message(with(10, -1.0)).find("body 'upper': mass") != std::string::npos);
  CHECK(message(with(14, -1.0)).find("body 'upper'") != std::string::npos);  // Ixx: not PSD
  const int fv = static_cast<int>(pi.size()) - 4;
  CHECK(message(with(fv, -1.0)).find("'" + names[fv] + "' must be >= 0") != std::string::npos);
}

ARMDYN_TEST_MAIN()
