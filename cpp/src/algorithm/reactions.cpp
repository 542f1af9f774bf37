// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/reactions.hpp"

namespace armdyn {

void joint_reaction(const Model& m, const Data& d, int j, Vec3& force, Vec3& torque) {
  const Joint& jt = m.joints[j];
  force.setZero();
  torque.setZero();
  const int r = joint_rows(jt.type);
  if (r == 0 || jt.row0 >= d.nrows) return;
  // find the joint's block (blocks are in joint order, rowless joints skipped)
  const ConstraintBlock* blk = nullptr;
  for (const ConstraintBlock& b : d.ce.blocks)
    if (b.row0 == jt.row0) {
      blk = &b;
      break;
    }
  // constraint force on a body: -zeta_b^T delta = (force world, torque body frame about the CoM)
  const bool on_child = jt.child != kGround;
  const int slot = on_child ? 1 : 0;
  const int body = on_child ? jt.child : jt.parent;
  const Eigen::Matrix<double, 6, 1> g =
      -blk->J.middleCols<6>(6 * slot).transpose() * d.delta.segment(jt.row0, r);
  const BodyKin& k = d.kin[body];
  const Vec3 F = g.head<3>();
  const Vec3 s = on_child ? jt.point_child : jt.point_parent;
  const Mat3& fr = on_child ? jt.frame_child : jt.frame_parent;
  // torque about the joint point: T_P = T_cm - (P - x) x F, with P - x = R s
  const Vec3 Tw = k.R * g.tail<3>() - (k.R * s).cross(F);
  const Mat3 B = k.R * fr;
  force = B.transpose() * F;
  torque = B.transpose() * Tw;
  if (!on_child) {
    force = -force;
    torque = -torque;
  }
}

}  // namespace armdyn
