// SPDX-License-Identifier: BSD-3-Clause
// Internal to simulate(): joint position limits as unilateral constraints (SimOptions::limits).
//
// Every one-coordinate joint (revolute, prismatic) with a finite lower or upper limit and no
// drive has a stop at each finite limit. A stop is free or engaged:
//  - free: its event function is the distance to the limit, s (q - limit) (s = +1 at a lower
//    limit, -1 at an upper; plus kMargin), located by the integrator when it turns negative: the
//    joint hits the stop. The impact is an impulse about the joint axis that leaves the rate s qd+
//    = -e s qd- (restitution e; engaged stops keep qd = 0), from the impulse-momentum equations of
//    the whole mechanism: the rate response to a unit impulse at stop k is the acceleration
//    response to a unit joint torque at k (the dynamics are affine in an added joint torque), so
//    one more evaluation per stop gives the Delassus matrix A_ik = s_i s_k (dqdd_i / dtau_k) (the
//    inverse mass matrix seen by the stops, positive definite for independent stops) and the
//    impulses solve A mu = s dqd. The kinetic energy drops by 1/2 (1 - e^2) qd-^2 / A_kk: it never
//    rises. With e = 0, or a rebound slower than kRestRate, the stop engages.
//  - engaged: the stop holds the joint with a torque s lambda (lambda >= 0) that keeps
//    s qdd = 0, from the same responses: A lambda = -s qdd_free. Its event function is lambda:
//    when the load would pull the joint off the stop (lambda turns negative), it releases.
// Both formulations give the same dynamics through the same three primitives (StopAccess):
// the accelerations with an added joint torque, the joint coordinate at a state, and its
// acceleration; the Cartesian path reuses the KKT factorisation for the responses.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "armdyn/errors.hpp"
#include "armdyn/math/types.hpp"
#include "armdyn/model/model.hpp"

namespace armdyn::detail {

/// What the stops need from a formulation's ODE system on y.
class StopAccess {
 public:
  virtual ~StopAccess() = default;
  /// dy = f(t, y) with the joint torques tau (model.nv_joint, the dof layout; nullptr: none).
  /// again: the same (t, y) as the previous call (a formulation may reuse its factorisation).
  virtual void stop_eval(double t, const VecX& y, const double* tau, VecX& dy, bool again) = 0;
  /// Load the state y for stop_coordinate (positions and rates).
  virtual void stop_load(const VecX& y) = 0;
  /// Joint coordinate c (model.coords index; angles multi-turn) and its rate at the loaded y.
  virtual void stop_coordinate(const VecX& y, int c, double& q, double& qd) = 0;
  /// The acceleration of coordinate c in dy, after stop_eval at y.
  virtual double stop_acceleration(const VecX& y, const VecX& dy, int c) = 0;
  /// The velocity block of y (and dy): [offset, offset + size).
  virtual long stop_velocity_offset() const = 0;
  virtual long stop_velocity_size() const = 0;
  /// Put coordinate c exactly on q (joint space; the Cartesian state leaves it as located).
  virtual void stop_place(VecX& /*y*/, int /*c*/, double /*q*/) {}
  /// Displace the positions of y along the velocity-shaped dv (first order: u += S(u) dv).
  virtual void stop_displace(VecX& /*y*/, const VecX& /*dv*/) {}
};

class LimitStops {
 public:
  struct Stop {
    int joint = 0, coord = 0, dof = 0;
    int side = 1;  ///< +1 lower limit, -1 upper
    double limit = 0.0;
    bool engaged = false;
    double lambda = 0.0;  ///< the stop's torque/force magnitude (engaged), >= 0
  };
  /// Kinds of the recorded events.
  enum Kind { Hit = 0, Bounce = 1, Release = 2 };
  /// Rebounds slower than this [rad/s or m/s] engage the stop instead of bouncing (no chatter
  /// of ever smaller bounces).
  static constexpr double kRestRate = 1e-6;
  /// A free stop's event fires this far (relative to max(1, |limit|)) beyond its limit.
  static constexpr double kMargin = 1e-9;
  /// Contact changes at one instant before the run is stopped as chattering.
  static constexpr int kMaxSwitches = 200;

