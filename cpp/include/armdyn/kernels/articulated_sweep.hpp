// SPDX-License-Identifier: BSD-3-Clause
// The KKT system of a tree in Cartesian coordinates,
//   Gamma vdot + zeta^T delta = eta,   zeta vdot = -xi,
// solved in O(n) by articulated-body recursions over the bodies' own coordinates (no KKT matrix,
// no Schur complement, no fill), exact for the system as evaluated (off the constraint manifold
// too).
//
// Each tree joint j (parent p, child c) has k rows Z_p vdot_p + Z_c vdot_c = -xi_j. Completed by
// 6 - k rows C (the joint's free directions: its axis, its slide, ...) to the invertible
//   T = [Z_c; C],   T^-1 = [P | S]   (P: 6 x k, S: 6 x (6 - k)),
// the child's acceleration is vdot_c = A vdot_p + S s + b with A = -P Z_p, b = -P xi_j and s free
// (any A + S M serves as well: the one used is [I X; 0 Y], 3 x 3 blocks, for every joint type).
// The balance of the child's subtree, Z_c^T delta_j = -(I^A_c vdot_c + p^A_c), gives S^T (I^A_c
// vdot_c + p^A_c) = 0 (Z_c S = 0), hence s, and passes I^A_c and p^A_c to the parent through A
// (Z_p^T delta_j = A^T (I^A_c vdot_c + p^A_c)): Featherstone's articulated-body algorithm with the
// constraint rows in place of the joint models. The multipliers follow from
// delta_j = -P^T (I^A_c vdot_c + p^A_c).
//
// Rows outside the tree's joints (ideal gears, couplings, drives of some coordinates) take one
// of two ways. Gear and coupling rows E on a body p and some of its children only (mimic fingers
// on a hand, a motor's rotor and the link it drives, both hanging from the same link) form a
// group, eliminated where the backward pass reaches p: each child keeps its own articulated step,
// its subtree's balance then loaded by the rows' forces E_i^T mu, so its acceleration is
// Q_i A_i vdot_p + b_i - Phi_i (h_i + E_i^T mu) (Q_i = 1 - S_i D_i^-1 U_i^T, Phi_i = S_i D_i^-1
// S_i^T, h_i = I^A_i b_i + p^A_i), and the rows give H mu = c0 + C vdot_p with
// H = sum_i E_i Phi_i E_i^T, C = E_p + sum_i E_i Q_i A_i, c0 = xi + sum_i E_i (b_i - Phi_i h_i):
// p receives C^T H^-1 C and C^T H^-1 c0 besides its children's usual shares (a rank-r update,
// r the group's rows). The other rows (at most kMaxExtraRows) enter through their multipliers
// mu: the solution is linear in them, so one response per row (the sweep with eta = -E_r^T,
// xi = 0) and a small dense solve give mu.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <vector>

#include "armdyn/kernels/constraint_rows.hpp"

namespace armdyn {

namespace artic_detail {
/// M += A^T Ia A for a transport A = [I X; 0 Y]
void add_congruence(const Mat6& Ia, const Mat3& X, const Mat3& Y, Mat6& M);
/// A^T v for a transport A = [I X; 0 Y] (a child's wrench carried to its parent)
inline Vec6 transport_transposed(const Mat3& X, const Mat3& Y, const Vec6& v) {
  Vec6 r;
  r.head<3>() = v.head<3>();
  r.tail<3>().noalias() = X.transpose() * v.head<3>() + Y.transpose() * v.tail<3>();
  return r;
}
}  // namespace artic_detail

class ArticulatedSweep {
 public:
  /// Each extra row costs one more sweep per factor (about a fifth of the solve): beyond two
  /// the KKT path's block elimination is cheaper (`python -m benchmarks.cartesian_fd
  /// --extra-rows`: a 200-link chain with 0 to 9 couplings; with the limit at 8 it measured
  /// 77, 91, 104, 134 and 189 us per state for 0, 1, 2, 4 and 8 rows, the KKT path 113 us).
  static constexpr int kMaxExtraRows = 2;
  /// Rows and children of a group at most.
  static constexpr int kMaxGroupRows = 4, kMaxGroupMembers = 4;
  /// The plan for model m with constraint blocks ce: ok() stays false unless m is a tree whose
  /// bodies each hang from one joint of a supported type (revolute, prismatic, cylindrical,
  /// universal, spherical, fixed, free), with no redundant rows and no forced dense KKT path.
  void plan(const Model& m, const ConstraintEval& ce);
  bool ok() const { return ok_; }
  /// Forget the factor (the next solve factors).
  void mark_stale() { factored_rows_ = -1; }
  /// The factor is the one of rows [0, nrows) at the pose loaded when kkt_factors (the KKT
  /// solver's factorisation count) was current.
  bool factored(int nrows, long kkt_factors) const {
    return factored_rows_ == nrows && kkt_factors_ == kkt_factors;
  }
  /// vdot and delta (rows [0, nrows)) from the evaluated constraints (with xi) and eta; when
  /// reuse, the factor of the last call (same pose, same rows) is kept. Without multipliers
  /// delta is left as it was (forward dynamics needs vdot only). Returns false, leaving
  /// vdot and delta unspecified, when a joint's completed block is singular to working
  /// precision, the extra rows are too many or dependent, or a result is not finite: the caller
  /// then takes the KKT path, which diagnoses it.
  bool solve(const Model& m, const std::vector<BodyKin>& kin, const ConstraintEval& ce, int nrows,
             const VecX& eta, VecX& vdot, VecX& delta, bool reuse, long kkt_factors,
             bool multipliers = true);

