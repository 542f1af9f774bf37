// SPDX-License-Identifier: BSD-3-Clause
// The articulated sweep's groups (articulated_sweep.hpp): gear and coupling rows on a body p and
// some of its children, eliminated together with those children's free directions where the
// backward pass reaches p, instead of one response sweep per row.
#include <algorithm>
#include <cmath>

#include "armdyn/kernels/articulated_sweep.hpp"

namespace armdyn {

namespace artic_group_detail {

// the slot of body x in block b, -1 if the block does not hold it
int slot_in(const ConstraintBlock& b, int x) {
  for (int k = 0; k < b.nbody; ++k)
    if (b.body[k] == x) return k;
  return -1;
}

// whether every body of block b but ground is p or a child of p (step_of: each body's step)
bool local_to(const ConstraintBlock& b, int p, const std::vector<int>& step_of,
              const std::vector<int>& parent_of_step) {
  bool child = false;
  for (int k = 0; k < b.nbody; ++k) {
    const int x = b.body[k];
    if (x == kGround || x == p) continue;
    if (step_of[x] < 0 || parent_of_step[step_of[x]] != p) return false;
    child = true;
  }
  return child;
}

}  // namespace artic_group_detail

void ArticulatedSweep::plan_groups(const Model& m, const ConstraintEval& ce,
                                   std::vector<char>& taken) {
  using artic_group_detail::local_to;
  groups_.clear();
  step_group_.assign(steps_.size(), -1);
  std::vector<int> step_of(m.nb, -1), parent_of_step(steps_.size());
  for (size_t k = 0; k < steps_.size(); ++k) {
    step_of[steps_[k].child] = static_cast<int>(k);
    parent_of_step[k] = steps_[k].parent;
  }
  std::vector<int> group_at(m.nb + 1, -1);  // per p (ground first), its group
  for (int bi = 0; bi < static_cast<int>(ce.blocks.size()); ++bi) {
    const ConstraintBlock& b = ce.blocks[bi];
    // gears and couplings only: drives take part in some calls and not in others
    if (taken[bi] || b.row0 >= m.nc_joint) continue;
    int p = -2;
    for (int k = 0; k < b.nbody && p == -2; ++k) {
      const int x = b.body[k];
      if (x == kGround) continue;
      if (local_to(b, x, step_of, parent_of_step)) p = x;
      if (p == -2 && step_of[x] >= 0 &&
          local_to(b, steps_[step_of[x]].parent, step_of, parent_of_step))
        p = steps_[step_of[x]].parent;
    }
    if (p == -2) continue;
    int& gi = group_at[p + 1];
    if (gi < 0) {
      gi = static_cast<int>(groups_.size());
      groups_.emplace_back();
      groups_.back().parent = p;
    }
    Group& g = groups_[gi];
    g.blocks.push_back(bi);
    g.nrows += b.nrows;
    for (int k = 0; k < b.nbody; ++k) {
      const int x = b.body[k];
      if (x == kGround || x == p) continue;
      const int st = step_of[x];
      if (std::find(g.members.begin(), g.members.end(), st) == g.members.end())
        g.members.push_back(st);
    }
  }
  // the trigger; a group over kMaxGroupRows rows or kMaxGroupMembers children is left to the
  // extra rows
  std::vector<Group> kept;
  for (Group& g : groups_) {
    if (g.nrows > kMaxGroupRows || static_cast<int>(g.members.size()) > kMaxGroupMembers) continue;
    std::sort(g.members.begin(), g.members.end());
    g.trigger = g.members.front();
    g.simple = g.nrows == 1;
    for (size_t i = 0; i < g.members.size(); ++i) {
      g.simple = g.simple && steps_[g.members[i]].nk == 5;
      g.slot[i] = artic_group_detail::slot_in(ce.blocks[g.blocks[0]], steps_[g.members[i]].child);
    }
    for (int bi : g.blocks) taken[bi] = 1;
    for (int k : g.members) step_group_[k] = static_cast<int>(kept.size());
    g.C.setZero(g.nrows, 6);
    g.HiC.setZero(g.nrows, 6);
    g.hc0.setZero(g.nrows);
    g.mu.setZero(g.nrows);
    kept.push_back(std::move(g));
  }
  groups_ = std::move(kept);
  ext_.assign(steps_.size(), Vec6::Zero());
}

// a group takes part when its rows do; rows of one group partly taking part: not solved here
bool ArticulatedSweep::groups_for_rows(const ConstraintEval& ce, int nrows) {
  for (Group& g : groups_) {
    int in = 0;
    for (int bi : g.blocks) in += ce.blocks[bi].row0 < nrows ? 1 : 0;
    if (in != 0 && in != static_cast<int>(g.blocks.size())) return false;
    g.on = in != 0;
  }
  return true;
}

Vec6 ArticulatedSweep::free_part(size_t k, const Vec6& v, Vec6& dv) const {
  const int nf = 6 - steps_[k].nk;
  Vec6 sv = Vec6::Zero();
  dv.setZero();
  if (nf == 0) return sv;
  sv.head(nf).noalias() = s_[k].leftCols(nf).transpose() * v;
  dv.head(nf).noalias() = dinv_[k].topLeftCorner(nf, nf) * sv.head(nf);
  return sv;
}

// C = E_p + sum_i E_i Q_i A_i (rows), H = sum_i E_i Phi_i E_i^T; p receives C^T H^-1 C. False
// when H is not positive definite (the rows do not move the members' free directions)
bool ArticulatedSweep::factor_group(const ConstraintEval& ce, Group& g) {
  using artic_detail::transport_transposed;
  if (g.simple) return factor_simple_group(ce, g);
  const int r = g.nrows;
  // per row and member: S_i^T E^T (here) and D_i^-1 S_i^T E^T (kept for the sweeps)
  Vec6 se[kMaxGroupRows][kMaxGroupMembers];
  auto& dse = g.dse_rows;
  int j = 0;
  for (int bi : g.blocks) {
    const ConstraintBlock& b = ce.blocks[bi];
    for (int row = 0; row < b.nrows; ++row, ++j) {
      Vec6 col = Vec6::Zero();
      for (size_t i = 0; i < g.members.size(); ++i) {
        se[j][i].setZero();
        dse[j][i].setZero();
      }
      for (int slot = 0; slot < b.nbody; ++slot) {
        const int x = b.body[slot];
        if (x == kGround) continue;
        const Vec6 E = b.J.row(row).segment<6>(6 * slot).transpose();
        if (x == g.parent) {
          col += E;
          continue;
        }
        for (size_t i = 0; i < g.members.size(); ++i) {
          const int k = g.members[i];
          if (steps_[k].child != x) continue;
          se[j][i] = free_part(k, E, dse[j][i]);
          // Q_i^T E^T = E^T - U_i D_i^-1 S_i^T E^T, carried to p by A_i^T
          Vec6 q = E;
          const int nf = 6 - steps_[k].nk;
          if (nf > 0) q.noalias() -= u_[k].leftCols(nf) * dse[j][i].head(nf);
          col += transport_transposed(x_[k], y_[k], q);
        }
      }
      g.C.row(j) = col.transpose();
    }
  }
  GroupMat H(r, r);
  for (int a = 0; a < r; ++a)
    for (int c = 0; c <= a; ++c) {
      double h = 0.0;
      for (size_t i = 0; i < g.members.size(); ++i) h += se[a][i].dot(dse[c][i]);
      H(a, c) = H(c, a) = h;
    }
  g.H.compute(H);
  if (g.H.info() != Eigen::Success) return false;
  const auto d = g.H.matrixLLT().diagonal();
  if (!(d.minCoeff() > 1e-7 * d.maxCoeff())) return false;  // condition ~ (ratio)^2 < 1e14
  g.HiC = g.H.solve(g.C);
  if (g.parent != kGround) ia_[g.parent].noalias() += g.C.transpose() * g.HiC;
  return true;
}

// factor_group with one row and one free direction per member: H and C^T are a number and a
// vector; H is accepted above 1e-14 of its terms' Cauchy-Schwarz bound (the row moves the
// members' free directions)
bool ArticulatedSweep::factor_simple_group(const ConstraintEval& ce, Group& g) {
  using artic_detail::transport_transposed;
  const ConstraintBlock& b = ce.blocks[g.blocks[0]];
  Vec6 col = Vec6::Zero();
  const int ps = g.parent == kGround ? -1 : artic_group_detail::slot_in(b, g.parent);
  if (ps >= 0) col = b.J.row(0).segment<6>(6 * ps).transpose();
  double h = 0.0, bound = 0.0;
  for (size_t i = 0; i < g.members.size(); ++i) {
    const int k = g.members[i];
    const Vec6 E = b.J.row(0).segment<6>(6 * g.slot[i]).transpose();
    const double se = s_[k].col(0).dot(E), di = dinv_[k](0, 0);
    g.dse[i] = di * se;
    col += transport_transposed(x_[k], y_[k], E - g.dse[i] * u_[k].col(0));
    h += se * g.dse[i];
    bound += di * s_[k].col(0).squaredNorm() * E.squaredNorm();
  }
  if (!(h > 1e-14 * bound) || !std::isfinite(h)) return false;
  g.c1 = col;
  g.h1 = h;
  if (g.parent != kGround) {
    const Vec6 w = col / h;
    ia_[g.parent].noalias() += w.lazyProduct(col.transpose());
  }
  return true;
}

// c0 = xi + sum_i E_i (b_i - Phi_i h_i), h_i = I^A_i b_i + p^A_i (no row values: b = 0,
// xi = 0); p^A_p += C^T H^-1 c0
void ArticulatedSweep::backward_group(const ConstraintEval& ce, const VecX* xi, Group& g) {
  if (g.simple) {
    // S_i^T h_i = S_i^T p^A_i + U_i^T b_i (I^A_i symmetric)
    const ConstraintBlock& b = ce.blocks[g.blocks[0]];
    double v = xi ? (*xi)[b.row0] : 0.0;
    for (size_t i = 0; i < g.members.size(); ++i) {
      const int k = g.members[i];
      double sh = s_[k].col(0).dot(pa_[steps_[k].child]);
      if (xi) {
        sh += u_[k].col(0).dot(b_[k]);
        v += b.J.row(0).segment<6>(6 * g.slot[i]).dot(b_[k]);
      }
      v -= g.dse[i] * sh;
    }
    g.hc0[0] = v / g.h1;
    if (g.parent != kGround) pa_[g.parent].noalias() += g.hc0[0] * g.c1;
    return;
  }
  // per member S_i^T h_i = S_i^T p^A_i + U_i^T b_i, once; per row E_i b_i - (D_i^-1 S_i^T E_i)
  // . S_i^T h_i
  Vec6 sh[kMaxGroupMembers];
  for (size_t i = 0; i < g.members.size(); ++i) {
    const int k = g.members[i], nf = 6 - steps_[k].nk;
    sh[i].setZero();
    sh[i].head(nf).noalias() = s_[k].leftCols(nf).transpose() * pa_[steps_[k].child];
    if (xi) sh[i].head(nf).noalias() += u_[k].leftCols(nf).transpose() * b_[k];
  }
  GroupVec c0(g.nrows);
  int j = 0;
  for (int bi : g.blocks) {
    const ConstraintBlock& b = ce.blocks[bi];
    for (int row = 0; row < b.nrows; ++row, ++j) {
      double v = xi ? (*xi)[b.row0 + row] : 0.0;
      for (size_t i = 0; i < g.members.size(); ++i) {
        const int slot = artic_group_detail::slot_in(b, steps_[g.members[i]].child);
        if (slot < 0) continue;
        if (xi) v += b.J.row(row).segment<6>(6 * slot).dot(b_[g.members[i]]);
        v -= g.dse_rows[j][i].dot(sh[i]);
      }
      c0[j] = v;
    }
  }
  g.hc0 = g.H.solve(c0);
  if (g.parent != kGround) pa_[g.parent].noalias() += g.C.transpose() * g.hc0;
}

// mu = H^-1 c0 + H^-1 C vdot_p; each member's load E_i^T mu
void ArticulatedSweep::forward_group(const ConstraintEval& ce, Group& g, const VecX& vd) {
  if (g.simple) {
    const ConstraintBlock& b = ce.blocks[g.blocks[0]];
    double mu = g.hc0[0];
    if (g.parent != kGround) mu += g.c1.dot(vd.segment<6>(6 * g.parent)) / g.h1;
    g.mu[0] = mu;
    for (size_t i = 0; i < g.members.size(); ++i)
      ext_[g.members[i]] = mu * b.J.row(0).segment<6>(6 * g.slot[i]).transpose();
    return;
  }
  g.mu = g.hc0;
  if (g.parent != kGround) g.mu.noalias() += g.HiC * vd.segment<6>(6 * g.parent);
  for (int k : g.members) ext_[k].setZero();
  int j = 0;
  for (int bi : g.blocks) {
    const ConstraintBlock& b = ce.blocks[bi];
    for (int row = 0; row < b.nrows; ++row, ++j)
      for (int k : g.members) {
        const int slot = artic_group_detail::slot_in(b, steps_[k].child);
        if (slot >= 0) ext_[k].noalias() += g.mu[j] * b.J.row(row).segment<6>(6 * slot).transpose();
      }
  }
}

}  // namespace armdyn
