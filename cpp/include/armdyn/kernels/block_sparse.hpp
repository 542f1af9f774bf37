// SPDX-License-Identifier: BSD-3-Clause
// Block-sparse Cholesky factorisation of the Schur complement A = zeta W^-1 zeta^T.
//
// The unknowns are the constraint row blocks (a joint's rows, an ideal gear's row, a drive's row);
// A has a nonzero block (g, h) exactly when blocks g and h touch a common body. The blocks are
// ordered once per model (kkt_plans(), on first use), by minimum (row-weighted) degree with the
// drive blocks last, and the symbolic factorisation (the block pattern of L, with its fill) is
// fixed then; the numeric factorisation and the solves only walk precomputed lists and touch no
// allocator.
//
// This is the block form of Baraff's linear-time elimination ("Linear-time dynamics using
// Lagrange multipliers", SIGGRAPH 1996) on the range-space (Schur) form: on a tree of joints the
// minimum-degree order eliminates leaves first and produces no fill, so the cost is linear in the
// number of bodies (each body contributes the clique of the row blocks attached to it); a few
// loop closures (ideal gears, closing joints) add fill confined to the blocks of their loops; any
// other topology gets a general sparse factorisation in the same code.
//
// A plan covers the blocks with rows < nrows: one for all rows (forward dynamics, projection)
// and one for the joint rows alone (joint-space solves) when the model has drives.
#pragma once

#include <string>
#include <vector>

#include "armdyn/kernels/constraint_rows.hpp"

namespace armdyn {

/// The path of a model's KKT solves: the block-sparse factor of a tree (no fill), of a tree with
/// loops (fill along the loops) or of a general pattern, or the dense pivoted Schur complement
/// (redundant rows, force_dense_kkt, a plan without rows). None: no constraint rows (a model's
/// kkt_path()), or no plan made (KktPlans::joint of a model without drives).
enum class KktPath { None, Tree, TreeLoops, Sparse, Dense };
/// The path's name in messages, summaries and Python (Model.kkt_path): "tree", "tree+loops",
/// "sparse", "dense", and "" for None.
const char* kkt_path_name(KktPath path);

/// Symbolic plan of the block-sparse Schur factorisation (armdyn/kernels/block_sparse.hpp).
struct KktPlan {
  KktPath path = KktPath::None;  ///< Tree, TreeLoops, Sparse, or Dense (no rows)
  std::string description;       ///< one line for summary() (armdyn/builder/summary.hpp)
  std::vector<int> order;        ///< elimination position -> block index
  std::vector<int> pos;          ///< block index -> elimination position
  /// per position: the later positions with a nonzero block in its column of L (sorted)
  std::vector<std::vector<int>> cols;
  int nrows = 0;  ///< the plan covers the blocks with rows < nrows
  long factor_entries = 0, fill_blocks = 0, flops = 0;
  int loop_rows = 0;  ///< rows of the blocks that receive fill
};

/// The plans of a model: all rows, and the joint rows alone (only when the model has drives).
struct KktPlans {
  KktPlan all, joint;
};

/// The model's plans, made on first use and kept with the model (Model::derived): the block
/// structure only; a redundant model or one with force_dense_kkt takes the dense path whatever
/// the plan (kkt_path()).
const KktPlans& kkt_plans(const Model& m);
/// The path the KKT solves of m take: Dense for a redundant model or force_dense_kkt, else
/// kkt_plans(m).all.path (Tree, TreeLoops or Sparse); None without rows.
KktPath kkt_path(const Model& m);
/// One line on that path for summaries.
std::string kkt_path_description(const Model& m);

/// Order the blocks with rows < nrows by minimum row-weighted degree and compute the fill.
/// There is no size below which the plan turns dense: the block elimination ties with the dense
/// Schur Cholesky at 3 links (15 rows) and is faster from 4 links up
/// (python benchmarks/kkt_paths.py). The dense path is kept for redundant models, as the
/// fallback of a near-singular factor and as the reference (Model::with_kkt_path("dense")).
KktPlan plan_kkt(const Model& m, int nrows);

class BlockSparseSchur {
 public:
  BlockSparseSchur(const Model& m, const KktPlan& plan);
  /// Assemble A over the plan's blocks with the per-body metric blocks winv (nullptr: identity;
  /// otherwise block-diagonal per body, diag(W_xx, W_ww), as Gamma^-1 about the centre of mass
  /// is, and only those two 3 x 3 blocks are read) and factor it. Returns false, leaving the
  /// factor invalid, when a pivot is not positive or falls below 1e-12 of its row's diagonal
  /// (singular or nearly so: the caller then uses the dense pivoted path).
  /// shift > 0 factors A + shift diag(A) instead (Tikhonov, scaled per row): positive
  /// definite near singular configurations too; the rows whose pivots fall to the shift's
  /// level (below 10 shift of their diagonal: nearly dependent) are listed in weak_rows().
  bool factor(const ConstraintEval& ce, const std::vector<Mat6>* winv, double shift = 0.0);
  /// Rows of the last shifted factor whose constraints are (nearly) dependent on earlier ones.
  const std::vector<int>& weak_rows() const { return weak_; }
  /// Smallest pivot of the last factor relative to its row's diagonal (1: orthogonal rows).
  double min_relative_pivot() const { return min_rel_; }
  /// Solve A x = b in place over the plan's rows with the last factor.
  void solve_in_place(VecX& x) const;
  int nrows() const { return nrows_; }

 private:
  struct Column {
    int row0 = 0, size = 0;
    int diag = 0;                 // offset of the diagonal block (size x size, column-major)
    int sub_begin = 0, nsub = 0;  // entries of sub_ for the blocks below it
    int upd_begin = 0, nupd = 0;  // entries of upd_
  };
  struct Sub {
    int pos, off;  // position of the row block, offset of L(pos, k)
  };
  struct Update {
    int a, b;    // indices into this column's subs (a >= b)
    int target;  // offset of the target block (a, b) or diagonal of a
  };
  struct Assembly {
    int body, g, sg, h, sh;  // blocks g (row side) and h (column side) through body, slots
    int jw;                  // offset of J_g,sg W_body^-1 in jw_
    int target;              // offset of the block (g, h) in L storage (diagonal when g == h)
  };
  const Model& m_;
  std::vector<Column> col_;
  std::vector<Sub> sub_;
  std::vector<Update> upd_;
  std::vector<Assembly> asm_;
  // J_g,s W_b^-1 of each live (block, slot), 6 doubles per row, computed once per factor
  struct Scaled {
    int g, slot, off;
  };
  std::vector<Scaled> scaled_;
  std::vector<int> scaled_off_;  // (block, slot) -> offset in jw_ (-1: not live)
  std::vector<double> jw_;
  std::vector<double> val_;
  std::vector<double> diag0_;     // assembled diagonal of A (by row), for the relative pivot test
  std::vector<double> inv_diag_;  // 1 / L(i, i) by row
  std::vector<int> weak_;         // rows with pivots at the shift's level (capacity nc)
  double shift_ = 0.0, min_rel_ = 1.0;
  /// Factor block column k (S: its size at compile time, 0: at run time).
  template <int S>
  bool factor_column(int k);
  /// The forward (L) and backward (L^T) substitutions of block column k on x.
  template <int S>
  void forward_column(int k, double* x) const;
  template <int S>
  void backward_column(int k, double* x) const;
  int nrows_ = 0;
};

}  // namespace armdyn