 private:
  struct Step {
    int joint, parent, child, block, nk;  // block: the joint's row block (-1: free joint)
    JointType type;
    // the joint's first rows make its points coincide and its free directions are rotations
    // (revolute, universal, spherical, fixed): T = [I B; 0 C], A = [I X; 0 Y]
    bool point;
  };
  std::vector<Step> steps_;
  std::vector<int> extra_blocks_;  // row blocks that are not tree joints' nor a group's
  using GroupMat =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxGroupRows, kMaxGroupRows>;
  using GroupVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxGroupRows, 1>;
  using GroupRows = Eigen::Matrix<double, Eigen::Dynamic, 6, 0, kMaxGroupRows, 6>;
  struct Group {
    int parent = kGround;      // p: a body, or ground
    int trigger = 0;           // the members' first step
    std::vector<int> members;  // steps whose children are p's children in the group
    std::vector<int> blocks;   // the rows' blocks
    int nrows = 0;
    bool on = false;  // its rows take part in this factor
    // per factor: C, H^-1 C, H's factor; per sweep: H^-1 c0; per forward pass: mu
    GroupRows C, HiC;
    Eigen::LLT<GroupMat> H;
    Vec6 dse_rows[kMaxGroupRows][kMaxGroupMembers];  // D_i^-1 S_i^T E_i^T per row and member
    GroupVec hc0, mu;
    // one row on one-direction children (a coupling, a gear: the common case), without the
    // dense algebra: the row's slot of each member, C^T, H, D_i^-1 S_i^T E_i^T
    bool simple = false;
    int slot[kMaxGroupMembers] = {};
    Vec6 c1 = Vec6::Zero();
    double h1 = 0.0, dse[kMaxGroupMembers] = {};
  };
  std::vector<Group> groups_;
  std::vector<int> step_group_;  // per step: its group, -1
  std::vector<Vec6> ext_;        // per member step: its rows' forces E_i^T mu
  // per step: P (T^-1 with S's columns zero: general joints), B and C^-1 (point joints), the
  // transport A = [I X; 0 Y], the free directions S, U = I^A S, D^-1 = (S^T U)^-1 (first
  // 6 - k columns), bias b
  std::vector<Mat6> tinv_, s_, u_;
  std::vector<Mat3> bm_, ci_, x_, y_;
  std::vector<Mat6> dinv_;  // top-left (6 - k) square used
  std::vector<Vec6> b_;
  // per body: articulated inertia and bias force
  std::vector<Mat6> ia_;
  std::vector<Vec6> pa_;
  // the extra rows' responses: per extra row, vdot and delta
  std::vector<VecX> resp_vd_, resp_delta_;
  VecX load_;
  bool resp_multipliers_ = false;  // the responses carry their multipliers
  std::vector<int> extra_rows_;    // the extra rows in [0, nrows), this solve's
  int factored_rows_ = -1;
  long kkt_factors_ = -1;
  bool ok_ = false;

  bool factor(const Model& m, const std::vector<BodyKin>& kin, const ConstraintEval& ce);
  void transport(const ConstraintEval& ce, size_t k);  // x_[k], y_[k]
  // groups (articulated_groups.cpp): formed by plan, switched on per factor by the rows taking
  // part, their rank-r update made at their trigger step (factor and backward: the members'
  // first step, after the members' own; forward: before them)
  void plan_groups(const Model& m, const ConstraintEval& ce, std::vector<char>& taken);
  bool groups_for_rows(const ConstraintEval& ce, int nrows);
  bool factor_group(const ConstraintEval& ce, Group& g);
  bool factor_simple_group(const ConstraintEval& ce, Group& g);
  void backward_group(const ConstraintEval& ce, const VecX* xi, Group& g);
  void forward_group(const ConstraintEval& ce, Group& g, const VecX& vdot);
  // S_i^T v and D_i^-1 S_i^T v of member step k (the first 6 - nk entries)
  Vec6 free_part(size_t k, const Vec6& v, Vec6& dv) const;
  void member_multipliers(const ConstraintEval& ce, size_t k, const Vec6& t, VecX& delta) const;
  bool complete_block(const Model& m, const std::vector<BodyKin>& kin, const ConstraintEval& ce,
                      const Step& s, Mat6& T) const;
  bool slide_block_inverse(const Model& m, const std::vector<BodyKin>& kin,
                           const ConstraintEval& ce, const Step& s, Mat6& Ti) const;
  void point_block(const Model& m, const std::vector<BodyKin>& kin, const ConstraintEval& ce,
                   const Step& s, Mat3& B, Mat3& C) const;
  /// The bias pass and the forward pass for loads eta and row values xi (tree rows only; none:
  /// a response, zero row values); the multipliers when delta is given.
  void sweep(const ConstraintEval& ce, const VecX* xi, const VecX& eta, VecX& vdot, VecX* delta);
  void backward(const ConstraintEval& ce, const VecX* xi, const VecX& eta);
  void forward(const ConstraintEval& ce, bool with_bias, VecX& vdot, VecX* delta);
  void bias(const ConstraintEval& ce, const VecX& xi, size_t k);
  bool extra_rows(const ConstraintEval& ce, int nrows, VecX& vdot, VecX* delta);
};

}  // namespace armdyn
