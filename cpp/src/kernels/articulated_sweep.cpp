// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/kernels/articulated_sweep.hpp"

#include <algorithm>
#include <cmath>

namespace armdyn {

namespace {

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

// closed-form inverse of a 3 x 3 block; false when it is singular to working precision (its
// determinant below 1e-10 of the product of its row norms)
inline bool inverse3(const Mat3& M, Mat3& Mi) {
  const double det = M.determinant();
  if (!(std::abs(det) > 1e-10 * M.row(0).norm() * M.row(1).norm() * M.row(2).norm())) return false;
  Mi = M.inverse();
  return true;
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
    if (!inverse3(L, Li) || !inverse3(C, Ci)) return false;
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

}  // namespace

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
  for (int ji : m.tree_order) {
    const Joint& j = m.joints[ji];
    // parent -> child joints only (the tree order's parent is the joint's)
    if (j.child == kGround || !supported(j.type)) return;
    Step s{ji, j.parent, j.child, -1, joint_rows(j.type), j.type};
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
  for (int b = 0; b < static_cast<int>(ce.blocks.size()); ++b)
    if (!joint_block[b]) extra_blocks_.push_back(b);
  const size_t n = steps_.size();
  tinv_.assign(n, Mat6::Identity());
  a_.assign(n, Mat6::Zero());
  u_.assign(n, Mat6::Zero());
  dinv_.assign(n, Mat6::Zero());
  b_.assign(n, Vec6::Zero());
  ia_.assign(m.nb, Mat6::Zero());
  pa_.assign(m.nb, Vec6::Zero());
  resp_vd_.assign(kMaxExtraRows, VecX::Zero(m.nv));
  resp_delta_.assign(kMaxExtraRows, VecX::Zero(m.nc));
  load_ = VecX::Zero(m.nv);
  zero_xi_ = VecX::Zero(m.nc);
  extra_rows_.reserve(kMaxExtraRows);
  ok_ = true;
}

// T = [Z_c; C]: the joint's rows on the child, then its free directions (world axes of the joint
// frames, in the child's velocity coordinates: linear in world, angular in the body frame)
bool ArticulatedSweep::complete_block(const Model& m, const std::vector<BodyKin>& kin,
                                      const ConstraintEval& ce, const Step& s, Mat6& T) const {
  T.setZero();
  if (s.nk > 0) T.topRows(s.nk) = ce.blocks[s.block].J.block(0, 6, s.nk, 6);
  int r = s.nk;
  const Joint& j = m.joints[s.joint];
  auto parent_axis = [&](int k) -> Vec3 {
    const Vec3 a = j.frame_parent.col(k);
    return j.parent == kGround ? a : Vec3(kin[j.parent].R * a);
  };
  const Mat3& Rc = kin[j.child].R;
  switch (s.type) {
    case JointType::Revolute:
      T.row(r++).tail<3>() = Rc.transpose() * parent_axis(2);
      break;
    case JointType::Prismatic:
      T.row(r++).head<3>() = parent_axis(2);
      break;
    case JointType::Cylindrical: {
      const Vec3 z = parent_axis(2);
      T.row(r++).tail<3>() = Rc.transpose() * z;
      T.row(r++).head<3>() = z;
      break;
    }
    case JointType::Universal:
      T.row(r++).tail<3>() = Rc.transpose() * parent_axis(2);
      T.row(r++).tail<3>() = j.frame_child.col(2);
      break;
    case JointType::Spherical:
      for (int k = 0; k < 3; ++k) T(r++, 3 + k) = 1.0;
      break;
    case JointType::Free:
      for (int k = 0; k < 6; ++k) T(r++, k) = 1.0;
      break;
    default:
      break;
  }
  return r == 6;
}

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
    if (!complete_block(m, kin, ce, s, T) || !invert_block(T, tinv_[k])) return false;
    const int nf = 6 - s.nk;
    const Mat6& I = ia_[s.child];
    const auto S = tinv_[k].rightCols(nf);
    auto U = u_[k].leftCols(nf);
    U.noalias() = I * S;
    Ia = I;
    if (nf == 1) {
      const double D = S.col(0).dot(U.col(0));
      if (!(D > 0.0) || !std::isfinite(D)) return false;
      dinv_[k](0, 0) = 1.0 / D;
      Ia.noalias() -= (U.col(0) / D) * U.col(0).transpose();
    } else if (nf > 1) {
      SmallMat D = S.transpose() * U;
      Eigen::LLT<SmallMat> llt(D);
      if (llt.info() != Eigen::Success) return false;
      SmallMat Di = llt.solve(SmallMat::Identity(nf, nf));
      dinv_[k].topLeftCorner(nf, nf) = Di;
      Ia.noalias() -= U * Di * U.transpose();
    }
    if (s.parent != kGround) {
      // A = -P Z_p: the child's acceleration as the parent's moves it with the joint held
      const ConstraintBlock& b = ce.blocks[s.block];
      a_[k].noalias() = -tinv_[k].leftCols(s.nk) * b.J.block(0, 0, s.nk, 6);
      ia_[s.parent].noalias() += a_[k].transpose() * Ia * a_[k];
    }
  }
  return ia_[steps_.empty() ? 0 : steps_.front().child].allFinite();
}

