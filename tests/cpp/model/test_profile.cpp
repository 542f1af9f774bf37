// SPDX-License-Identifier: BSD-3-Clause
// Time profiles (armdyn/model/profile.hpp) against their closed forms; derivatives against
// central differences of the values.
#include <cmath>
#include <vector>

#include "armdyn/errors.hpp"
#include "armdyn/model/profile.hpp"
#include "check.hpp"

using namespace armdyn;

namespace {

/// y' and y'' of the profile by central differences of y and y' at t.
void check_derivatives(const Profile& p, double t, double tol) {
  const double h = 1e-5;
  const ProfileValue a = p.eval(t - h), b = p.eval(t + h), c = p.eval(t);
  CHECK_NEAR(c.yd, (b.y - a.y) / (2 * h), tol);
  CHECK_NEAR(c.ydd, (b.yd - a.yd) / (2 * h), tol);
}

}  // namespace

TEST_CASE(constant) {
  const ProfileValue v = Profile::constant(2.5).eval(7.0);
  CHECK(v.y == 2.5 && v.yd == 0.0 && v.ydd == 0.0);
}

TEST_CASE(cubic_rest_to_rest) {
  const double y0 = 0.3, y1 = -1.1, t0 = 0.5, t1 = 2.5;
  const Profile p = Profile::cubic(y0, y1, t0, t1);
  CHECK_NEAR(p.eval(t0).y, y0, 1e-15);
  CHECK_NEAR(p.eval(t1).y, y1, 1e-15);
  CHECK_NEAR(p.eval(0.5 * (t0 + t1)).y, 0.5 * (y0 + y1), 1e-15);  // odd about the midpoint
  CHECK_NEAR(p.eval(t0).yd, 0.0, 1e-15);
  CHECK_NEAR(p.eval(t1).yd, 0.0, 1e-15);
  // s = (t - t0)/T: y = y0 + (y1 - y0)(3 s^2 - 2 s^3)
  const double t = 1.1, s = (t - t0) / (t1 - t0);
  CHECK_NEAR(p.eval(t).y, y0 + (y1 - y0) * (3 * s * s - 2 * s * s * s), 1e-15);
  CHECK_NEAR(p.eval(-3.0).y, y0, 0.0);  // constant outside
  CHECK_NEAR(p.eval(9.0).y, y1, 0.0);
  check_derivatives(p, 1.3, 1e-8);
}

TEST_CASE(quintic_rest_to_rest) {
  const double y0 = -0.2, y1 = 0.9, t0 = 0.0, t1 = 1.5;
  const Profile p = Profile::quintic(y0, y1, t0, t1);
  for (double t : {t0, t1}) {
    CHECK_NEAR(p.eval(t).yd, 0.0, 1e-14);
    CHECK_NEAR(p.eval(t).ydd, 0.0, 1e-13);
  }
  CHECK_NEAR(p.eval(t1).y, y1, 1e-15);
  const double t = 0.4, s = t / t1;
  CHECK_NEAR(p.eval(t).y, y0 + (y1 - y0) * s * s * s * (10 - 15 * s + 6 * s * s), 1e-15);
  // peak speed at the midpoint: 15/8 (y1 - y0) / T
  CHECK_NEAR(p.eval(0.75).yd, 15.0 / 8.0 * (y1 - y0) / t1, 1e-14);
  check_derivatives(p, 0.9, 1e-8);
}

TEST_CASE(sine) {
  const double a = 0.7, f = 1.3, ph = 0.4, off = -0.1, t = 0.37;
  const ProfileValue v = Profile::sine(a, f, ph, off).eval(t);
  const double w = 2 * M_PI * f;
  CHECK_NEAR(v.y, off + a * std::sin(w * t + ph), 1e-15);
  CHECK_NEAR(v.yd, a * w * std::cos(w * t + ph), 1e-14);
  CHECK_NEAR(v.ydd, -a * w * w * std::sin(w * t + ph), 1e-13);
}

TEST_CASE(natural_spline) {
  const std::vector<double> t = {0.0, 0.4, 1.0, 1.7, 2.0}, y = {0.0, 0.5, -0.3, 0.2, 1.0};
  const Profile p = Profile::spline(t, y);
  for (size_t k = 0; k < t.size(); ++k) CHECK_NEAR(p.eval(t[k]).y, y[k], 1e-14);
  // natural end conditions
  CHECK_NEAR(p.eval(t.front()).ydd, 0.0, 1e-12);
  CHECK_NEAR(p.eval(t.back()).ydd, 0.0, 1e-12);
  // C2 at an interior knot: one-sided second derivatives agree
  CHECK_NEAR(p.eval(1.0 - 1e-9).ydd, p.eval(1.0 + 1e-9).ydd, 1e-6);
  check_derivatives(p, 0.7, 1e-7);
  // linear extrapolation with the end slope
  CHECK_NEAR(p.eval(3.0).y, 1.0 + p.eval(2.0).yd * 1.0, 1e-12);
  // a spline through samples of a straight line is that line
  const Profile line = Profile::spline({0.0, 1.0, 3.0}, {1.0, 3.0, 7.0});
  CHECK_NEAR(line.eval(2.2).y, 1.0 + 2.0 * 2.2, 1e-14);
  CHECK_NEAR(line.eval(2.2).yd, 2.0, 1e-14);
  CHECK_THROWS(Profile::spline({0.0, 0.0}, {1.0, 2.0}), ModelError);
  CHECK_THROWS(Profile::spline({0.0}, {1.0}), ModelError);
}

TEST_CASE(callback) {
  const Profile p =
      Profile::callback([](double t) { return ProfileValue{t * t, 2 * t, 2.0}; }, "t^2");
  const ProfileValue v = p.eval(3.0);
  CHECK(v.y == 9.0 && v.yd == 6.0 && v.ydd == 2.0);
  CHECK(p.kind() == Profile::Kind::Callback);
}

ARMDYN_TEST_MAIN()
