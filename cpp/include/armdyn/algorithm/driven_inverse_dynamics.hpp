// SPDX-License-Identifier: BSD-3-Clause
// Inverse dynamics of a driven model (drives leave no freedom) through its driving constraints
// (methods.md §7.2), on the Cartesian Newton-Euler/KKT path: at each time the position problem
// (Newton on f(u, t) = 0), the velocity problem (zeta v = rhs) and the acceleration problem
// (zeta vdot = -xi) are solved, and the multipliers follow from Gamma vdot + zeta^T delta = eta.
// Drive multipliers give the actuator efforts tau = -delta_drive (the torque/force the actuator
// applies to the child body about/along the joint axis, the RNEA / URDF effort convention); the
// others the joint reactions. Joint-space inverse dynamics of a tree: armdyn/algorithm/rnea.hpp.
#pragma once

#include <string>
#include <vector>

#include "armdyn/data.hpp"
#include "armdyn/kernels/joint_space.hpp"
#include "armdyn/model/model.hpp"
#include "armdyn/poll.hpp"

namespace armdyn {

/// The state of a driven model (drives leave no freedom) at increasing times: the position
/// problem f(u, t) = 0, the velocity problem zeta v = rhs, then the acceleration problem and the
/// multipliers (body_accelerations, armdyn/algorithm/kkt.hpp), so that no time integration is
/// needed.
///  - a tree with every coordinate driven: the state is the forward kinematics of the drive
///    values (q, qd), checked by its residuals (Newton only when they exceed round-off);
///  - otherwise Newton from a prediction (the last state moved by its rates), with continuation
///    (halving the step towards t) when Newton fails or jumps to another assembly branch.
class DrivenSolver {
 public:
  /// d: a Data of m, whose pipeline (all rows) it runs. who names the caller in messages.
  /// t0: the time of the state passed to the first solve().
  /// @throws ModelError naming the undriven coordinates when the drives leave freedom.
  DrivenSolver(const Model& m, Data& d, const char* who, double t0);
  /// (the Data's angle tracking by rates back as it was)
  ~DrivenSolver();
  DrivenSolver(const DrivenSolver&) = delete;
  DrivenSolver& operator=(const DrivenSolver&) = delete;
  /// (u, v) at the last solved time (or t0) in, at t out; vd the accelerations; the Data is
  /// left loaded at (u, v, t) with its multipliers; rf, rv the position and velocity residuals.
  /// On failure (u, v) hold the last state solved on the way to t, at time t_good.
  /// @throws SolverError when the position problem fails or (throw_on_singular) the driven
  ///   constraints are kinematically singular at t (naming the dependent rows).
  void solve(double t, VecX& u, VecX& v, VecX& vd, double& rf, double& rv);
  /// false: a kinematically singular time is not an error; it is counted
  /// (Data::stats.singular_evaluations) and its minimum-norm multipliers are kept, as in a run.
  bool throw_on_singular = true;
  /// The time of the state left in (u, v) after a failed solve(): the last one solved.
  double t_good;

 private:
  const Model& m_;
  Data& d_;
  const char* who_;
  double t_prev_;
  bool fk_;
  // scratch in the Data (Data::driven_solve)
  VecX &qc_, &qdc_, &ud_, &u_save_, &v_save_, &u_pred_, &track_save_;
  // the angles are tracked by their rates between the times (Data::track_by_rates); the
  // caller's setting, and the commit saved with track_save_
  bool track_by_rates_before_;
  Data::TrackCommit commit_save_;
  TreeFkWork& fkw_;
  void predict(double t_from, double t, VecX& u, VecX& v, const VecX& vd);
  std::string singular_rows() const;  ///< a sentence when the factor lost rank, else empty
};

/// The tables of driven inverse dynamics, row-major, one row per time: X(name, columns, doc).
/// The one list of them: InverseDynamicsResult's members, the bindings' result dict and the
/// Python InverseDynamicsResult's fields (tests/docs/test_schema.py) follow it.
#define ARMDYN_DRIVEN_ID_TABLES(X)                                                          \
  X(t, None, "(n,) times [s]")                                                              \
  X(u, Nq, "(n, nq) Cartesian positions solving the driven constraints")                    \
  X(v, Nv, "(n, nv) Cartesian velocities solving the driven constraints")                   \
  X(q, Coords, "(n, n_coords) joint coordinates")                                           \
  X(qd, Coords, "(n, n_coords) joint rates")                                                \
  X(qdd, Coords, "(n, n_coords) joint accelerations")                                       \
  X(drive_forces, Drives,                                                                   \
    "(n, n_drives) actuator torque/force of each drive, tau = -delta_drive [N m or N]")     \
  X(reaction_forces, Joints3, "(n, n_joints, 3) joint reaction force on the child [N]")     \
  X(reaction_torques, Joints3, "(n, n_joints, 3) joint reaction torque on the child [N m]") \
  X(position_residual, None, "(n,) max |f| of the constraints [m or rad]")                  \
  X(velocity_residual, None, "(n,) max |zeta v - rhs|")

/// The rest of the result as Python sees it: X(name, doc).
#define ARMDYN_DRIVEN_ID_RECORDS(X) X(stats, "counters and CPU time (ARMDYN_DRIVEN_ID_STATS)")

/// The statistics, in the order of Python's result.stats: X(key, type, member, doc).
#define ARMDYN_DRIVEN_ID_STATS(X)                                                             \
  X(newton_iterations, long, newton_iterations, "Newton iterations of the position problems") \
  X(factorizations, long, factorizations, "KKT factorizations")                               \
  X(seconds, double, cpu_seconds, "CPU time [s]")

struct InverseDynamicsResult {
  long n = 0;
#define ARMDYN_DECLARE_TABLE(name, columns, doc) std::vector<double> name;
  ARMDYN_DRIVEN_ID_TABLES(ARMDYN_DECLARE_TABLE)
#undef ARMDYN_DECLARE_TABLE
#define ARMDYN_DECLARE_STAT(key, type, member, doc) type member{};
  ARMDYN_DRIVEN_ID_STATS(ARMDYN_DECLARE_STAT)
#undef ARMDYN_DECLARE_STAT
};

/// Inverse dynamics of a driven model at the given (increasing) times.
/// @throws ModelError when the drives leave degrees of freedom (naming the undriven
///   coordinates) or the times are invalid; SolverError when the driven constraints become
///   singular (naming the dependent drive/joint rows) or the position problem fails.
/// poll (poll.hpp; may be null) is called once per time: an Interrupted (or what its
/// callback throws) propagates.
InverseDynamicsResult inverse_dynamics_driven(const Model& m, const std::vector<double>& times,
                                              Poll* poll = nullptr);

}  // namespace armdyn
