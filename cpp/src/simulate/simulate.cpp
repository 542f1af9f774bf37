// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/simulate/simulate.hpp"

#include <cctype>
#include <chrono>
#include <cmath>
#include <memory>
#include <utility>

#include "armdyn/algorithm/constraints.hpp"
#include "armdyn/algorithm/cost_model.hpp"
#include "armdyn/algorithm/driven_inverse_dynamics.hpp"
#include "armdyn/algorithm/forces.hpp"
#include "armdyn/algorithm/kinematics.hpp"
#include "armdyn/algorithm/loop_coordinates.hpp"
#include "armdyn/algorithm/projection.hpp"
#include "armdyn/builder/weld.hpp"
#include "armdyn/data.hpp"
#include "armdyn/errors.hpp"
#include "ode_systems.hpp"

namespace armdyn {

double stiffness_estimate(const Model& m, std::string& culprit) {
  // Rates of each force element with the inverse effective mass of its direction g (a
  // generalised force row) under the constraints, at the assembled state:
  //   1/m_eff = g . vdot(eta = g^T, xi = 0)   (a KKT solve; driven coordinates give 0).
  double lam = 0.0;
  culprit = "no springs or dampers";
  if (m.springs.empty() && m.coord_forces.empty() && m.gears.empty()) return 0.0;
  Data dat(m);
  load_kinematics(m, dat, m.u0.data(), m.v0.data());
  evaluate_constraints(m, dat, 0.0, true);
  ConstraintEval& ce = dat.ce;
  ce.xi.setZero();
  KktSolver& kkt = dat.kkt;
  const std::vector<BodyKin>& kin = dat.kin;
  kkt.factor(ce, m.nc, Metric::Mass);
  VecX eta = VecX::Zero(m.nv), vd = VecX::Zero(m.nv), delta = VecX::Zero(m.nc);
  auto inv_mass = [&](const Row12& g, int pa, int pb) {
    eta.setZero();
    if (pa != kGround) eta.segment<6>(6 * pa) += g.segment<6>(0).transpose();
    if (pb != kGround) eta.segment<6>(6 * pb) += g.segment<6>(6).transpose();
    kkt.accelerations(ce, eta, vd, delta);
    return std::max(0.0, eta.dot(vd));
  };
  auto consider = [&](double rate, const std::string& what) {
    if (rate > lam) {
      lam = rate;
      culprit = what;
    }
  };
  for (const SpringDamper& sd : m.springs) {
    const VecJet d = difference(point_jet(kin_of(kin, sd.body_b), sd.point_b, 1),
                                point_jet(kin_of(kin, sd.body_a), sd.point_a, 0));
    const double L = d.val.norm();
    if (!(L > 0)) continue;
    const double im = inv_mass(d.left(d.val / L), sd.body_a, sd.body_b);
    consider(std::sqrt(sd.stiffness * im), msg("spring-damper '", sd.name, "' (stiffness)"));
    consider(sd.damping * im, msg("spring-damper '", sd.name, "' (damping)"));
  }
  for (const CoordForce& cf : m.coord_forces) {
    const ScalarJet q = coord_jet(m, kin, cf.coord);
    const Joint& j = m.joints[m.coords[cf.coord].joint];
    const double im = inv_mass(q.J, j.parent, j.child);
    const std::string& name = m.coords[cf.coord].name;
    consider(std::sqrt(cf.stiffness * im), msg("joint '", name, "' spring"));
    consider((cf.damping + cf.coulomb / cf.v_smooth) * im,
             msg("joint '", name, "' damping/friction"));
    if (cf.motor) {
      consider(std::sqrt(cf.kp * im), msg("motor on '", name, "' (kp)"));
      consider(cf.kd * im, msg("motor on '", name, "' (kd)"));
    }
  }
  for (const GearPair& g : m.gears) {
    // mesh direction: r_a J_qa + r_b J_qb over the (up to four) bodies of the two joints
    const ScalarJet qa = coord_jet(m, kin, g.coord_a), qb = coord_jet(m, kin, g.coord_b);
    const Joint& ja = m.joints[m.coords[g.coord_a].joint];
    const Joint& jb = m.joints[m.coords[g.coord_b].joint];
    eta.setZero();
    auto add = [&](const Row12& row, const Joint& j) {
      if (j.parent != kGround) eta.segment<6>(6 * j.parent) += row.segment<6>(0).transpose();
      if (j.child != kGround) eta.segment<6>(6 * j.child) += row.segment<6>(6).transpose();
    };
    add(g.r_a * qa.J, ja);
    add(g.r_b * qb.J, jb);
    kkt.accelerations(ce, eta, vd, delta);
    const double im = std::max(0.0, eta.dot(vd));
    // linearised contact stiffness at a penetration of 1 % of the backlash (or 1 um)
    const double d = std::max(0.01 * g.backlash, 1e-6);
    const double k = gear_contact_stiffness(g, d);
    consider(std::sqrt(k * im), msg("gear pair '", g.name, "' mesh"));
  }
  return lam;
}

Integrator choose_integrator(const Model& m, double t_end, double rtol, std::string& reason) {
  std::string culprit;
  const double lam = stiffness_estimate(m, culprit);
  const double steps = lam * t_end / 3.3;
  if (steps > 5000.0) {
    reason = msg("trbdf2: fastest rate ", lam, " 1/s from ", culprit,
                 "; an explicit method would need about ", static_cast<long>(steps),
                 " steps for stability alone");
    return Integrator::Trbdf2;
  }
  const std::string rate =
      msg("fastest rate ", lam, " 1/s (", culprit, "), about ", static_cast<long>(steps),
          " explicit steps for stability: not stiff");
  // tight tolerances: the 8th-order pair needs far fewer steps (benchmarks/results/workprecision)
  if (rtol <= 1e-7) {
    reason = msg("dop853: ", rate, "; rtol ", rtol, " <= 1e-7 favours the 8th-order pair");
    return Integrator::Dop853;
  }
  reason = msg("dopri5: ", rate);
  return Integrator::Dopri5;
}

namespace {

void check_options(const Model& m, double t_end, const SimOptions& opt, const VecX& u0,
                   const VecX& v0) {
  if (!(t_end > 0) || !std::isfinite(t_end))
    throw ModelError(msg("simulate: t_end must be positive and finite, got ", t_end));
  const StepOptions& s = opt.step;
  if (!(s.rtol > 0) || !std::isfinite(s.rtol))
    throw ModelError(msg("simulate: rtol must be positive, got ", s.rtol));
  if (!(s.atol > 0) || !std::isfinite(s.atol))
    throw ModelError(msg("simulate: atol must be positive, got ", s.atol));
  if (!(s.dt >= 0) || !std::isfinite(s.dt))
    throw ModelError(msg("simulate: dt must be positive, got ", s.dt));
  if (opt.integrator == Integrator::Rk4 && !(s.dt > 0))
    throw ModelError("simulate: integrator 'rk4' needs a step dt > 0");
  if (!(s.output_dt >= 0) || !std::isfinite(s.output_dt))
    throw ModelError(msg("simulate: output_dt must be positive, got ", s.output_dt));
  if (s.max_steps <= 0) throw ModelError("simulate: max_steps must be positive");
  if (!(opt.restitution >= 0.0 && opt.restitution <= 1.0))
    throw ModelError(msg("simulate: restitution must lie in [0, 1], got ", opt.restitution));
  if (u0.size() != m.nq || v0.size() != m.nv)
    throw ModelError(msg("simulate: initial state has sizes (", u0.size(), ", ", v0.size(),
                         "), expected (", m.nq, ", ", m.nv, ")"));
  if (opt.q_start.size() != 0 && opt.q_start.size() != m.nq_joint)
    throw ModelError(msg("simulate: q0 has length ", opt.q_start.size(), ", expected ", m.nq_joint,
                         " (model.n_coords)"));
  if (!u0.allFinite() || !v0.allFinite())
    throw ModelError("simulate: initial state contains NaN or inf");
}

/// What a run integrates and how: the model integrated (m or its welded form), the
/// integrator (never Default or Auto) and why, and the coordinates.
struct RunPlan {
  const Model* ms = nullptr;
  const Welding* welding = nullptr;
  bool welded = false;
  Integrator integrator = Integrator::Dopri5;
  std::string reason;
  bool joint = false;
  std::string why_coordinates;  ///< coordinates "auto": why this formulation
};

RunPlan plan_run(const Model& m, double t_end, const SimOptions& opt) {
  RunPlan p;
  // bodies joined by fixed joints integrate as one composite body (builder/weld.hpp); the outputs
  // are reported for every body and joint of m
  p.welding = opt.merge_welded ? welding(m) : nullptr;
  p.welded = p.welding != nullptr;
  p.ms = p.welded ? p.welding->model.get() : &m;
  // zero freedom left by the drives: every state follows from the constraints, no integration
  // (not with PI-motor states or gear contact, which have states or events of their own)
  const bool prescribed = m.mobility_driven == 0 && m.n_aux == 0 && m.gears.empty();
  const double output_dt = opt.step.output_dt;
  switch (opt.integrator) {
    case Integrator::Kinematic:
      if (!prescribed)
        throw ModelError(
            msg("simulate: integrator 'kinematic' needs a fully driven model; ",
                m.mobility_driven > 0
                    ? msg("the drives leave ", m.mobility_driven, " degree(s) of freedom")
                    : std::string("the model has motor or gear-contact states")));
      if (!(output_dt > 0)) throw ModelError("simulate: integrator 'kinematic' needs output_dt");
      p.integrator = Integrator::Kinematic;
      p.reason = "kinematic: requested";
      break;
    case Integrator::Default:
    case Integrator::Auto:
      if (prescribed && output_dt > 0) {
        p.integrator = Integrator::Kinematic;
        p.reason =
            "kinematic: the drives leave no degree of freedom, so each output state follows "
            "from the constraints (position, velocity and acceleration problems); nothing to "
            "integrate";
      } else if (opt.integrator == Integrator::Auto) {
        p.integrator = choose_integrator(*p.ms, t_end, opt.step.rtol, p.reason);
      } else {
        p.integrator = Integrator::Dopri5;
      }
      break;
    default:
      p.integrator = opt.integrator;
  }
  // Auto: where joint space applies (a tree without drives), the formulation whose right-hand
  // side the measured cost model predicts cheaper; the Cartesian path elsewhere
  p.joint = opt.coordinates == Coordinates::Joint;
  if (opt.coordinates == Coordinates::Auto) {
    if (p.integrator == Integrator::Kinematic) {
      p.why_coordinates = "joint space does not apply: fully driven";
    } else if (const std::string why = p.ms->joint_path_reason(); !why.empty()) {
      p.why_coordinates = msg("joint space does not apply: ", why);
    } else if (const std::string why = geared_light_reason(*p.ms); !why.empty()) {
      p.why_coordinates = msg("joint space does not apply: ", why);
    } else {
      const DynamicsCost& c = dynamics_cost(*p.ms);
      p.joint = c.joint_rhs_cheaper;
      p.why_coordinates = msg("auto: ", c.rhs_summary());
    }
  }
  if (p.joint && p.integrator == Integrator::Kinematic)
    throw ModelError(
        "simulate: coordinates 'joint' integrates a tree without drives; a fully driven model "
        "takes the kinematic path (coordinates 'cartesian')");
  return p;
}

void integrate(Integrator method, OdeSystem& ode, VecX& y, double t_end, const StepOptions& s,
               StepStats& stats, IntegratorWork& work) {
  switch (method) {
    case Integrator::Dopri5:
      return integrate_dopri5(ode, y, 0.0, t_end, s, stats, &work);
    case Integrator::Dop853:
      return integrate_dop853(ode, y, 0.0, t_end, s, stats, &work);
    case Integrator::Trbdf2:
      return integrate_trbdf2(ode, y, 0.0, t_end, s, stats, &work);
    case Integrator::Rk4:
      return integrate_rk4(ode, y, 0.0, t_end, s, stats, &work);
    default:
      throw ModelError(msg("simulate: '", integrator_name(method), "' does not integrate"));
  }
}

/// A fully driven model: each output state solved from the constraints. On failure y holds
/// the last state solved and t_last its time.
void run_kinematic(const Model& ms, detail::MbsSystem& sys, VecX& y, double t_end, double output_dt,
                   Poll* poll, SimResult& out, double& t_last) {
  DrivenSolver solver(ms, sys.data(), "simulate", 0.0);
  solver.throw_on_singular = false;  // counted and noted, as by the integrators
  VecX u = y.head(ms.nq), v = y.segment(ms.nq, ms.nv), vd = VecX::Zero(ms.nv);
  try {
    for (const double t : output_times(0.0, t_end, output_dt)) {
      if (poll) (*poll)(t, t_end);
      double rf, rv;
      solver.solve(t, u, v, vd, rf, rv);
      ++out.stats.rhs_evals;
      sys.record(t, u.data(), v.data(), vd, rf, rv);
    }
  } catch (const SolverError&) {
    y.head(ms.nq) = u;
    y.segment(ms.nq, ms.nv) = v;
    t_last = solver.t_good;
    throw;
  }
}

/// (q, qd, z) of the projected Cartesian state y = (u, v, z); angles start in (-pi, pi], as the
/// Cartesian run's tracking does.
VecX joint_state(const Model& ms, detail::MbsSystem& sys, VecX& y, Metric projection) {
  Data& d = sys.data();
  d.aux = y.data() + ms.nq + ms.nv;
  project(ms, d, 0.0, y.data(), y.data() + ms.nq, projection);
  VecX q, qd;
  joint_coordinates(ms, y.head(ms.nq), y.segment(ms.nq, ms.nv), q, qd);
  // angles over turns, as the projection's tracking followed them from the initial reference
  for (size_t c = 0; c < ms.coords.size(); ++c)
    if (ms.coords[c].angular) {
      double& x = q[7 * ms.n_free + static_cast<long>(c)];
      x = tracked(d, static_cast<int>(c), x);
    }
  // couplings' angle followers: the turn their leaders give (their poses give it modulo 2 pi)
  if (!ms.independent.identity()) ms.independent.align(ms.coords, q.data() + 7 * ms.n_free);
  VecX yj(q.size() + qd.size() + ms.n_aux);
  yj << q, qd, y.tail(ms.n_aux);
  return yj;
}

/// Append to the error message why the constraints are (nearly) singular at (y, t_last), when
/// they are.
void explain_failure(const Model& ms, detail::MbsSystem& sys, const VecX& y, double t_last,
                     bool kinematic, std::string& error) {
  try {
    Data& d = sys.data();
    d.aux = y.data() + ms.nq + ms.nv;
    // the kinematic path stops short of a limit point (no solution beyond it) by its
    // continuation's smallest step, where the rank loss shows only at looser thresholds
    std::string why;
    for (const double threshold : {1e-7, 1e-5, 1e-3}) {
      why = diagnose_singularity(ms, d, t_last, y.data(), y.data() + ms.nq, threshold);
      if (!why.empty() || !kinematic) break;
    }
    if (why.empty()) return;
    if (error.back() == '.') {
      why[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(why[0])));
      error += " " + why;
    } else {
      error += "; " + why;
    }
  } catch (const std::exception&) {
  }
}

/// The run's counters, and every table trimmed to the complete rows (a failed output may have
/// pushed part of one).
void finish(const Model& m, const Model& ms, const PipelineStats& st, SimResult& out) {
  out.solver_bodies = ms.nb;
  out.solver_rows = ms.nc;
  out.kkt_solves = st.kkt_solves;
  out.factorizations = st.factorizations;
  out.articulated_solves = st.articulated_solves;
  out.position_projections = st.position_projections;
  out.newton_iterations = st.newton_iterations;
  out.singular_evaluations = st.singular_evaluations;
  out.singular_note = st.singular_note;
  out.augmented_solves = st.augmented_solves;
  out.augmented_note = st.augmented_note;
  const size_t n = static_cast<size_t>(out.n), nj = m.joints.size();
  out.t.resize(n);
  out.u.resize(n * m.nq);
  out.v.resize(n * m.nv);
  out.q.resize(n * static_cast<size_t>(m.nq_joint));
  out.qd.resize(n * static_cast<size_t>(m.nv_joint));
  out.qdd.resize(n * static_cast<size_t>(m.nv_joint));
  out.drive_forces.resize(n * m.drives.size());
  out.joint_torques.resize(n * static_cast<size_t>(m.nv_joint));
  out.reaction_forces.resize(n * 3 * nj);
  out.reaction_torques.resize(n * 3 * nj);
  for (auto* col :
       {&out.position_residual, &out.velocity_residual, &out.kinetic_energy, &out.potential_energy})
    col->resize(n);
  out.gear_forces.resize(n * (m.gears.size() + m.gear_constraints.size()));
  out.limit_forces.resize(n * out.limit_joints.size());
}

/// The stops' events in the result (by joint name and side).
void record_stop_events(const Model& ms, const detail::LimitStops& stops, SimResult& out) {
  for (size_t e = 0; e < stops.event_t.size(); ++e) {
    const auto& s = stops.stops()[static_cast<size_t>(stops.event_stop[e])];
    out.limit_event_t.push_back(stops.event_t[e]);
    out.limit_event_joint.push_back(ms.joints[static_cast<size_t>(s.joint)].name);
    out.limit_event_side.push_back(s.side);
    out.limit_event_kind.push_back(stops.event_kind[e]);
  }
}

/// The Data the run evaluates on: d, or for a welded run d.welded_data (made for the welded
/// model when it holds none), both with fresh pipelines; the initial angles' turns from the q
/// the initial state was made from (multi-turn).
Data& run_data(const Model& m, Data& d, const RunPlan& plan, const SimOptions& opt) {
  const Model& ms = *plan.ms;
  if (plan.welded && (!d.welded_data || d.welded_data->model != &ms))
    d.welded_data = std::make_unique<Data>(ms);
  Data& ds = plan.welded ? *d.welded_data : d;
  reset_pipeline(ds);
  if (plan.welded) reset_pipeline(d);
  if (opt.q_start.size() == m.nq_joint) {
    const int off = 7 * m.n_free;
    for (size_t c = 0; c < m.coords.size(); ++c) {
      if (!m.coords[c].angular) continue;
      const double q = opt.q_start[off + static_cast<long>(c)];
      const int cs = plan.welded ? plan.welding->coord_map[c] : static_cast<int>(c);
      if (cs >= 0) ds.track_ref[cs] = q;
      if (plan.welded) d.track_ref[static_cast<long>(c)] = q;
    }
  }
  return ds;
}

/// An empty result naming the integrator, its tables reserved for the output times.
SimResult new_result(const Model& m, const RunPlan& plan, double t_end, const StepOptions& s) {
  SimResult out;
  out.integrator = integrator_name(plan.integrator);
  out.integrator_reason = plan.reason;
  if (s.output_dt > 0) {
    const size_t n = static_cast<size_t>(t_end / s.output_dt) + 2;
    out.t.reserve(n);
    out.u.reserve(n * m.nq);
    out.v.reserve(n * m.nv);
  }
  return out;
}

/// The joint-space system of a joint-coordinates run (null for a Cartesian one), and the
/// formulation's description in out.
std::unique_ptr<detail::JointSystem> formulation(const Model& ms, const RunPlan& plan,
                                                 const SimOptions& opt, detail::MbsSystem& sys,
                                                 SimResult& out) {
  std::unique_ptr<detail::JointSystem> jsys;
  if (plan.joint) {
    try {
      jsys = std::make_unique<detail::JointSystem>(ms, sys);
    } catch (const ModelError& err) {
      throw ModelError(msg("simulate: coordinates 'joint': ", err.what()));
    }
    out.formulation = jsys->dynamics().description();
  } else {
    out.formulation = msg("cartesian: ", ms.nb, " bodies, ", ms.nc, " constraint rows, KKT path '",
                          kkt_path_name(kkt_path(ms)), "'");
  }
  if (opt.coordinates == Coordinates::Auto) out.formulation += msg(" [", plan.why_coordinates, "]");
  return jsys;
}

/// The joint position limits' stops, given to sys (null when none: no limited joint, limits
/// off, or a fully driven model); their joints' names and force table in out.
std::unique_ptr<detail::LimitStops> joint_stops(const Model& ms, const RunPlan& plan, double t_end,
                                                const SimOptions& opt, detail::MbsSystem& sys,
                                                SimResult& out) {
  if (!opt.limits || plan.integrator == Integrator::Kinematic) return nullptr;
  auto stops = std::make_unique<detail::LimitStops>(ms, opt.restitution);
  if (stops->size() == 0) return nullptr;
  sys.set_stops(stops.get());
  for (int j : stops->limited_joints())
    out.limit_joints.push_back(ms.joints[static_cast<size_t>(j)].name);
  if (opt.step.output_dt > 0)
    out.limit_forces.reserve((static_cast<size_t>(t_end / opt.step.output_dt) + 2) *
                             out.limit_joints.size());
  return stops;
}

/// The initial Cartesian state y = (u, v, z = 0) of the model integrated: (u0, v0), or in a
/// welded run the composites' state contracted from it by the expander made here (given to sys).
VecX initial_state(const Model& m, Data& d, const RunPlan& plan, const VecX& u0, const VecX& v0,
                   detail::MbsSystem& sys, std::unique_ptr<detail::WeldExpander>& expander) {
  const Model& ms = *plan.ms;
  VecX y = VecX::Zero(ms.nq + ms.nv + ms.n_aux);
  if (plan.welded) {
    expander = std::make_unique<detail::WeldExpander>(m, *plan.welding, d);
    sys.set_expander(expander.get());
    VecX uw(ms.nq), vw(ms.nv);
    expander->contract(u0, v0, uw, vw);
    y.head(ms.nq) = uw;
    y.segment(ms.nq, ms.nv) = vw;
  } else {
    y.head(m.nq) = u0;
    y.segment(m.nq, m.nv) = v0;
  }
  return y;
}

/// The run itself on the plan's path (kinematic, joint-space or Cartesian), from y; on return
/// y is the last good state and t_last its time (a failure: the kinematic path's last state).
void run_path(const RunPlan& plan, const SimOptions& opt, double t_end, detail::MbsSystem& sys,
              detail::JointSystem* jsys, detail::LimitStops* stops, VecX& y, double& t_last,
              SimResult& out, IntegratorWork& work) {
  const Model& ms = *plan.ms;
  const StepOptions& s = opt.step;
  if (plan.integrator == Integrator::Kinematic) {
    run_kinematic(ms, sys, y, t_end, s.output_dt, s.poll, out, t_last);
  } else if (plan.joint) {
    VecX yj = joint_state(ms, sys, y, opt.projection);
    if (stops) stops->start(*jsys, 0.0, yj);
    integrate(plan.integrator, *jsys, yj, t_end, s, out.stats, work);
  } else {
    if (stops) {
      sys.data().aux = y.data() + ms.nq + ms.nv;
      project(ms, sys.data(), 0.0, y.data(), y.data() + ms.nq, opt.projection);
      stops->start(sys, 0.0, y);
    }
    integrate(plan.integrator, sys, y, t_end, s, out.stats, work);
  }
}

/// run_path, its failure (a SolverError: explained where the constraints are singular) or
/// interruption (Interrupted) kept in out with the outputs so far; the CPU time in out.
void run_and_catch(const RunPlan& plan, const SimOptions& opt, double t_end, detail::MbsSystem& sys,
                   detail::JointSystem* jsys, detail::LimitStops* stops, VecX& y, SimResult& out,
                   IntegratorWork& work) {
  const auto start = std::chrono::steady_clock::now();
  double t_last = 0.0;  // the time of the last good state y
  if (opt.step.poll) opt.step.poll->start();
  try {
    run_path(plan, opt, t_end, sys, jsys, stops, y, t_last, out, work);
  } catch (const SolverError& err) {
    out.error = err.what();
    out.exception = std::current_exception();
    const bool kinematic = plan.integrator == Integrator::Kinematic;
    if (!kinematic) t_last = out.t.empty() ? 0.0 : out.t.back();
    // (the joint-space path has no constraint Jacobian to diagnose but the gears' constant one)
    if (!plan.joint) explain_failure(*plan.ms, sys, y, t_last, kinematic, out.error);
  } catch (const Interrupted& err) {
    // stopped from outside (opt.step.poll; a profile callback's binding): the outputs so far
    out.error = err.what();
    if (out.error.empty()) out.error = "interrupted";
    out.exception = std::current_exception();
    out.interrupted = true;
  }
  out.cpu_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

Coordinates coordinates_from_name(const std::string& name) {
  if (name == "cartesian") return Coordinates::Cartesian;
  if (name == "joint") return Coordinates::Joint;
  if (name == "auto") return Coordinates::Auto;
  throw ModelError(
      msg("simulate: unknown coordinates '", name, "' (expected 'cartesian', 'joint' or 'auto')"));
}

Metric projection_from_name(const std::string& name) {
  if (name == "mass") return Metric::Mass;
  if (name == "unweighted") return Metric::Identity;
  throw ModelError(msg("projection must be 'mass' or 'unweighted', got '", name, "'"));
}

VecX q_start_from_independent(const Model& m, const VecX& qi) {
  if (qi.size() != m.independent.nq())
    throw ModelError(msg("q0 must have ", m.independent.nq(), " entries, got ", qi.size()));
  if (m.loop_coordinates) return loop_full_coordinates(m, qi);
  VecX q(m.nq_joint);
  m.independent.expand_q(qi.data(), q.data());
  return q;
}

SimResult simulate(const Model& m, double t_end, const SimOptions& opt, const VecX& u0,
                   const VecX& v0) {
  Data d(m);
  return simulate(m, d, t_end, opt, u0, v0);
}

SimResult simulate(const Model& m, Data& d, double t_end, const SimOptions& opt, const VecX& u0,
                   const VecX& v0) {
  check_data(m, d, "simulate");
  check_options(m, t_end, opt, u0, v0);
  const RunPlan plan = plan_run(m, t_end, opt);
  const Model& ms = *plan.ms;  // the model integrated
  Data& ds = run_data(m, d, plan, opt);
  SimResult out = new_result(m, plan, t_end, opt.step);
  // the formulation's ODE system; outputs are recorded by the Cartesian one
  detail::MbsSystem sys(ms, ds, opt.projection, out);
  const std::unique_ptr<detail::JointSystem> jsys = formulation(ms, plan, opt, sys, out);
  const std::unique_ptr<detail::LimitStops> stops = joint_stops(ms, plan, t_end, opt, sys, out);
  std::unique_ptr<detail::WeldExpander> expander;
  VecX y = initial_state(m, d, plan, u0, v0, sys, expander);
  run_and_catch(plan, opt, t_end, sys, jsys.get(), stops.get(), y, out, d.integrator);
  if (stops) record_stop_events(ms, *stops, out);
  finish(m, ms, sys.data().stats, out);
  return out;
}

}  // namespace armdyn
