// SPDX-License-Identifier: BSD-3-Clause
// Recursive Newton-Euler inverse dynamics (armdyn/algorithm/rnea.hpp) against the closed-form
// equations of motion of a planar two-link arm and a pendulum's static torque.
#include <cmath>

#include "armdyn/algorithm/crba.hpp"
#include "armdyn/algorithm/rnea.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

TEST_CASE(two_link_arm_equations_of_motion) {
  const armdyn_test::TwoLink arm;
  const ModelPtr m = arm.model();
  Data d(*m);
  const Eigen::Vector2d qs[] = {{0.0, 0.0}, {0.7, -1.2}, {-2.0, 2.8}};
  const Eigen::Vector2d qds[] = {{0.0, 0.0}, {1.5, -0.8}, {-2.2, 3.1}};
  const Eigen::Vector2d qdds[] = {{0.0, 0.0}, {-0.4, 2.0}, {5.0, -1.0}};
  for (const auto& q : qs)
    for (const auto& qd : qds)
      for (const auto& qdd : qdds)
        CHECK_MAT_NEAR(rnea(*m, d, q, qd, qdd), arm.torques(q, qd, qdd), 1e-12);
}

TEST_CASE(pendulum_holding_torque) {
  // at rest at phi the actuator holds m g L sin(phi)
  armdyn_test::Pendulum p;
  p.phi0 = 0.6;
  const ModelPtr m = p.model();
  Data d(*m);
  for (double q : {0.0, 0.4, -1.9}) {
    const VecX tau = rnea(*m, d, VecX::Constant(1, q), VecX::Zero(1), VecX::Zero(1));
    CHECK_NEAR(tau[0], p.m * p.g * p.L * std::sin(p.phi0 + q), 1e-12);
    // with an acceleration: I_O phi'' on top
    const VecX tau2 =
        rnea(*m, d, VecX::Constant(1, q), VecX::Constant(1, 3.0), VecX::Constant(1, 2.0));
    CHECK_NEAR(tau2[0], p.io() * 2.0 + p.m * p.g * p.L * std::sin(p.phi0 + q), 1e-12);
  }
}

TEST_CASE(linear_in_the_accelerations) {
  // tau(qdd) - tau(0) = M qdd on a spatial tree
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  Data d(*m);
  VecX q(4), qd(4), qdd(4);
  q << 0.5, 0.2, -0.03, -1.1;
  qd << -0.7, 1.1, 0.4, 0.9;
  qdd << 1.3, -0.6, 2.0, 0.2;
  const VecX t1 = rnea(*m, d, q, qd, qdd);
  const VecX t0 = rnea(*m, d, q, qd, VecX::Zero(4));
  const MatX M = crba(*m, d, q);
  CHECK_MAT_NEAR(t1 - t0, M * qdd, 1e-12);
}

ARMDYN_TEST_MAIN()
