// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/solver/kinematics.hpp"

#include <cmath>

#include "armdyn/math/quaternion.hpp"

namespace armdyn {

void body_kinematics(const Model& m, const double* u, const double* v, std::vector<BodyKin>& kin) {
  kin.resize(m.nb);
  for (int i = 0; i < m.nb; ++i) {
    const double* ui = u + 7 * i;
    BodyKin& k = kin[i];
    k.x = Vec3(ui[0], ui[1], ui[2]);
    k.R = quat_to_rot(Vec4(ui[3], ui[4], ui[5], ui[6]));
    if (v) {
      const double* vi = v + 6 * i;
      k.xd = Vec3(vi[0], vi[1], vi[2]);
      k.w = Vec3(vi[3], vi[4], vi[5]);
    } else {
      k.xd.setZero();
      k.w.setZero();
    }
  }
}

const BodyKin& kin_of(const std::vector<BodyKin>& kin, int b) {
  static const BodyKin ground{};
  return b == kGround ? ground : kin[b];
}

VecJet direction_jet(const BodyKin& k, const Vec3& a, int slot) {
  VecJet j;
  const Vec3 wa = k.w.cross(a);
  j.val = k.R * a;
  j.rate = k.R * wa;
  j.bias = k.R * k.w.cross(wa);
  j.J.setZero();
  j.J.block<3, 3>(0, 6 * slot + 3) = -k.R * skew(a);
  return j;
}

VecJet point_jet(const BodyKin& k, const Vec3& s, int slot) {
  VecJet j;
  const Vec3 ws = k.w.cross(s);
  j.val = k.x + k.R * s;
  j.rate = k.xd + k.R * ws;
  j.bias = k.R * k.w.cross(ws);
  j.J.setZero();
  j.J.block<3, 3>(0, 6 * slot).setIdentity();
  j.J.block<3, 3>(0, 6 * slot + 3) = -k.R * skew(s);
  return j;
}

VecJet difference(const VecJet& p, const VecJet& q) {
  VecJet j;
  j.val = p.val - q.val;
  j.rate = p.rate - q.rate;
  j.bias = p.bias - q.bias;
  j.J = p.J - q.J;
  return j;
}

ScalarJet dot(const VecJet& a, const VecJet& b) {
  ScalarJet s;
  s.val = a.val.dot(b.val);
  s.rate = a.rate.dot(b.val) + a.val.dot(b.rate);
  s.J = b.val.transpose() * a.J + a.val.transpose() * b.J;
  s.bias = a.bias.dot(b.val) + 2.0 * a.rate.dot(b.rate) + a.val.dot(b.bias);
  return s;
}

ScalarJet component(const VecJet& a, int k) {
  ScalarJet s;
  s.val = a.val[k];
  s.rate = a.rate[k];
  s.J = a.J.row(k);
  s.bias = a.bias[k];
  return s;
}

ScalarJet atan2_jet(const ScalarJet& s, const ScalarJet& c) {
  // theta = atan2(s, c): theta' = (c s' - s c') / r^2, and the bias follows from differentiating
  // once more: (c s_bias - s c_bias) / r^2 - 2 theta' (c c' + s s') / r^2
  ScalarJet t;
  const double r2 = s.val * s.val + c.val * c.val;
  t.val = std::atan2(s.val, c.val);
  t.rate = (c.val * s.rate - s.val * c.rate) / r2;
  t.J = (c.val * s.J - s.val * c.J) / r2;
  t.bias = (c.val * s.bias - s.val * c.bias) / r2 -
           2.0 * t.rate * (c.val * c.rate + s.val * s.rate) / r2;
  return t;
}

VecJet joint_axis_jet(const Model& m, const std::vector<BodyKin>& kin, int joint, int side,
                      int axis) {
  const Joint& jt = m.joints[joint];
  if (side == 0) return direction_jet(kin_of(kin, jt.parent), jt.frame_parent.col(axis), 0);
  return direction_jet(kin_of(kin, jt.child), jt.frame_child.col(axis), 1);
}

VecJet joint_separation_jet(const Model& m, const std::vector<BodyKin>& kin, int joint) {
  const Joint& jt = m.joints[joint];
  return difference(point_jet(kin_of(kin, jt.child), jt.point_child, 1),
                    point_jet(kin_of(kin, jt.parent), jt.point_parent, 0));
}

ScalarJet coord_jet(const Model& m, const std::vector<BodyKin>& kin, int coord) {
  const Coord& c = m.coords[coord];
  if (c.angular) {
    // angle of the child frame's x axis in the parent frame's (x, y) plane
    const VecJet xa = joint_axis_jet(m, kin, c.joint, 0, 0);
    const VecJet ya = joint_axis_jet(m, kin, c.joint, 0, 1);
    const VecJet xb = joint_axis_jet(m, kin, c.joint, 1, 0);
    return atan2_jet(dot(ya, xb), dot(xa, xb));
  }
  // displacement along the parent's joint axis
  return dot(joint_axis_jet(m, kin, c.joint, 0, 2), joint_separation_jet(m, kin, c.joint));
}

}  // namespace armdyn
