// SPDX-License-Identifier: BSD-3-Clause
// The result of a run (simulate): its output tables, events and statistics, each declared once
// in the field lists below. SimResult's members, the Python result dict the bindings make of it,
// the exported field lists (armdyn._core._SIM_TABLES, ...) and output_row_bytes expand from
// them; tests/docs/test_schema.py checks the Python SimulationResult against them.
#pragma once

#include <exception>
#include <string>
#include <vector>

#include "armdyn/integrate/integrators.hpp"
#include "armdyn/model/columns.hpp"
#include "armdyn/model/model.hpp"

namespace armdyn {

/// The output tables of a run, row-major, one row per output time: X(name, columns, doc). The
/// one list of them: SimResult's members, the bindings' result dict, the Python
/// SimulationResult's fields (tests/docs/test_schema.py) and output_row_bytes follow it.
#define ARMDYN_SIM_TABLES(X)                                                                    \
  X(t, None, "(n,) output times [s]")                                                           \
  X(u, Nq, "(n, nq) positions: per body CoM and Euler parameters (scalar first)")               \
  X(v, Nv, "(n, nv) velocities: per body CoM velocity (world) and angular velocity (body)")     \
  X(q, NqJoint, "(n, n_joint_coords) joint-space coordinates (angles unwrapped along the run)") \
  X(qd, NvJoint, "(n, n_joint_dofs) joint-space rates")                                         \
  X(qdd, NvJoint, "(n, n_joint_dofs) joint-space accelerations")                                \
  X(drive_forces, Drives, "(n, n_drives) actuator torque/force of each drive [N m or N]")       \
  X(joint_torques, NvJoint,                                                                     \
    "(n, n_joint_dofs) applied generalised force on every joint dof (Model::dof_names; "        \
    "floating bases' zero), joint side: drive efforts + torque inputs + motor torques (after "  \
    "their torque limits); springs, dampers and friction excluded [N m or N]")                  \
  X(reaction_forces, Joints3, "(n, n_joints, 3) joint reaction force on the child [N]")         \
  X(reaction_torques, Joints3, "(n, n_joints, 3) joint reaction torque on the child [N m]")     \
  X(position_residual, None, "(n,) max |f| of the constraints [m or rad]")                      \
  X(velocity_residual, None, "(n,) max |zeta v - rhs|")                                         \
  X(kinetic_energy, None, "(n,) kinetic energy [J]")                                            \
  X(potential_energy, None, "(n,) potential energy, gravity and springs [J]")

/// The output tables with named columns (a dict of names and force in Python): X(name,
/// columns, doc).
#define ARMDYN_SIM_NAMED_TABLES(X)                                                          \
  X(gear_forces, Gears,                                                                     \
    "mesh force along the line of action of every gear pair, then every ideal gear [N] "    \
    "(positive when s > 0: pushes q_a and q_b back)")                                       \
  X(limit_forces, Limits,                                                                   \
    "the stops' torque/force on each joint held by one (limit_joints), positive along the " \
    "coordinate (a lower stop pushes up) [N m or N]")

/// The rest of a run's result as Python sees it: X(name, doc).
#define ARMDYN_SIM_RECORDS(X)                                                             \
  X(stats, "the run's counters, notes and CPU time (ARMDYN_SIM_STATS)")                   \
  X(events, "located events: gear contact onset and separation, the joint stops' events") \
  X(error, "why the run stopped early (empty: a complete run)")

/// A run's statistics, in the order of Python's result.stats: STEP(key, member, doc) for a
/// counter of the integrator's StepStats (SimResult::stats.member), OWN(key, type, member, doc)
/// for a member of SimResult itself.
#define ARMDYN_SIM_STATS(STEP, OWN)                                                           \
  STEP(steps, steps, "accepted steps")                                                        \
  STEP(rejected, rejected, "rejected steps")                                                  \
  STEP(rhs_evals, rhs_evals, "right-hand side evaluations")                                   \
  OWN(kkt_solves, long, kkt_solves, "KKT systems solved")                                     \
  OWN(factorizations, long, factorizations, "KKT factorizations")                             \
  OWN(articulated_solves, long, articulated_solves,                                           \
      "KKT systems of a tree solved by the articulated-body recursion (no factorization)")    \
  OWN(position_projections, long, position_projections, "position projections")               \
  OWN(newton_iterations, long, newton_iterations, "Newton iterations of the projections")     \
  OWN(seconds, double, cpu_seconds, "CPU time of the run [s]")                                \
  STEP(jacobians, jacobians, "Jacobians of the implicit integrator")                          \
  STEP(lu_factorizations, lu_factorizations, "LU factorizations of the implicit integrator")  \
  STEP(newton_iterations_implicit, newton_iterations,                                         \
       "Newton iterations of the implicit integrator")                                        \
  STEP(newton_failures, newton_failures, "failed Newton solves of the implicit integrator")   \
  STEP(events, events, "located events")                                                      \
  OWN(singular_evaluations, long, singular_evaluations,                                       \
      "evaluations at a kinematically singular state")                                        \
  OWN(singular_note, std::string, singular_note, "where the first singular evaluation was")   \
  OWN(augmented_solves, long, augmented_solves,                                               \
      "accelerations solved in augmented form (light bodies, or lost accuracy)")              \
  OWN(augmented_note, std::string, augmented_note, "why accelerations were solved augmented") \
  OWN(integrator, std::string, integrator, "the integrator used")                             \
  OWN(integrator_reason, std::string, integrator_reason, "why (for integrator 'auto')")       \
  OWN(solver_bodies, int, solver_bodies, "bodies of the model integrated")                    \
  OWN(solver_rows, int, solver_rows, "constraint rows of the model integrated")               \
  OWN(formulation, std::string, formulation,                                                  \
      "the coordinates integrated and the solver path, one line")

/// Row-major output tables: one row per output time (ARMDYN_SIM_TABLES).
struct SimResult {
  long n = 0;
#define ARMDYN_DECLARE_TABLE(name, columns, doc) std::vector<double> name;
  ARMDYN_SIM_TABLES(ARMDYN_DECLARE_TABLE)
  ARMDYN_SIM_NAMED_TABLES(ARMDYN_DECLARE_TABLE)
#undef ARMDYN_DECLARE_TABLE
  /// the joints held by stops (limits enforced): the columns of limit_forces
  std::vector<std::string> limit_joints;
  /// located stop events: time, joint, side (+1 lower, -1 upper), kind (0 the joint came to
  /// rest on the stop, 1 it bounced, 2 it left the stop)
  std::vector<double> limit_event_t;
  std::vector<std::string> limit_event_joint;
  std::vector<int> limit_event_side, limit_event_kind;
  /// located events: gear contact onset (+1) and separation (-1), by gear index
  std::vector<double> event_t;
  std::vector<int> event_index, event_direction;
  StepStats stats;
#define ARMDYN_DECLARE_STEP_STAT(key, member, doc)
#define ARMDYN_DECLARE_OWN_STAT(key, type, member, doc) type member{};
  ARMDYN_SIM_STATS(ARMDYN_DECLARE_STEP_STAT, ARMDYN_DECLARE_OWN_STAT)
#undef ARMDYN_DECLARE_STEP_STAT
#undef ARMDYN_DECLARE_OWN_STAT
  std::string error;  ///< non-empty when the run stopped early (SolverError message)
  /// The exception that stopped the run early, when one did: an Interrupted (`error` then
  /// holds its message) or the SolverError. Callers that carry their own exception types
  /// (derived from these) through the run -- the Python bindings -- rethrow it.
  std::exception_ptr exception;
  bool interrupted = false;  ///< stopped by an Interrupted (opt.step.poll), not a SolverError
};

/// "lower" (side +1) or "upper" (-1): a stop event's side (SimResult::limit_event_side).
const char* limit_side_name(int side);
/// "rest", "bounce" or "release": a stop event's kind (SimResult::limit_event_kind).
const char* limit_event_kind_name(int kind);

/// Bytes of one output time of a run of m: every table's row (ARMDYN_SIM_TABLES and
/// ARMDYN_SIM_NAMED_TABLES), the limit forces counted for every joint (the most a run has).
size_t output_row_bytes(const Model& m);

}  // namespace armdyn
