// SPDX-License-Identifier: BSD-3-Clause
// Quaternion algebra (armdyn/math/quaternion.hpp) against Rodrigues' formula and the identities
// of unit quaternions.
#include <cmath>

#include "armdyn/math/quaternion.hpp"
#include "check.hpp"

using namespace armdyn;

namespace {

/// Rodrigues: R = I + sin(a) K + (1 - cos(a)) K^2, K the cross-product matrix of the unit axis.
Mat3 rodrigues(const Vec3& axis, double angle) {
  const Vec3 n = axis.normalized();
  Mat3 k;
  k << 0, -n.z(), n.y(), n.z(), 0, -n.x(), -n.y(), n.x(), 0;
  return Mat3::Identity() + std::sin(angle) * k + (1 - std::cos(angle)) * k * k;
}

const Vec3 kAxes[] = {Vec3(1, 0, 0), Vec3(0.3, -0.7, 0.2), Vec3(-1, 2, 3)};
const double kAngles[] = {0.0, 0.4, -1.3, 2.9, 3.1};

}  // namespace

TEST_CASE(skew_is_the_cross_product) {
  const Vec3 a(0.3, -1.2, 2.0), b(-0.7, 0.5, 1.1);
  CHECK_MAT_NEAR(skew(a) * b, a.cross(b), 1e-15);
  CHECK_MAT_NEAR(skew(a).transpose(), -skew(a), 0.0);
}

TEST_CASE(rotation_of_exponential_is_rodrigues) {
  for (const Vec3& axis : kAxes)
    for (double angle : kAngles) {
      const Vec4 e = quat_exp(axis.normalized() * angle);
      CHECK_NEAR(e.norm(), 1.0, 1e-15);
      CHECK_NEAR(e[0], std::cos(0.5 * angle), 1e-15);
      CHECK_MAT_NEAR(quat_to_rot(e), rodrigues(axis, angle), 1e-14);
      CHECK_MAT_NEAR(axis_angle(axis.normalized(), angle), rodrigues(axis, angle), 1e-14);
    }
  // the small-angle series branch agrees with the closed form to round-off
  const Vec3 tiny(3e-9, -2e-9, 1e-9);
  const double a = tiny.norm();
  CHECK_NEAR(quat_exp(tiny)[0], std::cos(0.5 * a), 1e-16);
  CHECK_MAT_NEAR(quat_exp(tiny).tail<3>(), std::sin(0.5 * a) / a * tiny, 1e-22);
}

TEST_CASE(rotation_matrix_is_proper_orthogonal) {
  const Vec4 e = Vec4(0.3, -0.5, 0.7, 0.2).normalized();
  const Mat3 r = quat_to_rot(e);
  CHECK_MAT_NEAR(r.transpose() * r, Mat3::Identity(), 1e-15);
  CHECK_NEAR(r.determinant(), 1.0, 1e-15);
  // -e describes the same rotation
  CHECK_MAT_NEAR(quat_to_rot(-e), r, 0.0);
}

TEST_CASE(product_composes_rotations) {
  const Vec4 a = quat_exp(Vec3(0.4, -0.2, 1.0)), b = quat_exp(Vec3(-1.1, 0.3, 0.6));
  CHECK_MAT_NEAR(quat_to_rot(quat_mul(a, b)), quat_to_rot(a) * quat_to_rot(b), 1e-15);
  // the identity and the conjugate (inverse of a unit quaternion)
  const Vec4 one(1, 0, 0, 0);
  CHECK_MAT_NEAR(quat_mul(a, one), a, 0.0);
  const Vec4 conj(a[0], -a[1], -a[2], -a[3]);
  CHECK_MAT_NEAR(quat_mul(a, conj), one, 1e-16);
  // the product of unit quaternions is a unit quaternion; not commutative
  CHECK_NEAR(quat_mul(a, b).norm(), 1.0, 1e-15);
  CHECK((quat_mul(a, b) - quat_mul(b, a)).norm() > 0.1);
}

TEST_CASE(matrix_to_quaternion_round_trip) {
  // every branch of Shepperd's method: trace largest, then each diagonal entry largest
  for (const Vec3& axis :
       {Vec3(0.2, 0.1, 0.3), Vec3(1, 0.01, 0.02), Vec3(0.01, 1, 0.02), Vec3(0.01, 0.02, 1)})
    for (double angle : {0.3, 2.5, 3.1}) {
      const Vec4 e = quat_exp(axis.normalized() * angle);
      const Vec4 back = rot_to_quat(quat_to_rot(e));
      CHECK(back[0] >= 0.0);
      CHECK_MAT_NEAR(back, e[0] >= 0 ? e : Vec4(-e), 1e-14);
    }
}

TEST_CASE(rate_is_the_derivative_for_a_body_frame_angular_velocity) {
  // e(t) = e0 (x) exp(w t) turns at the constant body-frame rate w; its derivative at t = 0
  // by central differences
  const Vec4 e0 = quat_exp(Vec3(0.5, -0.4, 0.9));
  const Vec3 w(1.3, -0.6, 2.1);
  const double h = 1e-5;
  const Vec4 fd = (quat_mul(e0, quat_exp(w * h)) - quat_mul(e0, quat_exp(-w * h))) / (2 * h);
  CHECK_MAT_NEAR(quat_rate(e0, w), fd, 1e-10);
  // and R' = R skew(w) (body-frame angular velocity)
  const Mat3 rd =
      (quat_to_rot(quat_mul(e0, quat_exp(w * h))) - quat_to_rot(quat_mul(e0, quat_exp(-w * h)))) /
      (2 * h);
  CHECK_MAT_NEAR(rd, quat_to_rot(e0) * skew(w), 1e-9);
}

TEST_CASE(frame_from_z_is_right_handed_orthonormal) {
  for (const Vec3& z : {Vec3(0, 0, 1), Vec3(1, 0, 0), Vec3(0.3, -2, 0.7), Vec3(0.95, 0.1, 0)}) {
    const Mat3 f = frame_from_z(z);
    CHECK_MAT_NEAR(f.transpose() * f, Mat3::Identity(), 1e-15);
    CHECK_NEAR(f.determinant(), 1.0, 1e-15);
    CHECK_MAT_NEAR(f.col(2), z.normalized(), 1e-16);
  }
}

ARMDYN_TEST_MAIN()