  /// The stops of m (joints with finite limits, not driven); restitution in [0, 1].
  LimitStops(const Model& m, double restitution) : m_(m), e_(restitution) {
    std::vector<bool> driven(m.joints.size(), false);
    for (const Drive& d : m.drives) driven[static_cast<size_t>(d.joint)] = true;
    for (int j = 0; j < static_cast<int>(m.joints.size()); ++j) {
      const Joint& jt = m.joints[static_cast<size_t>(j)];
      if (driven[static_cast<size_t>(j)] || joint_coords(jt.type) != 1 || jt.coord0 < 0) continue;
      const bool has_lower = jt.lower > -1e299, has_upper = jt.upper < 1e299;
      if (!has_lower && !has_upper) continue;
      limited_.push_back(j);
      if (has_lower) stops_.push_back({j, jt.coord0, jt.dof0, 1, jt.lower});
      if (has_upper) stops_.push_back({j, jt.coord0, jt.dof0, -1, jt.upper});
    }
    const long k = static_cast<long>(stops_.size());
    A_.resize(k, k);
    L_.resize(k, k);
    rhs_.resize(k);
    sol_.resize(k);
    a0_.resize(k);
    set_.reserve(stops_.size());
    pending_.reserve(stops_.size());
    tau_ = VecX::Zero(m.nv_joint);
  }

  int size() const { return static_cast<int>(stops_.size()); }
  const std::vector<Stop>& stops() const { return stops_; }
  /// Joints with at least one stop (their columns in the outputs).
  const std::vector<int>& limited_joints() const { return limited_; }
  bool any_engaged() const {
    for (const Stop& s : stops_)
      if (s.engaged) return true;
    return false;
  }
  /// The stops' generalised force on joint j's coordinate (signed; 0 when free).
  double joint_force(int j) const {
    double f = 0.0;
    for (const Stop& s : stops_)
      if (s.joint == j && s.engaged) f += s.side * s.lambda;
    return f;
  }
  /// The engaged stops' joint torques (dof layout) from their lambdas.
  const VecX& torques() {
    tau_.setZero();
    for (const Stop& s : stops_)
      if (s.engaged) tau_[s.dof] += s.side * s.lambda;
    return tau_;
  }

  /// The initial state: refused outside the limits (beyond round-off); at a limit and not
  /// moving off it, the stop is hit there. Returns whether y changed.
  bool start(StopAccess& a, double t, VecX& y) {
    a.stop_load(y);
    for (int i = 0; i < size(); ++i) {
      const Stop& s = stops_[static_cast<size_t>(i)];
      double q, qd;
      a.stop_coordinate(y, s.coord, q, qd);
      const double tol = 1e-9 * std::max(1.0, std::abs(s.limit));
      const Joint& jt = m_.joints[static_cast<size_t>(s.joint)];
      if (s.side * (q - s.limit) < -tol)
        throw ModelError(msg("simulate: joint '", jt.name, "' starts at ", q, ", outside its ",
                             s.side > 0 ? "lower" : "upper", " limit ", s.limit,
                             " (limits='ignore' runs without them)"));
      if (s.side * (q - s.limit) <= tol && s.side * qd <= 0) pending_.push_back(i);
    }
    return apply(a, t, y);
  }

  /// Event functions: free stops' distance to their limits, engaged stops' lambdas.
  void events(StopAccess& a, double t, const VecX& y, VecX& scratch, double* g) {
    if (any_engaged()) {
      scratch.resize(y.size());
      a.stop_eval(t, y, nullptr, scratch, false);
      solve(a, t, y, scratch);
    } else {
      a.stop_load(y);
    }
    for (size_t i = 0; i < stops_.size(); ++i) {
      const Stop& s = stops_[i];
      if (s.engaged) {
        g[i] = s.lambda;
      } else {
        // the distance to the stop, plus a margin far below any tolerance: a joint that left
        // its stop (exactly on it) starts on the free side, so its next contact is a crossing
        double q, qd;
        a.stop_coordinate(y, s.coord, q, qd);
        g[i] = s.side * (q - s.limit) + kMargin * std::max(1.0, std::abs(s.limit));
      }
    }
  }

  void on_event(int i, int direction) {
    if (direction < 0) pending_.push_back(i);
  }

