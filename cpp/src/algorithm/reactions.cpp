// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/reactions.hpp"

#include <Eigen/QR>
#include <algorithm>

namespace armdyn {

void joint_reaction(const Model& m, const Data& d, int j, Vec3& force, Vec3& torque) {
  const Joint& jt = m.joints[j];
  force.setZero();
  torque.setZero();
  const int r = joint_rows(jt.type);
  if (r == 0 || jt.row0 >= d.nrows) return;
  const ConstraintBlock& blk = d.ce.blocks[d.joint_block[j]];
  // constraint force on a body: -zeta_b^T delta = (force world, torque body frame about the CoM)
  const bool on_child = jt.child != kGround;
  const int slot = on_child ? 1 : 0;
  const int body = on_child ? jt.child : jt.parent;
  const Eigen::Matrix<double, 6, 1> g =
      -blk.J.middleCols<6>(6 * slot).transpose() * d.delta.segment(jt.row0, r);
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

double sweep_multipliers(const Model& m, Data& d, const VecX& vd,
                         const std::vector<std::pair<int, int>>& joints) {
  const ConstraintEval& ce = d.ce;
  for (const auto& jf : joints) {
    const Joint& jt = m.joints[jf.first];
    d.delta.segment(jt.row0, joint_rows(jt.type)).setZero();
  }
  // r = eta - Gamma vd - zeta^T delta (the rows not swept)
  VecX& r = d.vd_work;
  for (int b = 0; b < m.nb; ++b) {
    const Body& bd = m.bodies[b];
    r.segment<3>(6 * b) = d.eta.segment<3>(6 * b) - bd.mass * vd.segment<3>(6 * b);
    r.segment<3>(6 * b + 3) = d.eta.segment<3>(6 * b + 3) - bd.inertia * vd.segment<3>(6 * b + 3);
  }
  zeta_transpose_times(ce, m.nc, d.delta, d.tmp_nv);
  r -= d.tmp_nv;
  using ZtMat = Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, 6>;
  using RowsVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;
  double worst = 0.0;
  for (const auto& [j, far] : joints) {
    const Joint& jt = m.joints[j];
    const int k = joint_rows(jt.type);
    const ConstraintBlock& blk = ce.blocks[d.joint_block[j]];
    const int sf = jt.child == far ? 1 : 0;
    const ZtMat Zt = blk.J.block(0, 6 * sf, k, 6).transpose();
    const Vec6 rf = r.segment<6>(6 * far);
    const Eigen::ColPivHouseholderQR<ZtMat> qr(Zt);
    const RowsVec dj = qr.solve(rf);
    worst = std::max(worst, (rf - Zt * dj).cwiseAbs().maxCoeff());
    d.delta.segment(jt.row0, k) = dj;
    const int near = sf == 1 ? jt.parent : jt.child;
    if (near != kGround)
      r.segment<6>(6 * near).noalias() -= blk.J.block(0, 6 * (1 - sf), k, 6).transpose() * dj;
  }
  return worst;
}

}  // namespace armdyn
