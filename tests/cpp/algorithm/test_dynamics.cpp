// SPDX-License-Identifier: BSD-3-Clause
// Joint-space forward and inverse dynamics (armdyn/algorithm/dynamics.hpp): the Joint (CRBA /
// RNEA) and Cartesian (KKT) methods agree, forward and inverse dynamics are inverse to each
// other, and closed forms: a pendulum, a prismatic body falling at g, the two-link arm.
#include <cmath>

#include "armdyn/algorithm/dynamics.hpp"
#include "armdyn/errors.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

TEST_CASE(pendulum_closed_form_by_both_methods) {
  armdyn_test::Pendulum p;
  p.phi0 = 1.1;
  const ModelPtr m = p.model();
  Data d(*m);
  for (DynamicsMethod method : {DynamicsMethod::Joint, DynamicsMethod::Cartesian}) {
    for (double q : {0.0, 0.5, -2.0}) {
      const VecX qdd = forward_dynamics(*m, d, VecX::Constant(1, q), VecX::Constant(1, 1.3),
                                        VecX::Zero(1), 0.0, method);
      CHECK_NEAR(qdd[0], p.phidd(p.phi0 + q), 1e-12);
      // a joint torque adds tau / I_O
      const VecX qdd2 = forward_dynamics(*m, d, VecX::Constant(1, q), VecX::Zero(1),
                                         VecX::Constant(1, 0.7), 0.0, method);
      CHECK_NEAR(qdd2[0], p.phidd(p.phi0 + q) + 0.7 / p.io(), 1e-12);
    }
  }
}

TEST_CASE(prismatic_body_falls_at_g) {
  // a slider along a tilted axis n: qdd = g . n, whatever the rate
  ModelBuilder b(Vec3(0, 0, -9.81));
  const Vec3 n = Vec3(1, 0, -2).normalized();
  b.add_body("block", 3.0, Vec3(0.1, 0.1, 0.1).asDiagonal(), Vec3(0, 0, 1),
             armdyn_test::kIdentityQuat);
  b.add_prismatic("rail", "ground", "block", Vec3(0, 0, 1), n);
  const ModelPtr m = b.finalize();
  Data d(*m);
  for (DynamicsMethod method : {DynamicsMethod::Joint, DynamicsMethod::Cartesian}) {
    const VecX qdd = forward_dynamics(*m, d, VecX::Constant(1, 0.4), VecX::Constant(1, -2.0),
                                      VecX::Zero(1), 0.0, method);
    CHECK_NEAR(qdd[0], Vec3(0, 0, -9.81).dot(n), 1e-12);
    // holding it takes the weight's component along the rail
    const VecX tau =
        inverse_dynamics(*m, d, VecX::Constant(1, 0.4), VecX::Zero(1), VecX::Zero(1), 0.0, method);
    CHECK_NEAR(tau[0], -3.0 * Vec3(0, 0, -9.81).dot(n), 1e-12);
  }
}

TEST_CASE(cartesian_kkt_equals_joint_space_crba) {
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  Data d(*m);
  VecX q(4), qd(4), tau(4);
  q << -0.4, 0.8, 0.05, 1.3;
  qd << 1.2, -0.3, 0.5, -2.0;
  tau << 2.0, -5.0, 10.0, 0.3;
  const VecX joint = forward_dynamics(*m, d, q, qd, tau, 0.0, DynamicsMethod::Joint);
  const VecX cart = forward_dynamics(*m, d, q, qd, tau, 0.0, DynamicsMethod::Cartesian);
  CHECK_MAT_NEAR(joint, cart, 1e-10);
  const VecX autom = forward_dynamics(*m, d, q, qd, tau);
  CHECK_MAT_NEAR(autom, joint, 0.0);
  // inverse dynamics by both methods, and the round trip ID(FD(tau)) = tau
  const VecX t1 = inverse_dynamics(*m, d, q, qd, joint, 0.0, DynamicsMethod::Joint);
  const VecX t2 = inverse_dynamics(*m, d, q, qd, joint, 0.0, DynamicsMethod::Cartesian);
  CHECK_MAT_NEAR(t1, tau, 1e-10);
  CHECK_MAT_NEAR(t2, tau, 1e-9);
}

TEST_CASE(two_link_forward_dynamics_by_hand) {
  const armdyn_test::TwoLink arm;
  const ModelPtr m = arm.model();
  Data d(*m);
  const Eigen::Vector2d q(0.3, -0.9), qd(1.1, 2.0), tau(4.0, -1.5);
  // qdd = M^-1 (tau - C qd - G): the closed-form torques at qdd = 0 are C qd + G
  const Eigen::Vector2d qdd =
      arm.mass_matrix(q[1]).inverse() * (tau - arm.torques(q, qd, Eigen::Vector2d::Zero()));
  CHECK_MAT_NEAR(forward_dynamics(*m, d, q, qd, tau), qdd, 1e-12);
}

TEST_CASE(method_names_and_bad_input) {
  CHECK(dynamics_method("auto", "f") == DynamicsMethod::Auto);
  CHECK(dynamics_method("joint", "f") == DynamicsMethod::Joint);
  CHECK(dynamics_method("cartesian", "f") == DynamicsMethod::Cartesian);
  CHECK(dynamics_method("crba", "f") == DynamicsMethod::Crba);
  CHECK(dynamics_method("aba", "f") == DynamicsMethod::Aba);
  CHECK_THROWS(dynamics_method("crba", "f", false), ModelError);  // inverse dynamics
  CHECK_THROWS(dynamics_method("lu", "f"), ModelError);
  const ModelPtr m = armdyn_test::TwoLink().model();
  Data d(*m);
  CHECK_THROWS(forward_dynamics(*m, d, VecX::Zero(3), VecX::Zero(2), VecX::Zero(2)), ModelError);
  CHECK_THROWS(forward_dynamics(*m, d, VecX::Zero(2), VecX::Constant(2, NAN), VecX::Zero(2)),
               ModelError);
  // a Data made for another model is refused
  const ModelPtr other = armdyn_test::TwoLink().model();
  Data wrong(*other);
  CHECK_THROWS(forward_dynamics(*m, wrong, VecX::Zero(2), VecX::Zero(2), VecX::Zero(2)),
               ModelError);
}

ARMDYN_TEST_MAIN()