  /// dy (the free dynamics at (t, y), just evaluated) with the engaged stops' torques; their
  /// lambdas kept. Allocates nothing.
  void solve(StopAccess& a, double t, const VecX& y, VecX& dy) {
    set_.clear();
    for (int i = 0; i < size(); ++i) {
      Stop& s = stops_[static_cast<size_t>(i)];
      s.lambda = 0.0;
      if (s.engaged) set_.push_back(i);
    }
    if (set_.empty()) return;
    const long k = static_cast<long>(set_.size());
    responses(a, t, y, dy);
    for (long r = 0; r < k; ++r) rhs_[r] = -a0_[r];
    const long v0 = a.stop_velocity_offset(), nv = a.stop_velocity_size();
    solve_delassus(k);
    for (long c = 0; c < k; ++c) {
      Stop& s = stops_[static_cast<size_t>(set_[static_cast<size_t>(c)])];
      s.lambda = sol_[c];
      dy.segment(v0, nv).noalias() += sol_[c] * R_.col(c);
    }
  }

  /// Hold the engaged stops' joints exactly on them after a projection that knows nothing of
  /// the stops (the Cartesian one): the rates s qd and offsets s (q - limit) removed along the
  /// stops' responses (which keep the velocity constraints), dy the free dynamics at (t, y).
  /// Returns whether y moved (then f must be evaluated afresh).
  bool hold(StopAccess& a, double t, VecX& y, const VecX& dy) {
    set_.clear();
    for (int i = 0; i < size(); ++i)
      if (stops_[static_cast<size_t>(i)].engaged) set_.push_back(i);
    if (set_.empty()) return false;
    const long k = static_cast<long>(set_.size());
    responses(a, t, y, dy);
    const long v0 = a.stop_velocity_offset(), nv = a.stop_velocity_size();
    bool moved = false;
    for (int pass = 0; pass < 2; ++pass) {  // rates, then positions
      for (long r = 0; r < k; ++r) {
        const Stop& s = stops_[static_cast<size_t>(set_[static_cast<size_t>(r)])];
        double q, qd;
        a.stop_coordinate(y, s.coord, q, qd);
        rhs_[r] = pass == 0 ? -qd : s.limit - q;
        moved = moved || rhs_[r] != 0.0;
        rhs_[r] *= s.side;
      }
      solve_delassus(k);
      if (pass == 0) {
        for (long c = 0; c < k; ++c) y.segment(v0, nv).noalias() += sol_[c] * R_.col(c);
      } else {
        dv_.setZero(nv);
        for (long c = 0; c < k; ++c) dv_.noalias() += sol_[c] * R_.col(c);
        a.stop_displace(y, dv_);
      }
    }
    return moved;
  }

  /// The located crossings of a step, at the end of the cut step: hits (impacts), releases.
  /// Returns whether anything changed.
  bool apply(StopAccess& a, double t, VecX& y) {
    if (pending_.empty()) return false;
    bool changed = false;
    std::vector<int> hits;  // only on events: not a hot path
    for (int i : pending_) {
      Stop& s = stops_[static_cast<size_t>(i)];
      if (s.engaged) {
        s.engaged = false;
        s.lambda = 0.0;
        record(t, i, Release);
        changed = true;
      } else {
        hits.push_back(i);
      }
    }
    pending_.clear();
    if (!hits.empty()) {
      impact(a, t, y, hits);
      changed = true;
    }
    settle(a, t, y);
    // never a silent hang: a mechanism whose stops keep switching at one instant is an error
    if (t - chatter_t_ > 1e-9 * std::max(1.0, std::abs(t))) {
      chatter_t_ = t;
      chatter_n_ = 0;
    }
    if (++chatter_n_ > kMaxSwitches) {
      std::string names;
      for (const Stop& s : stops_)
        if (s.engaged) names += (names.empty() ? "'" : ", '") + m_.joints[s.joint].name + "'";
      throw SolverError(msg(
          "joint stops switch without end at t=", t, " (", kMaxSwitches,
          " contact changes at one instant; engaged: ", names.empty() ? std::string("none") : names,
          "); simulate(limits='ignore') runs without the stops"));
    }
    return changed;
  }

