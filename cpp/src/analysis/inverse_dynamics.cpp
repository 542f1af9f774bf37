// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/analysis/inverse_dynamics.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "armdyn/analysis/joint_space.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/solver/block_sparse.hpp"
#include "armdyn/solver/engine.hpp"
#include "armdyn/solver/kinematics.hpp"

namespace armdyn {

namespace {

std::string undriven_coordinates(const Model& m) {
  std::vector<bool> driven(m.coords.size(), false);
  for (const Drive& d : m.drives) driven[m.joints[d.joint].coord0 + d.coord] = true;
  std::string s;
  for (size_t c = 0; c < m.coords.size(); ++c)
    if (!driven[c]) s += (s.empty() ? "'" : ", '") + m.coords[c].name + "'";
  return s.empty() ? std::string("none (free bodies or loops)") : s;
}

}  // namespace

InverseDynamicsResult inverse_dynamics_driven(const Model& m, const std::vector<double>& times) {
  if (m.mobility_driven > 0)
    throw ModelError(
        msg("inverse_dynamics: the drives leave ", m.mobility_driven,
            " degree(s) of freedom unprescribed; undriven coordinates: ", undriven_coordinates(m),
            " (add drives, or use inverse_dynamics(model, q, qd, qdd) on a tree)"));
  if (times.empty()) throw ModelError("inverse_dynamics: no times given");
  for (size_t k = 0; k < times.size(); ++k) {
    if (!std::isfinite(times[k]))
      throw ModelError(msg("inverse_dynamics: time ", k, " is not finite"));
    if (k > 0 && !(times[k] > times[k - 1]))
      throw ModelError(msg("inverse_dynamics: times must increase strictly (index ", k, ")"));
  }
  const auto start = std::chrono::steady_clock::now();
  InverseDynamicsResult out;
  Engine e(m);
  const int nco = static_cast<int>(m.coords.size());
  VecX u = m.u0, v = VecX::Zero(m.nv), vd = VecX::Zero(m.nv), ud = VecX::Zero(m.nq);
  std::vector<double> qprev(nco, 0.0);
  const bool fk_predictor = m.joint_space_ok;  // a driven tree: all coordinates are driven
  VecX qc = VecX::Zero(nco), qdc = VecX::Zero(nco), u_save(m.nq), v_save(m.nv), u_pred(m.nq);
  VecX track_save = e.tracking();
  // configuration distance: per body max(|dx| / length scale, rotation angle), max over bodies
  auto distance = [&](const VecX& a, const VecX& b) {
    double d = 0.0;
    for (int i = 0; i < m.nb; ++i) {
      const double dx = (a.segment<3>(7 * i) - b.segment<3>(7 * i)).norm() / m.length_scale;
      const double c =
          std::min(1.0, std::abs(a.segment<4>(7 * i + 3).dot(b.segment<4>(7 * i + 3))));
      d = std::max({d, dx, 2.0 * std::acos(c)});
    }
    return d;
  };
  // predicted state at time t from the solution (u, v, vd) at t_from
  auto predict = [&](double t_from, double t) {
    if (fk_predictor) {
      joint_coordinates(m, u, v, qc, qdc);
      for (const Drive& d : m.drives) {
        const ProfileValue p = d.profile.eval(t);
        const int c = m.joints[d.joint].coord0 + d.coord;
        qc[c] = p.y;
        qdc[c] = p.yd;
      }
      state_from_joints(m, qc, qdc, u, v);
    } else if (t != t_from) {
      const double h = t - t_from;
      e.udot(u.data(), v.data(), ud.data());
      u += h * ud;
      v += h * vd;
    }
  };
  auto singular_rows = [&]() {
    KktSolver& kkt = e.kkt();
    std::string why;
    if (kkt.used_pseudo_inverse() && kkt.rank() < m.rank_all) {
      std::string rows;
      for (int r : kkt.dependent_rows()) rows += (rows.empty() ? "" : "; ") + m.row_name(r);
      why = msg(" The driven constraints are kinematically singular there: rank ", kkt.rank(),
                " instead of ", m.rank_all, "; dependent rows: ", rows, ".");
    }
    return why;
  };
  double t_prev = times.front() >= 0.0 ? 0.0 : times.front();  // u0 is assembled at t = 0
  for (size_t k = 0; k < times.size(); ++k) {
    const double t = times[k];
    // position and velocity problems (Newton; exact solves when zeta is square), by
    // continuation: when Newton fails from the prediction, halve the step towards t
    double t_cur = t_prev, h = t - t_prev;
    const double h_min = std::ldexp(std::max(std::abs(h), 1e-300), -12);
    do {
      const double t_next = std::min(t_cur + h, t);
      u_save = u;
      v_save = v;
      track_save = e.tracking();
      std::string failure;
      try {
        predict(t_cur, t_next);
        u_pred = u;
        e.project(t_next, u.data(), v.data(), Metric::Mass);
        if (const int bad = flipped_joint(m, e.kin()); bad >= 0)
          failure = msg("the position problem converged to a flipped configuration of joint '",
                        m.joints[bad].name, "'");
        // Newton must stay on the branch it was predicted on: a correction much larger than
        // the predicted motion means it may have jumped to another assembly mode
        if (!fk_predictor && failure.empty() &&
            distance(u, u_pred) > std::max(0.25 * distance(u_pred, u_save), 1e-3))
          failure = "the position correction is large against the predicted motion";
      } catch (const SolverError& err) {
        failure = err.what();
      }
      if (failure.empty()) {
        t_cur = t_next;
        if (t_cur < t) e.dynamics(t_cur, u.data(), v.data(), vd.data(), true);
        continue;
      }
      u = u_save;
      v = v_save;
      e.set_tracking(track_save);
      h *= 0.5;
      if (fk_predictor || !(h >= h_min))
        throw SolverError(msg("inverse_dynamics at t=", t_next, ": ", failure, ".", singular_rows(),
                              " Times solved before this one: ", k));
    } while (t_cur < t);
    t_prev = t;
    // acceleration problem and multipliers, with the factor left by the projection
    e.dynamics(t, u.data(), v.data(), vd.data(), true);
    KktSolver& kkt = e.kkt();
    if (kkt.used_pseudo_inverse() && kkt.rank() < m.rank_all) {
      std::string rows;
      for (int r : kkt.dependent_rows()) rows += (rows.empty() ? "" : "; ") + m.row_name(r);
      throw SolverError(msg("inverse_dynamics: kinematically singular at t=", t,
                            ": the driven constraints have rank ", kkt.rank(), " instead of ",
                            m.rank_all, "; dependent rows: ", rows));
    }
    for (int c = 0; c < nco; ++c) {
      const ScalarJet s = coord_jet(m, e.kin(), c);
      double qv = s.val;
      if (m.coords[c].angular && k > 0) qv = qprev[c] + std::remainder(s.val - qprev[c], 2 * M_PI);
      qprev[c] = qv;
      out.q.push_back(qv);
      out.qd.push_back(s.rate);
      out.qdd.push_back(coord_acceleration(m, s, c, vd));
    }
    for (const Drive& d : m.drives) out.efforts.push_back(-e.delta()[d.row]);
    for (size_t j = 0; j < m.joints.size(); ++j) {
      Vec3 f, tq;
      e.joint_reaction(static_cast<int>(j), f, tq);
      for (int i = 0; i < 3; ++i) {
        out.reaction_forces.push_back(f[i]);
        out.reaction_torques.push_back(tq[i]);
      }
    }
    double rf, rv;
    e.residuals(t, u.data(), v.data(), rf, rv);
    out.t.push_back(t);
    out.u.insert(out.u.end(), u.data(), u.data() + m.nq);
    out.v.insert(out.v.end(), v.data(), v.data() + m.nv);
    out.position_residual.push_back(rf);
    out.velocity_residual.push_back(rv);
    ++out.n;
  }
  out.newton_iterations = e.pstats.newton_iterations;
  out.factorizations = e.factorizations;
  out.cpu_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

JointSpaceInverseDynamics::JointSpaceInverseDynamics(std::shared_ptr<const Model> m)
    : src_(std::move(m)) {
  if (!src_) throw ModelError("inverse_dynamics: no model");
  require_joint_space(*src_, "inverse_dynamics");
  driven_ = *src_;
  driven_.drives.clear();
  driven_.drive_index.clear();
  const int nco = static_cast<int>(driven_.coords.size());
  for (int c = 0; c < nco; ++c) {
    Drive d;
    d.name = driven_.coords[c].name;
    d.joint = driven_.coords[c].joint;
    d.coord = driven_.coords[c].sub;
    d.profile = Profile::constant(0.0);
    d.row = driven_.nc_joint + c;
    driven_.drive_index[d.name] = c;
    driven_.drives.push_back(d);
  }
  driven_.nc = driven_.nc_joint + nco;
  driven_.rank_all = driven_.rank_joint + nco;
  driven_.mobility_driven = driven_.mobility - nco;
  driven_.redundant = false;
  driven_.redundant_rows.clear();
  // the drives changed the row blocks: plan the KKT factorisation afresh
  driven_.kkt_all = plan_kkt(driven_, driven_.nc);
  driven_.kkt_joint = plan_kkt(driven_, driven_.nc_joint);
  e_ = std::make_unique<Engine>(driven_);
  u_ = VecX::Zero(driven_.nq);
  v_ = VecX::Zero(driven_.nv);
  vd_ = VecX::Zero(driven_.nv);
  ref_ = VecX::Zero(3 * nco);
  e_->constraints().drive_ref = ref_.data();
  // the sweep plan: joints in tree order, each with its rows and its drives' rows (6 in all)
  const ConstraintEval& ce = e_->constraints();
  std::vector<int> block_at_row(driven_.nc, -1);  // block starting at each row
  for (int b = 0; b < static_cast<int>(ce.blocks.size()); ++b) block_at_row[ce.blocks[b].row0] = b;
  sweep_ok_ = driven_.gear_constraints.empty();
  for (int ji : driven_.tree_order) {
    const Joint& j = driven_.joints[ji];
    const int nco_j = joint_coords(j.type);
    Sweep s{ji, j.parent, j.child, {-1, -1, -1}, 0};
    if (joint_rows(j.type) > 0) s.blocks[s.nblocks++] = block_at_row[j.row0];
    for (int c = 0; c < nco_j && s.nblocks < 3; ++c)  // drives are in coordinate order
      s.blocks[s.nblocks++] = block_at_row[driven_.nc_joint + j.coord0 + c];
    if (joint_rows(j.type) + nco_j != 6 || s.nblocks != 1 + nco_j || j.child == kGround)
      sweep_ok_ = false;
    sweep_.push_back(s);
  }
  if (static_cast<int>(sweep_.size()) != driven_.nb) sweep_ok_ = false;
  lu_.resize(sweep_.size());
  delta_ = VecX::Zero(driven_.nc);
  r_ = VecX::Zero(driven_.nv);
}

void JointSpaceInverseDynamics::compute_sweep(double t) {
  // the same constraint and force evaluation as the KKT path, then two sweeps instead of the
  // KKT solve: zeta vdot = -xi forward (parents first), zeta^T delta = eta - Gamma vdot backward
  e_->load(u_.data(), v_.data());
  eval_constraints(driven_, e_->kin(), t, true, e_->constraints());
  e_->forces(t);
  const ConstraintEval& ce = e_->constraints();
  auto gather = [&](const Sweep& s, int slot, Mat6& Z, Vec6* rhs) {
    int r = 0;
    for (int k = 0; k < s.nblocks; ++k) {
      const ConstraintBlock& b = ce.blocks[s.blocks[k]];
      for (int i = 0; i < b.nrows; ++i, ++r) {
        Z.row(r) = b.J.row(i).segment<6>(6 * slot);
        if (rhs) (*rhs)[r] = -ce.xi[b.row0 + i];
      }
    }
  };
  Mat6 Zc, Zp;
  Vec6 rhs;
  for (size_t k = 0; k < sweep_.size(); ++k) {
    const Sweep& s = sweep_[k];
    gather(s, 1, Zc, &rhs);
    if (s.parent != kGround) {
      gather(s, 0, Zp, nullptr);
      rhs.noalias() -= Zp * vd_.segment<6>(6 * s.parent);
    }
    lu_[k].compute(Zc);
    vd_.segment<6>(6 * s.child) = lu_[k].solve(rhs);
  }
  // r = eta - Gamma vdot
  const VecX& eta = e_->eta();
  for (int i = 0; i < driven_.nb; ++i) {
    const Body& b = driven_.bodies[i];
    r_.segment<3>(6 * i) = eta.segment<3>(6 * i) - b.mass * vd_.segment<3>(6 * i);
    r_.segment<3>(6 * i + 3) = eta.segment<3>(6 * i + 3) - b.inertia * vd_.segment<3>(6 * i + 3);
  }
  for (size_t k = sweep_.size(); k-- > 0;) {
    const Sweep& s = sweep_[k];
    // delta of this joint's rows from its child's balance (its children's shares already out)
    Vec6 d = lu_[k].transpose().solve(r_.segment<6>(6 * s.child));
    int r = 0;
    for (int q = 0; q < s.nblocks; ++q) {
      const ConstraintBlock& b = ce.blocks[s.blocks[q]];
      for (int i = 0; i < b.nrows; ++i, ++r) delta_[b.row0 + i] = d[r];
    }
    if (s.parent != kGround) {
      gather(s, 0, Zp, nullptr);
      r_.segment<6>(6 * s.parent).noalias() -= Zp.transpose() * d;
    }
  }
}

JointSpaceInverseDynamics::~JointSpaceInverseDynamics() = default;

VecX JointSpaceInverseDynamics::compute(const VecX& q, const VecX& qd, const VecX& qdd, double t) {
  VecX tau(static_cast<long>(driven_.coords.size()));
  compute(q, qd, qdd, tau, t);
  return tau;
}

void JointSpaceInverseDynamics::compute(Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                                        Eigen::Ref<const VecX> qdd, Eigen::Ref<VecX> tau,
                                        double t) {
  const long nco = static_cast<long>(driven_.coords.size());
  if (qdd.size() != nco)
    throw ModelError(msg("inverse_dynamics: qdd has length ", qdd.size(), ", expected ", nco));
  if (!qdd.allFinite()) throw ModelError("inverse_dynamics: qdd contains NaN or inf");
  if (!std::isfinite(t)) throw ModelError("inverse_dynamics: t is not finite");
  if (tau.size() != nco)
    throw ModelError(msg("inverse_dynamics: tau has length ", tau.size(), ", expected ", nco));
  state_from_joints(*src_, q, qd, u_, v_, fk_);  // checks q, qd
  for (long c = 0; c < nco; ++c) {
    ref_[3 * c] = q[c];
    ref_[3 * c + 1] = qd[c];
    ref_[3 * c + 2] = qdd[c];
  }
  if (sweep_ok_) {
    compute_sweep(t);
    for (long c = 0; c < nco; ++c) tau[c] = -delta_[driven_.nc_joint + c];
    if (tau.allFinite()) return;
  }
  e_->dynamics(t, u_.data(), v_.data(), vd_.data());
  for (long c = 0; c < nco; ++c) tau[c] = -e_->delta()[driven_.nc_joint + c];
}

}  // namespace armdyn
