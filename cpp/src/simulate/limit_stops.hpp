// SPDX-License-Identifier: BSD-3-Clause
// Internal to simulate(): joint position limits as unilateral constraints (SimOptions::limits).
//
// Every one-coordinate joint (revolute, prismatic) with a finite lower or upper limit and no
// drive has a stop at each finite limit; s = +1 at a lower limit, -1 at an upper, so that the
// gap s (q - limit) >= 0 inside. A stop is free or engaged:
//  - free: its event function is the gap plus kMargin (relative to max(1, |limit|)); the
//    integrator locates its sign change and, through the event rates
//    s qd, a gap that turns negative and back within one step (the joint out past the stop and
//    back). Every contact change leaves a free stop exactly on its limit or inside it, so its
//    event function always starts positive and the next crossing is a sign change.
//  - engaged: the stop holds the joint with a torque s lambda, lambda >= 0, that keeps
//    s qdd = 0 (a bilateral solve over the engaged stops between events, A lambda = -s qdd_free).
//    Its event function is lambda: when it turns negative, the contact problem is solved again.
// The contact problem, at every event, over the stops in contact C (engaged, crossed at the event,
// or within 2 kTol of their limits), through the Delassus matrix A_ik = s_i s_k dqdd_i/dtau_k (the
// inverse mass matrix seen by the stops: the rate response to a unit impulse at k, positive
// semi-definite):
//  1. Impact, when a stop of C approaches (s qd < 0): Poisson's law as linear complementarity
//     problems (lcp.hpp, exact pivoting, any number of stops, redundant ones too). The
//     compression impulses solve  w = A mu_c + v-,  mu_c >= 0, w >= 0, mu_c' w = 0  (v- the stops'
//     rates s qd); restitution adds e mu_c, so v+ = v- + (1 + e) A mu_c. The kinetic energy drops
//     by 1/2 (1 - e^2) mu_c' A mu_c: it never rises (one stop: 1/2 (1 - e^2) qd-^2 / A_kk). A stop
//     that the restitution drives into its limit (coupled stops) starts another round.
//  2. Accumulation: a rebound whose apex v+^2 / (2 |a|) under the acceleration a back into the
//     stop (with the other resting stops' forces, not its own) stays within the stop's tolerance
//     cannot be resolved by any event location: the geometric series of ever shorter bounces that
//     would follow is summed at once (its restitution is dropped, the joint rests on the stop),
//     losing exactly the energy the series would lose, the rebound's kinetic energy. (Should
//     dropping some coupled stops' restitution but not others' raise the energy, the whole impact
//     is plastic.)
//  3. Resting contact: over the stops of C at rest (a rate within the same apex bound: a held
//     stop's own force would make its acceleration 0 and release it at any round-off rate, and
//     two coupled stops, one struck while the other rests, would then take turns), the
//     acceleration-level problem  w = A lambda + a0,  lambda >= 0, w >= 0, lambda' w = 0  (a0 the
//     stops' s qdd without stop forces): a stop with w = 0 engages (degenerate ones, lambda = 0,
//     stay free, and so does one the bilateral solve over the engaged stops then finds pulling
//     or holding with less than 1e-6 of the torque that stops its free acceleration: the event
//     function of every engaged stop starts positive), one with w > 0 is free and leaves its
//     limit.
// Each stop whose state changed records one event ("rest", "bounce" or "release"): never a rest
// and a release of one stop at one instant. Positions of C are put on their limits, rates of
// the engaged stops to zero (joint space: exactly; Cartesian: along the stops' responses, which
// keep the velocity constraints; the Cartesian system projects the located state onto the
// constraints before, and the integrator after, so that the stops stay on their limits to
// round-off and the velocity residual stays at round-off). Both formulations give the same dynamics
// through the same primitives (StopAccess); the Cartesian path reuses the KKT factorisation for the
// responses.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "armdyn/errors.hpp"
#include "armdyn/math/types.hpp"
#include "armdyn/model/model.hpp"
#include "lcp.hpp"

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
  /// Hold coordinate c exactly on q at rest (joint space: q and its rate 0; the Cartesian
  /// state is held along the stops' responses by hold()).
  virtual void stop_pin(VecX& /*y*/, int /*c*/, double /*q*/) {}
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
  /// The stop's tolerance, relative to max(1, |limit|): a rebound whose apex stays within it
  /// ends at rest (an accumulation); stops this close to their limits are in contact.
  static constexpr double kTol = 1e-9;
  /// A free stop's event fires this far (relative to max(1, |limit|)) beyond its limit: far
  /// below kTol, so that putting a located hit back on the limit adds far less potential energy
  /// than the smallest resolved bounce dissipates (else a chatter of bounces at that energy).
  static constexpr double kMargin = 1e-12;
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
    for (MatX* M : {&A_, &L_, &Ms_}) M->resize(k, k);
    for (VecX* v : {&rhs_, &sol_, &a0_, &vm_, &vp_, &vr_, &mu_, &ep_, &lam_, &acc_, &qs_})
      v->resize(k);
    for (std::vector<char>* f : {&pend_, &was_, &hit_, &rest_, &sep_}) f->assign(stops_.size(), 0);
    set_.reserve(stops_.size());
    sub_.reserve(stops_.size());
    cset_.reserve(stops_.size());
    pending_.reserve(stops_.size());
    lcp_.reserve(static_cast<int>(k));
    tau_ = VecX::Zero(m.nv_joint);
    // the time-varying loads (step_bound)
    for (const CoordForce& cf : m.coord_forces) {
      if (cf.has_input) loads_.push_back(&cf.input);
      if (cf.motor) loads_.push_back(&cf.reference);
    }
    for (const BodyLoad& bl : m.body_loads)
      if (bl.has_profile) loads_.push_back(&bl.profile);
    for (const Drive& d : m.drives) loads_.push_back(&d.profile);
  }

  /// Samples of a load's time scale per step while a stop is held (step_bound).
  static constexpr double kSamplesPerScale = 16.0;

  /// The longest step from t (OdeSystem::step_bound): unbounded while every stop is free (the
  /// gaps' sign changes follow the motion, which the error control resolves, and their dips
  /// are caught through their rates); while a stop is held, its event function is its holding
  /// force, a function of time through the applied loads while the state stands still. The
  /// error estimate is then zero (nothing moves) and the steps would grow without bound,
  /// stepping over an interval where the force turns negative and back (a release missed).
  /// The steps are bounded so that the force is sampled densely on the loads' own time
  /// scales: at most 1/16 of each time-varying load profile's local time scale (a sine's
  /// period, a cubic or quintic transition's duration while in it, a spline's sample interval
  /// while within its samples; none where a profile is constant or linear), and ending
  /// on the profiles' breakpoints (a transition's start and end, a spline's samples), so that
  /// a short pulse after a long constant stretch is sampled from its start. A callback profile
  /// has no known time scale: simulate's max_step bounds its steps.
  double step_bound(double t) const {
    double h = std::numeric_limits<double>::infinity();
    if (!any_engaged()) return h;
    const double eps = 1e-12 * std::max(1.0, std::abs(t));
    for (const Profile* p : loads_) {
      h = std::min(h, p->time_scale(t, eps) / kSamplesPerScale);
      h = std::min(h, p->next_breakpoint(t, eps) - t);
    }
    return h;
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
  /// The stop's tolerance in its coordinate's unit.
  double tolerance(const Stop& s) const { return kTol * std::max(1.0, std::abs(s.limit)); }

  /// The initial state: refused outside the limits (beyond the tolerance); the contact problem
  /// at the stops on their limits. Returns whether y changed.
  bool start(StopAccess& a, double t, VecX& y) {
    a.stop_load(y);
    for (int i = 0; i < size(); ++i) {
      const Stop& s = stops_[static_cast<size_t>(i)];
      double q, qd;
      a.stop_coordinate(y, s.coord, q, qd);
      const Joint& jt = m_.joints[static_cast<size_t>(s.joint)];
      if (s.side * (q - s.limit) < -tolerance(s))
        throw ModelError(msg("simulate: joint '", jt.name, "' starts at ", q, ", outside its ",
                             s.side > 0 ? "lower" : "upper", " limit ", s.limit,
                             " (limits='ignore' runs without them)"));
    }
    return resolve(a, t, y);
  }

  /// Event functions: free stops' gaps plus kMargin, engaged stops' lambdas.
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
        double q, qd;
        a.stop_coordinate(y, s.coord, q, qd);
        g[i] = s.side * (q - s.limit) + kMargin * std::max(1.0, std::abs(s.limit));
      }
    }
  }
  /// The event functions' rates where known: s qd for the free stops, NaN for the engaged.
  void event_rates(StopAccess& a, const VecX& y, double* dg) {
    a.stop_load(y);
    for (size_t i = 0; i < stops_.size(); ++i) {
      const Stop& s = stops_[i];
      double q, qd;
      a.stop_coordinate(y, s.coord, q, qd);
      dg[i] = s.engaged ? std::numeric_limits<double>::quiet_NaN() : s.side * qd;
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
    responses(a, t, y, dy);
    return place(a, y, static_cast<long>(set_.size()), true);
  }

  /// The engaged stops' coordinates exactly on their limits at rest (joint space, after each
  /// step: the bilateral solve keeps their accelerations at round-off, whose integral would
  /// otherwise drift them off the limits, and a stop released off its limit would fire again).
  void pin(StopAccess& a, VecX& y) {
    for (const Stop& s : stops_)
      if (s.engaged) a.stop_pin(y, s.coord, s.limit);
  }

  /// The located crossings of a step, at the end of the cut step: the contact problem there.
  /// Returns whether anything changed.
  bool apply(StopAccess& a, double t, VecX& y) {
    if (pending_.empty()) return false;
    std::fill(pend_.begin(), pend_.end(), 0);
    for (int i : pending_) pend_[static_cast<size_t>(i)] = 1;
    pending_.clear();
    const bool changed = resolve(a, t, y);
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
    return changed || true;  // the crossed functions' signs are taken afresh either way
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

  Stop& at(long r) { return stops_[static_cast<size_t>(set_[static_cast<size_t>(r)])]; }

  // The contact problem at (t, y) over the stops in contact (see the header). Returns whether
  // y or the contact state changed.
  bool resolve(StopAccess& a, double t, VecX& y) {
    // C: the engaged stops, the crossed ones and those within 2 kTol of their limits; their
    // rates v-
    a.stop_load(y);
    set_.clear();
    double vscale = 0.0;
    for (int i = 0; i < size(); ++i) {
      Stop& s = stops_[static_cast<size_t>(i)];
      was_[static_cast<size_t>(i)] = s.engaged;
      hit_[static_cast<size_t>(i)] = pend_[static_cast<size_t>(i)] && !s.engaged;
      double q, qd;
      a.stop_coordinate(y, s.coord, q, qd);
      // (a located crossing is a contact even where the Cartesian projection of the located
      // state moved the joint back inside by more than that: else it crosses again at once)
      if (!s.engaged && !pend_[static_cast<size_t>(i)] && s.side * (q - s.limit) > 2 * tolerance(s))
        continue;
      vm_[static_cast<long>(set_.size())] = s.side * qd;
      vscale = std::max(vscale, std::abs(s.side * qd));
      set_.push_back(i);
    }
    std::fill(pend_.begin(), pend_.end(), 0);
    const long k = static_cast<long>(set_.size());
    if (k == 0) return false;
    VecX& f = scratch_;
    f.resize(y.size());
    a.stop_eval(t, y, nullptr, f, false);
    responses(a, t, y, f);  // A over C (positions only: valid through the impacts), R
    eps_v_ = 1e-12 * vscale;
    const long v0 = a.stop_velocity_offset(), nv = a.stop_velocity_size();
    for (long r = 0; r < k; ++r) mu_[r] = 0.0;
    for (int round = 0; round < kMaxSwitches; ++round) {
      bool again = false;
      if (!impact(a, t, y, k, v0, nv, again)) break;
      if (!again) break;
    }
    if (mu_.head(k).isZero(0.0)) rest_set(a, t, y, k);  // no impact: the resting contact alone
    engage(a, t, y, k);
    // the record: one event per stop whose state changed
    for (long r = 0; r < k; ++r) {
      const int i = set_[static_cast<size_t>(r)];
      const Stop& s = stops_[static_cast<size_t>(i)];
      const bool was = was_[static_cast<size_t>(i)] != 0;
      if (was && !s.engaged)
        record(t, i, Release);
      else if (!was && s.engaged)
        record(t, i, Hit);
      else if (!was && (hit_[static_cast<size_t>(i)] || mu_[r] > 0))
        record(t, i, Bounce);
    }
    return true;
  }

  // One impact round from the stops' current rates; mu_ accumulates the impulses of C. Sets
  // again when the restitution drove a stop of C into its limit (another round). Returns false
  // when no stop approaches.
  bool impact(StopAccess& a, double t, VecX& y, long k, long v0, long nv, bool& again) {
    a.stop_load(y);
    bool approach = false;
    for (long r = 0; r < k; ++r) {
      double q, qd;
      a.stop_coordinate(y, at(r).coord, q, qd);
      qs_[r] = at(r).side * qd;
      approach = approach || qs_[r] < -eps_v_;
    }
    if (!approach) return false;
    for (long r = 0; r < k; ++r) vm_[r] = qs_[r];
    // compression: w = A mu_c + v-, complementary
    Ms_.topLeftCorner(k, k) = A_.topLeftCorner(k, k);
    if (!lcp_.solve(Ms_, qs_, static_cast<int>(k))) {
      std::string names;
      for (long r = 0; r < k; ++r) names += (r ? ", '" : "'") + m_.joints[at(r).joint].name + "'";
      throw SolverError(msg("joint stops: no impulse stops the impact at t=", t, " (stops of ",
                            names, "); simulate(limits='ignore') runs without the stops"));
    }
    dv_ = y.segment(v0, nv);  // the velocities before this round
    for (long r = 0; r < k; ++r) ep_[r] = lcp_.z()[r] > 0 ? e_ : 0.0;
    VecX& muc = sol_;
    muc.head(k) = lcp_.z().head(k);
    // restitution, dropped for rebounds that accumulate (their apex within the tolerance)
    for (int pass = 0; pass <= k; ++pass) {
      mixed_restitution_guard(k, muc);
      for (long r = 0; r < k; ++r) rhs_[r] = (1.0 + ep_[r]) * muc[r];
      y.segment(v0, nv) = dv_;
      for (long c = 0; c < k; ++c) y.segment(v0, nv).noalias() += rhs_[c] * R_.col(c);
      vp_.head(k) = vm_.head(k) + A_.topLeftCorner(k, k) * rhs_.head(k);
      rest_set(a, t, y, k);
      bool dropped = false;
      for (long r = 0; r < k; ++r) {
        // a rebound within the apex bound (rest_set): the series of bounces it starts is
        // summed, the stop rests
        if (ep_[r] > 0.0 && rest_[static_cast<size_t>(r)]) {
          ep_[r] = 0.0;
          dropped = true;
        }
      }
      if (!dropped) break;
    }
    for (long r = 0; r < k; ++r) mu_[r] += rhs_[r];
    again = false;
    for (long r = 0; r < k; ++r)
      again = again || (!rest_[static_cast<size_t>(r)] && vp_[r] < -vr_[r] - eps_v_);
    return true;
  }

  // Per-stop restitution (some rebounds dropped) can raise the kinetic energy of coupled stops:
  // 1/2 ((E mu)' A (E mu) - mu' A mu) > 0. Then every stop of the impact is plastic.
  void mixed_restitution_guard(long k, const VecX& muc) {
    bool mixed = false;
    for (long r = 0; r < k; ++r) mixed = mixed || (muc[r] > 0 && ep_[r] != e_);
    if (!mixed) return;
    for (long r = 0; r < k; ++r) qs_[r] = ep_[r] * muc[r];
    const double gain = qs_.head(k).dot(A_.topLeftCorner(k, k) * qs_.head(k)) -
                        muc.head(k).dot(A_.topLeftCorner(k, k) * muc.head(k));
    if (gain > 0)
      for (long r = 0; r < k; ++r) ep_[r] = 0.0;
  }

  // The resting contact at (t, y) over C: the stops' rates vp_, free accelerations a0_, the
  // rest set (rates within the apex bound vr_ of the acceleration acc_ back into the stop),
  // its LCP: lam_ (0 off the set), sep_ (separating: w > 0), acc_ = a0 + A lambda.
  void rest_set(StopAccess& a, double t, const VecX& y, long k) {
    VecX& f = scratch_;
    a.stop_eval(t, y, nullptr, f, false);
    for (long r = 0; r < k; ++r) {
      double q, qd;
      a.stop_coordinate(y, at(r).coord, q, qd);
      vp_[r] = at(r).side * qd;
      a0_[r] = at(r).side * a.stop_acceleration(y, f, at(r).coord);
      acc_[r] = a0_[r];
      lam_[r] = 0.0;
      rest_[static_cast<size_t>(r)] = 0;
    }
    for (int round = 0; round <= k + 1; ++round) {
      bool changed = false;
      for (long r = 0; r < k; ++r) {
        // the acceleration back into the stop without its own holding force (the others'
        // kept): with it, a held stop's acceleration is 0 and any rate would release it
        const double back = -(acc_[r] - A_(r, r) * lam_[r]);
        vr_[r] = std::sqrt(2.0 * tolerance(at(r)) * std::max(0.0, back));
        const char in = vp_[r] <= vr_[r] + eps_v_ ? 1 : 0;
        changed = changed || in != rest_[static_cast<size_t>(r)];
        rest_[static_cast<size_t>(r)] = in;
      }
      if (!changed && round > 0) break;
      sub_.clear();
      for (long r = 0; r < k; ++r)
        if (rest_[static_cast<size_t>(r)]) sub_.push_back(static_cast<int>(r));
      const long m = static_cast<long>(sub_.size());
      for (long i = 0; i < m; ++i) {
        qs_[i] = a0_[sub_[static_cast<size_t>(i)]];
        for (long j = 0; j < m; ++j)
          Ms_(i, j) = A_(sub_[static_cast<size_t>(i)], sub_[static_cast<size_t>(j)]);
      }
      if (m > 0 && !lcp_.solve(Ms_, qs_, static_cast<int>(m))) {
        std::string names;
        for (long i = 0; i < m; ++i)
          names += (i ? ", '" : "'") + m_.joints[at(sub_[static_cast<size_t>(i)]).joint].name + "'";
        throw SolverError(msg("joint stops: no contact forces hold the stops of ", names,
                              " at rest at t=", t,
                              "; simulate(limits='ignore') runs without the stops"));
      }
      lam_.head(k).setZero();
      for (long r = 0; r < k; ++r) sep_[static_cast<size_t>(r)] = 0;
      for (long i = 0; i < m; ++i) {
        const long r = sub_[static_cast<size_t>(i)];
        lam_[r] = lcp_.z()[i];
        sep_[static_cast<size_t>(r)] = !lcp_.basic_z(static_cast<int>(i)) && lcp_.w()[i] > 0;
      }
      acc_.head(k) = a0_.head(k) + A_.topLeftCorner(k, k) * lam_.head(k);
    }
  }

  // The new contact state over C from rest_set: the stops at rest that do not separate and
  // push engage (lambda > 0; the bilateral solve over them confirms it), the others are free;
  // then every stop of C on its limit, the engaged ones' rates zeroed.
  void engage(StopAccess& a, double t, VecX& y, long k) {
    cset_.assign(set_.begin(), set_.end());  // (solve rebuilds set_)
    for (long r = 0; r < k; ++r)
      at(r).engaged = rest_[static_cast<size_t>(r)] && !sep_[static_cast<size_t>(r)] && lam_[r] > 0;
    VecX& f = scratch_;
    // a stop the bilateral solve pulls, or holds with next to nothing (below 1e-6 of the torque
    // that stops its free acceleration: round-off of a degenerate contact), is free
    for (int round = 0; round <= k; ++round) {
      a.stop_eval(t, y, nullptr, f, false);
      solve(a, t, y, f);  // (set_: the engaged stops, a0_ and A_ theirs)
      long worst = -1;
      double worst_value = 0.0;
      for (long r = 0; r < static_cast<long>(set_.size()); ++r) {
        const double value = at(r).lambda - 1e-6 * std::abs(a0_[r]) / A_(r, r);
        if (value <= 0 && (worst < 0 || value < worst_value)) {
          worst = r;
          worst_value = value;
        }
      }
      if (worst < 0) break;
      at(worst).engaged = false;
      at(worst).lambda = 0.0;
    }
    // positions of C on their limits; the engaged stops' rates to zero
    set_.clear();
    for (int i : cset_)
      if (stops_[static_cast<size_t>(i)].engaged) set_.push_back(i);
    if (!set_.empty()) {
      a.stop_eval(t, y, nullptr, f, false);
      responses(a, t, y, f);
      place(a, y, static_cast<long>(set_.size()), true);
    }
    set_.assign(cset_.begin(), cset_.end());
    a.stop_eval(t, y, nullptr, f, false);
    responses(a, t, y, f);
    place(a, y, k, false);
  }

  // Rates (when rates) and offsets from the limits of the leading k stops of set_ removed along
  // their responses R_ (A_ their Delassus matrix); the joint formulation then places them
  // exactly. Returns whether y moved.
  bool place(StopAccess& a, VecX& y, long k, bool rates) {
    const long v0 = a.stop_velocity_offset(), nv = a.stop_velocity_size();
    bool moved = false;
    for (int pass = rates ? 0 : 1; pass < 2; ++pass) {  // rates, then positions
      a.stop_load(y);
      for (long r = 0; r < k; ++r) {
        const Stop& s = at(r);
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
        for (long r = 0; r < k; ++r) {
          a.stop_place(y, at(r).coord, at(r).limit);
          if (rates) a.stop_pin(y, at(r).coord, at(r).limit);  // an engaged stop at rest
        }
      }
    }
    a.stop_load(y);
    return moved;
  }

  // R_ (velocity block x k): the responses of dy to a unit torque s_k at each stop of set_;
  // A_: their accelerations at the stops (times s_i); a0_: the stops' s_i qdd in dy.
  void responses(StopAccess& a, double t, const VecX& y, const VecX& dy) {
    const long k = static_cast<long>(set_.size());
    const long v0 = a.stop_velocity_offset(), nv = a.stop_velocity_size();
    if (R_.rows() != nv || R_.cols() < k) R_.resize(nv, size());
    dyk_.resize(dy.size());
    for (long r = 0; r < k; ++r) a0_[r] = at(r).side * a.stop_acceleration(y, dy, at(r).coord);
    for (long c = 0; c < k; ++c) {
      const Stop& sc = at(c);
      tau_.setZero();
      tau_[sc.dof] = sc.side;
      a.stop_eval(t, y, tau_.data(), dyk_, true);
      R_.col(c) = dyk_.segment(v0, nv) - dy.segment(v0, nv);
      for (long r = 0; r < k; ++r)
        A_(r, c) = at(r).side * a.stop_acceleration(y, dyk_, at(r).coord) - a0_[r];
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

  const Model& m_;
  double e_;
  double eps_v_ = 0.0;  // the round-off of the stops' rates at this event
  double chatter_t_ = -1e300;
  int chatter_n_ = 0;
  std::vector<Stop> stops_;
  std::vector<const Profile*> loads_;  // the model's time-varying loads (step_bound)
  std::vector<int> limited_, set_, sub_, cset_, pending_;
  std::vector<char> pend_, was_, hit_, rest_, sep_;
  LcpSolver lcp_;
  MatX A_, L_, R_, Ms_;
  VecX rhs_, sol_, a0_, vm_, vp_, vr_, mu_, ep_, lam_, acc_, qs_, tau_, dyk_, scratch_, dv_;
};

}  // namespace armdyn::detail
