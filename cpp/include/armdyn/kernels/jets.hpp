// SPDX-License-Identifier: BSD-3-Clause
// Kinematic "jets": a quantity's value, its rate, its velocity Jacobian and its bias
// (second time derivative with zero accelerations). Every constraint, drive and
// joint-coordinate force is built from these, so zeta = F S and xi are exact by construction:
//   d/dt q = J v,   d2/dt2 q = J vdot + bias.
// J has 12 columns: [v_a (6), v_b (6)] for the two bodies a joint connects, each v = (xdot world,
// omega body). Ground has zero velocity and its columns are dropped when scattered.
#pragma once

#include <vector>

#include "armdyn/math/types.hpp"
#include "armdyn/model/model.hpp"

namespace armdyn {

/// Per-body kinematic cache for the current (u, v).
struct BodyKin {
  Vec3 x = Vec3::Zero();  ///< centre of mass, world
  Mat3 R = Mat3::Identity();
  Vec3 xd = Vec3::Zero();  ///< velocity of the centre of mass, world
  Vec3 w = Vec3::Zero();   ///< angular velocity, body frame
  Vec3 W = Vec3::Zero();   ///< angular velocity, world frame (R w)
};

/// A vector's jet. Its 3 x 12 Jacobian is stored by structure: per slot s, the linear-velocity
/// columns are lin[s] * I (points: +-1, directions: 0) and the angular-velocity columns
/// -skew(arm[s]) R_s (present when has_ang[s]), where R_s is the slot body's rotation and arm[s]
/// the world lever of the body-fixed vector (-R skew(a) = -skew(R a) R). Dot products and
/// left(n) then cost a cross product and one R^T product per slot. The general form, for
/// spring-dampers and distance joints; joint rows use the fused AxisJet and SepJet below.
struct VecJet {
  Vec3 val, rate, bias;
  double lin[2] = {0.0, 0.0};
  bool has_ang[2] = {false, false};
  Vec3 arm[2];
  const Mat3* R[2] = {nullptr, nullptr};
  /// n^T J (the Jacobian of n . vector for a fixed n).
  Row12 left(const Vec3& n) const;
};

struct ScalarJet {
  double val = 0, rate = 0, bias = 0;
  Row12 J = Row12::Zero();
};

/// Fill kin (size nb) from u (nq) and v (nv). Quaternions are used as given (not normalised).
void body_kinematics(const Model& m, const double* u, const double* v, std::vector<BodyKin>& kin);

/// Ground's kinematics: the identity pose at rest.
extern const BodyKin kGroundKin;
/// Kinematics of ground or of body b (b = kGround gives the identity pose at rest).
inline const BodyKin& kin_of(const std::vector<BodyKin>& kin, int b) {
  return b == kGround ? kGroundKin : kin[b];
}

/// World direction R_b a of a vector a fixed in body b, placed in Jacobian slot (0 or 1).
VecJet direction_jet(const BodyKin& k, const Vec3& a, int slot);
/// World position x_b + R_b s of a point s fixed in body b.
VecJet point_jet(const BodyKin& k, const Vec3& s, int slot);
VecJet difference(const VecJet& p, const VecJet& q);  ///< p - q
ScalarJet dot(const VecJet& a, const VecJet& b);

/// A world direction fixed in a body: its value, rate W x p and bias W x (W x p). The cheap
/// form of a direction jet for rows that only dot two such directions.
struct AxisJet {
  Vec3 val, rate, bias;
};
inline AxisJet axis_jet(const BodyKin& k, const Vec3& a) {
  AxisJet j;
  j.val.noalias() = k.R * a;
  j.rate = k.W.cross(j.val);
  j.bias = k.W.cross(j.rate);
  return j;
}
/// The separation d = (x_b + R_b s_b) - (x_a + R_a s_a) of two body points, with its world
/// levers r_a = R_a s_a and r_b = R_b s_b (Jacobian [-I, skew(r_a) R_a | I, -skew(r_b) R_b]).
struct SepJet {
  Vec3 val, rate, bias, ra, rb;
};
SepJet sep_jet(const BodyKin& ka, const Vec3& sa, const BodyKin& kb, const Vec3& sb);
/// p . d for a direction p fixed in body A (slot 0) and the separation d of A's and B's points:
/// the same jet as dot(direction_jet(A), difference(point_jet(B), point_jet(A))).
ScalarJet dot_axis_sep(const AxisJet& p, const Mat3& Ra, const SepJet& d, const Mat3& Rb);

/// Jet of joint coordinate c (angle in (-pi, pi] or displacement) in the Jacobian slots of its
/// joint's (parent, child).
/// value = false skips the angle itself (rate, Jacobian and bias only).
ScalarJet coord_jet(const Model& m, const std::vector<BodyKin>& kin, int coord, bool value = true);
/// coord_jet into t (no temporary).
void coord_jet_into(const Model& m, const std::vector<BodyKin>& kin, int coord, bool value,
                    ScalarJet& t);
/// The value of coord_jet alone (positions only: no rates, Jacobian or bias).
double coord_value(const Model& m, const std::vector<BodyKin>& kin, int coord);

/// Joint-coordinate jets (with values) computed at most once per kinematic state: a coordinate
/// read by several elements (an ideal gear row, a motor, a backlash pair) is evaluated once.
/// reset() whenever the state changes.
class CoordJetCache {
 public:
  void init(const Model& m) {
    jet_.assign(m.coords.size(), ScalarJet());
    stamp_.assign(m.coords.size(), 0);
    now_ = 1;
  }
  void reset() { ++now_; }
  const ScalarJet& get(const Model& m, const std::vector<BodyKin>& kin, int c) {
    if (stamp_[c] != now_) {
      jet_[c] = coord_jet(m, kin, c);
      stamp_[c] = now_;
    }
    return jet_[c];
  }
  /// The jet of coordinate c when this state's is cached, else nullptr.
  const ScalarJet* cached(int c) const { return stamp_[c] == now_ ? &jet_[c] : nullptr; }

