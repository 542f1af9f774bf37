// SPDX-License-Identifier: BSD-3-Clause
// Internal to simulate(): the ODE systems of the two formulations and the recording of outputs.
//  - MbsSystem: the Cartesian state y = (u, v, z) with the constrained Newton-Euler equations
//    (armdyn/algorithm/kkt.hpp) and the topological projection (armdyn/algorithm/projection.hpp),
//    on a Data of its model; it records every output table.
//  - JointSystem: the joint coordinates y = (q, qd, z) of a tree (TreeDynamics); its outputs
//    are recorded by MbsSystem at the state, accelerations and multipliers of the tree's
//    recursive sweeps (no KKT solve).
//  - WeldExpander: reports a run of the welded model (builder/weld.hpp) in the bodies and joints of
//    the full model.
#pragma once

#include <limits>
#include <vector>

#include "armdyn/algorithm/constraints.hpp"
#include "armdyn/algorithm/energy.hpp"
#include "armdyn/algorithm/forces.hpp"
#include "armdyn/algorithm/kinematics.hpp"
#include "armdyn/algorithm/kkt.hpp"
#include "armdyn/algorithm/projection.hpp"
#include "armdyn/algorithm/reactions.hpp"
#include "armdyn/algorithm/tree_dynamics.hpp"
#include "armdyn/builder/weld.hpp"
#include "armdyn/data.hpp"
#include "armdyn/math/quaternion.hpp"
#include "armdyn/simulate/simulate.hpp"
#include "limit_stops.hpp"

namespace armdyn::detail {

// Reports a run of the welded model (builder/weld.hpp) in the bodies and joints of the full model.
class WeldExpander {
 public:
  /// On d, a Data of the full model: its run buffers hold the expanded state, its pipeline the
  /// full model's evaluation.
  WeldExpander(const Model& full, const Welding& welding, Data& d)
      : m_(full), wd_(welding), d_(d), u_(d.run.u), v_(d.run.v), vd_(d.run.vd) {
    u_ = VecX::Zero(full.nq);
    v_ = VecX::Zero(full.nv);
    vd_ = VecX::Zero(full.nv);
  }

