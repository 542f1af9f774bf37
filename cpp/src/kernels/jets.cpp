// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/kernels/jets.hpp"

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
      k.W.noalias() = k.R * k.w;
    } else {
      k.xd.setZero();
      k.w.setZero();
      k.W.setZero();
    }
  }
}

const BodyKin kGroundKin{};

namespace {
// (R^T (arm x n))^T: n^T times the angular block -skew(arm) R
inline Eigen::Matrix<double, 1, 3> ang_left(const Mat3& R, const Vec3& arm, const Vec3& n) {
  return (R.transpose() * arm.cross(n)).transpose();
}
}  // namespace

Row12 VecJet::left(const Vec3& n) const {
  Row12 r;
  for (int s = 0; s < 2; ++s) {
    r.segment<3>(6 * s) = lin[s] * n.transpose();
    if (has_ang[s])
      r.segment<3>(6 * s + 3) = ang_left(*R[s], arm[s], n);
    else
      r.segment<3>(6 * s + 3).setZero();
  }
  return r;
}

VecJet direction_jet(const BodyKin& k, const Vec3& a, int slot) {
  // world vector p = R a: p' = W x p, p'' (zero accelerations) = W x (W x p)
  VecJet j;
  j.val.noalias() = k.R * a;
  j.rate = k.W.cross(j.val);
  j.bias = k.W.cross(j.rate);
  j.has_ang[slot] = true;
  j.arm[slot] = j.val;
  j.R[slot] = &k.R;
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
    if (p.has_ang[s] && q.has_ang[s]) {
      j.arm[s] = p.arm[s] - q.arm[s];
      j.R[s] = p.R[s];
    } else if (p.has_ang[s]) {
      j.arm[s] = p.arm[s];
      j.R[s] = p.R[s];
    } else if (q.has_ang[s]) {
      j.arm[s] = -q.arm[s];
      j.R[s] = q.R[s];
    }
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
    // b^T (-skew(arm_a) R) + a^T (-skew(arm_b) R) = (R^T (arm_a x b + arm_b x a))^T
    if (a.has_ang[k] && b.has_ang[k])
      w = (a.R[k]->transpose() * (a.arm[k].cross(b.val) + b.arm[k].cross(a.val))).transpose();
    else if (a.has_ang[k])
      w = ang_left(*a.R[k], a.arm[k], b.val);
    else if (b.has_ang[k])
      w = ang_left(*b.R[k], b.arm[k], a.val);
    else
      w.setZero();
  }
  return s;
}

SepJet sep_jet(const BodyKin& ka, const Vec3& sa, const BodyKin& kb, const Vec3& sb) {
  SepJet d;
  d.ra.noalias() = ka.R * sa;
  d.rb.noalias() = kb.R * sb;
  const Vec3 wra = ka.W.cross(d.ra), wrb = kb.W.cross(d.rb);
  d.val = kb.x + d.rb - ka.x - d.ra;
  d.rate = kb.xd + wrb - ka.xd - wra;
  d.bias = kb.W.cross(wrb) - ka.W.cross(wra);
  return d;
}

ScalarJet dot_axis_sep(const AxisJet& p, const Mat3& Ra, const SepJet& d, const Mat3& Rb) {
  // slot 0: -p^T | Ra^T (p x d) + p^T skew(r_a) R_a = Ra^T (p x (d + r_a))
  // slot 1: +p^T | p^T (-skew(r_b) R_b) = Rb^T (r_b x p)
  ScalarJet s;
  s.val = p.val.dot(d.val);
  s.rate = p.rate.dot(d.val) + p.val.dot(d.rate);
  s.bias = p.bias.dot(d.val) + 2.0 * p.rate.dot(d.rate) + p.val.dot(d.bias);
  s.J.segment<3>(0) = -p.val.transpose();
  s.J.segment<3>(3) = (Ra.transpose() * p.val.cross(d.val + d.ra)).transpose();
  s.J.segment<3>(6) = p.val.transpose();
  s.J.segment<3>(9) = (Rb.transpose() * d.rb.cross(p.val)).transpose();
  return s;
}

double coord_value(const Model& m, const std::vector<BodyKin>& kin, int coord) {
  const Coord& c = m.coords[coord];
  const Joint& jt = m.joints[c.joint];
  const BodyKin& ka = kin_of(kin, jt.parent);
  const BodyKin& kb = kin_of(kin, jt.child);
  if (c.angular) {
    const Vec3 xb = kb.R * jt.frame_child.col(0);
    return std::atan2((ka.R * jt.frame_parent.col(1)).dot(xb),
                      (ka.R * jt.frame_parent.col(0)).dot(xb));
  }
  const Vec3 d = kb.x + kb.R * jt.point_child - ka.x - ka.R * jt.point_parent;
  return (ka.R * jt.frame_parent.col(2)).dot(d);
}

void coord_jet_into(const Model& m, const std::vector<BodyKin>& kin, int coord, bool value,
                    ScalarJet& t) {
  const Coord& c = m.coords[coord];
  const Joint& jt = m.joints[c.joint];
  const BodyKin& ka = kin_of(kin, jt.parent);
  const BodyKin& kb = kin_of(kin, jt.child);
  if (!c.angular) {
    // displacement along the parent's joint axis
    t = dot_axis_sep(axis_jet(ka, jt.frame_parent.col(2)), ka.R,
                     sep_jet(ka, jt.point_parent, kb, jt.point_child), kb.R);
    return;
  }
  // angle of the child frame's x axis in the parent frame's (x, y) plane
  const AxisJet xa = axis_jet(ka, jt.frame_parent.col(0));
  const AxisJet ya = axis_jet(ka, jt.frame_parent.col(1));
  const AxisJet xb = axis_jet(kb, jt.frame_child.col(0));
  // theta = atan2(s, c) with s = ya . xb, c = xa . xb: theta' = (c s' - s c') / r^2 and
  // bias (c s_bias - s c_bias) / r^2 - 2 theta' (c c' + s s') / r^2; the two dot products'
  // Jacobians (as put_axes_row's in constraint_rows.cpp) folded into one R^T product per side
  const double sv = ya.val.dot(xb.val), cv = xa.val.dot(xb.val);
  const double sr = ya.rate.dot(xb.val) + ya.val.dot(xb.rate);
  const double cr = xa.rate.dot(xb.val) + xa.val.dot(xb.rate);
  const double sb = ya.bias.dot(xb.val) + 2.0 * ya.rate.dot(xb.rate) + ya.val.dot(xb.bias);
  const double cb = xa.bias.dot(xb.val) + 2.0 * xa.rate.dot(xb.rate) + xa.val.dot(xb.bias);
  const double ir2 = 1.0 / (sv * sv + cv * cv);
  t.val = value ? std::atan2(sv, cv) : 0.0;
  t.rate = (cv * sr - sv * cr) * ir2;
  t.bias = (cv * sb - sv * cb) * ir2 - 2.0 * t.rate * (cv * cr + sv * sr) * ir2;
  const Vec3 g = ((cv * ir2) * ya.val - (sv * ir2) * xa.val).cross(xb.val);
  t.J.segment<3>(0).setZero();
  t.J.segment<3>(3).noalias() = g.transpose() * ka.R;
  t.J.segment<3>(6).setZero();
  t.J.segment<3>(9).noalias() = -g.transpose() * kb.R;
}

ScalarJet coord_jet(const Model& m, const std::vector<BodyKin>& kin, int coord, bool value) {
  ScalarJet t;
  coord_jet_into(m, kin, coord, value, t);
  return t;
}

}  // namespace armdyn
