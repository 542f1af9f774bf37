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

Mat3x12 VecJet::full() const {
  Mat3x12 J = Mat3x12::Zero();
  for (int s = 0; s < 2; ++s) {
    J.block<3, 3>(0, 6 * s).diagonal().setConstant(lin[s]);
    if (has_ang[s]) J.block<3, 3>(0, 6 * s + 3) = ang[s];
  }
  return J;
}

Row12 VecJet::left(const Vec3& n) const {
  Row12 r;
  for (int s = 0; s < 2; ++s) {
    r.segment<3>(6 * s) = lin[s] * n.transpose();
    if (has_ang[s])
      r.segment<3>(6 * s + 3).noalias() = n.transpose() * ang[s];
    else
      r.segment<3>(6 * s + 3).setZero();
  }
  return r;
}

namespace {
// -R skew(a), column by column: -R (a x e_k) = R (e_k x a)
inline Mat3 minus_r_skew(const Mat3& R, const Vec3& a) {
  Mat3 M;
  M.col(0) = a[1] * R.col(2) - a[2] * R.col(1);
  M.col(1) = a[2] * R.col(0) - a[0] * R.col(2);
  M.col(2) = a[0] * R.col(1) - a[1] * R.col(0);
  return M;
}
}  // namespace

VecJet direction_jet(const BodyKin& k, const Vec3& a, int slot) {
  VecJet j;
  const Vec3 wa = k.w.cross(a);
  j.val.noalias() = k.R * a;
  j.rate.noalias() = k.R * wa;
  j.bias.noalias() = k.R * k.w.cross(wa);
  j.has_ang[slot] = true;
  j.ang[slot] = minus_r_skew(k.R, a);
  return j;
}

VecJet point_jet(const BodyKin& k, const Vec3& s, int slot) {
  VecJet j = direction_jet(k, s, slot);
  j.val += k.x;
  j.rate += k.xd;
  j.lin[slot] = 1.0;
  return j;
}

VecJet difference(const VecJet& p, const VecJet& q) {
  VecJet j;
  j.val = p.val - q.val;
  j.rate = p.rate - q.rate;
  j.bias = p.bias - q.bias;
  for (int s = 0; s < 2; ++s) {
    j.lin[s] = p.lin[s] - q.lin[s];
    j.has_ang[s] = p.has_ang[s] || q.has_ang[s];
    if (p.has_ang[s] && q.has_ang[s])
      j.ang[s] = p.ang[s] - q.ang[s];
    else if (p.has_ang[s])
      j.ang[s] = p.ang[s];
    else if (q.has_ang[s])
      j.ang[s] = -q.ang[s];
  }
  return j;
}

ScalarJet dot(const VecJet& a, const VecJet& b) {
  ScalarJet s;
  s.val = a.val.dot(b.val);
  s.rate = a.rate.dot(b.val) + a.val.dot(b.rate);
  s.bias = a.bias.dot(b.val) + 2.0 * a.rate.dot(b.rate) + a.val.dot(b.bias);
  for (int k = 0; k < 2; ++k) {
    s.J.segment<3>(6 * k) = a.lin[k] * b.val.transpose() + b.lin[k] * a.val.transpose();
    auto w = s.J.segment<3>(6 * k + 3);
    if (a.has_ang[k] && b.has_ang[k])
      w.noalias() = b.val.transpose() * a.ang[k] + a.val.transpose() * b.ang[k];
    else if (a.has_ang[k])
      w.noalias() = b.val.transpose() * a.ang[k];
    else if (b.has_ang[k])
      w.noalias() = a.val.transpose() * b.ang[k];
    else
      w.setZero();
  }
  return s;
}

ScalarJet component(const VecJet& a, int k) {
  ScalarJet s;
  s.val = a.val[k];
  s.rate = a.rate[k];
  s.bias = a.bias[k];
  for (int sl = 0; sl < 2; ++sl) {
    s.J.segment<3>(6 * sl).setZero();
    s.J[6 * sl + k] = a.lin[sl];
    if (a.has_ang[sl])
      s.J.segment<3>(6 * sl + 3) = a.ang[sl].row(k);
    else
      s.J.segment<3>(6 * sl + 3).setZero();
  }
  return s;
}

ScalarJet atan2_jet(const ScalarJet& s, const ScalarJet& c, bool value) {
  // theta = atan2(s, c): theta' = (c s' - s c') / r^2, and the bias follows from differentiating
  // once more: (c s_bias - s c_bias) / r^2 - 2 theta' (c c' + s s') / r^2
  ScalarJet t;
  const double r2 = s.val * s.val + c.val * c.val;
  t.val = value ? std::atan2(s.val, c.val) : 0.0;
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

ScalarJet coord_jet(const Model& m, const std::vector<BodyKin>& kin, int coord, bool value) {
  const Coord& c = m.coords[coord];
  if (c.angular) {
    // angle of the child frame's x axis in the parent frame's (x, y) plane
    const VecJet xa = joint_axis_jet(m, kin, c.joint, 0, 0);
    const VecJet ya = joint_axis_jet(m, kin, c.joint, 0, 1);
    const VecJet xb = joint_axis_jet(m, kin, c.joint, 1, 0);
    return atan2_jet(dot(ya, xb), dot(xa, xb), value);
  }
  // displacement along the parent's joint axis
  return dot(joint_axis_jet(m, kin, c.joint, 0, 2), joint_separation_jet(m, kin, c.joint));
}

}  // namespace armdyn
