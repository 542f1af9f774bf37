// SPDX-License-Identifier: BSD-3-Clause
// Constraint assembly: f(u, t), zeta = F S (velocity-space Jacobian) and xi with
//   zeta v = rhs (rhs = -df/dt, nonzero only for drives),  zeta vdot = -xi.
// zeta is stored as row blocks, one per joint (its rows) and one per drive (one row), each with
// 12 columns for the two bodies it touches. Row order: joints (by joint index), then drives.
#pragma once

#include <vector>

#include "armdyn/kernels/jets.hpp"

namespace armdyn {

/// A row block touches up to four bodies (joints and drives: two; ideal gears: the two gears
/// and their carriers), six columns each.
constexpr int kMaxBlockBodies = 4;
using BlockMat = Eigen::Matrix<double, Eigen::Dynamic, 6 * kMaxBlockBodies, Eigen::RowMajor, 6,
                               6 * kMaxBlockBodies>;

struct ConstraintBlock {
  int row0 = 0, nrows = 0;
  int nbody = 2;
  int body[kMaxBlockBodies] = {kGround, kGround, kGround, kGround};
  /// Rows 0..2 are coincident-point rows (spherical, revolute, universal and fixed joints):
  /// their translational columns are -I (slot 0) and +I (slot 1), and the block's other rows
  /// have none. The KKT assembly uses this structure.
  bool point_rows = false;
  BlockMat J;
};

struct ConstraintEval {
  VecX f, rhs, xi;
  /// Optional drive references overriding the drives' profiles: 3 * n_drives values laid out
  /// (q, qd, qdd) per drive; nullptr to use the profiles (joint-space inverse dynamics).
  const double* drive_ref = nullptr;
  /// false: drive rows get no residual (f = 0, no angle evaluated), for callers that only want
  /// zeta, rhs and xi at states built on the manifold (joint-space inverse dynamics).
  bool drive_values = true;
  /// Optional cache of coordinate jets at the evaluated state (the ideal gear rows read it).
  CoordJetCache* coord_cache = nullptr;
  /// Optional unwrapped references of angle coordinates (by coordinate index), so that ideal
  /// gear rows see multi-turn angles; nullptr: wrapped angles.
  const VecX* track_ref = nullptr;
  std::vector<ConstraintBlock> blocks;
  /// for each body: (block index, slot) of the blocks that touch it
  std::vector<std::vector<std::pair<int, int>>> body_blocks;

  void init(const Model& m);  ///< sizes and block structure (once per model)
};

/// Bodies of an ideal gear's row block (the gears and their carriers, ground excluded).
std::vector<int> gear_bodies(const Model& m, const GearConstraint& g);

/// Evaluate f, rhs and zeta (and xi when with_xi) at the kinematic state kin and time t.
void eval_constraints(const Model& m, const std::vector<BodyKin>& kin, double t, bool with_xi,
                      ConstraintEval& ce);

/// Zeta rows of joints and drives are stored in the first 12 columns (slots 0 and 1).
/// y = zeta x over rows [0, nrows) (y sized nc; rows >= nrows untouched).
void zeta_times(const ConstraintEval& ce, int nrows, Eigen::Ref<const VecX> x, VecX& y);
/// x = zeta^T y over rows [0, nrows) (x sized nv, overwritten).
void zeta_transpose_times(const ConstraintEval& ce, int nrows, Eigen::Ref<const VecX> y, VecX& x);
/// The rotation rows of revolute, cylindrical, prismatic and fixed joints are dot products of
/// frame axes; they also vanish on "flipped" branches (e.g. the child's joint axis reversed).
/// Returns the index of the first joint whose frames sit on such a branch (an aligned axis pair
/// with a negative dot product), or -1.
int flipped_joint(const Model& m, const std::vector<BodyKin>& kin);
/// Dense zeta (nc x nv), for tests and diagnostics.
MatX dense_zeta(const Model& m, const ConstraintEval& ce);

}  // namespace armdyn
