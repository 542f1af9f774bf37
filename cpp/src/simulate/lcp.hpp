// SPDX-License-Identifier: BSD-3-Clause
// A small dense linear complementarity solver: find z with
//     w = M z + q,   w >= 0,   z >= 0,   w_i z_i = 0,
// by Lemke's complementary pivoting with the covering vector e and the lexicographic ratio
// test (Cottle, Pang & Stone, The Linear Complementarity Problem, 4.4 and 4.9). It is exact in
// the sense of a pivoting method: the answer is a complementary basis, so each pair has w_i = 0
// or z_i = 0 exactly, whatever the round-off in the other. The lexicographic rule makes it
// terminate on degenerate problems (zero entries of q, redundant rows); for a copositive-plus
// M (every symmetric positive semi-definite M, e.g. the Delassus matrix of joint stops) it finds
// a solution whenever one exists, and otherwise ends on a secondary ray (solve returns false).
// In floating point, a singular M (redundant rows) can break exact ties the wrong way and end on
// a ray of a feasible problem; solve then retries on M + delta I (delta 1e-12, then 1e-9, of
// the largest diagonal entry), a P-matrix: the answer is still a complementary basis, with
// w = M z + q >= 0 to within delta |z| (an answer off by more than 1e-6 |q| is refused: the
// problem is then infeasible).
// The workspace is sized once (reserve); solving allocates nothing.
#pragma once

#include <vector>

#include "armdyn/math/types.hpp"

namespace armdyn {

class LcpSolver {
 public:
  explicit LcpSolver(int max_n = 0) { reserve(max_n); }
  /// Size the workspace for problems of up to n unknowns (allocates).
  void reserve(int n);
  /// Solve the problem on the leading n x n block of M and the first n entries of q. Returns
  /// whether a solution was found (then z(), w(), basic_z() hold it); false on a secondary ray
  /// (no solution for a copositive-plus M) or when the pivot budget runs out.
  bool solve(const MatX& M, const VecX& q, int n);
  /// The solution (leading n entries valid).
  const VecX& z() const { return z_; }
  /// w = M z + q, computed from z (not from the tableau); w_i is set to 0 where z_i is basic.
  const VecX& w() const { return w_; }
  /// Whether z_i is in the final basis (then w_i = 0 by complementarity; z_i may be a
  /// degenerate 0).
  bool basic_z(int i) const { return zbasic_[static_cast<size_t>(i)] != 0; }
  /// Pivots of the last solve.
  int pivots() const { return pivots_; }

 private:
  bool lemke(const MatX& M, const VecX& q, int n, double delta);
  void pivot(int n, int row, int col);
  int ratio_row(int n, int col) const;

  MatX T_;  // n x (2n + 2): [w (identity at start) | z | z0 | rhs]
  std::vector<int> basis_;
  std::vector<char> zbasic_;
  VecX z_, w_;
  int pivots_ = 0;
};

}  // namespace armdyn
