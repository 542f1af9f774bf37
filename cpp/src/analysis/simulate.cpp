// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/analysis/simulate.hpp"

#include <cctype>
#include <chrono>
#include <cmath>
#include <memory>

#include "armdyn/analysis/inverse_dynamics.hpp"
#include "armdyn/analysis/tree_dynamics.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/math/quaternion.hpp"
#include "armdyn/solver/engine.hpp"

namespace armdyn {

namespace {

// Reports a run of the welded model (Model::welded) in the bodies and joints of the full model.
class WeldExpander {
 public:
  explicit WeldExpander(const Model& full)
      : m_(full),
        w_(*full.welded),
        e_(full),
        u_(VecX::Zero(full.nq)),
        v_(VecX::Zero(full.nv)),
        vd_(VecX::Zero(full.nv)),
        delta_(VecX::Zero(full.nc)),
        r_(VecX::Zero(full.nv)),
        tmp_(VecX::Zero(full.nv)) {
    for (const Model::Weld& w : m_.weld) qrel_.push_back(rot_to_quat(w.rotation));
    // rows of the full model -> rows of the welded one (-1: a merged fixed joint)
    row_map_.assign(m_.nc, -1);
    for (size_t j = 0; j < m_.joints.size(); ++j) {
      const int jw = m_.weld_joint[j];
      if (jw < 0) continue;
      for (int k = 0; k < joint_rows(m_.joints[j].type); ++k)
        row_map_[m_.joints[j].row0 + k] = w_.joints[jw].row0 + k;
    }
    for (size_t g = 0; g < m_.gear_constraints.size(); ++g)
      row_map_[m_.gear_constraints[g].row] = w_.gear_constraints[g].row;
    // coordinates of the full model -> those of the welded one (fixed joints have none)
    coord_map_.assign(m_.coords.size(), -1);
    for (size_t j = 0; j < m_.joints.size(); ++j) {
      const int jw = m_.weld_joint[j];
      if (jw < 0) continue;
      for (int k = 0; k < joint_coords(m_.joints[j].type); ++k)
        coord_map_[m_.joints[j].coord0 + k] = w_.joints[jw].coord0 + k;
    }
    track_ = VecX::Zero(static_cast<long>(m_.coords.size()));
    for (size_t k = 0; k < m_.drives.size(); ++k) row_map_[m_.drives[k].row] = w_.drives[k].row;
    // the block of each merged joint
    block_of_.assign(m_.joints.size(), -1);
    const ConstraintEval& ce = e_.constraints();
    for (size_t j = 0; j < m_.joints.size(); ++j)
      for (size_t b = 0; b < ce.blocks.size(); ++b)
        if (joint_rows(m_.joints[j].type) > 0 && ce.blocks[b].row0 == m_.joints[j].row0)
          block_of_[j] = static_cast<int>(b);
  }

  /// The composites' state (uw, vw) from a full state: each from its root body.
  void contract(const VecX& u, const VecX& v, VecX& uw, VecX& vw) const {
    for (int c = 0; c < w_.nb; ++c) {
      const int r = m_.weld_root[c];
      const Model::Weld& w = m_.weld[r];
      const Vec4 qr = u.segment<4>(7 * r + 3).normalized();
      const Vec4& e = qrel_[r];
      const Vec4 qc = quat_mul(qr, Vec4(e[0], -e[1], -e[2], -e[3]));
      const Mat3 Rc = quat_to_rot(qc);
      const Vec3 wc = w.rotation * v.segment<3>(6 * r + 3);
      uw.segment<3>(7 * c) = u.segment<3>(7 * r) - Rc * w.offset;
      uw.segment<4>(7 * c + 3) = qc;
      vw.segment<3>(6 * c) = v.segment<3>(6 * r) - Rc * wc.cross(w.offset);
      vw.segment<3>(6 * c + 3) = wc;
    }
  }

