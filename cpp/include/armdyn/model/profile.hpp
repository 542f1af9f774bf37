// SPDX-License-Identifier: BSD-3-Clause
// Time profiles y(t) with first and second derivatives, used by drives (prescribed joint
// coordinates) and by profiled loads. All built-in kinds are evaluated in C++; a callback kind
// exists for user functions (the Python binding wraps a Python callable: slow, it takes the GIL).
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace armdyn {

/// Value, rate and second derivative of a profile at one time.
struct ProfileValue {
  double y = 0.0, yd = 0.0, ydd = 0.0;
};

class Profile {
 public:
  enum class Kind { Constant, Cubic, Quintic, Sine, Spline, Callback };
  using Callback = std::function<ProfileValue(double)>;

  /// y(t) = value.
  static Profile constant(double value);
  /// Cubic rest-to-rest from y0 at t0 to y1 at t1 (3s^2 - 2s^3), constant outside [t0, t1].
  static Profile cubic(double y0, double y1, double t0, double t1);
  /// Quintic rest-to-rest (10s^3 - 15s^4 + 6s^5), zero velocity and acceleration at both ends.
  static Profile quintic(double y0, double y1, double t0, double t1);
  /// y(t) = offset + amplitude sin(2 pi frequency t + phase); frequency in Hz.
  static Profile sine(double amplitude, double frequency, double phase, double offset);
  /// Natural cubic spline through (t_k, y_k), t strictly increasing, >= 2 samples; linear
  /// extrapolation (end slope) outside the samples.
  static Profile spline(const std::vector<double>& t, const std::vector<double>& y);
  /// User function returning y, dy/dt, d2y/dt2.
  static Profile callback(Callback fn, std::string description);

  ProfileValue eval(double t) const;
  /// eval at each of the n times t[k]: y[k], yd[k], ydd[k] (Python's Profile.eval of an array).
  void eval(const double* t, long n, double* y, double* yd, double* ydd) const;
  Kind kind() const { return kind_; }
  /// The time over which the profile changes appreciably on the step from t (t + eps taken
  /// for t: a step starting within eps before a breakpoint starts on it): a cubic/quintic's
  /// transition duration inside the transition, a sine's period, the spline's sample
  /// interval inside its samples; infinity where it is constant or linear (before or after a
  /// transition, a spline's extrapolation), for a constant and for a callback (unknown).
  /// Bounds the steps that must sample a load (simulate's held joint stops).
  double time_scale(double t, double eps) const;
  /// The first time strictly after t + eps where the profile's form changes (cubic/quintic:
  /// the transition's start and end; spline: its samples); infinity when none.
  double next_breakpoint(double t, double eps) const;
  std::string describe() const;

  /// The stored values of a built-in profile, for serialization (armdyn/io/serialize.hpp):
  /// restore(raw()) evaluates bit for bit as the original. A callback has none to store.
  struct Raw {
    Kind kind = Kind::Constant;
    double p[4] = {0, 0, 0, 0};
    std::vector<double> t, y, m;
    std::string description;
  };
  /// @throws ModelError for a callback profile (a user function cannot be stored).
  Raw raw() const;
  /// The profile made again by its factory (constant(), cubic(), ..., spline()), which checks
  /// every value; the spline's second derivatives are recomputed (raw.m is not read).
  /// @throws ModelError for a callback kind, a value the factory refuses (non-finite, t1 <= t0,
  /// samples not increasing) or stored values the factory would not have made.
  static Profile restore(const Raw& raw);

 private:
  Kind kind_ = Kind::Constant;
  double p_[4] = {0, 0, 0, 0};
  std::vector<double> t_, y_, m_;  // spline samples and second derivatives
  Callback fn_;
  std::string description_;
};

}  // namespace armdyn
