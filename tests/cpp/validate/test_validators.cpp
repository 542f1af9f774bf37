// SPDX-License-Identifier: BSD-3-Clause
// Validators independent of the Newton-Euler path (armdyn/validate/validators.hpp): the
// Euler-Lagrange torques of the two-link arm by hand, the Lagrange mass matrix against CRBA on a
// spatial tree, end-effector positions, and the error metrics by hand.
#include <cmath>

#include "armdyn/algorithm/crba.hpp"
#include "armdyn/algorithm/rnea.hpp"
#include "armdyn/kernels/joint_space.hpp"
#include "armdyn/math/quaternion.hpp"
#include "armdyn/validate/validators.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

TEST_CASE(lagrange_two_link_by_hand) {
  const armdyn_test::TwoLink arm;
  const LagrangeValidator lv(arm.model());
  const Eigen::Vector2d q(0.5, 1.1), qd(-1.3, 0.7), qdd(2.0, -0.6);
  CHECK_MAT_NEAR(lv.torques(q, qd, qdd), arm.torques(q, qd, qdd), 1e-11);
  CHECK_MAT_NEAR(lv.mass_matrix(q), arm.mass_matrix(q[1]), 1e-13);
}

TEST_CASE(lagrange_agrees_with_the_recursive_algorithms) {
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  const LagrangeValidator lv(m);
  Data d(*m);
  VecX q(4), qd(4), qdd(4);
  q << -0.9, 0.4, 0.06, 0.8;
  qd << 0.5, -1.2, 0.3, 1.9;
  qdd << -1.0, 0.7, 1.5, -0.4;
  CHECK_MAT_NEAR(lv.mass_matrix(q), crba(*m, d, q), 1e-12);
  CHECK_MAT_NEAR(lv.torques(q, qd, qdd), rnea(*m, d, q, qd, qdd), 1e-10);
}

TEST_CASE(end_effector_position) {
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  VecX q(4);
  q << 0.3, -0.6, 0.1, 2.0;
  VecX u, v;
  state_from_joints(*m, q, VecX::Zero(4), u, v);
  const Vec3 s(0.05, -0.02, 0.1);
  const Vec3 p = u.segment<3>(21) + quat_to_rot(u.segment<4>(24)) * s;
  CHECK_MAT_NEAR(end_effector_position(*m, 3, s, q), p, 1e-14);
  // the planar two-link arm: l1 dir(q1) + (lc2 + 0.1) dir(q1 + q2)
  const armdyn_test::TwoLink arm;
  const ModelPtr m2 = arm.model();
  const Eigen::Vector2d q2(0.4, 0.9);
  auto dir = [](double a) { return Vec3(std::cos(a), 0, -std::sin(a)); };
  CHECK_MAT_NEAR(end_effector_position(*m2, 1, Vec3(0.1, 0, 0), q2),
                 Vec3(arm.l1 * dir(0.4) + (arm.lc2 + 0.1) * dir(1.3)), 1e-15);
}

TEST_CASE(torque_error_metrics_by_hand) {
  MatX ref(3, 2), a(3, 2);
  ref << 1.0, -4.0, 2.0, 2.0, -2.0, 1.0;
  a << 1.1, -4.0, 2.0, 2.4, -1.8, 0.8;
  const TorqueErrorMetrics e = torque_error_metrics(a, ref);
  // column maxima |ref|: 2 and 4; percent = |a - ref| / max * 100
  CHECK_NEAR(e.percent(0, 0), 5.0, 1e-12);
  CHECK_NEAR(e.percent(2, 0), 10.0, 1e-12);
  CHECK_NEAR(e.percent(1, 1), 10.0, 1e-12);
  CHECK_NEAR(e.max[0], 10.0, 1e-12);
  CHECK_NEAR(e.rms[0], std::sqrt((25.0 + 0.0 + 100.0) / 3.0), 1e-12);
  CHECK_NEAR(e.rms[1], std::sqrt((0.0 + 100.0 + 25.0) / 3.0), 1e-12);
}

ARMDYN_TEST_MAIN()
