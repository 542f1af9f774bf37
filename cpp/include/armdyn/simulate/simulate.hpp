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
#include "armdyn/simulate/result.hpp"

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

/// The projection metric by its name: "mass" or "unweighted"; throws ModelError otherwise.
Metric projection_from_name(const std::string& name);

/// The full joint-space q (model.nq_joint) a run starts its multi-turn tracking from
/// (SimOptions::q_start), of the independent coordinates qi (a coupled model's followers set by
/// their couplings). @throws ModelError when qi has not model.independent.nq() entries.
VecX q_start_from_independent(const Model& m, const VecX& qi);

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
