// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/reactions.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>

#include "armdyn/algorithm/constraints.hpp"
#include "armdyn/algorithm/forces.hpp"
#include "armdyn/algorithm/kinematics.hpp"
#include "armdyn/algorithm/loop_coordinates.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/kernels/joint_space.hpp"

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
  zeta_transpose_times(ce, d.nrows, d.delta, d.tmp_nv);
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

std::vector<std::pair<int, int>> tree_sweep(const Model& m) {
  std::vector<std::pair<int, int>> sweep;
  for (auto it = m.tree_order.rbegin(); it != m.tree_order.rend(); ++it)
    if (joint_rows(m.joints[*it].type) > 0) sweep.emplace_back(*it, m.joints[*it].child);
  return sweep;
}

double load_tree_motion(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                        Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> qdd, double t,
                        const double* gear_delta, const std::vector<std::pair<int, int>>& sweep,
                        VecX& u, VecX& v, VecX& vd) {
  // the bodies' Cartesian state and accelerations from the tree's kinematics and forward sweep
  rne_forward(m, d.kin, qd, qdd, d.rne);
  tree_body_accelerations(m, d.kin, d.rne, vd.data());
  cartesian_state(m, d.kin, u.data(), v.data());
  base_orientations(m, q.data(), u.data());
  // the Cartesian pipeline there, angles tracked from the multi-turn coordinates
  d.track_ref = q.tail(d.nco);
  load_kinematics(m, d, u.data(), v.data());
  evaluate_constraints(m, d, t, false);
  cartesian_forces(m, d, t);
  d.delta.setZero();
  if (gear_delta)
    for (size_t g = 0; g < m.gear_constraints.size(); ++g)
      d.delta[m.gear_constraints[g].row] = gear_delta[g];
  return sweep_multipliers(m, d, vd, sweep);
}

namespace {

// Restores the pipeline settings joint_reactions changes, also when it throws.
struct ReactionSettings {
  Data& d;
  const int nrows = d.nrows;
  ~ReactionSettings() {
    d.nrows = nrows;
    d.aux = nullptr;
    d.joint_torques = nullptr;
    d.with_coordinate_forces = true;
  }
};

}  // namespace

void joint_reactions(const Model& m, Data& d, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                     Eigen::Ref<const VecX> qdd, double t, double* forces, double* torques) {
  constexpr const char* fn = "joint_reactions";
  if (m.loop_coordinates) return loop_joint_reactions(m, d, q, qd, qdd, t, forces, torques);
  require_joint_space(m, fn, true);
  check_data(m, d, fn);
  check_joint_vector(q, d.niq, fn, "q");
  check_joint_vector(qd, d.ni, fn, "qd");
  check_joint_vector(qdd, d.ni, fn, "qdd");
  if (!std::isfinite(t)) throw ModelError(msg(fn, ": t is not finite"));
  check_base_quaternions(m, q, fn);
  if (!d.reaction_sweep_made) {
    d.reaction_sweep = tree_sweep(m);
    d.reaction_sweep_made = true;
  }
  Data::RunScratch& w = d.run;
  if (w.u.size() != m.nq) w.u = VecX::Zero(m.nq);
  if (w.v.size() != m.nv) w.v = VecX::Zero(m.nv);
  if (w.vd.size() != m.nv) w.vd = VecX::Zero(m.nv);
  // every coordinate of the model: a coupled model's followers from the independent ones
  Eigen::Ref<const VecX> qf = d.ni != d.n ? Eigen::Ref<const VecX>(d.coupled.q) : q;
  if (d.ni != d.n) {
    const IndependentCoords& ic = m.independent;
    ic.expand_q(q.data(), d.coupled.q.data());
    ic.expand_v(qd.data(), d.coupled.qd.data());
    ic.expand_v(qdd.data(), d.coupled.qdd.data());
  }
  const Eigen::Ref<const VecX> qdf = d.ni != d.n ? Eigen::Ref<const VecX>(d.coupled.qd) : qd;
  const Eigen::Ref<const VecX> qddf = d.ni != d.n ? Eigen::Ref<const VecX>(d.coupled.qdd) : qdd;
  // each coordinate's total axis force of the motion (the inverse dynamics' torque with the
  // model's coordinate forces, gear pairs and couplings' forces) and each floating base's
  // wrench: with them every body balances, and the joints' rows carry the rest
  joint_space_kinematics(m, qf, qdf, d.kin, d.rne);
  body_forces(m, d.kin, t, d.eta);
  rne_residual(m, d.kin, qdf, qddf, d.eta, d.rne, d.tau);
  const ReactionSettings restore{d};
  d.nrows = m.nc_joint;  // the drives play no part
  d.aux = nullptr;
  d.joint_torques = d.tau.data();
  d.with_coordinate_forces = false;
  load_tree_motion(m, d, qf, qdf, qddf, t, nullptr, d.reaction_sweep, w.u, w.v, w.vd);
  for (int j = 0; j < static_cast<int>(m.joints.size()); ++j) {
    Vec3 f, tq;
    joint_reaction(m, d, j, f, tq);
    for (int k = 0; k < 3; ++k) {
      forces[3 * j + k] = f[k];
      torques[3 * j + k] = tq[k];
    }
  }
}

}  // namespace armdyn