  /// The full state (and accelerations, when vdw is given) from the composites'.
  void expand(const double* uw, const double* vw, const double* vdw) {
    for (int b = 0; b < m_.nb; ++b) {
      const Model::Weld& w = m_.weld[b];
      if (w.composite == kGround) {
        u_.segment<3>(7 * b) = w.offset;
        u_.segment<4>(7 * b + 3) = qrel_[b];
        v_.segment<6>(6 * b).setZero();
        vd_.segment<6>(6 * b).setZero();
        continue;
      }
      const int c = w.composite;
      const Vec4 qc(uw[7 * c + 3], uw[7 * c + 4], uw[7 * c + 5], uw[7 * c + 6]);
      const Mat3 Rc = quat_to_rot(qc);
      const Vec3 wc(vw[6 * c + 3], vw[6 * c + 4], vw[6 * c + 5]);
      const Vec3 wxo = wc.cross(w.offset);
      u_.segment<3>(7 * b) = Vec3(uw[7 * c], uw[7 * c + 1], uw[7 * c + 2]) + Rc * w.offset;
      u_.segment<4>(7 * b + 3) = quat_mul(qc, qrel_[b]);
      v_.segment<3>(6 * b) = Vec3(vw[6 * c], vw[6 * c + 1], vw[6 * c + 2]) + Rc * wxo;
      v_.segment<3>(6 * b + 3) = w.rotation.transpose() * wc;
      if (vdw) {
        const Vec3 al(vdw[6 * c + 3], vdw[6 * c + 4], vdw[6 * c + 5]);
        vd_.segment<3>(6 * b) = Vec3(vdw[6 * c], vdw[6 * c + 1], vdw[6 * c + 2]) +
                                Rc * (al.cross(w.offset) + wc.cross(wxo));
        vd_.segment<3>(6 * b + 3) = w.rotation.transpose() * al;
      }
    }
  }

  /// Multipliers of the full model at the expanded state: the welded run's for its rows, the
  /// merged fixed joints' from each member's Newton-Euler balance, far members first
  /// (zeta_far^T delta_j = eta - Gamma vdot - the other rows' forces). Leaves the engine loaded
  /// for joint_reaction() and the residuals.
  void reactions(double t, const VecX& delta_w, const double* aux, const VecX& tracking_w) {
    e_.set_aux(aux);
    // the welded run's multi-turn angles: the gear rows (and their residuals) need them
    for (size_t c = 0; c < coord_map_.size(); ++c)
      if (coord_map_[c] >= 0) track_[static_cast<long>(c)] = tracking_w[coord_map_[c]];
    e_.set_tracking(track_);
    e_.load(u_.data(), v_.data());
    ConstraintEval& ce = e_.constraints();
    eval_constraints(m_, e_.kin(), t, false, ce);
    e_.forces(t);
    for (int r = 0; r < m_.nc; ++r) delta_[r] = row_map_[r] >= 0 ? delta_w[row_map_[r]] : 0.0;
    const VecX& eta = e_.eta();
    for (int b = 0; b < m_.nb; ++b) {
      const Body& bd = m_.bodies[b];
      r_.segment<3>(6 * b) = eta.segment<3>(6 * b) - bd.mass * vd_.segment<3>(6 * b);
      r_.segment<3>(6 * b + 3) = eta.segment<3>(6 * b + 3) - bd.inertia * vd_.segment<3>(6 * b + 3);
    }
    zeta_transpose_times(ce, m_.nc, delta_, tmp_);
    r_ -= tmp_;
    for (const auto& [j, far] : m_.weld_sweep) {
      const Joint& jt = m_.joints[j];
      const ConstraintBlock& blk = ce.blocks[block_of_[j]];
      const int sf = jt.child == far ? 1 : 0;
      const Mat6 Zf = blk.J.block<6, 6>(0, 6 * sf);
      const Vec6 d = Zf.transpose().partialPivLu().solve(Vec6(r_.segment<6>(6 * far)));
      delta_.segment<6>(jt.row0) = d;
      const int near = sf == 1 ? jt.parent : jt.child;
      if (near != kGround)
        r_.segment<6>(6 * near).noalias() -= blk.J.block<6, 6>(0, 6 * (1 - sf)).transpose() * d;
    }
    e_.set_multipliers(delta_);
  }

  Engine& engine() { return e_; }
  const VecX& u() const { return u_; }
  const VecX& v() const { return v_; }

