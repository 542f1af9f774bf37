// SPDX-License-Identifier: BSD-3-Clause
// armdyn::LcpSolver (Lemke, lexicographic) against brute-force enumeration of the complementary
// bases: random P-matrix problems (one solution, which both must find), positive semi-definite
// problems with redundant rows and zero entries of q (degenerate: a solution exists; Lemke's
// satisfies every condition), and an infeasible one (a ray, reported as false).
#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "check.hpp"
#include "simulate/lcp.hpp"

using namespace armdyn;

namespace {

// The solution by enumeration of the 2^n supports (z_S = -M_SS^-1 q_S); false when none.
bool brute_force(const MatX& M, const VecX& q, VecX& z) {
  const int n = static_cast<int>(q.size());
  for (int mask = 0; mask < (1 << n); ++mask) {
    std::vector<int> s;
    for (int i = 0; i < n; ++i)
      if (mask & (1 << i)) s.push_back(i);
    const int k = static_cast<int>(s.size());
    MatX Ms(k, k);
    VecX qs(k);
    for (int a = 0; a < k; ++a) {
      qs[a] = q[s[a]];
      for (int b = 0; b < k; ++b) Ms(a, b) = M(s[a], s[b]);
    }
    VecX zs = k ? VecX(Ms.completeOrthogonalDecomposition().solve(-qs)) : VecX();
    if (k && (Ms * zs + qs).norm() > 1e-9 * (1 + qs.norm())) continue;  // not solvable on S
    z = VecX::Zero(n);
    for (int a = 0; a < k; ++a) z[s[a]] = zs[a];
    const VecX w = M * z + q;
    bool ok = true;
    for (int i = 0; i < n; ++i) ok = ok && z[i] >= -1e-10 && w[i] >= -1e-10;
    if (ok) return true;
  }
  return false;
}

// z >= 0, w = M z + q >= 0, z' w = 0 (within tol), and w() agrees with M z + q
void check_solution(const LcpSolver& lcp, const MatX& M, const VecX& q, int n, double tol) {
  const VecX z = lcp.z().head(n);
  const VecX w = M.topLeftCorner(n, n) * z + q.head(n);
  for (int i = 0; i < n; ++i) {
    CHECK(z[i] >= 0.0);
    CHECK(w[i] >= -tol);
    CHECK(std::abs(z[i] * w[i]) <= tol * (1 + std::abs(z[i])));
    if (lcp.basic_z(i)) CHECK(lcp.w()[i] == 0.0);
    if (!lcp.basic_z(i)) CHECK(z[i] == 0.0);
  }
}

// a random P-matrix: symmetric positive definite plus a skew part (P but not symmetric)
MatX random_p_matrix(std::mt19937& rng, int n) {
  std::normal_distribution<double> g;
  MatX B(n, n), S(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      B(i, j) = g(rng);
      S(i, j) = g(rng);
    }
  return B * B.transpose() + 0.1 * MatX::Identity(n, n) + 0.5 * (S - S.transpose());
}

}  // namespace

TEST_CASE(random_p_matrix_problems_match_enumeration) {
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  LcpSolver lcp(8);
  for (int trial = 0; trial < 400; ++trial) {
    const int n = 1 + trial % 8;
    const MatX M = random_p_matrix(rng, n);
    VecX q(n);
    for (int i = 0; i < n; ++i) q[i] = g(rng);
    VecX zb;
    CHECK(brute_force(M, q, zb));  // a P-matrix LCP has exactly one solution
    CHECK(lcp.solve(M, q, n));
    check_solution(lcp, M, q, n, 1e-9);
    CHECK_MAT_NEAR(lcp.z().head(n), zb, 1e-8 * (1 + zb.norm()));
  }
}

TEST_CASE(a_larger_workspace_solves_a_leading_block) {
  std::mt19937 rng(3);
  LcpSolver lcp(10);
  const MatX big = random_p_matrix(rng, 10);
  VecX q = VecX::LinSpaced(10, -1.0, 0.8);
  CHECK(lcp.solve(big, q, 4));
  const MatX M = big.topLeftCorner(4, 4);
  VecX zb;
  CHECK(brute_force(M, q.head(4), zb));
  CHECK_MAT_NEAR(lcp.z().head(4), zb, 1e-10);
}

TEST_CASE(degenerate_semidefinite_problems_are_solved) {
  // Delassus-like W M^-1 W' of rank r < n (redundant stops) with q = W v + zeros: feasible
  std::mt19937 rng(11);
  std::normal_distribution<double> g;
  LcpSolver lcp(8);
  int zeros = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const int n = 2 + trial % 7, r = 1 + trial % (n - 1);
    MatX W(n, r);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < r; ++j) W(i, j) = g(rng);
    if (trial % 3 == 0) W.row(n - 1) = W.row(0);   // two identical stops
    if (trial % 4 == 1) W.row(n - 1) = -W.row(0);  // a lower and an upper stop of one joint
    VecX v(r);
    for (int j = 0; j < r; ++j) v[j] = g(rng);
    if (trial % 2 == 0)  // degenerate: stops at rest (rows orthogonal to v, q_i = 0)
      for (int i = 0; i < n; i += 2)
        W.row(i) -= (W.row(i).dot(v) / v.squaredNorm()) * v.transpose();
    const MatX M = W * W.transpose();
    VecX q = W * v;
    if (trial % 2 == 0)
      for (int i = 0; i < n; i += 2) q[i] = 0.0;
    VecX zb;
    const bool exists = brute_force(M, q, zb);
    CHECK(exists);  // q in the range of M: the QP min z'Mz/2 + q'z (z >= 0) is bounded
    CHECK(lcp.solve(M, q, n));
    check_solution(lcp, M, q, n, 1e-8 * (1 + q.norm()) * (1 + lcp.z().head(n).norm()));
    zeros += trial % 2 == 0;
  }
  CHECK(zeros > 0);
}

TEST_CASE(all_zero_and_nonnegative_q_give_z_zero) {
  LcpSolver lcp(3);
  MatX M = MatX::Identity(3, 3);
  VecX q = VecX::Zero(3);
  CHECK(lcp.solve(M, q, 3));
  CHECK(lcp.z().head(3).isZero(0.0));
  q << 0.0, 2.0, 0.5;
  CHECK(lcp.solve(M, q, 3));
  CHECK(lcp.z().head(3).isZero(0.0));
  CHECK(lcp.pivots() == 0);
}

TEST_CASE(an_infeasible_problem_ends_on_a_ray) {
  // w1 = z1 - z2 + q1, w2 = -z1 + z2 + q2 with q1 + q2 < 0: w1 + w2 = q1 + q2 < 0
  MatX M(2, 2);
  M << 1, -1, -1, 1;
  VecX q(2);
  q << -1.0, -0.5;
  LcpSolver lcp(2);
  CHECK(!lcp.solve(M, q, 2));
  VecX zb;
  CHECK(!brute_force(M, q, zb));
}

ARMDYN_TEST_MAIN()
