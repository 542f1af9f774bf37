// SPDX-License-Identifier: BSD-3-Clause
// The closed-form inverse of a 3 x 3 block, refused when singular to working precision.
#pragma once

#include <cmath>

#include "armdyn/math/types.hpp"

namespace armdyn {

/// Mi = M^-1; false (Mi untouched) when M is singular to working precision: its determinant
/// below 1e-10 of the product of its row norms.
inline bool inverse3_checked(const Mat3& M, Mat3& Mi) {
  const double det = M.determinant();
  if (!(std::abs(det) > 1e-10 * M.row(0).norm() * M.row(1).norm() * M.row(2).norm())) return false;
  Mi = M.inverse();
  return true;
}

}  // namespace armdyn
