// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/model/profile.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "armdyn/errors.hpp"

namespace armdyn {

namespace {
void require_finite(double x, const char* what) {
  if (!std::isfinite(x)) throw ModelError(msg("profile: ", what, " must be finite, got ", x));
}
}  // namespace

Profile Profile::constant(double value) {
  require_finite(value, "value");
  Profile p;
  p.kind_ = Kind::Constant;
  p.p_[0] = value;
  return p;
}

Profile Profile::cubic(double y0, double y1, double t0, double t1) {
  require_finite(y0, "y0");
  require_finite(y1, "y1");
  require_finite(t0, "t0");
  require_finite(t1, "t1");
  if (!(t1 > t0)) throw ModelError(msg("profile cubic: need t1 > t0, got t0=", t0, " t1=", t1));
  Profile p;
  p.kind_ = Kind::Cubic;
  p.p_[0] = y0;
  p.p_[1] = y1;
  p.p_[2] = t0;
  p.p_[3] = t1;
  return p;
}

Profile Profile::quintic(double y0, double y1, double t0, double t1) {
  Profile p = cubic(y0, y1, t0, t1);
  p.kind_ = Kind::Quintic;
  return p;
}

Profile Profile::sine(double amplitude, double frequency, double phase, double offset) {
  require_finite(amplitude, "amplitude");
  require_finite(frequency, "frequency");
  require_finite(phase, "phase");
  require_finite(offset, "offset");
  Profile p;
  p.kind_ = Kind::Sine;
  p.p_[0] = amplitude;
  p.p_[1] = frequency;
  p.p_[2] = phase;
  p.p_[3] = offset;
  return p;
}

Profile Profile::spline(const std::vector<double>& t, const std::vector<double>& y) {
  const size_t n = t.size();
  if (n < 2 || y.size() != n)
    throw ModelError(
        msg("profile spline: need >= 2 samples and len(t) == len(y), got ", n, " and ", y.size()));
  for (size_t i = 0; i < n; ++i) {
    require_finite(t[i], "sample time");
    require_finite(y[i], "sample value");
    if (i > 0 && !(t[i] > t[i - 1]))
      throw ModelError(msg("profile spline: sample times must increase strictly (t[", i,
                           "] = ", t[i], " <= t[", i - 1, "] = ", t[i - 1], ")"));
  }
  Profile p;
  p.kind_ = Kind::Spline;
  p.t_ = t;
  p.y_ = y;
  // natural cubic spline: tridiagonal system for the second derivatives m_k, m_0 = m_{n-1} = 0
  p.m_.assign(n, 0.0);
  if (n > 2) {
    std::vector<double> c(n, 0.0), d(n, 0.0);
    for (size_t i = 1; i + 1 < n; ++i) {
      const double h0 = t[i] - t[i - 1], h1 = t[i + 1] - t[i];
      const double a = h0, b = 2.0 * (h0 + h1), cc = h1;
      const double r = 6.0 * ((y[i + 1] - y[i]) / h1 - (y[i] - y[i - 1]) / h0);
      const double denom = b - a * c[i - 1];
      c[i] = cc / denom;
      d[i] = (r - a * d[i - 1]) / denom;
    }
    for (size_t i = n - 2; i >= 1; --i) {
      p.m_[i] = d[i] - c[i] * p.m_[i + 1];
      if (i == 1) break;
    }
  }
  return p;
}

Profile Profile::callback(Callback fn, std::string description) {
  if (!fn) throw ModelError("profile callback: empty function");
  Profile p;
  p.kind_ = Kind::Callback;
  p.fn_ = std::move(fn);
  p.description_ = std::move(description);
  return p;
}

Profile::Raw Profile::raw() const {
  if (kind_ == Kind::Callback)
    throw ModelError(msg("profile ", describe(),
                         " is a user function: it cannot be stored (pickled or copied); use a "
                         "built-in profile (constant, cubic, quintic, sine, spline)"));
  Raw r;
  r.kind = kind_;
  for (int i = 0; i < 4; ++i) r.p[i] = p_[i];
  r.t = t_;
  r.y = y_;
  r.m = m_;
  r.description = description_;
  return r;
}

Profile Profile::restore(const Raw& raw) {
  // through the factories, which check every value; the spline's second derivatives are
  // computed again from its samples (raw.m is not read)
  Profile p;
  switch (raw.kind) {
    case Kind::Constant:
      p = constant(raw.p[0]);
      break;
    case Kind::Cubic:
      p = cubic(raw.p[0], raw.p[1], raw.p[2], raw.p[3]);
      break;
    case Kind::Quintic:
      p = quintic(raw.p[0], raw.p[1], raw.p[2], raw.p[3]);
      break;
    case Kind::Sine:
      p = sine(raw.p[0], raw.p[1], raw.p[2], raw.p[3]);
      break;
    case Kind::Spline:
      p = spline(raw.t, raw.y);
      break;
    default:
      throw ModelError("profile: a callback profile cannot be restored from stored values");
  }
  // the values a factory does not take must be its own (zeros, no samples, no description)
  for (int i = 0; i < 4; ++i)
    if (std::memcmp(&p.p_[i], &raw.p[i], sizeof(double)) != 0)
      throw ModelError(msg("profile: stored parameter ", i, " (", raw.p[i], ") is not the ",
                           p.describe(), "'s"));
  if ((raw.kind != Kind::Spline && (!raw.t.empty() || !raw.y.empty())) || !raw.description.empty())
    throw ModelError(
        msg("profile: stored samples or description do not belong to a ", p.describe()));
  return p;
}

void Profile::eval(const double* t, long n, double* y, double* yd, double* ydd) const {
  for (long k = 0; k < n; ++k) {
    const ProfileValue v = eval(t[k]);
    y[k] = v.y;
    yd[k] = v.yd;
    ydd[k] = v.ydd;
  }
}

ProfileValue Profile::eval(double t) const {
  ProfileValue v;
  switch (kind_) {
    case Kind::Constant:
      v.y = p_[0];
      break;
    case Kind::Cubic:
    case Kind::Quintic: {
      const double y0 = p_[0], dy = p_[1] - p_[0], t0 = p_[2], T = p_[3] - p_[2];
      if (t <= t0) {
        v.y = y0;
      } else if (t >= p_[3]) {
        v.y = p_[1];
      } else {
        const double s = (t - t0) / T;
        if (kind_ == Kind::Cubic) {
          v.y = y0 + dy * s * s * (3.0 - 2.0 * s);
          v.yd = dy * 6.0 * s * (1.0 - s) / T;
          v.ydd = dy * (6.0 - 12.0 * s) / (T * T);
        } else {
          const double s2 = s * s, s3 = s2 * s;
          v.y = y0 + dy * s3 * (10.0 - 15.0 * s + 6.0 * s2);
          v.yd = dy * 30.0 * s2 * (1.0 - s) * (1.0 - s) / T;
          v.ydd = dy * 60.0 * s * (1.0 - s) * (1.0 - 2.0 * s) / (T * T);
        }
      }
      break;
    }
    case Kind::Sine: {
      const double w = 2.0 * M_PI * p_[1];
      const double a = w * t + p_[2];
      v.y = p_[3] + p_[0] * std::sin(a);
      v.yd = p_[0] * w * std::cos(a);
      v.ydd = -p_[0] * w * w * std::sin(a);
      break;
    }
    case Kind::Spline: {
      const size_t n = t_.size();
      if (t <= t_[0] || t >= t_[n - 1]) {
        // linear extrapolation with the end slope
        const bool lo = t <= t_[0];
        const size_t i = lo ? 0 : n - 2;
        const double h = t_[i + 1] - t_[i];
        const double slope =
            lo ? (y_[1] - y_[0]) / h - h * (2.0 * m_[0] + m_[1]) / 6.0
               : (y_[n - 1] - y_[n - 2]) / h + h * (m_[n - 2] + 2.0 * m_[n - 1]) / 6.0;
        const double te = lo ? t_[0] : t_[n - 1];
        v.y = (lo ? y_[0] : y_[n - 1]) + slope * (t - te);
        v.yd = slope;
        break;
      }
      const size_t i =
          static_cast<size_t>(std::upper_bound(t_.begin(), t_.end(), t) - t_.begin()) - 1;
      const double h = t_[i + 1] - t_[i];
      const double a = (t_[i + 1] - t) / h, b = (t - t_[i]) / h;
      v.y = a * y_[i] + b * y_[i + 1] +
            ((a * a * a - a) * m_[i] + (b * b * b - b) * m_[i + 1]) * h * h / 6.0;
      v.yd = (y_[i + 1] - y_[i]) / h - (3.0 * a * a - 1.0) * h * m_[i] / 6.0 +
             (3.0 * b * b - 1.0) * h * m_[i + 1] / 6.0;
      v.ydd = a * m_[i] + b * m_[i + 1];
      break;
    }
    case Kind::Callback:
      v = fn_(t);
      if (!std::isfinite(v.y) || !std::isfinite(v.yd) || !std::isfinite(v.ydd))
        throw SolverError(
            msg("profile callback ", description_, " returned a non-finite value at t=", t));
      break;
  }
  return v;
}

double Profile::time_scale(double t, double eps) const {
  constexpr double inf = std::numeric_limits<double>::infinity();
  const double te = t + eps;
  switch (kind_) {
    case Kind::Cubic:
    case Kind::Quintic:
      return p_[1] != p_[0] && te >= p_[2] && te < p_[3] ? p_[3] - p_[2] : inf;
    case Kind::Sine:
      return p_[0] != 0.0 && p_[1] != 0.0 ? 1.0 / std::abs(p_[1]) : inf;
    case Kind::Spline: {
      if (te < t_.front() || te >= t_.back()) return inf;
      const size_t i =
          static_cast<size_t>(std::upper_bound(t_.begin(), t_.end(), te) - t_.begin()) - 1;
      return t_[i + 1] - t_[i];
    }
    default:
      return inf;
  }
}

double Profile::next_breakpoint(double t, double eps) const {
  constexpr double inf = std::numeric_limits<double>::infinity();
  switch (kind_) {
    case Kind::Cubic:
    case Kind::Quintic:
      if (p_[1] == p_[0]) return inf;
      if (p_[2] > t + eps) return p_[2];
      return p_[3] > t + eps ? p_[3] : inf;
    case Kind::Spline: {
      const auto it = std::upper_bound(t_.begin(), t_.end(), t + eps);
      return it == t_.end() ? inf : *it;
    }
    default:
      return inf;
  }
}

std::string Profile::describe() const {
  switch (kind_) {
    case Kind::Constant:
      return msg("constant(", p_[0], ")");
    case Kind::Cubic:
      return msg("cubic(", p_[0], " -> ", p_[1], ", t ", p_[2], " -> ", p_[3], ")");
    case Kind::Quintic:
      return msg("quintic(", p_[0], " -> ", p_[1], ", t ", p_[2], " -> ", p_[3], ")");
    case Kind::Sine:
      return msg("sine(amplitude ", p_[0], ", ", p_[1], " Hz)");
    case Kind::Spline:
      return msg("spline(", t_.size(), " samples)");
    case Kind::Callback:
      return msg("callback(", description_, ")");
  }
  return "profile";
}

}  // namespace armdyn