  /// The composites' state (uw, vw) from a full state: each from its root body.
  void contract(const VecX& u, const VecX& v, VecX& uw, VecX& vw) const {
    for (int c = 0; c < wd_.model->nb; ++c) {
      const int r = wd_.roots[c];
      const Weld& w = wd_.weld[r];
      const Vec4 qr = u.segment<4>(7 * r + 3).normalized();
      const Vec4& e = wd_.qrel[r];
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
      const Weld& w = wd_.weld[b];
      if (w.composite == kGround) {
        u_.segment<3>(7 * b) = w.offset;
        u_.segment<4>(7 * b + 3) = wd_.qrel[b];
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
      u_.segment<4>(7 * b + 3) = quat_mul(qc, wd_.qrel[b]);
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
  /// (sweep_multipliers). Leaves data() loaded (kinematics, constraints, multipliers) for
  /// joint_reaction() and the residuals.
  void reactions(double t, const VecX& delta_w, const double* aux, const VecX& tracking_w) {
    d_.aux = aux;
    // the welded run's multi-turn angles: the gear rows (and their residuals) need them
    for (size_t c = 0; c < wd_.coord_map.size(); ++c)
      if (wd_.coord_map[c] >= 0) d_.track_ref[static_cast<long>(c)] = tracking_w[wd_.coord_map[c]];
    load_kinematics(m_, d_, u_.data(), v_.data());
    evaluate_constraints(m_, d_, t, false);
    cartesian_forces(m_, d_, t);
    for (int r = 0; r < m_.nc; ++r)
      d_.delta[r] = wd_.row_map[r] >= 0 ? delta_w[wd_.row_map[r]] : 0.0;
    sweep_multipliers(m_, d_, vd_, wd_.sweep);
  }

  /// The full model's pipeline, loaded by reactions().
  Data& data() { return d_; }
  const VecX& u() const { return u_; }
  const VecX& v() const { return v_; }

 private:
  const Model& m_;
  const Welding& wd_;
  Data& d_;
  VecX &u_, &v_, &vd_;
};

// the constrained equations of motion as an ODE on y = (u, v), with projection and recording
class MbsSystem : public OdeSystem, public StopAccess {
 public:
  /// On d, a Data of m (its pipeline; its run buffers hold the output state).
  MbsSystem(const Model& m, Data& d, Metric metric, SimResult& out)
      : m_(m), d_(d), metric_(metric), out_(out), yo_(d.run.y), vd_(d.run.vd) {
    yo_ = VecX::Zero(m.nq + m.nv + m.n_aux);
    vd_ = VecX::Zero(m.nv);
    // a run in time: the angles tracked by their rates between projections
    d_.track_by_rates = true;
    d_.track_commit = Data::TrackCommit{};
  }
  ~MbsSystem() override { d_.track_by_rates = false; }
  MbsSystem(const MbsSystem&) = delete;
  MbsSystem& operator=(const MbsSystem&) = delete;

  // y = (u, v, z): z the auxiliary states (PI integral terms), not projected
  void rhs(double t, const VecX& y, VecX& dy) override {
    d_.aux = y.data() + m_.nq + m_.nv;
    body_accelerations(m_, d_, t, y.data(), y.data() + m_.nq, dy.data() + m_.nq);
    udot(m_, y.data(), y.data() + m_.nq, dy.data());
    if (m_.n_aux) aux_rates(m_, d_, t, dy.data() + m_.nq + m_.nv);
    if (stops_ && stops_->any_engaged()) stops_->solve(*this, t, y, dy);
  }

  void project_and_rhs(double t, VecX& y, VecX& dy) override {
    d_.aux = y.data() + m_.nq + m_.nv;
    project(m_, d_, t, y.data(), y.data() + m_.nq, metric_);
    bool reuse = true;
    if (stops_ && stops_->any_engaged()) {
      // the engaged stops' joints back on their limits (the projection knows only the joints)
      body_accelerations(m_, d_, t, y.data(), y.data() + m_.nq, dy.data() + m_.nq, true);
      reuse = !stops_->hold(*this, t, y, dy);
      // the constraints again to round-off (the hold moved along them to first order)
      if (!reuse) project(m_, d_, t, y.data(), y.data() + m_.nq, metric_);
    }
    body_accelerations(m_, d_, t, y.data(), y.data() + m_.nq, dy.data() + m_.nq, reuse);
    udot(m_, y.data(), y.data() + m_.nq, dy.data());
    if (m_.n_aux) aux_rates(m_, d_, t, dy.data() + m_.nq + m_.nv);
    if (stops_ && stops_->any_engaged()) stops_->solve(*this, t, y, dy);
  }

  void output(double t, const VecX& y) override {
    yo_ = y;
    double* u = yo_.data();
    double* v = yo_.data() + m_.nq;
    d_.aux = yo_.data() + m_.nq + m_.nv;
    project(m_, d_, t, u, v, metric_);
    body_accelerations(m_, d_, t, u, v, vd_.data(), true);
    if (stops_ && stops_->any_engaged()) {
      // the engaged stops' joints on their limits, their torques, then the accelerations and
      // multipliers with them
      fo_.resize(yo_.size());
      fo_.segment(m_.nq, m_.nv) = vd_;
      if (stops_->hold(*this, t, yo_, fo_)) {
        project(m_, d_, t, u, v, metric_);
        body_accelerations(m_, d_, t, u, v, vd_.data());
        fo_.segment(m_.nq, m_.nv) = vd_;
      }
      stops_->solve(*this, t, yo_, fo_);
      d_.joint_torques = stops_->torques().data();
      body_accelerations(m_, d_, t, u, v, vd_.data(), true);
      d_.joint_torques = nullptr;
    }
    double rf, rv;
    loaded_residuals(m_, d_, v, rf, rv);
    record(t, u, v, vd_, rf, rv, yo_.data() + m_.nq + m_.nv);
  }

  bool project_last_stage() const override { return !d_.kkt.near_singular(); }

  // The angle tracking (the unwrapped angles' turns, committed at every projection) of the
  // accepted state, restored after a rejected step whose trial end point was projected: a
  // rejected trial step can move an angle by more than half a turn (its reference then off by
  // a turn, and with it the stops' coordinates near limits of +-2 pi).
  void step_accepted() override {
    track_save_ = d_.track_ref;
    commit_save_ = d_.track_commit;
  }
  void step_rejected() override {
    if (track_save_.size() != d_.track_ref.size()) return;
    d_.track_ref = track_save_;
    d_.track_commit = commit_save_;
  }

  /// Report in the bodies and joints of the full model (a welded run).
  void set_expander(WeldExpander* ex) { ex_ = ex; }
  /// Enforce the joint position limits (simulate's limits="enforce").
  void set_stops(LimitStops* stops) { stops_ = stops; }
  LimitStops* stops() const { return stops_; }

  // StopAccess: the Cartesian state y = (u, v, z)
  void stop_eval(double t, const VecX& y, const double* tau, VecX& dy, bool again) override {
    d_.aux = y.data() + m_.nq + m_.nv;
    d_.joint_torques = tau;
    if (again)
      body_accelerations_loaded(m_, d_, t, dy.data() + m_.nq, true);
    else
      body_accelerations(m_, d_, t, y.data(), y.data() + m_.nq, dy.data() + m_.nq);
    d_.joint_torques = nullptr;
    udot(m_, y.data(), y.data() + m_.nq, dy.data());
    if (m_.n_aux) aux_rates(m_, d_, t, dy.data() + m_.nq + m_.nv);
  }
  void stop_load(const VecX& y) override { load_kinematics(m_, d_, y.data(), y.data() + m_.nq); }
  void stop_coordinate(const VecX& /*y*/, int c, double& q, double& qd) override {
    const ScalarJet jet = coord_jet(m_, d_.kin, c);
    q = m_.coords[c].angular ? tracked(d_, c, jet.val) : jet.val;
    qd = jet.rate;
  }
  double stop_acceleration(const VecX& /*y*/, const VecX& dy, int c) override {
    return coord_acceleration(m_, coord_jet(m_, d_.kin, c, false), c, dy.segment(m_.nq, m_.nv));
  }
  long stop_velocity_offset() const override { return m_.nq; }
  long stop_velocity_size() const override { return m_.nv; }
  void stop_displace(VecX& y, const VecX& dv) override {
    du_.resize(m_.nq);
    udot(m_, y.data(), dv.data(), du_.data());
    y.head(m_.nq) += du_;
    load_kinematics(m_, d_, y.data(), y.data() + m_.nq);
  }

  /// Record the outputs at (u, v, t); data() holds the dynamics evaluated there.
  void record(double t, const double* u, const double* v, const VecX& vd, double rf, double rv,
              const double* aux = nullptr) {
    // the floating bases' poses, velocities and accelerations (their frames' axes), then the
    // joint coordinates (angles unwrapped along the run), rates and accelerations
    const long row = out_.n;
    if (m_.n_free) {
      base_q_.resize(m_.nq_joint);
      base_qd_.resize(m_.nv_joint);
      base_qdd_.resize(m_.nv_joint);
      base_coordinates(m_, d_.kin, u, base_q_.data(), base_qd_.data());
      base_accelerations(m_, d_.kin, vd.data(), base_qdd_.data());
      out_.q.insert(out_.q.end(), base_q_.data(), base_q_.data() + 7 * m_.n_free);
      out_.qd.insert(out_.qd.end(), base_qd_.data(), base_qd_.data() + 6 * m_.n_free);
      out_.qdd.insert(out_.qdd.end(), base_qdd_.data(), base_qdd_.data() + 6 * m_.n_free);
    }
    for (size_t c = 0; c < m_.coords.size(); ++c) {
      const ScalarJet q = coord_jet(m_, d_.kin, static_cast<int>(c));
      // angles unwrapped over turns, followed at every projection
      const double qv = m_.coords[c].angular ? tracked(d_, static_cast<int>(c), q.val) : q.val;
      out_.q.push_back(qv);
      out_.qd.push_back(q.rate);
      out_.qdd.push_back(coord_acceleration(m_, q, static_cast<int>(c), vd));
    }
    // couplings' angle followers: the turn their leaders give
    if (!m_.independent.identity())
      m_.independent.align(m_.coords, out_.q.data() + out_.q.size() - m_.coords.size());
    // gear mesh forces: contact law of the gear pairs, multipliers of the ideal gears
    for (int gi = 0; gi < static_cast<int>(m_.gears.size()); ++gi) {
      double sm, sd, pen;
      gear_mesh(m_, d_, gi, sm, sd, pen);
      out_.gear_forces.push_back(gear_mesh_force(m_.gears[gi], sm, sd));
    }
    for (const GearConstraint& g : m_.gear_constraints) out_.gear_forces.push_back(d_.delta[g.row]);
    // actuator efforts: tau = -delta of the drive rows
    for (const Drive& d : m_.drives) out_.drive_forces.push_back(-d_.delta[d.row]);
    // the joint stops' torques/forces on their joints' coordinates
    if (stops_)
      for (int j : stops_->limited_joints()) out_.limit_forces.push_back(stops_->joint_force(j));
    // applied joint torques, every joint dof (floating bases' zero): the drives' efforts, the
    // torque inputs and the motors' torques after their limits; not springs, dampers, friction
    {
      const size_t nco = m_.coords.size(), off = out_.joint_torques.size();
      out_.joint_torques.resize(off + 6 * static_cast<size_t>(m_.n_free) + nco, 0.0);
      double* jt = out_.joint_torques.data() + off + 6 * m_.n_free;
      const double* qc = out_.q.data() + out_.q.size() - nco;
      const double* qdc = out_.qd.data() + out_.qd.size() - nco;
      for (const CoordForce& cf : m_.coord_forces) {
        if (!cf.motor && !cf.has_input) continue;
        const double z = (cf.aux >= 0 && aux) ? aux[cf.aux] : 0.0;
        jt[cf.coord] += coord_actuation_value(cf, m_.coords[cf.coord].angular, qc[cf.coord],
                                              qdc[cf.coord], t, z);
      }
      for (const Drive& d : m_.drives) jt[m_.joints[d.joint].coord0 + d.coord] -= d_.delta[d.row];
    }
    Data* rd = &d_;  // the pipeline of the bodies and joints reported
    if (ex_) {
      ex_->expand(u, v, vd.data());
      ex_->reactions(t, d_.delta, aux, d_.track_ref);
      rd = &ex_->data();
      loaded_residuals(*rd->model, *rd, ex_->v().data(), rf, rv);
      u = ex_->u().data();
      v = ex_->v().data();
    }
    const Model& rm = *rd->model;
    double ke, pe;  // of every body (those welded to ground too)
    energy(rm, *rd, u, v, ke, pe);
    for (size_t j = 0; j < rm.joints.size(); ++j) {
      Vec3 f, tq;
      joint_reaction(rm, *rd, static_cast<int>(j), f, tq);
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

  int n_events() const override {
    return static_cast<int>(m_.gears.size()) + (stops_ ? stops_->size() : 0);
  }
  void events(double t, const VecX& y, double* g) override {
    const int ng = static_cast<int>(m_.gears.size());
    if (ng) {
      load_kinematics(m_, d_, y.data(), y.data() + m_.nq);
      for (int i = 0; i < ng; ++i) {
        double s, sd;
        gear_mesh(m_, d_, i, s, sd, g[i]);
      }
    }
    if (stops_) stops_->events(*this, t, y, fe_, g + ng);
  }
  bool event_rates(double /*t*/, const VecX& y, double* dg) override {
    if (!stops_) return false;
    const int ng = static_cast<int>(m_.gears.size());
    for (int i = 0; i < ng; ++i) dg[i] = std::numeric_limits<double>::quiet_NaN();
    stops_->event_rates(*this, y, dg + ng);
    return true;
  }
  void on_event(double t, int i, int direction) override {
    const int ng = static_cast<int>(m_.gears.size());
    if (i >= ng) return stops_->on_event(i - ng, direction);
    out_.event_t.push_back(t);
    out_.event_index.push_back(i);
    out_.event_direction.push_back(direction);
  }
  double step_bound(double t) override {
    return stops_ ? stops_->step_bound(t) : std::numeric_limits<double>::infinity();
  }
  bool apply_events(double t, VecX& y) override {
    if (!stops_) return false;
    // the contact problem on the constraint manifold: the located state is the dense output's,
    // off it by the local error, and projecting it after the stops were put on their limits
    // would move them off again (by more than their event margin)
    d_.aux = y.data() + m_.nq + m_.nv;
    project(m_, d_, t, y.data(), y.data() + m_.nq, metric_);
    return stops_->apply(*this, t, y);
  }

  /// The model's Cartesian pipeline (settings, tracking, counters).
  Data& data() { return d_; }

 private:
  const Model& m_;
  Data& d_;
  Metric metric_;
  SimResult& out_;
  VecX &yo_, &vd_;
  VecX base_q_, base_qd_, base_qdd_;  // floating bases' outputs (sized on first use)
  WeldExpander* ex_ = nullptr;
  LimitStops* stops_ = nullptr;
  VecX fo_, fe_, du_;              // the stops' scratch at outputs and events
  VecX track_save_;                // the angle tracking of the last accepted state
  Data::TrackCommit commit_save_;  // and its commit (rates, time)
};

// The joint-space equations of motion of a tree (TreeDynamics) as an ODE on y = (q, qd, z).
// At an output, the joint-space dynamics give qdd (and the ideal gears' multipliers); the
// tree's forward sweep gives the bodies' Cartesian state and accelerations, and the bodies'
// Newton-Euler balances, children first, give every joint's multipliers (sweep_multipliers):
// no Cartesian KKT solve and no projection. The Cartesian system then records the same tables
// a Cartesian run reports (poses, reactions, gear forces, residuals, energies).
class JointSystem : public OdeSystem, public StopAccess {
 public:
  /// On the Data of the Cartesian system (its joint-space buffers; its run buffers hold the
  /// output state).
  JointSystem(const Model& m, MbsSystem& cart)
      : m_(m),
        td_(m, cart.data()),
        cart_(cart),
        n_(td_.n()),
        nq_(m.nq_joint),
        u_(cart.data().run.u),
        v_(cart.data().run.v),
        vd_(cart.data().run.vd),
        qdd_(cart.data().run.qdd) {
    u_ = VecX::Zero(m.nq);
    v_ = VecX::Zero(m.nv);
    vd_ = VecX::Zero(m.nv);
    qdd_ = VecX::Zero(n_);
  }

  // y = (q (nq_), qd (n_), z); q holds the floating bases' quaternions where qd has 3 rates
  void rhs(double t, const VecX& y, VecX& dy) override {
    stop_eval(t, y, nullptr, dy, false);
    if (LimitStops* st = cart_.stops(); st && st->any_engaged()) st->solve(*this, t, y, dy);
  }

  // StopAccess: the joint state y = (q, qd, z); stop_eval is also the free right-hand side
  void stop_eval(double t, const VecX& y, const double* tau, VecX& dy, bool /*again*/) override {
    const double* q = y.data();
    const double* qd = q + nq_;
    const double* z = qd + n_;
    if (m_.n_free)
      configuration_rate(m_, q, qd, dy.data());
    else
      dy.head(n_) = y.segment(n_, n_);
    td_.accelerations(t, q, qd, z, tau, dy.data() + nq_);
    if (m_.n_aux) td_.aux_rates(t, q, qd, z, dy.data() + nq_ + n_);
  }
  void stop_load(const VecX& /*y*/) override {}
  void stop_coordinate(const VecX& y, int c, double& q, double& qd) override {
    q = y[7 * m_.n_free + c];
    qd = y[nq_ + 6 * m_.n_free + c];
  }
  double stop_acceleration(const VecX& /*y*/, const VecX& dy, int c) override {
    return dy[nq_ + 6 * m_.n_free + c];
  }
  long stop_velocity_offset() const override { return nq_; }
  long stop_velocity_size() const override { return n_; }
  void stop_place(VecX& y, int c, double q) override {
    // exactly on the stop, unless the coordinate is tied to others by a gear or coupling row
    for (const GearConstraint& g : m_.gear_constraints)
      if (g.coord_a == c || g.coord_b == c) return;
    y[7 * m_.n_free + c] = q;
  }
  void stop_pin(VecX& y, int c, double q) override {
    for (const GearConstraint& g : m_.gear_constraints)
      if (g.coord_a == c || g.coord_b == c) return;
    y[7 * m_.n_free + c] = q;
    y[nq_ + 6 * m_.n_free + c] = 0.0;
  }

  void project_and_rhs(double t, VecX& y, VecX& dy) override {
    td_.project(y.data(), y.data() + nq_);
    if (LimitStops* st = cart_.stops(); st && st->any_engaged()) st->pin(*this, y);
    rhs(t, y, dy);
  }

  void output(double t, const VecX& y_dense) override {
    // the engaged stops' joints exactly on their limits at rest, as at the steps' ends (the
    // dense output between them carries the stages' round-off)
    LimitStops* stops = cart_.stops();
    const VecX* yp = &y_dense;
    if (stops && stops->any_engaged()) {
      yp_ = y_dense;
      stops->pin(*this, yp_);
      yp = &yp_;
    }
    const VecX& y = *yp;
    const double* z = y.data() + nq_ + n_;
    const Eigen::Map<const VecX> q(y.data(), nq_), qd(y.data() + nq_, n_);
    td_.accelerations(t, q.data(), qd.data(), z, nullptr, qdd_.data());
    const double* stop_tau = nullptr;
    if (stops && stops->any_engaged()) {
      // the engaged stops' torques, then the accelerations with them
      fo_.resize(y.size());
      fo_.segment(nq_, n_) = qdd_;
      stops->solve(*this, t, y, fo_);
      stop_tau = stops->torques().data();
      td_.accelerations(t, q.data(), qd.data(), z, stop_tau, qdd_.data());
    }
    // the same Data: the tree's kinematics and joint frames at (q, qd), read before the
    // Cartesian pipeline loads the same state (load_tree_motion)
    Data& d = cart_.data();
    const VecX& gear_delta = td_.gear_multipliers(qdd_.data());
    d.aux = z;
    d.joint_torques = stop_tau;
    load_tree_motion(m_, d, q, qd, qdd_, t, gear_delta.size() ? gear_delta.data() : nullptr, sweep_,
                     u_, v_, vd_);
    d.joint_torques = nullptr;
    double rf, rv;
    loaded_residuals(m_, d, v_.data(), rf, rv);
    cart_.record(t, u_.data(), v_.data(), vd_, rf, rv, z);
  }

  int n_events() const override { return cart_.n_events(); }
  void events(double t, const VecX& y, double* g) override {
    double s, sd;
    const int ng = static_cast<int>(m_.gears.size());
    for (int i = 0; i < ng; ++i) td_.gear_mesh(i, y.data(), y.data() + nq_, s, sd, g[i]);
    if (LimitStops* st = cart_.stops()) st->events(*this, t, y, fe_, g + ng);
  }
  bool event_rates(double /*t*/, const VecX& y, double* dg) override {
    LimitStops* st = cart_.stops();
    if (!st) return false;
    const int ng = static_cast<int>(m_.gears.size());
    for (int i = 0; i < ng; ++i) dg[i] = std::numeric_limits<double>::quiet_NaN();
    st->event_rates(*this, y, dg + ng);
    return true;
  }
  void on_event(double t, int i, int direction) override { cart_.on_event(t, i, direction); }
  double step_bound(double t) override { return cart_.step_bound(t); }
  bool apply_events(double t, VecX& y) override {
    LimitStops* st = cart_.stops();
    return st && st->apply(*this, t, y);
  }

  const TreeDynamics& dynamics() const { return td_; }

 private:
  const Model& m_;
  TreeDynamics td_;
  MbsSystem& cart_;
  int n_, nq_;
  VecX u_, v_, vd_, qdd_;
  VecX fo_, fe_, yp_;  // the stops' scratch at outputs and events
  // the joints whose multipliers load_tree_motion sweeps, children before parents
  const std::vector<std::pair<int, int>> sweep_ = tree_sweep(m_);
};

}  // namespace armdyn::detail
