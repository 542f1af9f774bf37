// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/kernels/articulated_sweep.hpp"

#include <algorithm>
#include <cmath>

#include "armdyn/math/inverse3.hpp"

namespace armdyn {

namespace artic_detail {

using SmallMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 8, 8>;
using SmallVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 8, 1>;

bool supported(JointType t) {
  switch (t) {
    case JointType::Revolute:
    case JointType::Prismatic:
    case JointType::Cylindrical:
    case JointType::Universal:
    case JointType::Spherical:
    case JointType::Fixed:
    case JointType::Free:
      return true;
    default:
      return false;
  }
}

// T^-1 of a completed block whose rows split into three with linear columns and three without
// (every supported joint type): with the rows so ordered, T = [L B; 0 C] and
// T^-1 = [L^-1, -L^-1 B C^-1; 0, C^-1]. Other blocks: a pivoted LU. False when singular.
bool invert_block(const Mat6& T, Mat6& Ti) {
  int lin[6], ang[6], nl = 0, na = 0;
  for (int r = 0; r < 6; ++r) {
    if (T.row(r).head<3>().isZero(0.0))
      ang[na++] = r;
    else
      lin[nl++] = r;
  }
  if (nl == 3 && na == 3) {
    Mat3 L, B, C, Li, Ci;
    for (int i = 0; i < 3; ++i) {
      L.row(i) = T.row(lin[i]).head<3>();
      B.row(i) = T.row(lin[i]).tail<3>();
      C.row(i) = T.row(ang[i]).tail<3>();
    }
    if (!inverse3_checked(L, Li) || !inverse3_checked(C, Ci)) return false;
    const Mat3 X = -Li * B * Ci;
    for (int i = 0; i < 3; ++i) {
      Ti.col(lin[i]).head<3>() = Li.col(i);
      Ti.col(lin[i]).tail<3>().setZero();
      Ti.col(ang[i]).head<3>() = X.col(i);
      Ti.col(ang[i]).tail<3>() = Ci.col(i);
    }
    return true;
  }
  const Eigen::PartialPivLU<Mat6> lu(T);
  const auto d = lu.matrixLU().diagonal().cwiseAbs();
  if (!(d.minCoeff() > 1e-10 * d.maxCoeff())) return false;
  Ti = lu.inverse();
  return true;
}

}  // namespace artic_detail

void ArticulatedSweep::plan(const Model& m, const ConstraintEval& ce) {
  ok_ = false;
  factored_rows_ = -1;
  steps_.clear();
  extra_blocks_.clear();
  if (!m.is_tree || m.redundant || m.force_dense_kkt || m.nb == 0) return;
  if (static_cast<int>(m.tree_order.size()) != m.nb) return;
  std::vector<int> block_at_row(m.nc + 1, -1);
  for (int b = 0; b < static_cast<int>(ce.blocks.size()); ++b)
    if (ce.blocks[b].row0 <= m.nc) block_at_row[ce.blocks[b].row0] = b;
  std::vector<char> joint_block(ce.blocks.size(), 0);
  std::vector<char> reached(m.nb, 0);  // bodies already the child of an earlier step
  for (int ji : m.tree_order) {
    const Joint& j = m.joints[ji];
    // parent -> child joints only: the joint's parent is ground or reached before its child
    if (j.child == kGround || !artic_detail::supported(j.type)) return;
    if (j.parent != kGround && !reached[j.parent]) return;
    reached[j.child] = 1;
    Step s{ji, j.parent, j.child, -1, joint_rows(j.type), j.type, false};
    s.point = j.type == JointType::Revolute || j.type == JointType::Universal ||
              j.type == JointType::Spherical || j.type == JointType::Fixed;
    if (j.type == JointType::Free && j.parent != kGround) return;
    if (s.nk > 0) {
      s.block = block_at_row[j.row0];
      if (s.block < 0) return;
      const ConstraintBlock& b = ce.blocks[s.block];
      if (b.nbody != 2 || b.body[0] != j.parent || b.body[1] != j.child || b.nrows != s.nk) return;
      joint_block[s.block] = 1;
    }
    steps_.push_back(s);
  }
  plan_groups(m, ce, joint_block);  // marks the groups' blocks too
  for (int b = 0; b < static_cast<int>(ce.blocks.size()); ++b)
    if (!joint_block[b]) extra_blocks_.push_back(b);
  const size_t n = steps_.size();
  tinv_.assign(n, Mat6::Identity());
  s_.assign(n, Mat6::Zero());
  u_.assign(n, Mat6::Zero());
  bm_.assign(n, Mat3::Zero());
  ci_.assign(n, Mat3::Identity());
  x_.assign(n, Mat3::Zero());
  y_.assign(n, Mat3::Zero());
  dinv_.assign(n, Mat6::Zero());
  b_.assign(n, Vec6::Zero());
  ia_.assign(m.nb, Mat6::Zero());
  pa_.assign(m.nb, Vec6::Zero());
  resp_vd_.assign(kMaxExtraRows, VecX::Zero(m.nv));
  resp_delta_.assign(kMaxExtraRows, VecX::Zero(m.nc));
  load_ = VecX::Zero(m.nv);
  extra_rows_.reserve(kMaxExtraRows);
  ok_ = true;
}

// T = [Z_c; C]: the joint's rows on the child, then its free directions (axes of the joint
// frames, in the child's velocity coordinates: linear in world, angular in the body frame). Any
// C that completes Z_c gives the same solution (s is free); the child's own axes cost least.
bool ArticulatedSweep::complete_block(const Model& m, const std::vector<BodyKin>& kin,
                                      const ConstraintEval& ce, const Step& s, Mat6& T) const {
  T.setZero();
  if (s.nk > 0) T.topRows(s.nk) = ce.blocks[s.block].J.block(0, 6, s.nk, 6);
  const Joint& j = m.joints[s.joint];
  const Vec3 z = kin[j.child].R * j.frame_child.col(2);
  switch (s.type) {
    case JointType::Cylindrical:
      T.row(4).tail<3>() = j.frame_child.col(2);
      T.row(5).head<3>() = z;
      return true;
    case JointType::Free:
      T.setIdentity();
      return true;
    default:
      return false;
  }
}

// A prismatic joint's T^-1 without forming T: its rows are three rotation locks [0 W], two
// on-axis rows [L_xy K_xy] and the slide [z^T 0] (z the child's joint axis in world), so with
// L = [L_xy; z^T] and K = [K_xy; 0], T^-1 = [-L^-1 K W^-1, L^-1; W^-1, 0] (invert_block's split,
// its columns in the rows' order)
bool ArticulatedSweep::slide_block_inverse(const Model& m, const std::vector<BodyKin>& kin,
                                           const ConstraintEval& ce, const Step& s,
                                           Mat6& Ti) const {
  const BlockMat& J = ce.blocks[s.block].J;
  const Joint& j = m.joints[s.joint];
  Mat3 L, K, W, Li, Wi;
  W = J.block<3, 3>(0, 9);
  L.topRows<2>() = J.block<2, 3>(3, 6);
  L.row(2) = (kin[j.child].R * j.frame_child.col(2)).transpose();
  K.topRows<2>() = J.block<2, 3>(3, 9);
  K.row(2).setZero();
  if (!inverse3_checked(L, Li) || !inverse3_checked(W, Wi)) return false;
  Ti.topLeftCorner<3, 3>().noalias() = -Li * K * Wi;
  Ti.bottomLeftCorner<3, 3>() = Wi;
  Ti.topRightCorner<3, 3>() = Li;
  Ti.bottomRightCorner<3, 3>().setZero();
  return true;
}

// A point joint's T = [I B; 0 C]: B (the point rows' angular columns) and C (the rotation rows'
// angular columns, then the free rotations)
void ArticulatedSweep::point_block(const Model& m, const std::vector<BodyKin>& kin,
                                   const ConstraintEval& ce, const Step& s, Mat3& B,
                                   Mat3& C) const {
  const BlockMat& J = ce.blocks[s.block].J;
  const Joint& j = m.joints[s.joint];
  B = J.block<3, 3>(0, 9);
  int r = 0;
  for (; r < s.nk - 3; ++r) C.row(r) = J.row(3 + r).segment<3>(9);
  switch (s.type) {
    case JointType::Revolute:
      C.row(2) = j.frame_child.col(2).transpose();
      break;
    case JointType::Universal: {
      const Vec3 za = j.parent == kGround ? Vec3(j.frame_parent.col(2))
                                          : Vec3(kin[j.parent].R * j.frame_parent.col(2));
      C.row(1) = (kin[j.child].R.transpose() * za).transpose();
      C.row(2) = j.frame_child.col(2).transpose();
      break;
    }
    case JointType::Spherical:
      C.setIdentity();
      break;
    default:
      break;
  }
}

namespace artic_detail {

// G = Ci[:, :K] W for the K rotation rows W (K x 3) of a point joint
template <int K>
Mat3 point_rows_product(const Mat3& Ci, const BlockMat& J, int col) {
  if constexpr (K == 0) {
    return Mat3::Zero();
  } else {
    return Ci.leftCols<K>() * J.block<K, 3>(3, col);
  }
}

Mat3 point_product(int K, const Mat3& Ci, const BlockMat& J, int col) {
  switch (K) {
    case 1:
      return point_rows_product<1>(Ci, J, col);
    case 2:
      return point_rows_product<2>(Ci, J, col);
    case 3:
      return point_rows_product<3>(Ci, J, col);
    default:
      return Mat3::Zero();
  }
}

// M += A^T Ia A for A = [I X; 0 Y] (a point joint's transport): with Z = [X; Y] (6 x 3) and
// W = Ia Z, A^T Ia A = [Ia_11, W_top; W_top^T, Z^T W] (the 6-row products vectorise)
void add_congruence(const Mat6& Ia, const Mat3& X, const Mat3& Y, Mat6& M) {
  Eigen::Matrix<double, 6, 3> Z;
  Z.topRows<3>() = X;
  Z.bottomRows<3>() = Y;
  Eigen::Matrix<double, 6, 3> W;
  W.noalias() = Ia * Z;
  M.topLeftCorner<3, 3>() += Ia.topLeftCorner<3, 3>();
  M.topRightCorner<3, 3>() += W.topRows<3>();
  M.bottomLeftCorner<3, 3>() += W.topRows<3>().transpose();
  M.bottomRightCorner<3, 3>().noalias() += Z.transpose() * W;
}

}  // namespace artic_detail

bool ArticulatedSweep::factor(const Model& m, const std::vector<BodyKin>& kin,
                              const ConstraintEval& ce) {
  for (int i = 0; i < m.nb; ++i) {
    Mat6& I = ia_[i];
    I.setZero();
    I.topLeftCorner<3, 3>().diagonal().setConstant(m.bodies[i].mass);
    I.bottomRightCorner<3, 3>() = m.bodies[i].inertia;
  }
  Mat6 T, Ia;
  for (size_t k = steps_.size(); k-- > 0;) {
    const Step& s = steps_[k];
    const int nf = 6 - s.nk;
    Mat6& S = s_[k];
    if (s.point) {
      // T^-1 = [I, -B C^-1; 0, C^-1]
      Mat3 C;
      point_block(m, kin, ce, s, bm_[k], C);
      if (!inverse3_checked(C, ci_[k])) return false;
      if (nf == 1) {  // revolute: the last column
        S.col(0).head<3>().noalias() = -bm_[k] * ci_[k].col(2);
        S.col(0).tail<3>() = ci_[k].col(2);
      } else {
        S.topLeftCorner(3, nf).noalias() = -bm_[k] * ci_[k].rightCols(nf);
        S.bottomLeftCorner(3, nf) = ci_[k].rightCols(nf);
      }
    } else {
      if (s.type == JointType::Prismatic) {
        if (!slide_block_inverse(m, kin, ce, s, tinv_[k])) return false;
      } else if (!complete_block(m, kin, ce, s, T) || !artic_detail::invert_block(T, tinv_[k])) {
        return false;
      }
      if (nf == 1) {
        S.col(0) = tinv_[k].col(5);
        tinv_[k].col(5).setZero();
      } else {
        S.leftCols(nf) = tinv_[k].rightCols(nf);
        tinv_[k].rightCols(nf).setZero();  // P, padded to 6 x 6
      }
    }
    // U = I^A S, D = S^T U; the child's inertia with its free directions taken out,
    // I^A - U D^-1 U^T, passes to the parent
    const Mat6& I = ia_[s.child];
    const bool to_parent = s.parent != kGround;
    if (nf == 1) {
      const Vec6 u = I * S.col(0);
      u_[k].col(0) = u;
      const double D = S.col(0).dot(u);
      if (!(D > 0.0) || !std::isfinite(D)) return false;
      dinv_[k](0, 0) = 1.0 / D;
      if (to_parent) {
        const Vec6 w = u / D;
        Ia = I;
        Ia.noalias() -= w.lazyProduct(u.transpose());
      }
    } else if (nf > 1) {
      u_[k].leftCols(nf).noalias() = I * S.leftCols(nf);
      artic_detail::SmallMat D = S.leftCols(nf).transpose() * u_[k].leftCols(nf);
      Eigen::LLT<artic_detail::SmallMat> llt(D);
      if (llt.info() != Eigen::Success) return false;
      const artic_detail::SmallMat Di = llt.solve(artic_detail::SmallMat::Identity(nf, nf));
      dinv_[k].topLeftCorner(nf, nf) = Di;
      if (to_parent) {
        Ia = I;
        Ia.noalias() -= u_[k].leftCols(nf) * Di * u_[k].leftCols(nf).transpose();
      }
    }
    if (s.parent != kGround) {
      transport(ce, k);
      // (no free directions: the child's inertia passes whole)
      artic_detail::add_congruence(nf == 0 ? I : Ia, x_[k], y_[k], ia_[s.parent]);
    }
    // a group's rank-r update once its members are done (its trigger is their first step)
    const int gi = step_group_[k];
    if (gi >= 0 && groups_[gi].on && static_cast<int>(k) == groups_[gi].trigger &&
        !factor_group(ce, groups_[gi]))
      return false;
  }
  return true;
}

void ArticulatedSweep::transport(const ConstraintEval& ce, size_t k) {
  const Step& s = steps_[k];
  // A = -P Z_p moves the child with the parent, the joint held; A + S M for any M does as
  // well (s absorbs it, and Ia S = 0): with M = C's linear columns, A = [I X; 0 Y] for every
  // joint type (the rows' linear columns are opposite on parent and child), [X; Y] = -P Z_p's
  // angular columns (none for a free joint, whose parent is ground)
  if (s.nk == 0) {
    x_[k].setZero();
    y_[k].setZero();
    return;
  }
  const ConstraintBlock& b = ce.blocks[s.block];
  if (s.point) {
    // Z_p = [-I K; 0 W]: Y = -C^-1[:, :nk-3] W, X = -K - B Y
    const Mat3 G = artic_detail::point_product(s.nk - 3, ci_[k], b.J, 3);
    y_[k] = -G;
    x_[k].noalias() = bm_[k] * G - b.J.block<3, 3>(0, 3);
  } else if (s.nk > 0) {
    Eigen::Matrix<double, 6, 3> Zp;
    if (s.nk == 5) {
      Zp.topRows<5>() = b.J.block<5, 3>(0, 3);
      Zp.row(5).setZero();
    } else {
      Zp.setZero();
      Zp.topRows(s.nk) = b.J.block(0, 3, s.nk, 3);
    }
    const Eigen::Matrix<double, 6, 3> XY = -tinv_[k] * Zp;
    x_[k] = XY.topRows<3>();
    y_[k] = XY.bottomRows<3>();
  }
}

// b = -P xi_j: the child's acceleration with the parent at rest and the free directions still
void ArticulatedSweep::bias(const ConstraintEval& ce, const VecX& xi, size_t k) {
  const Step& s = steps_[k];
  if (s.nk == 0) {
    b_[k].setZero();
    return;
  }
  const int r0 = ce.blocks[s.block].row0;
  if (s.point) {
    Vec3 g = Vec3::Zero();
    for (int r = 3; r < s.nk; ++r) g.noalias() += xi[r0 + r] * ci_[k].col(r - 3);
    b_[k].head<3>().noalias() = bm_[k] * g - xi.segment<3>(r0);
    b_[k].tail<3>() = -g;
  } else {
    Vec6 x = Vec6::Zero();
    x.head(s.nk) = xi.segment(r0, s.nk);
    b_[k].noalias() = -tinv_[k] * x;
  }
}

void ArticulatedSweep::sweep(const ConstraintEval& ce, const VecX* xi, const VecX& eta, VecX& vd,
                             VecX* delta) {
  backward(ce, xi, eta);
  forward(ce, xi != nullptr, vd, delta);
}

// the bias forces, children first: I^A b + p^A with the child's free directions taken out,
// passed to the parent (b = 0 without row values xi: a response)
void ArticulatedSweep::backward(const ConstraintEval& ce, const VecX* xi, const VecX& eta) {
  const int nb = static_cast<int>(pa_.size());
  for (int i = 0; i < nb; ++i) pa_[i] = -eta.segment<6>(6 * i);
  Vec6 t;
  for (size_t k = steps_.size(); k-- > 0;) {
    const Step& s = steps_[k];
    const int nf = 6 - s.nk;
    if (xi) bias(ce, *xi, k);
    const int gi = step_group_[k];
    if (gi >= 0 && groups_[gi].on && static_cast<int>(k) == groups_[gi].trigger) {
      backward_group(ce, xi, groups_[gi]);  // reads the members' b and p^A before the passing
    }
    if (s.parent == kGround) continue;
    t = pa_[s.child];
    if (xi) t.noalias() += ia_[s.child] * b_[k];
    if (nf == 1) {
      t.noalias() -= (dinv_[k](0, 0) * s_[k].col(0).dot(t)) * u_[k].col(0);
    } else if (nf > 1) {
      const artic_detail::SmallVec st = s_[k].leftCols(nf).transpose() * t;
      const artic_detail::SmallVec w = dinv_[k].topLeftCorner(nf, nf) * st;
      t.noalias() -= u_[k].leftCols(nf) * w;
    }
    pa_[s.parent] += artic_detail::transport_transposed(x_[k], y_[k], t);
  }
}

// the accelerations, parents first; with delta, the multipliers delta = -P^T (I^A vdot + p^A).
// The free directions' accelerations s = -D^-1 S^T (I^A a + p^A) = -D^-1 (U^T a + S^T p^A)
// (I^A symmetric, U = I^A S): without multipliers I^A a is never formed.
void ArticulatedSweep::forward(const ConstraintEval& ce, bool with_bias, VecX& vd, VecX* delta) {
  Vec6 a, t;
  for (size_t k = 0; k < steps_.size(); ++k) {
    const Step& s = steps_[k];
    const int nf = 6 - s.nk;
    // a group member's load includes its rows' forces E_i^T mu (mu from the group's trigger)
    const int gi = step_group_[k];
    const bool member = gi >= 0 && groups_[gi].on;
    if (member && static_cast<int>(k) == groups_[gi].trigger) forward_group(ce, groups_[gi], vd);
    if (with_bias)
      a = b_[k];
    else
      a.setZero();
    if (s.parent != kGround) {
      const auto vp = vd.segment<6>(6 * s.parent);
      a.head<3>().noalias() += vp.head<3>() + x_[k] * vp.tail<3>();
      a.tail<3>().noalias() += y_[k] * vp.tail<3>();
    }
    Vec6 pm;
    const Vec6* pp = &pa_[s.child];
    if (member) {
      pm = *pp + ext_[k];
      pp = &pm;
    }
    const Vec6& p = *pp;
    if (delta) {
      t.noalias() = ia_[s.child] * a;
      t += p;
    }
    if (nf == 1) {
      const double sv = -dinv_[k](0, 0) * (u_[k].col(0).dot(a) + s_[k].col(0).dot(p));
      a.noalias() += sv * s_[k].col(0);
      if (delta) t.noalias() += sv * u_[k].col(0);
    } else if (nf > 1) {
      const artic_detail::SmallVec st =
          u_[k].leftCols(nf).transpose() * a + s_[k].leftCols(nf).transpose() * p;
      const artic_detail::SmallVec sv = -(dinv_[k].topLeftCorner(nf, nf) * st);
      a.noalias() += s_[k].leftCols(nf) * sv;
      if (delta) t.noalias() += u_[k].leftCols(nf) * sv;
    }
    vd.segment<6>(6 * s.child) = a;
    if (delta) member_multipliers(ce, k, t, *delta);
  }
  if (!delta) return;
  for (const Group& g : groups_) {
    if (!g.on) continue;
    int j = 0;
    for (int bi : g.blocks)
      for (int r = 0; r < ce.blocks[bi].nrows; ++r) (*delta)[ce.blocks[bi].row0 + r] = g.mu[j++];
  }
}

// delta = -P^T t for the joint of step k, t = I^A vdot + p^A (+ the group rows' E^T mu)
void ArticulatedSweep::member_multipliers(const ConstraintEval& ce, size_t k, const Vec6& t,
                                          VecX& delta) const {
  const Step& s = steps_[k];
  if (s.nk == 0) return;
  const int r0 = ce.blocks[s.block].row0;
  if (s.point) {
    delta.segment<3>(r0) = -t.head<3>();
    const Vec3 w = t.tail<3>() - bm_[k].transpose() * t.head<3>();
    for (int r = 3; r < s.nk; ++r) delta[r0 + r] = -ci_[k].col(r - 3).dot(w);
  } else {
    const Vec6 d = -tinv_[k].transpose() * t;
    delta.segment(r0, s.nk) = d.head(s.nk);
  }
}

namespace artic_detail {
// E_r v: row r of block b applied to the body velocities (or accelerations) v
double row_times(const ConstraintBlock& b, int r, const VecX& v) {
  double sum = 0.0;
  for (int k = 0; k < b.nbody; ++k)
    if (b.body[k] != kGround) sum += b.J.row(r).segment<6>(6 * k).dot(v.segment<6>(6 * b.body[k]));
  return sum;
}
}  // namespace artic_detail

bool ArticulatedSweep::extra_rows(const ConstraintEval& ce, int nrows, VecX& vd, VecX* delta) {
  const int ne = static_cast<int>(extra_rows_.size());
  if (ne == 0) return true;
  // E Vd mu = -xi_E - E vd0
  artic_detail::SmallMat H(ne, ne);
  artic_detail::SmallVec rhs(ne);
  int i = 0;
  for (int bi : extra_blocks_) {
    const ConstraintBlock& b = ce.blocks[bi];
    if (b.row0 >= nrows) continue;
    for (int r = 0; r < b.nrows; ++r, ++i) {
      for (int e = 0; e < ne; ++e) H(i, e) = artic_detail::row_times(b, r, resp_vd_[e]);
      rhs[i] = -ce.xi[b.row0 + r] - artic_detail::row_times(b, r, vd);
    }
  }
  const Eigen::PartialPivLU<artic_detail::SmallMat> lu(H);
  const auto d = lu.matrixLU().diagonal().cwiseAbs();
  if (!(d.minCoeff() > 1e-12 * d.maxCoeff())) return false;
  const artic_detail::SmallVec mu = lu.solve(rhs);
  for (int e = 0; e < ne; ++e) vd.noalias() += mu[e] * resp_vd_[e];
  if (!delta) return true;
  for (int e = 0; e < ne; ++e) delta->head(nrows).noalias() += mu[e] * resp_delta_[e].head(nrows);
  for (int e = 0; e < ne; ++e) (*delta)[extra_rows_[e]] = mu[e];
  return true;
}

bool ArticulatedSweep::solve(const Model& m, const std::vector<BodyKin>& kin,
                             const ConstraintEval& ce, int nrows, const VecX& eta, VecX& vd,
                             VecX& delta, bool reuse, long kkt_factors, bool multipliers) {
  if (!ok_) return false;
  if (!(reuse && factored(nrows, kkt_factors) && (resp_multipliers_ || !multipliers))) {
    factored_rows_ = -1;
    extra_rows_.clear();
    if (!groups_for_rows(ce, nrows)) return false;
    for (int bi : extra_blocks_) {
      const ConstraintBlock& b = ce.blocks[bi];
      if (b.row0 >= nrows) continue;
      for (int r = 0; r < b.nrows; ++r) {
        if (static_cast<int>(extra_rows_.size()) == kMaxExtraRows) return false;
        extra_rows_.push_back(b.row0 + r);
      }
    }
    if (!factor(m, kin, ce)) return false;
    // the extra rows' responses: the sweep under a unit multiplier of each, no row values
    int e = 0;
    for (int bi : extra_blocks_) {
      const ConstraintBlock& b = ce.blocks[bi];
      if (b.row0 >= nrows) continue;
      for (int r = 0; r < b.nrows; ++r, ++e) {
        load_.setZero();
        for (int k = 0; k < b.nbody; ++k)
          if (b.body[k] != kGround)
            load_.segment<6>(6 * b.body[k]) = -b.J.row(r).segment<6>(6 * k).transpose();
        if (multipliers) resp_delta_[e].setZero();
        sweep(ce, nullptr, load_, resp_vd_[e], multipliers ? &resp_delta_[e] : nullptr);
      }
    }
    resp_multipliers_ = multipliers;
    factored_rows_ = nrows;
    kkt_factors_ = kkt_factors;
  }
  VecX* out = multipliers ? &delta : nullptr;
  sweep(ce, &ce.xi, eta, vd, out);
  if (!extra_rows(ce, nrows, vd, out)) {
    factored_rows_ = -1;
    return false;
  }
  // a sum is finite only if every term is (an overflowing sum, never reached by physical
  // accelerations, only sends the solve to the KKT path)
  return std::isfinite(vd.sum()) && (!multipliers || std::isfinite(delta.head(nrows).sum()));
}

}  // namespace armdyn
