// SPDX-License-Identifier: BSD-3-Clause
// Euler parameters (unit quaternions), SCALAR-FIRST: e = [e0, e1, e2, e3], e0 = cos(phi/2).
// R(e) maps body coordinates to world coordinates. Angular velocity omega is expressed in the
// BODY frame, so de/dt = 1/2 e (x) [0, omega] (Nikravesh 1988, eq. 6.100 with L(e)^T).
#pragma once

#include <cmath>

#include "armdyn/math/types.hpp"

namespace armdyn {

/// Skew-symmetric matrix: skew(a) b = a x b.
inline Mat3 skew(const Vec3& a) {
  Mat3 s;
  s << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return s;
}

/// Rotation matrix (body -> world) of a unit quaternion [e0, e1, e2, e3].
inline Mat3 quat_to_rot(const Vec4& e) {
  const double e0 = e[0], e1 = e[1], e2 = e[2], e3 = e[3];
  Mat3 r;
  r << 1 - 2 * (e2 * e2 + e3 * e3), 2 * (e1 * e2 - e0 * e3), 2 * (e1 * e3 + e0 * e2),
      2 * (e1 * e2 + e0 * e3), 1 - 2 * (e1 * e1 + e3 * e3), 2 * (e2 * e3 - e0 * e1),
      2 * (e1 * e3 - e0 * e2), 2 * (e2 * e3 + e0 * e1), 1 - 2 * (e1 * e1 + e2 * e2);
  return r;
}

/// Unit quaternion of a proper rotation matrix (Shepperd's method), scalar-first, e0 >= 0.
inline Vec4 rot_to_quat(const Mat3& r) {
  Vec4 e;
  const double tr = r.trace();
  if (tr > r(0, 0) && tr > r(1, 1) && tr > r(2, 2)) {
    const double s = 2.0 * std::sqrt(1.0 + tr);
    e << 0.25 * s, (r(2, 1) - r(1, 2)) / s, (r(0, 2) - r(2, 0)) / s, (r(1, 0) - r(0, 1)) / s;
  } else if (r(0, 0) > r(1, 1) && r(0, 0) > r(2, 2)) {
    const double s = 2.0 * std::sqrt(1.0 + r(0, 0) - r(1, 1) - r(2, 2));
    e << (r(2, 1) - r(1, 2)) / s, 0.25 * s, (r(0, 1) + r(1, 0)) / s, (r(0, 2) + r(2, 0)) / s;
  } else if (r(1, 1) > r(2, 2)) {
    const double s = 2.0 * std::sqrt(1.0 + r(1, 1) - r(0, 0) - r(2, 2));
    e << (r(0, 2) - r(2, 0)) / s, (r(0, 1) + r(1, 0)) / s, 0.25 * s, (r(1, 2) + r(2, 1)) / s;
  } else {
    const double s = 2.0 * std::sqrt(1.0 + r(2, 2) - r(0, 0) - r(1, 1));
    e << (r(1, 0) - r(0, 1)) / s, (r(0, 2) + r(2, 0)) / s, (r(1, 2) + r(2, 1)) / s, 0.25 * s;
  }
  if (e[0] < 0) e = -e;
  return e.normalized();
}

/// Quaternion product a (x) b (scalar-first): rotation b followed by a, R(a (x) b) = R(a) R(b).
inline Vec4 quat_mul(const Vec4& a, const Vec4& b) {
  Vec4 c;
  c[0] = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
  c[1] = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
  c[2] = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
  c[3] = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
  return c;
}

/// Unit quaternion of a rotation vector theta (axis * angle), exact exponential map.
inline Vec4 quat_exp(const Vec3& theta) {
  const double a = theta.norm();
  Vec4 e;
  if (a < 1e-8) {
    // series to O(a^4): sin(a/2)/a = 1/2 - a^2/48
    e << 1.0 - a * a / 8.0, (0.5 - a * a / 48.0) * theta;
  } else {
    e << std::cos(0.5 * a), std::sin(0.5 * a) / a * theta;
  }
  return e;
}

/// de/dt for body-frame angular velocity: 1/2 e (x) [0, w].
inline Vec4 quat_rate(const Vec4& e, const Vec3& w_body) {
  Vec4 wq(0.0, w_body.x(), w_body.y(), w_body.z());
  return 0.5 * quat_mul(e, wq);
}

/// Rotation of angle `angle` [rad] about unit axis `axis`.
inline Mat3 axis_angle(const Vec3& axis, double angle) {
  return quat_to_rot(quat_exp(axis * angle));
}

/// A right-handed orthonormal frame whose third column is the unit vector z.
inline Mat3 frame_from_z(const Vec3& z) {
  Vec3 zz = z.normalized();
  // pick the world axis least aligned with z, so the construction is deterministic and stable
  Vec3 helper = std::abs(zz.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  Vec3 x = (helper - helper.dot(zz) * zz).normalized();
  Vec3 y = zz.cross(x);
  Mat3 f;
  f.col(0) = x;
  f.col(1) = y;
  f.col(2) = zz;
  return f;
}

}  // namespace armdyn
