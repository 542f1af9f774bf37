// SPDX-License-Identifier: BSD-3-Clause
// The reactions stage (armdyn/algorithm/reactions.hpp): the hinge of a pendulum carries
// m (g cos(phi) + L w^2) along the rod and m (L phi'' + g sin(phi)) across it, and no torque;
// at rest straight down, the weight. The multipliers of a tree swept from the bodies' balances
// (sweep_multipliers) equal the KKT solve's.
#include <cmath>
#include <utility>
#include <vector>

#include "armdyn/algorithm/constraints.hpp"
#include "armdyn/algorithm/forces.hpp"
#include "armdyn/algorithm/kinematics.hpp"
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

TEST_CASE(swept_multipliers_of_a_tree_equal_the_kkt_solve) {
  // spatial arm: revolute and prismatic joints at odd axes, inertias with products, gravity off
  // the axes; at a moving state the KKT solve gives (vdot, delta); the sweep, given vdot alone,
  // must give the same delta (children first, each joint's rows balancing its child)
  ModelBuilder b = armdyn_test::spatial_arm_builder();
  const ModelPtr m = b.finalize();
  std::vector<std::pair<int, int>> order;
  for (auto it = m->tree_order.rbegin(); it != m->tree_order.rend(); ++it)
    order.emplace_back(*it, m->joints[*it].child);
  Data d(*m);
  const VecX q = (VecX(4) << 0.4, -0.7, 0.05, 1.9).finished();
  const VecX qd = (VecX(4) << -1.2, 0.8, 0.3, 2.5).finished();
  VecX u, v, vdot(m->nv);
  state_from_joints(*m, q, qd, u, v);
  body_accelerations(*m, d, 0.0, u.data(), v.data(), vdot.data());
  const VecX kkt_delta = d.delta;
  CHECK(kkt_delta.norm() > 1.0);
  Data s(*m);
  load_kinematics(*m, s, u.data(), v.data());
  evaluate_constraints(*m, s, 0.0, false);
  cartesian_forces(*m, s, 0.0);
  s.delta.setRandom();  // overwritten for the swept rows
  const double residual = sweep_multipliers(*m, s, vdot, order);
  CHECK(residual < 1e-12);
  CHECK_MAT_NEAR(s.delta, kkt_delta, 1e-11 * kkt_delta.cwiseAbs().maxCoeff());
  for (int j = 0; j < static_cast<int>(m->joints.size()); ++j) {
    Vec3 f1, t1, f2, t2;
    joint_reaction(*m, d, j, f1, t1);
    joint_reaction(*m, s, j, f2, t2);
    CHECK_MAT_NEAR(f2, f1, 1e-11);
    CHECK_MAT_NEAR(t2, t1, 1e-11);
  }
  // accelerations that are not the model's motion leave an unbalanced residual, reported
  VecX wrong = vdot;
  wrong.segment<6>(0) += Vec6::Ones();  // the base turning faster about its joint axis, too
  CHECK(sweep_multipliers(*m, s, wrong, order) > 1e-3);
}

ARMDYN_TEST_MAIN()
