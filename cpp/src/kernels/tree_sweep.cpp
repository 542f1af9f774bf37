// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/kernels/tree_sweep.hpp"

#include <algorithm>
#include <cmath>

#include "armdyn/math/inverse3.hpp"

namespace armdyn {

void TreeSweep::plan(const Model& m, const ConstraintEval& ce) {
  ok_ = false;
  steps_.clear();
  if (!m.is_tree || !m.joint_space_ok || !m.gear_constraints.empty() || m.nc != m.nv) return;
  if (static_cast<int>(m.tree_order.size()) != m.nb) return;
  std::vector<int> block_at_row(m.nc, -1);  // the block starting at each row
  for (int b = 0; b < static_cast<int>(ce.blocks.size()); ++b) block_at_row[ce.blocks[b].row0] = b;
  std::vector<int> drive_of_coord(m.coords.size(), -1);
  for (const Drive& d : m.drives) {
    int& slot = drive_of_coord[m.joints[d.joint].coord0 + d.coord];
    if (slot >= 0) return;  // two drives on one coordinate
    slot = d.row;
  }
  for (int ji : m.tree_order) {
    const Joint& j = m.joints[ji];
    const int nco = joint_coords(j.type);
    if (j.child == kGround || joint_rows(j.type) + nco != 6) return;
    Step s{j.parent, j.child, {-1, -1, -1, -1}, 0};
    if (joint_rows(j.type) > 0) s.blocks[s.nblocks++] = block_at_row[j.row0];
    for (int c = 0; c < nco; ++c) {
      const int row = drive_of_coord[j.coord0 + c];
      if (row < 0 || s.nblocks >= 4) return;
      s.blocks[s.nblocks++] = block_at_row[row];
    }
    for (int k = 0; k < s.nblocks; ++k) {
      if (s.blocks[k] < 0) return;
      const ConstraintBlock& b = ce.blocks[s.blocks[k]];
      if (b.nbody != 2 || b.body[0] != j.parent || b.body[1] != j.child) return;
    }
    steps_.push_back(s);
  }
  lu_.resize(steps_.size());
  tri_.assign(steps_.size(), 0);
  ai_.assign(steps_.size(), Mat3::Identity());
  b_.assign(steps_.size(), Mat3::Zero());
  ci_.assign(steps_.size(), Mat3::Identity());
  r_ = VecX::Zero(m.nv);
  ok_ = true;
}

void TreeSweep::gather_child(const ConstraintEval& ce, const Step& s, Mat6& Z, Vec6& rhs) const {
  int r = 0;
  for (int k = 0; k < s.nblocks; ++k) {
    const ConstraintBlock& b = ce.blocks[s.blocks[k]];
    for (int i = 0; i < b.nrows; ++i, ++r) {
      Z.row(r) = b.J.row(i).segment<6>(6);
      rhs[r] = -ce.xi[b.row0 + i];
    }
  }
}

void TreeSweep::sub_parent_times(const ConstraintEval& ce, const Step& s, const Vec6& x,
                                 Vec6& y) const {
  int r = 0;
  for (int k = 0; k < s.nblocks; ++k) {
    const ConstraintBlock& b = ce.blocks[s.blocks[k]];
    for (int i = 0; i < b.nrows; ++i, ++r) y[r] -= b.J.row(i).head<6>().dot(x.transpose());
  }
}

void TreeSweep::sub_parent_transpose_times(const ConstraintEval& ce, const Step& s, const Vec6& d,
                                           Eigen::Ref<Vec6> y) const {
  int r = 0;
  for (int k = 0; k < s.nblocks; ++k) {
    const ConstraintBlock& b = ce.blocks[s.blocks[k]];
    for (int i = 0; i < b.nrows; ++i, ++r) y.noalias() -= d[r] * b.J.row(i).head<6>().transpose();
  }
}

bool TreeSweep::solve(const Model& m, const ConstraintEval& ce, const VecX& eta, VecX& vd,
                      VecX& delta) {
  Mat6 Zc;
  Vec6 rhs;
  for (size_t k = 0; k < steps_.size(); ++k) {
    const Step& s = steps_[k];
    gather_child(ce, s, Zc, rhs);
    if (s.parent != kGround) sub_parent_times(ce, s, vd.segment<6>(6 * s.parent), rhs);
    int tri = 0;
    if (Zc.block<3, 3>(3, 0).isZero(0.0))
      tri = 1;
    else if (Zc.block<3, 3>(0, 0).isZero(0.0))
      tri = 2;
    tri_[k] = static_cast<char>(tri);
    if (tri) {
      // rows (top, bot) = [A B; 0 C]: x_w = C^-1 rhs_bot, x_v = A^-1 (rhs_top - B x_w)
      const int top = tri == 1 ? 0 : 3, bot = 3 - top;
      if (!inverse3_checked(Zc.block<3, 3>(top, 0), ai_[k]) ||
          !inverse3_checked(Zc.block<3, 3>(bot, 3), ci_[k]))
        return false;
      b_[k] = Zc.block<3, 3>(top, 3);
      const Vec3 xw = ci_[k] * rhs.segment<3>(bot);
      vd.segment<3>(6 * s.child + 3) = xw;
      vd.segment<3>(6 * s.child).noalias() = ai_[k] * (rhs.segment<3>(top) - b_[k] * xw);
      continue;
    }
    lu_[k].compute(Zc);
    const auto d = lu_[k].matrixLU().diagonal().cwiseAbs();
    if (!(d.minCoeff() > 1e-10 * d.maxCoeff())) return false;
    vd.segment<6>(6 * s.child) = lu_[k].solve(rhs);
  }
  // r = eta - Gamma vdot
  for (int i = 0; i < m.nb; ++i) {
    const Body& b = m.bodies[i];
    r_.segment<3>(6 * i) = eta.segment<3>(6 * i) - b.mass * vd.segment<3>(6 * i);
    r_.segment<3>(6 * i + 3) = eta.segment<3>(6 * i + 3) - b.inertia * vd.segment<3>(6 * i + 3);
  }
  for (size_t k = steps_.size(); k-- > 0;) {
    const Step& s = steps_[k];
    // this joint's and its drives' multipliers from its child's balance (its children's
    // shares already taken out)
    Vec6 d;
    if (tri_[k]) {
      // [A^T 0; B^T C^T] (d_top, d_bot) = r: d_top = A^-T r_v, d_bot = C^-T (r_w - B^T d_top)
      const int top = tri_[k] == 1 ? 0 : 3, bot = 3 - top;
      const Vec3 dt = ai_[k].transpose() * r_.segment<3>(6 * s.child);
      d.segment<3>(top) = dt;
      d.segment<3>(bot).noalias() =
          ci_[k].transpose() * (r_.segment<3>(6 * s.child + 3) - b_[k].transpose() * dt);
    } else {
      d = lu_[k].transpose().solve(r_.segment<6>(6 * s.child));
    }
    int r = 0;
    for (int q = 0; q < s.nblocks; ++q) {
      const ConstraintBlock& b = ce.blocks[s.blocks[q]];
      for (int i = 0; i < b.nrows; ++i, ++r) delta[b.row0 + i] = d[r];
    }
    if (s.parent != kGround) sub_parent_transpose_times(ce, s, d, r_.segment<6>(6 * s.parent));
  }
  return vd.allFinite() && delta.allFinite();
}

}  // namespace armdyn
