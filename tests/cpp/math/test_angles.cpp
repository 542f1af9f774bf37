// SPDX-License-Identifier: BSD-3-Clause
// wrap_angle (armdyn/math/angles.hpp) against std::remainder(a, 2 pi).
#include <cmath>
#include <limits>

#include "armdyn/math/angles.hpp"
#include "check.hpp"

using armdyn::wrap_angle;

TEST_CASE(wrap_equals_remainder) {
  const double two_pi = 2.0 * M_PI;
  for (double a = -1000.0; a <= 1000.0; a += 0.7371) {
    const double w = wrap_angle(a);
    CHECK(std::abs(w) <= M_PI + 1e-15);
    CHECK_NEAR(w, std::remainder(a, two_pi), 4e-16 * std::max(1.0, std::abs(a)));
    // a and its wrap differ by a whole number of turns
    const double turns = (a - w) / two_pi;
    CHECK_NEAR(turns, std::round(turns), 1e-12);
  }
}

TEST_CASE(wrap_keeps_small_angles_and_handles_large_ones) {
  CHECK(wrap_angle(0.0) == 0.0);
  CHECK(wrap_angle(1.25) == 1.25);
  CHECK(wrap_angle(-3.0) == -3.0);
  CHECK_NEAR(wrap_angle(3.5), 3.5 - 2 * M_PI, 1e-15);
  // beyond the Cody-Waite range: the library remainder
  CHECK(wrap_angle(1e9) == std::remainder(1e9, 2.0 * M_PI));
  CHECK(std::isnan(wrap_angle(std::numeric_limits<double>::quiet_NaN())));
}

ARMDYN_TEST_MAIN()