  /// The contact state at (t, y) consistent with the stops' unilateral law (an active set over
  /// the stops at their limits and at rest there): every engaged stop pushes (lambda >= 0) and
  /// no free one at its limit accelerates into it. One change at a time, the worst first.
  void settle(StopAccess& a, double t, VecX& y) {
    VecX& f = scratch_;
    f.resize(y.size());
    a.stop_load(y);
    std::vector<bool> at_rest(stops_.size(), false);
    for (int i = 0; i < size(); ++i) {
      const Stop& s = stops_[static_cast<size_t>(i)];
      double q, qd;
      a.stop_coordinate(y, s.coord, q, qd);
      const double scale = std::max(1.0, std::abs(s.limit));
      at_rest[static_cast<size_t>(i)] =
          !s.engaged && std::abs(q - s.limit) <= 1e-9 * scale && std::abs(qd) <= kRestRate;
    }
    for (int round = 0; round < 4 * size() + 4; ++round) {
      a.stop_eval(t, y, nullptr, f, false);
      solve(a, t, y, f);
      int worst = -1;
      double worst_value = 0.0;
      for (int i = 0; i < size(); ++i) {
        const Stop& s = stops_[static_cast<size_t>(i)];
        double value = 0.0;
        if (s.engaged)
          value = s.lambda;  // < 0: it would pull
        else if (at_rest[static_cast<size_t>(i)])
          value = s.side * a.stop_acceleration(y, f, s.coord);  // < 0: into the stop
        if (value < worst_value) {
          worst = i;
          worst_value = value;
        }
      }
      if (worst < 0) return;
      Stop& s = stops_[static_cast<size_t>(worst)];
      s.engaged = !s.engaged;
      s.lambda = 0.0;
      at_rest[static_cast<size_t>(worst)] = !s.engaged;
      if (s.engaged) a.stop_place(y, s.coord, s.limit);
      record(t, worst, s.engaged ? Hit : Release);
    }
  }

  /// Located stop events: time, stop index, kind.
  std::vector<double> event_t;
  std::vector<int> event_stop, event_kind;

 private:
  void record(double t, int i, Kind kind) {
    event_t.push_back(t);
    event_stop.push_back(i);
    event_kind.push_back(kind);
  }

  // R_ (velocity block x k): the responses of dy to a unit torque s_k at each stop of set_;
  // A_: their accelerations at the stops (times s_i); a0_: the stops' s_i qdd in dy.
  void responses(StopAccess& a, double t, const VecX& y, const VecX& dy) {
    const long k = static_cast<long>(set_.size());
    const long v0 = a.stop_velocity_offset(), nv = a.stop_velocity_size();
    if (R_.rows() != nv || R_.cols() < k) R_.resize(nv, size());
    dyk_.resize(dy.size());
    for (long r = 0; r < k; ++r) {
      const Stop& s = stops_[static_cast<size_t>(set_[static_cast<size_t>(r)])];
      a0_[r] = s.side * a.stop_acceleration(y, dy, s.coord);
    }
    for (long c = 0; c < k; ++c) {
      const Stop& sc = stops_[static_cast<size_t>(set_[static_cast<size_t>(c)])];
      tau_.setZero();
      tau_[sc.dof] = sc.side;
      a.stop_eval(t, y, tau_.data(), dyk_, true);
      R_.col(c) = dyk_.segment(v0, nv) - dy.segment(v0, nv);
      for (long r = 0; r < k; ++r) {
        const Stop& sr = stops_[static_cast<size_t>(set_[static_cast<size_t>(r)])];
        A_(r, c) = sr.side * a.stop_acceleration(y, dyk_, sr.coord) - a0_[r];
      }
    }
    tau_.setZero();
  }

  // sol_ = A^-1 rhs_ on the leading k x k block: Cholesky, a stop whose pivot vanishes
  // (dependent on the others: coupled joints on their stops together) takes no force.
  void solve_delassus(long k) {
    double scale = 0.0;
    for (long i = 0; i < k; ++i) scale = std::max(scale, std::abs(A_(i, i)));
    const double tiny = 1e-12 * scale;
    for (long j = 0; j < k; ++j) {
      double d = A_(j, j);
      for (long p = 0; p < j; ++p) d -= L_(j, p) * L_(j, p);
      const bool ok = d > tiny;
      L_(j, j) = ok ? std::sqrt(d) : 0.0;
      for (long i = j + 1; i < k; ++i) {
        double x = A_(i, j);
        for (long p = 0; p < j; ++p) x -= L_(i, p) * L_(j, p);
        L_(i, j) = ok ? x / L_(j, j) : 0.0;
      }
    }
    for (long i = 0; i < k; ++i) {  // L z = rhs
      double x = rhs_[i];
      for (long p = 0; p < i; ++p) x -= L_(i, p) * sol_[p];
      sol_[i] = L_(i, i) > 0 ? x / L_(i, i) : 0.0;
    }
    for (long i = k - 1; i >= 0; --i) {  // L^T sol = z
      double x = sol_[i];
      for (long p = i + 1; p < k; ++p) x -= L_(p, i) * sol_[p];
      sol_[i] = L_(i, i) > 0 ? x / L_(i, i) : 0.0;
    }
  }

