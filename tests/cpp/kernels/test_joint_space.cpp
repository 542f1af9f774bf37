// SPDX-License-Identifier: BSD-3-Clause
// Joint-space state (armdyn/kernels/joint_space.hpp): the Cartesian state of joint
// coordinates by hand on the two-link arm, the round trip to joint coordinates, and the
// kinematic cache straight from (q, qd).
#include <cmath>

#include "armdyn/errors.hpp"
#include "armdyn/kernels/joint_space.hpp"
#include "armdyn/math/quaternion.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

TEST_CASE(two_link_state_by_hand) {
  const armdyn_test::TwoLink arm;
  const ModelPtr m = arm.model();
  const double q1 = 0.7, q2 = -0.4, w1 = 1.2, w2 = -0.5;
  VecX u, v;
  state_from_joints(*m, Eigen::Vector2d(q1, q2), Eigen::Vector2d(w1, w2), u, v);
  auto dir = [](double a) { return Vec3(std::cos(a), 0, -std::sin(a)); };  // R_y(a) x
  const Vec3 x1 = arm.lc1 * dir(q1), x2 = arm.l1 * dir(q1) + arm.lc2 * dir(q1 + q2);
  CHECK_MAT_NEAR(u.segment<3>(0), x1, 1e-15);
  CHECK_MAT_NEAR(u.segment<3>(7), x2, 1e-15);
  CHECK_MAT_NEAR(quat_to_rot(u.segment<4>(10)), axis_angle(Vec3::UnitY(), q1 + q2), 1e-15);
  // velocities: d/dt of the positions; angular rates about y (body and world y coincide)
  const Vec3 y = Vec3::UnitY();
  CHECK_MAT_NEAR(v.segment<3>(0), Vec3(w1 * y.cross(x1)), 1e-15);
  CHECK_MAT_NEAR(v.segment<3>(6),
                 Vec3(w1 * y.cross(x2) + w2 * y.cross(Vec3(x2 - arm.l1 * dir(q1)))), 1e-15);
  CHECK_MAT_NEAR(v.segment<3>(3), Vec3(w1 * y), 1e-15);
  CHECK_MAT_NEAR(v.segment<3>(9), Vec3((w1 + w2) * y), 1e-15);
}

TEST_CASE(round_trip_through_the_cartesian_state) {
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  VecX q(4), qd(4);
  q << 2.8, -1.4, 0.12, -3.0;
  qd << 0.3, -1.1, 0.6, 2.5;
  VecX u, v, q2, qd2;
  state_from_joints(*m, q, qd, u, v);
  joint_coordinates(*m, u, v, q2, qd2);
  CHECK_MAT_NEAR(q2, q, 1e-13);
  CHECK_MAT_NEAR(qd2, qd, 1e-13);
  // the kinematic cache from (q, qd) equals body_kinematics of (u, v)
  std::vector<BodyKin> a(m->nb), b(m->nb);
  joint_space_kinematics(*m, q, qd, a);
  body_kinematics(*m, u.data(), v.data(), b);
  for (int i = 0; i < m->nb; ++i) {
    CHECK_MAT_NEAR(a[i].x, b[i].x, 1e-14);
    CHECK_MAT_NEAR(a[i].R, b[i].R, 1e-14);
    CHECK_MAT_NEAR(a[i].xd, b[i].xd, 1e-13);
    CHECK_MAT_NEAR(a[i].W, b[i].W, 1e-13);
  }
  // and back into (u, v)
  VecX u2(m->nq), v2(m->nv);
  cartesian_state(*m, a, u2.data(), v2.data());
  CHECK_MAT_NEAR(u2.segment<3>(7), u.segment<3>(7), 1e-14);
  CHECK_MAT_NEAR(v2, v, 1e-13);
}

TEST_CASE(refuses_loops_and_wrong_sizes) {
  ModelBuilder b;
  const Mat3 in = Vec3(0.01, 0.02, 0.015).asDiagonal();
  b.add_body("crank", 1.0, in, Vec3(0, 0, 0.25), armdyn_test::kIdentityQuat);
  b.add_body("rocker", 1.0, in, Vec3(1.0, 0, 0.25), armdyn_test::kIdentityQuat);
  b.add_revolute("A", "ground", "crank", Vec3(0, 0, 0), Vec3::UnitY());
  b.add_revolute("D", "ground", "rocker", Vec3(1, 0, 0), Vec3::UnitY());
  b.add_distance("rod", "crank", Vec3(0, 0, 0.5), "rocker", Vec3(1, 0, 0.5));
  const ModelPtr loop = b.finalize();
  VecX u, v;
  CHECK_THROWS(state_from_joints(*loop, VecX::Zero(2), VecX::Zero(2), u, v), ModelError);
  const ModelPtr m = armdyn_test::TwoLink().model();
  CHECK_THROWS(state_from_joints(*m, VecX::Zero(3), VecX::Zero(3), u, v), ModelError);
}

ARMDYN_TEST_MAIN()