 private:
  const Model& m_;
  const Model& w_;
  Engine e_;
  VecX u_, v_, vd_, delta_, r_, tmp_, track_;
  std::vector<Vec4> qrel_;
  std::vector<int> coord_map_;
  std::vector<int> row_map_, block_of_;
};

// the constrained equations of motion as an ODE on y = (u, v), with projection and recording
class MbsSystem : public OdeSystem {
 public:
  MbsSystem(const Model& m, Metric metric, SimResult& out)
      : m_(m), e_(m), metric_(metric), out_(out), yo_(m.nq + m.nv), vd_(m.nv) {}

  // y = (u, v, z): z the auxiliary states (PI integral terms), not projected
  void rhs(double t, const VecX& y, VecX& dy) override {
    e_.set_aux(y.data() + m_.nq + m_.nv);
    e_.dynamics(t, y.data(), y.data() + m_.nq, dy.data() + m_.nq);
    e_.udot(y.data(), y.data() + m_.nq, dy.data());
    if (m_.n_aux) e_.aux_rates(t, dy.data() + m_.nq + m_.nv);
  }

  void project_and_rhs(double t, VecX& y, VecX& dy) override {
    e_.set_aux(y.data() + m_.nq + m_.nv);
    e_.project(t, y.data(), y.data() + m_.nq, metric_);
    e_.dynamics(t, y.data(), y.data() + m_.nq, dy.data() + m_.nq, true);
    e_.udot(y.data(), y.data() + m_.nq, dy.data());
    if (m_.n_aux) e_.aux_rates(t, dy.data() + m_.nq + m_.nv);
  }

  void output(double t, const VecX& y) override {
    yo_ = y;
    double* u = yo_.data();
    double* v = yo_.data() + m_.nq;
    e_.set_aux(yo_.data() + m_.nq + m_.nv);
    e_.project(t, u, v, metric_);
    e_.dynamics(t, u, v, vd_.data(), true);
    double rf, rv;
    e_.loaded_residuals(v, rf, rv);
    record(t, u, v, vd_, rf, rv, yo_.data() + m_.nq + m_.nv);
  }

  bool project_last_stage() const override { return !e_.kkt().near_singular(); }

  /// Report in the bodies and joints of the full model (a welded run).
  void set_expander(WeldExpander* ex) { ex_ = ex; }

  /// Record the outputs at (u, v, t); the engine holds the dynamics evaluated there.
  void record(double t, const double* u, const double* v, const VecX& vd, double rf, double rv,
              const double* aux = nullptr) {
    // joint coordinates (angles unwrapped along the run) and rates
    const long row = out_.n;
    for (size_t c = 0; c < m_.coords.size(); ++c) {
      const ScalarJet q = coord_jet(m_, e_.kin(), static_cast<int>(c));
      // angles unwrapped over turns by the engine, which follows them at every projection
      const double qv = m_.coords[c].angular ? e_.tracked(static_cast<int>(c), q.val) : q.val;
      out_.q.push_back(qv);
      out_.qd.push_back(q.rate);
      out_.qdd.push_back(coord_acceleration(m_, q, static_cast<int>(c), vd));
    }
    // gear mesh forces: contact law of the gear pairs, multipliers of the ideal gears
    for (int gi = 0; gi < static_cast<int>(m_.gears.size()); ++gi) {
      double sm, sd, pen;
      e_.gear_mesh(gi, sm, sd, pen);
      const double f = gear_force(m_.gears[gi], sm, sd, pen);
      out_.gear_forces.push_back(sm >= 0 ? f : -f);
    }
    for (const GearConstraint& g : m_.gear_constraints)
      out_.gear_forces.push_back(e_.delta()[g.row]);
    // actuator efforts: tau = -delta of the drive rows
    for (const Drive& d : m_.drives) out_.drive_forces.push_back(-e_.delta()[d.row]);
    Engine* re = &e_;  // the engine of the bodies and joints reported
    if (ex_) {
      ex_->expand(u, v, vd.data());
      ex_->reactions(t, e_.delta(), aux, e_.tracking());
      re = &ex_->engine();
      re->loaded_residuals(ex_->v().data(), rf, rv);
      u = ex_->u().data();
      v = ex_->v().data();
    }
    double ke, pe;  // of every body (those welded to ground too)
    re->energy(u, v, ke, pe);
    const Model& rm = re->model();
    for (size_t j = 0; j < rm.joints.size(); ++j) {
      Vec3 f, tq;
      re->joint_reaction(static_cast<int>(j), f, tq);
      for (int k = 0; k < 3; ++k) {
        out_.reaction_forces.push_back(f[k]);
        out_.reaction_torques.push_back(tq[k]);
      }
    }
    out_.t.push_back(t);
    out_.u.insert(out_.u.end(), u, u + rm.nq);
    out_.v.insert(out_.v.end(), v, v + rm.nv);
    out_.position_residual.push_back(rf);
    out_.velocity_residual.push_back(rv);
    out_.kinetic_energy.push_back(ke);
    out_.potential_energy.push_back(pe);
    out_.n = row + 1;
  }

