// SPDX-License-Identifier: BSD-3-Clause
// Square constraint systems of fully driven trees. When every joint coordinate of a tree is
// driven, each joint's rows plus its drives' rows are six rows on its child's six velocities, so
// zeta is square and block-triangular in tree order, and the KKT system splits:
//   zeta vdot = -xi                    forward sweep (parents first) of 6x6 solves,
//   zeta^T delta = eta - Gamma vdot    backward sweep (children first),
// O(n) with no fill and no factorisation of the KKT matrix (Gamma does not enter the first).
#pragma once

#include <Eigen/LU>
#include <vector>

#include "armdyn/kernels/constraint_rows.hpp"

namespace armdyn {

class TreeSweep {
 public:
  /// The plan for model m with constraint blocks ce; ok() stays false when m is not a tree
  /// with every coordinate driven exactly once (or has ideal gears).
  void plan(const Model& m, const ConstraintEval& ce);
  bool ok() const { return ok_; }
  /// vdot and delta (all rows) from the evaluated constraints (with xi) and eta. Returns false,
  /// leaving vdot and delta unspecified, when a 6x6 block is singular to working precision
  /// (pivot ratio below 1e-10): the caller then takes the KKT path, which diagnoses it.
  bool solve(const Model& m, const ConstraintEval& ce, const VecX& eta, VecX& vdot, VecX& delta);

 private:
  struct Step {
    int parent, child;
    int blocks[4];  // the joint's block (if it has rows) and its drives' blocks
    int nblocks;
  };
  std::vector<Step> steps_;
  std::vector<Eigen::PartialPivLU<Mat6>> lu_;
  // block-triangular steps: the child's block is [A B; 0 C] (revolute joint plus drive, fixed
  // joint: A = +-I) or [0 C; A B] (prismatic joint plus drive), solved through the 3 x 3 inverses
  // of A and C. tri_: 0 full 6 x 6 LU, 1 upper form, 2 rows swapped.
  std::vector<char> tri_;
  std::vector<Mat3> ai_, b_, ci_;
  VecX r_;
  bool ok_ = false;
  void gather_child(const ConstraintEval& ce, const Step& s, Mat6& Z, Vec6& rhs) const;
  /// y -= Z_parent x (the parent's columns of the step's rows, read in place)
  void sub_parent_times(const ConstraintEval& ce, const Step& s, const Vec6& x, Vec6& y) const;
  /// y -= Z_parent^T d
  void sub_parent_transpose_times(const ConstraintEval& ce, const Step& s, const Vec6& d,
                                  Eigen::Ref<Vec6> y) const;
};

}  // namespace armdyn