  // The impulse of the stops hit (and of the engaged ones, which keep qd = 0) at (t, y).
  void impact(StopAccess& a, double t, VecX& y, const std::vector<int>& hits) {
    VecX& f = scratch_;
    f.resize(y.size());
    a.stop_load(y);
    std::vector<double> rate(stops_.size(), 0.0);
    for (int i = 0; i < size(); ++i) {
      double q, qd;
      a.stop_coordinate(y, stops_[static_cast<size_t>(i)].coord, q, qd);
      rate[static_cast<size_t>(i)] = qd;
    }
    // the post-impact rates: rebound -e qd- for the hits, 0 for the engaged
    std::vector<double> target(stops_.size(), 0.0);
    std::vector<bool> sticks(stops_.size(), false);
    for (int i : hits) {
      const Stop& s = stops_[static_cast<size_t>(i)];
      const double into = -s.side * rate[static_cast<size_t>(i)];  // > 0 moving into the stop
      const double out = e_ * std::max(into, 0.0);
      sticks[static_cast<size_t>(i)] = !(out > kRestRate);
      target[static_cast<size_t>(i)] = sticks[static_cast<size_t>(i)] ? 0.0 : s.side * out;
    }
    std::vector<bool> in_set(stops_.size(), false);
    for (int i = 0; i < size(); ++i) in_set[static_cast<size_t>(i)] = stops_[i].engaged;
    for (int i : hits) in_set[static_cast<size_t>(i)] = true;
    // impulses must push: a stop whose impulse would pull leaves the set (it separates)
    for (int round = 0; round <= size(); ++round) {
      set_.clear();
      for (int i = 0; i < size(); ++i)
        if (in_set[static_cast<size_t>(i)]) set_.push_back(i);
      if (set_.empty()) break;
      const long k = static_cast<long>(set_.size());
      a.stop_eval(t, y, nullptr, f, false);
      responses(a, t, y, f);
      for (long r = 0; r < k; ++r) {
        const int i = set_[static_cast<size_t>(r)];
        const Stop& s = stops_[static_cast<size_t>(i)];
        rhs_[r] = s.side * (target[static_cast<size_t>(i)] - rate[static_cast<size_t>(i)]);
      }
      solve_delassus(k);
      int worst = -1;
      for (long r = 0; r < k; ++r)
        if (sol_[r] < 0 && (worst < 0 || sol_[r] < sol_[worst])) worst = static_cast<int>(r);
      if (worst < 0 || round == size()) {
        const long v0 = a.stop_velocity_offset(), nv = a.stop_velocity_size();
        for (long c = 0; c < k; ++c) y.segment(v0, nv).noalias() += sol_[c] * R_.col(c);
        break;
      }
      in_set[static_cast<size_t>(set_[static_cast<size_t>(worst)])] = false;
    }
    for (int i : hits) {
      Stop& s = stops_[static_cast<size_t>(i)];
      const bool engage = sticks[static_cast<size_t>(i)] && in_set[static_cast<size_t>(i)];
      if (engage) {
        s.engaged = true;
        a.stop_place(y, s.coord, s.limit);
      }
      record(t, i, engage ? Hit : Bounce);
    }
    for (int i = 0; i < size(); ++i) {
      Stop& s = stops_[static_cast<size_t>(i)];
      if (s.engaged && !in_set[static_cast<size_t>(i)]) {
        s.engaged = false;
        record(t, i, Release);
      }
    }
  }

  const Model& m_;
  double e_;
  double chatter_t_ = -1e300;
  int chatter_n_ = 0;
  std::vector<Stop> stops_;
  std::vector<int> limited_, set_, pending_;
  MatX A_, L_, R_;
  VecX rhs_, sol_, a0_, tau_, dyk_, scratch_, dv_;
};

}  // namespace armdyn::detail