  int n_events() const override { return static_cast<int>(m_.gears.size()); }
  void events(double /*t*/, const VecX& y, double* g) override {
    e_.load(y.data(), y.data() + m_.nq);
    for (int i = 0; i < n_events(); ++i) {
      double s, sd;
      e_.gear_mesh(i, s, sd, g[i]);
    }
  }
  void on_event(double t, int i, int direction) override {
    out_.event_t.push_back(t);
    out_.event_index.push_back(i);
    out_.event_direction.push_back(direction);
  }

  Engine& engine() { return e_; }

 private:
  const Model& m_;
  Engine e_;
  Metric metric_;
  SimResult& out_;
  VecX yo_, vd_;
  WeldExpander* ex_ = nullptr;
};

// The joint-space equations of motion of a tree (TreeDynamics) as an ODE on y = (q, qd, z).
// Outputs go through the Cartesian system at the state built by forward kinematics, with the
// engine's multi-turn angles set from q: every table (poses, reactions, gear forces, residuals)
// is the one a Cartesian run reports.
class JointSystem : public OdeSystem {
 public:
  JointSystem(const Model& m, MbsSystem& cart)
      : m_(m), td_(m), cart_(cart), n_(td_.n()), yc_(VecX::Zero(m.nq + m.nv + m.n_aux)) {
    fkw_.kin.resize(m.nb);
  }

  void rhs(double t, const VecX& y, VecX& dy) override {
    const double* q = y.data();
    const double* qd = q + n_;
    const double* z = qd + n_;
    dy.head(n_) = y.segment(n_, n_);
    td_.accelerations(t, q, qd, z, nullptr, dy.data() + n_);
    if (m_.n_aux) td_.aux_rates(t, q, qd, z, dy.data() + 2 * n_);
  }

  void project_and_rhs(double t, VecX& y, VecX& dy) override {
    td_.project(y.data(), y.data() + n_);
    rhs(t, y, dy);
  }

  void output(double t, const VecX& y) override {
    const Eigen::Map<const VecX> q(y.data(), n_), qd(y.data() + n_, n_);
    joint_space_kinematics(m_, q, qd, fkw_.kin);
    cartesian_state(m_, fkw_.kin, yc_.data(), yc_.data() + m_.nq);
    yc_.tail(m_.n_aux) = y.tail(m_.n_aux);
    cart_.engine().set_tracking(q);
    cart_.output(t, yc_);
  }

  int n_events() const override { return static_cast<int>(m_.gears.size()); }
  void events(double /*t*/, const VecX& y, double* g) override {
    double s, sd;
    for (int i = 0; i < n_events(); ++i) td_.gear_mesh(i, y.data(), y.data() + n_, s, sd, g[i]);
  }
  void on_event(double t, int i, int direction) override { cart_.on_event(t, i, direction); }

  const TreeDynamics& dynamics() const { return td_; }

