// SPDX-License-Identifier: BSD-3-Clause
// The reactions stage (armdyn/algorithm/reactions.hpp): the hinge of a pendulum carries
// m (g cos(phi) + L w^2) along the rod and m (L phi'' + g sin(phi)) across it, and no torque;
// at rest straight down, the weight.
#include <cmath>

#include "armdyn/algorithm/kkt.hpp"
#include "armdyn/algorithm/reactions.hpp"
#include "armdyn/math/quaternion.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

TEST_CASE(hinge_reaction_of_a_hanging_pendulum) {
  // at rest straight down the hinge carries the weight: m g up, no torque about the axis
  const armdyn_test::Pendulum p;
  const ModelPtr m = p.model();
  Data d(*m);
  VecX vdot(m->nv);
  body_accelerations(*m, d, 0.0, m->u0.data(), m->v0.data(), vdot.data());
  CHECK(vdot.norm() < 1e-12);
  Vec3 f, t;
  joint_reaction(*m, d, 0, f, t);
  const Joint& j = m->joints[0];
  const Mat3 B = quat_to_rot(m->u0.segment<4>(3)) * j.frame_child;  // joint frame in world
  CHECK_MAT_NEAR(B * f, Vec3(0, 0, p.m * p.g), 1e-12);
  CHECK_NEAR((B * t).dot(Vec3::UnitY()), 0.0, 1e-12);
}

TEST_CASE(swinging_pendulum_reaction_along_and_across_the_rod) {
  const armdyn_test::Pendulum p;
  const ModelPtr m = p.model();
  Data d(*m);
  const Joint& j = m->joints[0];
  for (const auto& [phi, w] : {std::pair{0.7, 2.3}, std::pair{-2.1, -0.4}, std::pair{2.9, 5.0}}) {
    VecX u, v;
    state_from_joints(*m, VecX::Constant(1, phi), VecX::Constant(1, w), u, v);
    VecX vdot(m->nv);
    body_accelerations(*m, d, 0.0, u.data(), v.data(), vdot.data());
    Vec3 f, t;
    joint_reaction(*m, d, 0, f, t);
    const Mat3 B = quat_to_rot(u.segment<4>(3)) * j.frame_child;
    const Vec3 F = B * f;                                  // on the bob, world axes
    const Vec3 rhat(-std::sin(phi), 0.0, -std::cos(phi));  // hinge -> centre of mass
    const Vec3 that = Vec3::UnitY().cross(rhat);           // direction of motion for phi' > 0
    CHECK_NEAR(-F.dot(rhat), p.m * (p.g * std::cos(phi) + p.L * w * w), 1e-11);
    CHECK_NEAR(F.dot(that), p.m * (p.L * p.phidd(phi) + p.g * std::sin(phi)), 1e-11);
    CHECK_NEAR(F.y(), 0.0, 1e-12);
    CHECK_MAT_NEAR(B * t, Vec3::Zero(), 1e-11);
  }
}

ARMDYN_TEST_MAIN()
