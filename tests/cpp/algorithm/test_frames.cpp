// SPDX-License-Identifier: BSD-3-Clause
// Named frames (armdyn/algorithm/frames.hpp): the pose at assembly is the builder's input, the
// Jacobian maps qd to the frame velocity the bodies' velocities give (state_from_joints), and
// frame_pose / frame_jacobian allocate nothing once the Data exists.
#include <atomic>
#include <cstdlib>
#include <vector>

#include "alloc_counter.hpp"
#include "armdyn/algorithm/frames.hpp"
#include "armdyn/builder/builder.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/math/quaternion.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

namespace {
ModelPtr arm_with_frames(Vec3& tool_p, Mat3& tool_R) {
  ModelBuilder b = armdyn_test::spatial_arm_builder();
  const Vec4 e = quat_exp(Vec3(0.3, 0.1, -0.2));
  tool_p = Vec3(0.6, 0.15, 0.4);
  tool_R = quat_to_rot(e);
  b.add_frame("tool", "wrist", tool_p, e);
  b.add_frame("mid", "slide", Vec3(0.4, 0.1, 0.55), Vec4(1, 0, 0, 0));
  b.add_frame("site", "ground", Vec3(1, 2, 3), e);
  return b.finalize();
}
}  // namespace

TEST_CASE(pose_at_assembly_is_the_builders_input) {
  Vec3 p;
  Mat3 R;
  const ModelPtr m = arm_with_frames(p, R);
  Data d(*m);
  const Mat4& T = frame_pose(*m, d, VecX::Zero(4), "tool");
  CHECK_MAT_NEAR(Mat3(T.topLeftCorner<3, 3>()), R, 1e-14);
  CHECK_MAT_NEAR(Vec3(T.topRightCorner<3, 1>()), p, 1e-14);
  CHECK_THROWS(frame_pose(*m, d, VecX::Zero(4), "nope"), ModelError);
  CHECK_THROWS(frame_pose(*m, d, VecX::Zero(4), 3), ModelError);
  CHECK_THROWS(frame_jacobian(*m, d, VecX::Zero(3), 0), ModelError);
}

TEST_CASE(jacobian_gives_the_frame_velocity) {
  Vec3 p;
  Mat3 R;
  const ModelPtr m = arm_with_frames(p, R);
  Data d(*m);
  VecX q(4), qd(4), u, v;
  q << 0.4, -0.7, 0.05, 1.1;
  qd << 0.3, -0.2, 0.5, 0.9;
  state_from_joints(*m, q, qd, u, v);
  for (int f = 0; f < 3; ++f) {
    const Mat6X J = frame_jacobian(*m, d, q, f);
    const Vec3 pf = d.frame_pose.topRightCorner<3, 1>();
    Vec6 expect = Vec6::Zero();
    const int b = m->frames[f].body;
    if (b != kGround) {
      const Mat3 Rb = quat_to_rot(u.segment<4>(7 * b + 3));
      const Vec3 W = Rb * v.segment<3>(6 * b + 3);
      expect << v.segment<3>(6 * b) + W.cross(pf - u.segment<3>(7 * b)), W;
    }
    CHECK_MAT_NEAR(Vec6(J * qd), expect, 1e-13);
    CHECK_MAT_NEAR(Vec6(frame_jacobian_cartesian(*m, d, u, f) * v), expect, 1e-13);
  }
}

TEST_CASE(no_allocation_per_call) {
  Vec3 p;
  Mat3 R;
  const ModelPtr m = arm_with_frames(p, R);
  Data d(*m);
  VecX q(4);
  q << 0.4, -0.7, 0.05, 1.1;
  VecX u, v;
  state_from_joints(*m, q, q, u, v);
  const std::string name = "tool";
  frame_jacobian(*m, d, q, name);  // warm
  const long before = g_allocations.load();
  double sum = 0.0;
  for (int k = 0; k < 10; ++k) {
    sum += frame_pose(*m, d, q, k % 3)(0, 3);
    sum += frame_jacobian(*m, d, q, name)(0, 0);
    sum += frame_pose_cartesian(*m, d, u, 1)(1, 3);
    sum += frame_jacobian_cartesian(*m, d, u, 0)(0, 0);
  }
  CHECK(g_allocations.load() == before);
  CHECK(std::isfinite(sum));
  // the counter sees Eigen's and the standard library's allocations
  {
    const VecX x = VecX::Ones(100);
    CHECK(g_allocations.load() == before + 1);
    const std::vector<int> y(100, 1);
    CHECK(g_allocations.load() == before + 2);
    sum += x.sum() + y[0];
  }
}

ARMDYN_TEST_MAIN()