 private:
  const Model& m_;
  TreeDynamics td_;
  MbsSystem& cart_;
  int n_;
  VecX yc_;
  TreeFkWork fkw_;
};

}  // namespace

double stiffness_estimate(const Model& m, std::string& culprit) {
  // Rates of each force element with the inverse effective mass of its direction g (a
  // generalised force row) under the constraints, at the assembled state:
  //   1/m_eff = g . vdot(eta = g^T, xi = 0)   (a KKT solve; driven coordinates give 0).
  double lam = 0.0;
  culprit = "no springs or dampers";
  if (m.springs.empty() && m.coord_forces.empty() && m.gears.empty()) return 0.0;
  Engine e(m);
  e.load(m.u0.data(), m.v0.data());
  ConstraintEval& ce = e.constraints();
  eval_constraints(m, e.kin(), 0.0, true, ce);
  ce.xi.setZero();
  KktSolver& kkt = e.kkt();
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
    const VecJet d = difference(point_jet(kin_of(e.kin(), sd.body_b), sd.point_b, 1),
                                point_jet(kin_of(e.kin(), sd.body_a), sd.point_a, 0));
    const double L = d.val.norm();
    if (!(L > 0)) continue;
    const double im = inv_mass(d.left(d.val / L), sd.body_a, sd.body_b);
    consider(std::sqrt(sd.stiffness * im), msg("spring-damper '", sd.name, "' (stiffness)"));
    consider(sd.damping * im, msg("spring-damper '", sd.name, "' (damping)"));
  }
  for (const CoordForce& cf : m.coord_forces) {
    const ScalarJet q = coord_jet(m, e.kin(), cf.coord);
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
    const ScalarJet qa = coord_jet(m, e.kin(), g.coord_a), qb = coord_jet(m, e.kin(), g.coord_b);
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
    const double k = g.stiffness * g.exponent * std::pow(d, g.exponent - 1.0);
    consider(std::sqrt(k * im), msg("gear pair '", g.name, "' mesh"));
  }
  return lam;
}

std::string choose_integrator(const Model& m, double t_end, double rtol, std::string& reason) {
  std::string culprit;
  const double lam = stiffness_estimate(m, culprit);
  const double steps = lam * t_end / 3.3;
  if (steps > 5000.0) {
    reason = msg("trbdf2: fastest rate ", lam, " 1/s from ", culprit,
                 "; an explicit method would need about ", static_cast<long>(steps),
                 " steps for stability alone");
    return "trbdf2";
  }
  const std::string rate =
      msg("fastest rate ", lam, " 1/s (", culprit, "), about ", static_cast<long>(steps),
          " explicit steps for stability: not stiff");
  // tight tolerances: the 8th-order pair needs far fewer steps (docs/results/workprecision)
  if (rtol <= 1e-7) {
    reason = msg("dop853: ", rate, "; rtol ", rtol, " <= 1e-7 favours the 8th-order pair");
    return "dop853";
  }
  reason = msg("dopri5: ", rate);
  return "dopri5";
}

