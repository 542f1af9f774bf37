// SPDX-License-Identifier: BSD-3-Clause
// Joint-space forward kinematics of a tree model by composing joint transforms, templated on the
// scalar so that the Lagrange validator can differentiate it (forward-mode automatic
// differentiation) and the geometric validator can evaluate it in double. It uses only the
// model's data (joint points and frames in the body frames, coordinates in joint order) and never
// the Cartesian state or the constraint kernels of the Newton-Euler path.
//
// Per body: rotation R (body -> world), centre of mass x (world) and, when asked, the Jacobians
// of the CoM velocity Jv and of the world angular velocity Jw with respect to qdot (3 x n each).
//
// The coordinates are those of the joint-space velocity vector (n = model.nv_joint). A floating
// base (free joint) has no coordinates whose rates are its velocities (its orientation is a
// quaternion), so it takes a local chart about a reference pose (P0, R0) from the joint-space q
// (`base`): six coordinates (xi, phi) with P = P0 + R0 xi and R = R0 exp([phi]), evaluated at
// xi = phi = 0. There xi' = v and phi' = w (the base frame's velocities in its own axes), and the
// chart's generalised forces are the base wrench's components; exp is taken to second order,
// exact in value and first derivative at phi = 0, which is all the Lagrange validator
// differentiates.
#pragma once

#include <cmath>
#include <vector>

#include "armdyn/kernels/joint_space.hpp"
#include "armdyn/math/quaternion.hpp"

namespace armdyn {

template <class T>
struct JointFk {
  using V3 = Eigen::Matrix<T, 3, 1>;
  using M3 = Eigen::Matrix<T, 3, 3>;
  using J3 = Eigen::Matrix<T, 3, Eigen::Dynamic>;
  std::vector<M3> R;
  std::vector<V3> x;
  std::vector<J3> Jv, Jw;
};

template <class T>
void joint_fk(const Model& m, const Eigen::Matrix<T, Eigen::Dynamic, 1>& q, JointFk<T>& r,
              bool jacobians, const double* base = nullptr) {
  using V3 = typename JointFk<T>::V3;
  using M3 = typename JointFk<T>::M3;
  using J3 = typename JointFk<T>::J3;
  using std::cos;
  using std::sin;
  const int n = m.nv_joint;
  r.R.assign(m.nb, M3::Identity());
  r.x.assign(m.nb, V3::Zero());
  if (jacobians) {
    r.Jv.assign(m.nb, J3::Zero(3, n));
    r.Jw.assign(m.nb, J3::Zero(3, n));
  }
  const M3 I3 = M3::Identity();
  const V3 O3 = V3::Zero();
  const J3 Z = jacobians ? J3::Zero(3, n) : J3();
  for (int ji : m.tree_order) {
    const Joint& j = m.joints[ji];
    if (j.type == JointType::Free) {
      // a floating base: the chart (xi, phi) about the reference pose in base[q0 .. q0 + 7)
      const int d0 = j.dof0;
      const Vec3 P0(base[j.q0], base[j.q0 + 1], base[j.q0 + 2]);
      const M3 R0 =
          quat_to_rot(
              Vec4(base[j.q0 + 3], base[j.q0 + 4], base[j.q0 + 5], base[j.q0 + 6]).normalized())
              .cast<T>();
      const V3 xi(q[d0], q[d0 + 1], q[d0 + 2]);
      M3 S = M3::Zero();  // [phi]x
      S(0, 1) = -q[d0 + 5];
      S(0, 2) = q[d0 + 4];
      S(1, 0) = q[d0 + 5];
      S(1, 2) = -q[d0 + 3];
      S(2, 0) = -q[d0 + 4];
      S(2, 1) = q[d0 + 3];
      const M3 E = I3 + S + T(0.5) * S * S;
      const V3 P = P0.cast<T>() + R0 * xi;
      const int b = j.child;
      r.R[b] = R0 * E * j.frame_child.transpose().cast<T>();
      r.x[b] = P - r.R[b] * j.point_child.cast<T>();
      if (!jacobians) continue;
      // w (world) = R0 (1 + [phi]/2) phi' to first order; v_P = R0 xi'
      const M3 Jw = R0 * (I3 + T(0.5) * S);
      for (int k = 0; k < 3; ++k) {
        r.Jv[b].col(d0 + k) = R0.col(k);
        r.Jw[b].col(d0 + 3 + k) = Jw.col(k);
        r.Jv[b].col(d0 + 3 + k) = V3(Jw.col(k)).cross(V3(r.x[b] - P));
      }
      continue;
    }
    const bool grounded = j.parent == kGround;
    const M3& Rp = grounded ? I3 : r.R[j.parent];
    const V3& xp = grounded ? O3 : r.x[j.parent];
    const V3 P = xp + Rp * j.point_parent.cast<T>();
    const M3 A = Rp * j.frame_parent.cast<T>();
    const V3 z = A.col(2);
    T th(0.0), d(0.0);
    int c_th = -1, c_d = -1;
    switch (j.type) {
      case JointType::Revolute:
        c_th = j.dof0;
        break;
      case JointType::Prismatic:
        c_d = j.dof0;
        break;
      case JointType::Cylindrical:
        c_th = j.dof0;
        c_d = j.dof0 + 1;
        break;
      default:
        break;
    }
    if (c_th >= 0) th = q[c_th];
    if (c_d >= 0) d = q[c_d];
    M3 Rz = M3::Identity();
    const T c = cos(th), s = sin(th);
    Rz(0, 0) = c;
    Rz(0, 1) = -s;
    Rz(1, 0) = s;
    Rz(1, 1) = c;
    const V3 Pc = P + d * z;
    const int b = j.child;
    r.R[b] = A * Rz * j.frame_child.transpose().cast<T>();
    r.x[b] = Pc - r.R[b] * j.point_child.cast<T>();
    if (!jacobians) continue;
    const J3& Jvp = grounded ? Z : r.Jv[j.parent];
    const J3& Jwp = grounded ? Z : r.Jw[j.parent];
    const V3 rel = r.x[b] - xp;
    J3& Jv = r.Jv[b];
    J3& Jw = r.Jw[b];
    Jw = Jwp;
    for (int k = 0; k < n; ++k) Jv.col(k) = Jvp.col(k) + V3(Jwp.col(k)).cross(rel);
    if (c_th >= 0) {
      Jw.col(c_th) += z;
      Jv.col(c_th) += z.cross(V3(r.x[b] - Pc));
    }
    if (c_d >= 0) Jv.col(c_d) += z;
  }
}

}  // namespace armdyn