 private:
  std::vector<ScalarJet> jet_;
  std::vector<unsigned long> stamp_;
  unsigned long now_ = 1;
};

/// The jet (value left 0) of revolute coordinate c at a state on the joint's constraint
/// manifold (bodies placed from joint coordinates), its rate qd given. There the joint axis is
/// z = R_p z_p = R_c z_c (z_p, z_c: the axis in each body's frame, constant), the angle's rate is
/// z . (omega_c - omega_p) and, omega_c - omega_p being parallel to z, its bias
/// (omega_p x z) . (omega_c - omega_p) vanishes: J = [0, -z_p^T, 0, z_c^T] (angular velocities
/// in body axes). The same second derivative as coord_jet's atan2 jet along every motion that
/// keeps the joint's rows; off the manifold use coord_jet.
inline void revolute_jet_on_manifold(const Model& m, int c, double qd, ScalarJet& t) {
  const Joint& j = m.joints[m.coords[c].joint];
  t.val = 0.0;
  t.rate = qd;
  t.bias = 0.0;
  t.J.segment<3>(0).setZero();
  t.J.segment<3>(3) = -j.frame_parent.col(2).transpose();
  t.J.segment<3>(6).setZero();
  t.J.segment<3>(9) = j.frame_child.col(2).transpose();
}

/// Acceleration of joint coordinate c from the Cartesian accelerations: J vdot + bias.
inline double coord_acceleration(const Model& m, const ScalarJet& s, int c,
                                 const Eigen::Ref<const VecX>& vdot) {
  const Joint& j = m.joints[m.coords[c].joint];
  double a = s.bias;
  if (j.parent != kGround) a += s.J.segment<6>(0).dot(vdot.segment<6>(6 * j.parent));
  if (j.child != kGround) a += s.J.segment<6>(6).dot(vdot.segment<6>(6 * j.child));
  return a;
}

}  // namespace armdyn
