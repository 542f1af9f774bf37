// SPDX-License-Identifier: BSD-3-Clause
// Whole runs: integrate the constrained equations of motion from the model's assembled state (or
// from given joint coordinates) and record, at every output time, the projected state and its
// derived outputs (joint coordinates, drive forces, joint reactions, residuals, energies).
#pragma once

#include <exception>
#include <string>
#include <vector>

#include "armdyn/data.hpp"
#include "armdyn/integrate/integrators.hpp"
#include "armdyn/kernels/kkt_factor.hpp"
#include "armdyn/model/model.hpp"

namespace armdyn {

/// The state integrated (see SimOptions::coordinates).
enum class Coordinates { Cartesian, Joint, Auto };

/// "cartesian", "joint" or "auto"; throws ModelError otherwise.
Coordinates coordinates_from_name(const std::string& name);

struct SimOptions {
  Integrator integrator = Integrator::Default;
  StepOptions step;
  Metric projection = Metric::Mass;
  /// integrate bodies joined by fixed joints as one composite body (Model::welded)
  bool merge_welded = true;
  /// Cartesian: the bodies' Cartesian state (u, v) with the constrained Newton-Euler
  /// equations and the topological projection (the paper's method). Joint: the joint
  /// coordinates and rates (q, qd) of a tree, ideal gears allowed (TreeDynamics: CRBA and the
  /// gears' null space); the outputs are the same Cartesian tables, built from (q, qd). Auto:
  /// Joint wherever it applies (a tree without drives), else Cartesian.
  Coordinates coordinates = Coordinates::Cartesian;
  /// The joint-space q (model.nq_joint) the initial state was made from, or empty: its angles
  /// start the run's multi-turn tracking (q0 = 3.5 rad is reported as 3.5, not -2.78).
  VecX q_start;
  /// Joint position limits as unilateral stops (detail/limit_stops.hpp): every joint with one
  /// coordinate, a finite limit and no drive is held within it (impacts located as events,
  /// then the joint rests on its stop until the load pulls it off). false: limits ignored.
  bool limits = true;
  /// The stops' coefficient of restitution in [0, 1]: 0 (default) a plastic impact (the joint
  /// stays on the stop), 1 an elastic one.
  double restitution = 0.0;
};

/// Row-major output tables: one row per output time.
struct SimResult {
  long n = 0;
  std::vector<double> t, u, v, q, qd, qdd, drive_forces, reaction_forces, reaction_torques;
  std::vector<double> position_residual, velocity_residual, kinetic_energy, potential_energy;
  /// mesh force along the line of action of every gear pair, then every ideal gear [N]
  /// (positive when s > 0: pushes q_a and q_b back), one row per output
  std::vector<double> gear_forces;
  /// the joints held by stops (limits enforced), and the stops' torque/force on each joint's
  /// coordinate (positive along the coordinate: a lower stop pushes up), one row per output
  std::vector<std::string> limit_joints;
  std::vector<double> limit_forces;
  /// located stop events: time, joint, side (+1 lower, -1 upper), kind (0 the joint came to
  /// rest on the stop, 1 it bounced, 2 it left the stop)
  std::vector<double> limit_event_t;
  std::vector<std::string> limit_event_joint;
  std::vector<int> limit_event_side, limit_event_kind;
  /// applied generalised force on every joint dof (Model::dof_names; floating bases' zero),
  /// joint side: drive efforts + torque inputs + motor torques (after their torque limits);
  /// springs, dampers and friction excluded. One row per output.
  std::vector<double> joint_torques;
  StepStats stats;
  long kkt_solves = 0, factorizations = 0, position_projections = 0, newton_iterations = 0;
  long singular_evaluations = 0;
  std::string singular_note;
  /// accelerations solved in augmented form (light bodies, or lost accuracy), and why
  long augmented_solves = 0;
  std::string augmented_note;
  /// located events: gear contact onset (+1) and separation (-1), by gear index
  std::vector<double> event_t;
  std::vector<int> event_index, event_direction;
  double cpu_seconds = 0.0;
  std::string error;  ///< non-empty when the run stopped early (SolverError message)
  /// The exception that stopped the run early, when one did: an Interrupted (`error` then
  /// holds its message) or the SolverError. Callers that carry their own exception types
  /// (derived from these) through the run -- the Python bindings -- rethrow it.
  std::exception_ptr exception;
  bool interrupted = false;  ///< stopped by an Interrupted (opt.step.poll), not a SolverError
  std::string integrator, integrator_reason;  ///< the method used, and why (for "auto")
  int solver_bodies = 0, solver_rows = 0;     ///< bodies and rows of the model integrated
  std::string formulation;  ///< the coordinates integrated and the solver path, one line
};

/// Stiffness estimate for integrator="auto": the fastest rate |lambda| [1/s] of the force
/// elements (springs: sqrt(k / m_eff), dampers: c / m_eff, with m_eff the effective mass of the
/// element's direction under the constraints at the assembled state, from one KKT solve each),
/// and a sentence naming the element. The explicit DOPRI5 needs about |lambda| t_end / 3.3 steps
/// for stability alone; "auto" picks TR-BDF2 when that exceeds 5000 steps, else DOP853 for
/// rtol <= 1e-7 and DOPRI5 above.
double stiffness_estimate(const Model& m, std::string& culprit);
Integrator choose_integrator(const Model& m, double t_end, double rtol, std::string& reason);

/// Run from (u0, v0) (projected first) over [0, t_end]. Errors during the run stop it: the
/// result up to the last good output is returned with `error` set. So is an interruption by
/// an Interrupted (thrown by opt.step.poll or by a profile callback; `interrupted` set): the
/// caller decides what to raise (SimResult::exception).
/// @throws ModelError for invalid options or initial-state sizes.
SimResult simulate(const Model& m, double t_end, const SimOptions& opt, const VecX& u0,
                   const VecX& v0);
/// The same on d, a Data of m, whose buffers the run uses and keeps for the next (the
/// integrator's stages, the pipeline, a Data of the welded model): a run allocates only its
/// output tables once d has seen a run of the same kind (integrator "auto" also makes one Data
/// for its stiffness estimate). The result equals that of a new Data,
/// bit for bit. One Data per thread.
/// @throws ModelError also when d was made for another model.
SimResult simulate(const Model& m, Data& d, double t_end, const SimOptions& opt, const VecX& u0,
                   const VecX& v0);

}  // namespace armdyn
