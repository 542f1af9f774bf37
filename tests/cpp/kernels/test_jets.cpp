// SPDX-License-Identifier: BSD-3-Clause
// Body kinematics and jets (armdyn/kernels/jets.hpp): a point on a rotating body, the jets'
// Jacobians against their rates, and joint-coordinate jets against the joint-space state.
#include <cmath>

#include "armdyn/kernels/jets.hpp"
#include "armdyn/kernels/joint_space.hpp"
#include "armdyn/math/quaternion.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

namespace {

/// One free-floating body: u = (x, e), v = (xd, w body).
struct OneBody {
  ModelPtr m;
  VecX u, v;
  OneBody() {
    ModelBuilder b;
    b.add_body("b", 1.0, Vec3(0.1, 0.2, 0.25).asDiagonal(), Vec3::Zero(),
               armdyn_test::kIdentityQuat);
    b.add_free("free", "b");
    m = b.finalize();
    u.resize(7);
    v.resize(6);
    u << 0.3, -0.2, 1.1, quat_exp(Vec3(0.4, -0.9, 0.3));
    v << 0.5, 0.1, -0.4, 1.2, -0.7, 2.0;
  }
};

}  // namespace

TEST_CASE(body_state_and_world_angular_velocity) {
  OneBody s;
  std::vector<BodyKin> kin(1);
  body_kinematics(*s.m, s.u.data(), s.v.data(), kin);
  const Mat3 r = quat_to_rot(s.u.segment<4>(3));
  CHECK_MAT_NEAR(kin[0].x, s.u.head<3>(), 0.0);
  CHECK_MAT_NEAR(kin[0].R, r, 1e-15);
  CHECK_MAT_NEAR(kin[0].xd, s.v.head<3>(), 0.0);
  CHECK_MAT_NEAR(kin[0].w, s.v.tail<3>(), 0.0);
  CHECK_MAT_NEAR(kin[0].W, r * s.v.tail<3>(), 1e-15);
  // ground: identity pose at rest
  CHECK_MAT_NEAR(kin_of(kin, kGround).R, Mat3::Identity(), 0.0);
  CHECK(kin_of(kin, kGround).xd.norm() == 0.0);
}

TEST_CASE(point_on_a_rotating_body) {
  // p = x + R s: p' = xd + W x (R s), p'' (no accelerations) = W x (W x R s)
  OneBody s;
  std::vector<BodyKin> kin(1);
  body_kinematics(*s.m, s.u.data(), s.v.data(), kin);
  const Vec3 sp(0.2, -0.5, 0.3);
  const VecJet j = point_jet(kin[0], sp, 0);
  const Vec3 rs = kin[0].R * sp;
  const Vec3 W = kin[0].W;
  CHECK_MAT_NEAR(j.val, kin[0].x + rs, 1e-15);
  CHECK_MAT_NEAR(j.rate, kin[0].xd + W.cross(rs), 1e-14);
  CHECK_MAT_NEAR(j.bias, W.cross(W.cross(rs)), 1e-14);
  // the rate by differences of the position along the motion
  const double h = 1e-6;
  const VecX up = armdyn_test::advance(*s.m, s.u, s.v, h),
             um = armdyn_test::advance(*s.m, s.u, s.v, -h);
  const Vec3 pp = up.head<3>() + quat_to_rot(up.segment<4>(3)) * sp;
  const Vec3 pm = um.head<3>() + quat_to_rot(um.segment<4>(3)) * sp;
  CHECK_MAT_NEAR((pp - pm) / (2 * h), j.rate, 1e-8);
  // n^T J v = n . rate for every direction n
  for (const Vec3& n : {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0.3, -0.4, 0.8)}) {
    const Row12 l = j.left(n);
    CHECK_NEAR(l.head<6>().dot(s.v), n.dot(j.rate), 1e-14);
  }
  // a direction fixed in the body: rate W x d, no translation in its Jacobian
  const VecJet d = direction_jet(kin[0], Vec3::UnitZ(), 0);
  CHECK_MAT_NEAR(d.rate, W.cross(kin[0].R.col(2)), 1e-14);
  CHECK_NEAR(d.left(Vec3(1, 2, 3)).head<3>().norm(), 0.0, 0.0);
  // the fused forms agree with the general ones
  const AxisJet a = axis_jet(kin[0], Vec3::UnitZ());
  CHECK_MAT_NEAR(a.val, d.val, 1e-15);
  CHECK_MAT_NEAR(a.rate, d.rate, 1e-15);
  CHECK_MAT_NEAR(a.bias, d.bias, 1e-14);
}

TEST_CASE(joint_coordinate_jets_on_a_tree) {
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  const int n = static_cast<int>(m->coords.size());
  VecX q(n), qd(n), qdd(n);
  q << 0.4, -0.7, 0.08, 1.9;
  qd << 1.1, -0.5, 0.3, 2.2;
  qdd << -0.8, 1.4, 0.6, -2.0;
  VecX u, v;
  state_from_joints(*m, q, qd, u, v);
  std::vector<BodyKin> kin(m->nb);
  body_kinematics(*m, u.data(), v.data(), kin);
  const VecX vdot = armdyn_test::cartesian_acceleration_fd(*m, q, qd, qdd);
  for (int c = 0; c < n; ++c) {
    const ScalarJet s = coord_jet(*m, kin, c);
    CHECK_NEAR(s.val, q[c], 1e-13);
    CHECK_NEAR(coord_value(*m, kin, c), q[c], 1e-13);
    CHECK_NEAR(s.rate, qd[c], 1e-13);
    // J v = rate, and J vdot + bias = qdd
    const Joint& j = m->joints[m->coords[c].joint];
    double jv = 0.0;
    if (j.parent != kGround) jv += s.J.head<6>().dot(v.segment<6>(6 * j.parent));
    if (j.child != kGround) jv += s.J.tail<6>().dot(v.segment<6>(6 * j.child));
    CHECK_NEAR(jv, qd[c], 1e-13);
    CHECK_NEAR(coord_acceleration(*m, s, c, vdot), qdd[c], 1e-7);
  }
  CHECK(m->coords[2].angular == false);  // the prismatic joint's displacement
}

ARMDYN_TEST_MAIN()
