// SPDX-License-Identifier: BSD-3-Clause
// Dense output the integrators share (private to cpp/src/integrate): the cubic Hermite
// interpolant of RK4 and TR-BDF2, and the output times served from a step's dense output.
#pragma once

#include <vector>

#include "armdyn/integrate/integrators.hpp"

namespace armdyn::detail {

/// Cubic Hermite interpolant on [t, t + h] through (y0, f0) and (y1, f1), at theta. The
/// expression is coefficient-wise, so out may be y1 itself.
inline void hermite(double th, double h, const VecX& y0, const VecX& f0, const VecX& y1,
                    const VecX& f1, VecX& out) {
  const double h00 = (1 + 2 * th) * (1 - th) * (1 - th), h10 = th * (1 - th) * (1 - th);
  const double h01 = th * th * (3 - 2 * th), h11 = th * th * (th - 1);
  out = h00 * y0 + (h10 * h) * f0 + h01 * y1 + (h11 * h) * f1;
}

/// The output times touts[ko..] in (t, tn] from the dense output dense(theta, yo) of the step
/// [t, t + h]; ko moves past them.
template <class Dense>
void serve_outputs(OdeSystem& sys, const std::vector<double>& touts, size_t& ko, double t, double h,
                   double tn, const Dense& dense, VecX& yo) {
  for (; ko < touts.size() && touts[ko] <= tn; ++ko) {
    dense((touts[ko] - t) / h, yo);
    sys.output(touts[ko], yo);
  }
}

}  // namespace armdyn::detail
