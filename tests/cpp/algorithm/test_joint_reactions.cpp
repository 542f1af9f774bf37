// SPDX-License-Identifier: BSD-3-Clause
// joint_reactions (armdyn/algorithm/reactions.hpp): a pendulum's hinge along any motion (not
// only the free one) carries m (g cos(phi) + L w^2) along the rod and m (L phi'' + g sin(phi))
// across it, and no torque but the axis'; no heap allocation per call after the first; the
// Data's pipeline settings restored when the call throws.
#include <atomic>
#include <cmath>
#include <cstdlib>

#include "alloc_counter.hpp"
#include "armdyn/algorithm/reactions.hpp"
#include "armdyn/algorithm/rnea.hpp"
#include "armdyn/builder/builder.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/math/quaternion.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

namespace {
/// The spatial arm with a tool welded to its wrist and its roll coupled to its yaw: every kind
/// of joint joint_reactions meets on a tree (revolute, prismatic, fixed, a coupling's follower).
ModelPtr welded_coupled_arm() {
  ModelBuilder b = armdyn_test::spatial_arm_builder();
  b.add_body("tool", 0.3, Vec3(1e-3, 2e-3, 3e-3).asDiagonal(), Vec3(0.6, 0.15, 0.42),
             quat_exp(Vec3(0.2, -0.1, 0.3)));
  b.add_fixed("tool_mount", "wrist", "tool", Vec3(0.58, 0.13, 0.45));
  b.add_coupling("roll_follows_yaw", "roll", "yaw", 0.5, 0.1);
  return b.finalize();
}
}  // namespace

TEST_CASE(pendulum_hinge_along_any_motion) {
  const armdyn_test::Pendulum p;
  const ModelPtr m = p.model();
  Data d(*m);
  const Joint& j = m->joints[0];
  for (const auto& [phi, w, a] :
       {std::tuple{0.7, 2.3, -4.0}, std::tuple{-2.1, -0.4, 11.0}, std::tuple{2.9, 5.0, 0.0}}) {
    const VecX q = VecX::Constant(1, phi), qd = VecX::Constant(1, w), qdd = VecX::Constant(1, a);
    Vec3 f, t;
    joint_reactions(*m, d, q, qd, qdd, 0.0, f.data(), t.data());
    // the hinge frame in world: the body turned by phi about y
    const Mat3 R = Eigen::AngleAxisd(phi, Vec3::UnitY()).toRotationMatrix();
    const Mat3 B = R * j.frame_child;
    const Vec3 F = B * f;
    const Vec3 rhat(-std::sin(phi), 0.0, -std::cos(phi));  // hinge -> centre of mass
    const Vec3 that = Vec3::UnitY().cross(rhat);           // direction of motion for phi' > 0
    CHECK_NEAR(-F.dot(rhat), p.m * (p.g * std::cos(phi) + p.L * w * w), 1e-11);
    CHECK_NEAR(F.dot(that), p.m * (p.L * a + p.g * std::sin(phi)), 1e-11);
    CHECK_NEAR(F.y(), 0.0, 1e-12);
    CHECK_MAT_NEAR(B * t, Vec3::Zero(), 1e-11);  // about the axis: the joint torque's, left out
    // the torque is the inverse dynamics': I_O phi'' + m g L sin(phi)
    const VecX& tau = rnea(*m, d, q, qd, qdd);
    CHECK_NEAR(tau[0], p.io() * a + p.m * p.g * p.L * std::sin(phi), 1e-11);
  }
}

TEST_CASE(no_allocation_per_call) {
  const ModelPtr m = welded_coupled_arm();
  Data d(*m);
  CHECK(d.ni == 3 && d.n == 4);  // the follower removed
  const long nj = static_cast<long>(m->joints.size());
  VecX f(3 * nj), t(3 * nj), q(3), qd(3), qdd(3);
  q << 0.4, -0.7, 0.05;
  qd << 0.3, -0.2, 0.5;
  qdd << 1.1, -0.6, 0.9;
  joint_reactions(*m, d, q, qd, qdd, 0.0, f.data(), t.data());  // warm: the sweep list
  const VecX f0 = f, t0 = t;
  const long before = g_allocations.load();
  double sum = 0.0;
  for (int k = 0; k < 20; ++k) {
    q[0] = 0.4 + 0.01 * k;
    joint_reactions(*m, d, q, qd, qdd, 0.1 * k, f.data(), t.data());
    sum += f.sum() + t.sum();
  }
  CHECK(g_allocations.load() == before);
  CHECK(std::isfinite(sum));
  // the welded tool's mount carries a load
  CHECK(f.segment<3>(3 * m->find_joint("tool_mount")).norm() > 0.3 * 9.81 * 0.5);
  q[0] = 0.4;
  joint_reactions(*m, d, q, qd, qdd, 0.0, f.data(), t.data());
  CHECK(f == f0 && t == t0);  // the same state, the same answer
}

TEST_CASE(settings_restored_when_it_throws) {
  const ModelPtr m = welded_coupled_arm();
  Data d(*m);
  const long nj = static_cast<long>(m->joints.size());
  VecX f(3 * nj), t(3 * nj), q(3), qd(3), qdd(3);
  q << 0.4, -0.7, 0.05;
  qd << 0.3, -0.2, 0.5;
  qdd << 1.1, -0.6, 0.9;
  joint_reactions(*m, d, q, qd, qdd, 0.0, f.data(), t.data());
  const VecX f0 = f, t0 = t;
  const int nrows = d.nrows;
  // accelerations whose forces overflow: the forces stage throws mid-call
  const VecX huge = VecX::Constant(3, 1.7e308);
  CHECK_THROWS(joint_reactions(*m, d, q, qd, huge, 0.0, f.data(), t.data()), SolverError);
  CHECK(d.nrows == nrows && d.nrows == m->nc);
  CHECK(d.joint_torques == nullptr && d.aux == nullptr && d.with_coordinate_forces);
  CHECK_THROWS(joint_reactions(*m, d, q, qd.head(2), qdd, 0.0, f.data(), t.data()), ModelError);
  joint_reactions(*m, d, q, qd, qdd, 0.0, f.data(), t.data());
  CHECK(f == f0 && t == t0);
}

ARMDYN_TEST_MAIN()