void ArticulatedSweep::sweep(const ConstraintEval& ce, const VecX& xi, const VecX& eta, VecX& vd,
                             VecX& delta) {
  const int nb = static_cast<int>(pa_.size());
  for (int i = 0; i < nb; ++i) pa_[i] = -eta.segment<6>(6 * i);
  Vec6 t;
  for (size_t k = steps_.size(); k-- > 0;) {
    const Step& s = steps_[k];
    const int nf = 6 - s.nk;
    if (s.nk > 0)
      b_[k].noalias() = -tinv_[k].leftCols(s.nk) * xi.segment(ce.blocks[s.block].row0, s.nk);
    else
      b_[k].setZero();
    if (s.parent == kGround) continue;
    // I^A b + p^A with the child's free directions taken out
    t.noalias() = ia_[s.child] * b_[k];
    t += pa_[s.child];
    if (nf > 0) {
      const auto S = tinv_[k].rightCols(nf);
      t.noalias() -= u_[k].leftCols(nf) *
                     (dinv_[k].topLeftCorner(nf, nf) * (S.transpose() * t).eval()).eval();
    }
    pa_[s.parent].noalias() += a_[k].transpose() * t;
  }
  Vec6 a;
  for (size_t k = 0; k < steps_.size(); ++k) {
    const Step& s = steps_[k];
    const int nf = 6 - s.nk;
    a = b_[k];
    if (s.parent != kGround) a.noalias() += a_[k] * vd.segment<6>(6 * s.parent);
    t.noalias() = ia_[s.child] * a;
    t += pa_[s.child];
    if (nf > 0) {
      const auto S = tinv_[k].rightCols(nf);
      const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1> sv =
          -(dinv_[k].topLeftCorner(nf, nf) * (S.transpose() * t));
      a.noalias() += S * sv;
      t.noalias() += u_[k].leftCols(nf) * sv;
    }
    vd.segment<6>(6 * s.child) = a;
    if (s.nk > 0)
      delta.segment(ce.blocks[s.block].row0, s.nk).noalias() =
          -tinv_[k].leftCols(s.nk).transpose() * t;
  }
}

namespace {
// E_r v: row r of block b applied to the body velocities (or accelerations) v
double row_times(const ConstraintBlock& b, int r, const VecX& v) {
  double sum = 0.0;
  for (int k = 0; k < b.nbody; ++k)
    if (b.body[k] != kGround) sum += b.J.row(r).segment<6>(6 * k).dot(v.segment<6>(6 * b.body[k]));
  return sum;
}
}  // namespace

bool ArticulatedSweep::extra_rows(const ConstraintEval& ce, int nrows, VecX& vd, VecX& delta) {
  const int ne = static_cast<int>(extra_rows_.size());
  if (ne == 0) return true;
  // E Vd mu = -xi_E - E vd0
  SmallMat H(ne, ne);
  SmallVec rhs(ne);
  int i = 0;
  for (int bi : extra_blocks_) {
    const ConstraintBlock& b = ce.blocks[bi];
    if (b.row0 >= nrows) continue;
    for (int r = 0; r < b.nrows; ++r, ++i) {
      for (int e = 0; e < ne; ++e) H(i, e) = row_times(b, r, resp_vd_[e]);
      rhs[i] = -ce.xi[b.row0 + r] - row_times(b, r, vd);
    }
  }
  const Eigen::PartialPivLU<SmallMat> lu(H);
  const auto d = lu.matrixLU().diagonal().cwiseAbs();
  if (!(d.minCoeff() > 1e-12 * d.maxCoeff())) return false;
  const SmallVec mu = lu.solve(rhs);
  for (int e = 0; e < ne; ++e) {
    vd.noalias() += mu[e] * resp_vd_[e];
    delta.head(nrows).noalias() += mu[e] * resp_delta_[e].head(nrows);
  }
  for (int e = 0; e < ne; ++e) delta[extra_rows_[e]] = mu[e];
  return true;
}

bool ArticulatedSweep::solve(const Model& m, const std::vector<BodyKin>& kin,
                             const ConstraintEval& ce, int nrows, const VecX& eta, VecX& vd,
                             VecX& delta, bool reuse, long kkt_factors) {
  if (!ok_) return false;
  if (!(reuse && factored(nrows, kkt_factors))) {
    factored_rows_ = -1;
    extra_rows_.clear();
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
        resp_delta_[e].setZero();
        sweep(ce, zero_xi_, load_, resp_vd_[e], resp_delta_[e]);
      }
    }
    factored_rows_ = nrows;
    kkt_factors_ = kkt_factors;
  }
  sweep(ce, ce.xi, eta, vd, delta);
  if (!extra_rows(ce, nrows, vd, delta)) {
    factored_rows_ = -1;
    return false;
  }
  return vd.allFinite() && delta.head(nrows).allFinite();
}

}  // namespace armdyn
