// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <cmath>

namespace armdyn {

/// a - 2 pi k with k the integer nearest a / (2 pi): the angle wrapped to [-pi, pi], as
/// std::remainder(a, 2 pi) gives it (to a rounding of the last bit, ties aside), without the
/// library call on the hot path. 2 pi (the double) is split Cody-Waite style, hi with 30
/// significant bits and lo = 2 pi - hi exactly, so k hi and k lo are exact for |k| < 2^22.
inline double wrap_angle(double a) {
  constexpr double kHi = 0x1.921fb544p+2;  // 6.2831853069365025
  constexpr double kLo = 0x1.0b46p-32;     // 2.430837753308879e-10, kHi + kLo == 2.0 * M_PI
  const double x = a * (1.0 / (kHi + kLo));
  if (!(std::abs(x) < 4.0e6)) return std::remainder(a, kHi + kLo);  // large, inf or NaN
  const double k = static_cast<double>(static_cast<long>(x + (x >= 0.0 ? 0.5 : -0.5)));
  return (a - k * kHi) - k * kLo;
}

}  // namespace armdyn
