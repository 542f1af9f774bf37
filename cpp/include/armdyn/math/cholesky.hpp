// SPDX-License-Identifier: BSD-3-Clause
// Dense Cholesky factorisation M = L L^T and solve for the small symmetric positive definite
// systems of joint-space dynamics (a mass matrix of a few to a few tens of coordinates), in
// plain loops on column-major storage: at these sizes they cost a fraction of a blocked,
// dynamically sized factorisation.
#pragma once

#include <cmath>

#include "armdyn/math/types.hpp"

namespace armdyn {

/// Factor the symmetric matrix m (n x n; its lower triangle is read) into l's lower triangle,
/// m = l l^T (l's upper triangle is left as it was). Returns false when a pivot is not positive
/// (m is not positive definite); l is then partly written. l and m may be the same matrix.
inline bool cholesky_factor(const MatX& m, MatX& l) {
  const long n = m.rows();
  for (long j = 0; j < n; ++j) {
    double d = m(j, j);
    for (long k = 0; k < j; ++k) d -= l(j, k) * l(j, k);
    if (!(d > 0.0)) return false;
    d = std::sqrt(d);
    l(j, j) = d;
    const double inv = 1.0 / d;
    for (long i = j + 1; i < n; ++i) {
      double s = m(i, j);
      for (long k = 0; k < j; ++k) s -= l(i, k) * l(j, k);
      l(i, j) = s * inv;
    }
  }
  return true;
}

/// x <- (l l^T)^-1 x with l from cholesky_factor.
template <class Vector>
inline void cholesky_solve(const MatX& l, Vector& x) {
  const long n = l.rows();
  for (long i = 0; i < n; ++i) {  // l y = x
    double s = x[i];
    for (long k = 0; k < i; ++k) s -= l(i, k) * x[k];
    x[i] = s / l(i, i);
  }
  for (long i = n - 1; i >= 0; --i) {  // l^T x = y
    double s = x[i];
    for (long k = i + 1; k < n; ++k) s -= l(k, i) * x[k];
    x[i] = s / l(i, i);
  }
}

}  // namespace armdyn
