// SPDX-License-Identifier: BSD-3-Clause
// Explicit integrators on y = (u, v), with a projection after every accepted step:
//  - DOPRI5: Dormand-Prince 5(4), FSAL, PI step control and 4th-order dense output (Hairer,
//    Norsett & Wanner, Solving ODEs I, II.5 and II.6; the ode45 scheme). The error is estimated on
//    the unprojected pair; the accepted value is projected and the first stage re-evaluated there.
//  - DOP853: Dormand-Prince 8(5,3), 12 stages plus the step's end (FSAL), the error of the
//    5th-order estimate damped by the 3rd-order one, and 7th-order dense output from three
//    more stages, computed only on steps that hold an output time or an event (Hairer, Norsett
//    & Wanner, Solving ODEs I, II.10; Hairer's dop853). For tight tolerances, where DOPRI5
//    needs many times its steps. The error is estimated on the unprojected pair; the accepted
//    end point is projected and the step's last stage evaluated there.
//  - RK4: classical fixed step, projected after each step.
//  - TR-BDF2: the L-stable, stiffly accurate ESDIRK form of the trapezoidal rule followed by
//    BDF2 (Bank et al. 1985; Hosea & Shampine 1996, the ode23tb scheme), for stiff scenes. Order
//    2 with an embedded order-3 estimate, filtered by (I - h d J)^-1 for stiff components.
//    Stages are solved by simplified Newton with a finite-difference Jacobian of the same
//    right-hand side (the KKT accelerations), reused across steps and refreshed only when
//    Newton converges slowly or fails. Cubic Hermite dense output; projection after every step.
// Output times on a grid are served from the dense output (DOPRI5) or by landing steps on them
// (RK4); every output state is projected.
#pragma once

#include <Eigen/LU>
#include <array>
#include <limits>
#include <string>
#include <vector>

#include "armdyn/math/types.hpp"
#include "armdyn/poll.hpp"