SimResult simulate(const Model& m, double t_end, const SimOptions& opt, const VecX& u0,
                   const VecX& v0) {
  if (!(t_end > 0) || !std::isfinite(t_end))
    throw ModelError(msg("simulate: t_end must be positive and finite, got ", t_end));
  if (opt.integrator != "dopri5" && opt.integrator != "dop853" && opt.integrator != "rk4" &&
      opt.integrator != "trbdf2" && opt.integrator != "auto" && opt.integrator != "kinematic" &&
      opt.integrator != "default")
    throw ModelError(
        msg("simulate: unknown integrator '", opt.integrator,
            "' (expected 'dopri5', 'dop853', 'rk4', 'trbdf2', 'kinematic' or 'auto')"));
  const StepOptions& s = opt.step;
  if (!(s.rtol > 0) || !std::isfinite(s.rtol))
    throw ModelError(msg("simulate: rtol must be positive, got ", s.rtol));
  if (!(s.atol > 0) || !std::isfinite(s.atol))
    throw ModelError(msg("simulate: atol must be positive, got ", s.atol));
  if (!(s.dt >= 0) || !std::isfinite(s.dt))
    throw ModelError(msg("simulate: dt must be positive, got ", s.dt));
  if (opt.integrator == "rk4" && !(s.dt > 0))
    throw ModelError("simulate: integrator 'rk4' needs a step dt > 0");
  if (!(s.output_dt >= 0) || !std::isfinite(s.output_dt))
    throw ModelError(msg("simulate: output_dt must be positive, got ", s.output_dt));
  if (s.max_steps <= 0) throw ModelError("simulate: max_steps must be positive");
  if (opt.coordinates != "cartesian" && opt.coordinates != "joint" && opt.coordinates != "auto")
    throw ModelError(msg("simulate: unknown coordinates '", opt.coordinates,
                         "' (expected 'cartesian', 'joint' or 'auto')"));
  if (u0.size() != m.nq || v0.size() != m.nv)
    throw ModelError(msg("simulate: initial state has sizes (", u0.size(), ", ", v0.size(),
                         "), expected (", m.nq, ", ", m.nv, ")"));
  if (!u0.allFinite() || !v0.allFinite())
    throw ModelError("simulate: initial state contains NaN or inf");

  SimResult out;
  out.integrator = opt.integrator;
  // zero freedom left by the drives: every state follows from the constraints, no integration
  // (not with PI-motor states or gear contact, which have states or events of their own)
  const bool prescribed = m.mobility_driven == 0 && m.n_aux == 0 && m.gears.empty();
  // bodies joined by fixed joints integrate as one composite body (Model::welded); the outputs
  // are reported for every body and joint of m
  const bool welded = m.welded != nullptr && opt.merge_welded;
  const Model& ms = welded ? *m.welded : m;  // the model integrated
  if (opt.integrator == "kinematic") {
    if (!prescribed)
      throw ModelError(
          msg("simulate: integrator 'kinematic' needs a fully driven model; ",
              m.mobility_driven > 0
                  ? msg("the drives leave ", m.mobility_driven, " degree(s) of freedom")
                  : std::string("the model has motor or gear-contact states")));
    if (!(s.output_dt > 0)) throw ModelError("simulate: integrator 'kinematic' needs output_dt");
    out.integrator_reason = "kinematic: requested";
  } else if ((opt.integrator == "default" || opt.integrator == "auto") && prescribed &&
             s.output_dt > 0) {
    out.integrator = "kinematic";
    out.integrator_reason =
        "kinematic: the drives leave no degree of freedom, so each output state follows from "
        "the constraints (position, velocity and acceleration problems); nothing to integrate";
  } else if (opt.integrator == "auto") {
    out.integrator = choose_integrator(ms, t_end, s.rtol, out.integrator_reason);
  } else if (opt.integrator == "default") {
    out.integrator = "dopri5";
  }
  // "auto": joint space wherever it applies (a tree without drives), the Cartesian path else
  const bool joint =
      opt.coordinates == "joint" || (opt.coordinates == "auto" && out.integrator != "kinematic" &&
                                     ms.joint_path_reason().empty());
  if (joint && out.integrator == "kinematic")
    throw ModelError(
        "simulate: coordinates 'joint' integrates a tree without drives; a fully driven model "
        "takes the kinematic path (coordinates 'cartesian')");
  if (s.output_dt > 0) {
    const size_t n = static_cast<size_t>(t_end / s.output_dt) + 2;
    out.t.reserve(n);
    out.u.reserve(n * m.nq);
    out.v.reserve(n * m.nv);
  }
  MbsSystem sys(ms, opt.projection, out);
  std::unique_ptr<JointSystem> jsys;
  if (joint) {
    try {
      jsys = std::make_unique<JointSystem>(ms, sys);
    } catch (const ModelError& err) {
      throw ModelError(msg("simulate: coordinates 'joint': ", err.what()));
    }
    out.formulation = jsys->dynamics().description();
  } else {
    out.formulation = msg("cartesian: ", ms.nb, " bodies, ", ms.nc, " constraint rows, KKT path '",
                          ms.kkt_all.path, "'");
    if (opt.coordinates == "auto")
      out.formulation +=
          msg(" (joint space does not apply: ",
              out.integrator == "kinematic" ? std::string("fully driven") : ms.joint_path_reason(),
              ")");
  }
  std::unique_ptr<WeldExpander> expander;
  VecX y = VecX::Zero(ms.nq + ms.nv + ms.n_aux);
  if (welded) {
    expander = std::make_unique<WeldExpander>(m);
    sys.set_expander(expander.get());
    VecX uw(ms.nq), vw(ms.nv);
    expander->contract(u0, v0, uw, vw);
    y.head(ms.nq) = uw;
    y.segment(ms.nq, ms.nv) = vw;
  } else {
    y.head(m.nq) = u0;
    y.segment(m.nq, m.nv) = v0;
  }
  const auto start = std::chrono::steady_clock::now();
  double t_last = 0.0;  // the time of the last good state y
  try {
    if (out.integrator == "kinematic") {
      Engine& e = sys.engine();
      DrivenSolver solver(ms, e, "simulate", 0.0);
      solver.throw_on_singular = false;  // counted and noted, as by the integrators
      VecX u = y.head(ms.nq), v = y.segment(ms.nq, ms.nv), vd = VecX::Zero(ms.nv);
      try {
        for (const double t : output_times(0.0, t_end, s.output_dt)) {
          double rf, rv;
          solver.solve(t, u, v, vd, rf, rv);
          ++out.stats.rhs_evals;
          sys.record(t, u.data(), v.data(), vd, rf, rv);
        }
      } catch (const SolverError&) {
        y.head(ms.nq) = u;  // the last state solved, for the diagnosis below
        y.segment(ms.nq, ms.nv) = v;
        t_last = solver.t_good;
        throw;
      }
    } else {
      OdeSystem* ode = &sys;
      VecX yj;
      if (joint) {
        // (q, qd) of the projected initial state; angles start in (-pi, pi], as the Cartesian
        // run's tracking does
        Engine& e = sys.engine();
        e.set_aux(y.data() + ms.nq + ms.nv);
        e.project(0.0, y.data(), y.data() + ms.nq, opt.projection);
        VecX q, qd;
        joint_coordinates(ms, y.head(ms.nq), y.segment(ms.nq, ms.nv), q, qd);
        const long nco = q.size();
        yj = VecX::Zero(2 * nco + ms.n_aux);
        yj << q, qd, y.tail(ms.n_aux);
        ode = jsys.get();
      }
      VecX& yi = joint ? yj : y;
      if (out.integrator == "dopri5")
        integrate_dopri5(*ode, yi, 0.0, t_end, s, out.stats);
      else if (out.integrator == "dop853")
        integrate_dop853(*ode, yi, 0.0, t_end, s, out.stats);
      else if (out.integrator == "trbdf2")
        integrate_trbdf2(*ode, yi, 0.0, t_end, s, out.stats);
      else
        integrate_rk4(*ode, yi, 0.0, t_end, s, out.stats);
    }
  } catch (const SolverError& err) {
    out.error = err.what();
    // say why when the constraints are (nearly) singular at the last accepted state
    if (out.integrator != "kinematic") t_last = out.t.empty() ? 0.0 : out.t.back();
    // (the joint-space path has no constraint Jacobian to diagnose but the gears' constant one)
    if (!joint) {
      try {
        sys.engine().set_aux(y.data() + ms.nq + ms.nv);
        // the kinematic path stops short of a limit point (no solution beyond it) by its
        // continuation's smallest step, where the rank loss shows only at looser thresholds
        std::string why;
        for (const double threshold : {1e-7, 1e-5, 1e-3}) {
          why = sys.engine().diagnose_singularity(t_last, y.data(), y.data() + ms.nq, threshold);
          if (!why.empty() || out.integrator != "kinematic") break;
        }
        if (!why.empty() && out.error.back() == '.') {
          why[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(why[0])));
          out.error += " " + why;
        } else if (!why.empty()) {
          out.error += "; " + why;
        }
      } catch (const std::exception&) {
      }
    }
  }
  out.cpu_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out.solver_bodies = ms.nb;
  out.solver_rows = ms.nc;
  Engine& e = sys.engine();
  out.kkt_solves = e.kkt_solves;
  out.factorizations = e.factorizations;
  out.position_projections = e.pstats.position_projections;
  out.newton_iterations = e.pstats.newton_iterations;
  out.singular_evaluations = e.singular_evaluations;
  out.singular_note = e.singular_note;
  // a failed output may have pushed part of a row: trim every table to n complete rows
  const size_t n = static_cast<size_t>(out.n);
  out.t.resize(n);
  out.u.resize(n * m.nq);
  out.v.resize(n * m.nv);
  out.q.resize(n * m.coords.size());
  out.qd.resize(n * m.coords.size());
  out.qdd.resize(n * m.coords.size());
  out.drive_forces.resize(n * m.drives.size());
  out.reaction_forces.resize(n * 3 * m.joints.size());
  out.reaction_torques.resize(n * 3 * m.joints.size());
  out.position_residual.resize(n);
  out.velocity_residual.resize(n);
  out.kinetic_energy.resize(n);
  out.potential_energy.resize(n);
  out.gear_forces.resize(n * (m.gears.size() + m.gear_constraints.size()));
  return out;
}

}  // namespace armdyn
