// SPDX-License-Identifier: BSD-3-Clause
#include "lcp.hpp"

#include <algorithm>
#include <cmath>

namespace armdyn {

void LcpSolver::reserve(int n) {
  if (n < 0) n = 0;
  if (T_.rows() >= n && static_cast<int>(basis_.size()) >= n) return;
  T_.resize(n, 2 * n + 2);
  basis_.assign(static_cast<size_t>(n), 0);
  zbasic_.assign(static_cast<size_t>(n), 0);
  z_.resize(n);
  w_.resize(n);
}

// Variables are numbered w_0..w_{n-1} = 0..n-1, z_0..z_{n-1} = n..2n-1, z0 = 2n; the tableau
// column of variable v is v, the right-hand side is column 2n + 1.
void LcpSolver::pivot(int n, int row, int col) {
  const int cols = 2 * n + 2;
  const double p = T_(row, col);
  for (int c = 0; c < cols; ++c) T_(row, c) /= p;
  T_(row, col) = 1.0;
  for (int r = 0; r < n; ++r) {
    if (r == row) continue;
    const double f = T_(r, col);
    if (f == 0.0) continue;
    for (int c = 0; c < cols; ++c) T_(r, c) -= f * T_(row, c);
    T_(r, col) = 0.0;
  }
  basis_[static_cast<size_t>(row)] = col;
  ++pivots_;
}

// The leaving row for the entering column col: the lexicographic minimum of
// (rhs_r, B^-1 row r) / T(r, col) over the rows with T(r, col) > 0 (B^-1 is the tableau's
// w-block). -1 when no entry is positive (a ray).
int LcpSolver::ratio_row(int n, int col) const {
  double cmax = 0.0;
  for (int r = 0; r < n; ++r) cmax = std::max(cmax, std::abs(T_(r, col)));
  const double piv_tol = 1e-12 * cmax;
  int best = -1;
  for (int r = 0; r < n; ++r) {
    const double a = T_(r, col);
    if (!(a > piv_tol)) continue;
    if (best < 0) {
      best = r;
      continue;
    }
    const double b = T_(best, col);
    // compare (rhs, B^-1 row) / a lexicographically, with a relative tie tolerance
    for (int k = -1; k < n; ++k) {
      const int c = k < 0 ? 2 * n + 1 : k;
      const double x = T_(r, c) / a, y = T_(best, c) / b;
      const double tol = 1e-10 * (std::abs(x) + std::abs(y));
      if (x < y - tol) {
        best = r;
        break;
      }
      if (x > y + tol) break;
    }
  }
  return best;
}

bool LcpSolver::solve(const MatX& M, const VecX& q, int n) {
  reserve(n);
  pivots_ = 0;
  if (lemke(M, q, n, 0.0)) return true;
  // A singular M (redundant rows: coupled stops) leaves exact ties that round-off breaks, and
  // Lemke may then end on a ray of a feasible problem. M + delta I is a P-matrix, on which it
  // always ends on a solution: complementary exactly, w = M z + q >= 0 to delta |z|.
  double scale = 0.0;
  for (int i = 0; i < n; ++i) scale = std::max(scale, std::abs(M(i, i)));
  // An infeasible problem has a solution with M + delta I too, with z ~ |q| / delta and w off by
  // the order of |q|: such an answer is refused.
  double qn = 0.0;
  for (int i = 0; i < n; ++i) qn = std::max(qn, std::abs(q[i]));
  for (double rel : {1e-12, 1e-9}) {
    if (!(scale > 0) || !lemke(M, q, n, rel * scale)) continue;
    bool feasible = true;
    for (int i = 0; i < n; ++i) {
      double wi = q[i];
      for (int k = 0; k < n; ++k) wi += M(i, k) * z_[k];
      feasible = feasible && wi >= -1e-6 * qn;
    }
    if (feasible) return true;
  }
  return false;
}

bool LcpSolver::lemke(const MatX& M, const VecX& q, int n, double delta) {
  const int rhs = 2 * n + 1, z0 = 2 * n;
  for (int i = 0; i < n; ++i) {
    basis_[static_cast<size_t>(i)] = i;
    zbasic_[static_cast<size_t>(i)] = 0;
    z_[i] = 0.0;
  }
  double qmin = 0.0;
  for (int i = 0; i < n; ++i) qmin = std::min(qmin, q[i]);
  if (qmin >= 0.0) {  // z = 0 solves it
    for (int i = 0; i < n; ++i) w_[i] = q[i];
    return true;
  }
  // the tableau [I | -M | -e | q]
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) {
      T_(r, c) = r == c ? 1.0 : 0.0;
      T_(r, n + c) = -M(r, c) - (r == c ? delta : 0.0);
    }
    T_(r, z0) = -1.0;
    T_(r, rhs) = q[r];
  }
  // z0 enters at the lexicographically most negative row: (q_r, e_r) smallest, ties to the
  // largest index
  int row = -1;
  for (int r = 0; r < n; ++r)
    if (row < 0 || q[r] <= q[row]) row = r;
  const int budget = 50 * (n + 1) * (n + 1) + 100;
  int leaving = basis_[static_cast<size_t>(row)];
  pivot(n, row, z0);
  for (;;) {
    const int entering = leaving < n ? leaving + n : leaving - n;  // the complement
    row = ratio_row(n, entering);
    if (row < 0 || pivots_ > budget) return false;  // a secondary ray
    // z0 leaves whenever it ties for the minimum: the basis is then complementary
    for (int r = 0; r < n; ++r) {
      if (basis_[static_cast<size_t>(r)] != z0 || r == row) continue;
      const double a = T_(r, entering);
      if (a > 0 && T_(r, rhs) / a <= T_(row, rhs) / T_(row, entering) * (1 + 1e-13) + 1e-300)
        row = r;
    }
    leaving = basis_[static_cast<size_t>(row)];
    pivot(n, row, entering);
    if (leaving == z0) break;
  }
  for (int r = 0; r < n; ++r) {
    const int v = basis_[static_cast<size_t>(r)];
    if (v >= n && v < 2 * n) {
      z_[v - n] = std::max(0.0, T_(r, rhs));
      zbasic_[static_cast<size_t>(v - n)] = 1;
    }
  }
  for (int i = 0; i < n; ++i) {
    if (zbasic_[static_cast<size_t>(i)]) {
      w_[i] = 0.0;
    } else {
      double s = q[i];
      for (int k = 0; k < n; ++k) s += M(i, k) * z_[k];
      w_[i] = s;
    }
  }
  return true;
}

}  // namespace armdyn