namespace armdyn {

/// The time integration of a run. Default: Kinematic for a fully driven model with output
/// times, else Dopri5. Auto: Kinematic likewise, else choose_integrator().
enum class Integrator { Default, Auto, Dopri5, Dop853, Rk4, Trbdf2, Kinematic };
/// "dopri5", "dop853", "rk4", "trbdf2", "kinematic", "auto", "default".
const char* integrator_name(Integrator i);
/// The inverse of integrator_name; throws ModelError naming the accepted names.
Integrator integrator_from_name(const std::string& name);

class OdeSystem {
 public:
  virtual ~OdeSystem() = default;
  /// dy = f(t, y).
  virtual void rhs(double t, const VecX& y, VecX& dy) = 0;
  /// Project an accepted y in place, then dy = f(t, y) at the projected state.
  virtual void project_and_rhs(double t, VecX& y, VecX& dy) = 0;
  /// Whether DOPRI5 may evaluate its last stage at the projected end point (FSAL with the
  /// projection folded in). Near singular configurations the projection is ill-conditioned and
  /// the right-hand side changes fast under it, so the error estimate then needs the classic
  /// last stage at the unprojected point.
  virtual bool project_last_stage() const { return true; }
  /// Record an output at t (y is a state to be projected by the system, not yet recorded).
  virtual void output(double t, const VecX& y) = 0;
  /// Event functions g_i(t, y): a sign change inside a step is located on the dense output
  /// (Illinois method), the step is cut there and the integration restarts from that state
  /// (DOPRI5: its 4th-order dense output; TR-BDF2 and RK4: cubic Hermite).
  virtual int n_events() const { return 0; }
  virtual void events(double /*t*/, const VecX& /*y*/, double* /*g*/) {}
  /// The rates dg_i/dt of the event functions at (t, y) where the system knows them (NaN
  /// elsewhere); false when it knows none. With them, a function that turns and comes back
  /// within one step (of one sign at both ends, of the other between) is located too.
  virtual bool event_rates(double /*t*/, const VecX& /*y*/, double* /*dg*/) { return false; }
  /// Called for each located crossing; direction +1 when g goes from negative to positive.
  virtual void on_event(double /*t*/, int /*i*/, int /*direction*/) {}
  /// Called once after the on_event calls of a step's crossings, at the end of the cut step
  /// (the outputs inside it already served): the system may change the state y in place (an
  /// impact's velocity jump) and redefine its event functions (a stop engaging or releasing).
  /// Returns whether it did: the integrator then evaluates f afresh at the (projected) y and
  /// takes the event functions' signs there.
  virtual bool apply_events(double /*t*/, VecX& /*y*/) { return false; }
  /// Called by the adaptive explicit methods (DOPRI5, DOP853) once the run holds an accepted
  /// state (at the start and after each accepted step), and after each rejected step, whose
  /// trial end point the system may have projected (project_and_rhs): a system that keeps a
  /// state of its own along the run (the Cartesian run's angle tracking) saves it at the one
  /// and restores it at the other.
  virtual void step_accepted() {}
  virtual void step_rejected() {}
  /// The longest step the system allows from the accepted state at t (infinity: none), on top
  /// of the error control: a quantity the error estimate does not see -- a held joint stop's
  /// holding force under time-varying loads, whose sign an event function watches while the
  /// state stands still -- must be sampled densely enough for its sign changes to show. The
  /// adaptive methods (DOPRI5, DOP853, TR-BDF2) take it at the start and after every accepted
  /// step; RK4 keeps its fixed step.
  virtual double step_bound(double /*t*/) { return std::numeric_limits<double>::infinity(); }
};

struct StepStats {
  long steps = 0, rejected = 0, rhs_evals = 0, events = 0;
  long jacobians = 0, lu_factorizations = 0, newton_iterations = 0, newton_failures = 0;
};

struct StepOptions {
  double rtol = 1e-6, atol = 1e-8;
  double dt = 0.0;         ///< RK4 step; DOPRI5/DOP853 initial step (0: automatic)
  double max_step = 0.0;   ///< DOPRI5, DOP853, TR-BDF2 (0: no limit)
  double output_dt = 0.0;  ///< 0: output every accepted step
  long max_steps = 10000000;
  /// Called once per step (accepted or rejected; poll.hpp) with (t, t1): cancellation and
  /// progress. Null: none. The caller starts it (simulate() does); Interrupted (or whatever its
  /// callback throws) propagates out of the integrators.
  Poll* poll = nullptr;
};

/// Output times t0 + k dt strictly before t1 (within 1e-9 dt), then t1; empty when dt <= 0
/// (an output at every accepted step).
std::vector<double> output_times(double t0, double t1, double dt);
/// The same into ts (no allocation when its capacity suffices).
void output_times(double t0, double t1, double dt, std::vector<double>& ts);

/// Every buffer of the integrators -- stages, dense-output coefficients, event values, the
/// output times, TR-BDF2's Jacobian and LU -- sized by a run and reused by later runs of the
/// same size, so that a run allocates nothing once its work has been used (a Data holds one:
/// Data::integrator; without one, each call makes its own).
struct IntegratorWork {
  /// Vector slot i sized n (allocates only when its size changes).
  VecX& vec(int i, long n) {
    VecX& x = v_[static_cast<size_t>(i)];
    if (x.size() != n) x.resize(n);
    return x;
  }
  /// Matrix slot i sized n x n.
  MatX& mat(int i, long n) {
    MatX& x = m_[static_cast<size_t>(i)];
    if (x.rows() != n || x.cols() != n) x.resize(n, n);
    return x;
  }
  std::array<VecX, 16> stages;  ///< DOP853's stages
  std::array<VecX, 7> dense;    ///< DOP853's dense-output coefficients
  Eigen::PartialPivLU<MatX> lu;
  std::vector<double> times;
  std::vector<int> signs, crossed;

 private:
  std::array<VecX, 44> v_;
  std::array<MatX, 2> m_;
};

/// Integrate from t0 to t1; y holds the projected initial state on entry, the final on exit.
/// @throws SolverError on step-size underflow, too many steps or non-finite values.
void integrate_dopri5(OdeSystem& sys, VecX& y, double t0, double t1, const StepOptions& opt,
                      StepStats& stats, IntegratorWork* work = nullptr);
void integrate_dop853(OdeSystem& sys, VecX& y, double t0, double t1, const StepOptions& opt,
                      StepStats& stats, IntegratorWork* work = nullptr);
void integrate_trbdf2(OdeSystem& sys, VecX& y, double t0, double t1, const StepOptions& opt,
                      StepStats& stats, IntegratorWork* work = nullptr);
void integrate_rk4(OdeSystem& sys, VecX& y, double t0, double t1, const StepOptions& opt,
                   StepStats& stats, IntegratorWork* work = nullptr);

}  // namespace armdyn
