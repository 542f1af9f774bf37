// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/driven_inverse_dynamics.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "armdyn/algorithm/kinematics.hpp"
#include "armdyn/algorithm/kkt.hpp"
#include "armdyn/algorithm/projection.hpp"
#include "armdyn/algorithm/reactions.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/kernels/block_sparse.hpp"
#include "armdyn/kernels/jets.hpp"
#include "armdyn/kernels/joint_space.hpp"

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

DrivenSolver::DrivenSolver(const Model& m, Data& d, const char* who, double t0)
    : t_good(t0),
      m_(m),
      d_(d),
      who_(who),
      t_prev_(t0),
      fk_(m.joint_space_ok),
      qc_(d.driven_solve.qc),
      qdc_(d.driven_solve.qdc),
      ud_(d.driven_solve.ud),
      u_save_(d.driven_solve.u_save),
      v_save_(d.driven_solve.v_save),
      u_pred_(d.driven_solve.u_pred),
      track_save_(d.driven_solve.track_save),
      track_by_rates_before_(d.track_by_rates),
      fkw_(d.driven_solve.fk) {
  check_data(m, d, who);
  if (m.mobility_driven > 0)
    throw ModelError(
        msg(who, ": the drives leave ", m.mobility_driven,
            " degree(s) of freedom unprescribed; undriven coordinates: ", undriven_coordinates(m),
            " (add drives, or use inverse_dynamics(model, q, qd, qdd) on a tree)"));
  const long nco = static_cast<long>(m.coords.size());
  for (auto [x, n] : {std::pair{&qc_, nco}, std::pair{&qdc_, nco}, std::pair{&ud_, long{m.nq}},
                      std::pair{&u_save_, long{m.nq}}, std::pair{&v_save_, long{m.nv}},
                      std::pair{&u_pred_, long{m.nq}}})
    if (x->size() != n) *x = VecX::Zero(n);
  track_save_ = d.track_ref;
  // a run in time: each angle's turn between two times follows its rate (a fast rotor may
  // turn more than half a turn from one time to the next)
  d.track_by_rates = true;
  d.track_commit = Data::TrackCommit{};
}

DrivenSolver::~DrivenSolver() { d_.track_by_rates = track_by_rates_before_; }

void DrivenSolver::predict(double t_from, double t, VecX& u, VecX& v, const VecX& vd) {
  if (fk_) {
    // a tree with no freedom left has every coordinate driven: the state follows from the
    // drive values alone
    for (const Drive& d : m_.drives) {
      const ProfileValue p = d.profile.eval(t);
      const int c = m_.joints[d.joint].coord0 + d.coord;
      qc_[c] = p.y;
      qdc_[c] = p.yd;
    }
    state_from_joints(m_, qc_, qdc_, u, v, fkw_);
  } else if (t != t_from) {
    const double h = t - t_from;
    udot(m_, u.data(), v.data(), ud_.data());
    u += h * ud_;
    v += h * vd;
  }
}

std::string DrivenSolver::singular_rows() const {
  const KktSolver& kkt = d_.kkt;
  if (!(kkt.used_pseudo_inverse() && kkt.rank() < m_.rank_all)) return "";
  return msg(" The driven constraints are kinematically singular there: rank ", kkt.rank(),
             " instead of ", m_.rank_all, "; dependent rows: ", dependent_row_names(m_, d_), ".");
}

void DrivenSolver::solve(double t, VecX& u, VecX& v, VecX& vd, double& rf, double& rv) {
  // configuration distance: per body max(|dx| / length scale, rotation angle), max over bodies
  auto distance = [&](const VecX& a, const VecX& b) {
    double d = 0.0;
    for (int i = 0; i < m_.nb; ++i) {
      const double dx = (a.segment<3>(7 * i) - b.segment<3>(7 * i)).norm() / m_.length_scale;
      const double c =
          std::min(1.0, std::abs(a.segment<4>(7 * i + 3).dot(b.segment<4>(7 * i + 3))));
      d = std::max({d, dx, 2.0 * std::acos(c)});
    }
    return d;
  };
  bool solved = false;
  if (fk_) {
    // closed form, accepted when it meets the constraints to round-off: one factorisation
    u_save_ = u;
    v_save_ = v;
    predict(t_prev_, t, u, v, vd);
    track_save_ = d_.track_ref;
    advance_tracking(m_, d_, t);
    body_accelerations(m_, d_, t, u.data(), v.data(), vd.data());
    loaded_residuals(m_, d_, v.data(), rf, rv);
    const double tol_f = 1e-13 * std::max(1.0, m_.length_scale);
    const double tol_v = 1e-13 * std::max(1.0, v.cwiseAbs().maxCoeff());
    solved = rf <= tol_f && rv <= tol_v && flipped_joint(m_, d_.kin) < 0;
    if (solved) {
      commit_tracking(m_, d_, t);
    } else {
      u = u_save_;
      v = v_save_;
      d_.track_ref = track_save_;
    }
  }
  if (!solved) {
    // position and velocity problems (Newton; exact solves when zeta is square), by
    // continuation: when Newton fails from the prediction, halve the step towards t
    double t_cur = t_prev_, h = t - t_prev_;
    const double h_min = std::ldexp(std::max(std::abs(h), 1e-300), -12);
    do {
      const double t_next = std::min(t_cur + h, t);
      u_save_ = u;
      v_save_ = v;
      track_save_ = d_.track_ref;
      commit_save_ = d_.track_commit;
      std::string failure;
      try {
        predict(t_cur, t_next, u, v, vd);
        u_pred_ = u;
        project(m_, d_, t_next, u.data(), v.data(), Metric::Mass);
        if (const int bad = flipped_joint(m_, d_.kin); bad >= 0)
          failure = msg("the position problem converged to a flipped configuration of joint '",
                        m_.joints[bad].name, "'");
        // Newton must stay on the branch it was predicted on: a correction much larger than
        // the predicted motion means it may have jumped to another assembly mode
        if (!fk_ && failure.empty() &&
            distance(u, u_pred_) > std::max(0.25 * distance(u_pred_, u_save_), 1e-3))
          failure = "the position correction is large against the predicted motion";
      } catch (const SolverError& err) {
        failure = err.what();
      }
      if (failure.empty()) {
        t_cur = t_next;
        t_good = t_cur;
        if (t_cur < t) body_accelerations(m_, d_, t_cur, u.data(), v.data(), vd.data(), true);
        continue;
      }
      u = u_save_;
      v = v_save_;
      d_.track_ref = track_save_;
      d_.track_commit = commit_save_;
      h *= 0.5;
      if (fk_ || !(h >= h_min))
        throw SolverError(msg(who_, " at t=", t_next, ": ", failure, ".", singular_rows()));
    } while (t_cur < t);
    // acceleration problem and multipliers, with the factor left by the projection
    body_accelerations(m_, d_, t, u.data(), v.data(), vd.data(), true);
    loaded_residuals(m_, d_, v.data(), rf, rv);
  }
  t_prev_ = t;
  t_good = t;
  const KktSolver& kkt = d_.kkt;
  if (throw_on_singular && !d_.swept && kkt.used_pseudo_inverse() && kkt.rank() < m_.rank_all)
    throw SolverError(msg(who_, ": kinematically singular at t=", t,
                          ": the driven constraints have rank ", kkt.rank(), " instead of ",
                          m_.rank_all, "; dependent rows: ", dependent_row_names(m_, d_)));
}

InverseDynamicsResult inverse_dynamics_driven(const Model& m, const std::vector<double>& times,
                                              Poll* poll) {
  Data d(m);
  const double t0 = (!times.empty() && times.front() < 0.0) ? times.front() : 0.0;
  DrivenSolver solver(m, d, "driven_inverse_dynamics", t0);  // u0 is assembled at t = 0
  if (times.empty()) throw ModelError("driven_inverse_dynamics: no times given");
  for (size_t k = 0; k < times.size(); ++k) {
    if (!std::isfinite(times[k]))
      throw ModelError(msg("driven_inverse_dynamics: time ", k, " is not finite"));
    if (k > 0 && !(times[k] > times[k - 1]))
      throw ModelError(
          msg("driven_inverse_dynamics: times must increase strictly (index ", k, ")"));
  }
  const auto start = std::chrono::steady_clock::now();
  InverseDynamicsResult out;
  const int nco = static_cast<int>(m.coords.size());
  const size_t nt = times.size();
  out.t.reserve(nt);
  out.u.reserve(nt * m.nq);
  out.v.reserve(nt * m.nv);
  out.q.reserve(nt * nco);
  out.qd.reserve(nt * nco);
  out.qdd.reserve(nt * nco);
  out.drive_forces.reserve(nt * m.drives.size());
  out.reaction_forces.reserve(nt * 3 * m.joints.size());
  out.reaction_torques.reserve(nt * 3 * m.joints.size());
  out.position_residual.reserve(nt);
  out.velocity_residual.reserve(nt);
  VecX u = m.u0, v = VecX::Zero(m.nv), vd = VecX::Zero(m.nv);
  if (poll) poll->start();
  for (size_t k = 0; k < nt; ++k) {
    const double t = times[k];
    if (poll) (*poll)(t, times.back());
    double rf, rv;
    try {
      solver.solve(t, u, v, vd, rf, rv);
    } catch (const SolverError& err) {
      std::throw_with_nested(SolverError(msg(err.what(), " Times solved before this one: ", k)));
    }
    for (int c = 0; c < nco; ++c) {
      const ScalarJet s = coord_jet(m, d.kin, c);
      // angles over turns: as tracked by the solve (by their rates from one time to the next)
      out.q.push_back(m.coords[c].angular ? tracked(d, c, s.val) : s.val);
      out.qd.push_back(s.rate);
      out.qdd.push_back(coord_acceleration(m, s, c, vd));
    }
    for (const Drive& dr : m.drives) out.drive_forces.push_back(-d.delta[dr.row]);
    for (size_t j = 0; j < m.joints.size(); ++j) {
      Vec3 f, tq;
      joint_reaction(m, d, static_cast<int>(j), f, tq);
      for (int i = 0; i < 3; ++i) {
        out.reaction_forces.push_back(f[i]);
        out.reaction_torques.push_back(tq[i]);
      }
    }
    out.t.push_back(t);
    out.u.insert(out.u.end(), u.data(), u.data() + m.nq);
    out.v.insert(out.v.end(), v.data(), v.data() + m.nv);
    out.position_residual.push_back(rf);
    out.velocity_residual.push_back(rv);
    ++out.n;
  }
  out.newton_iterations = d.stats.newton_iterations;
  out.factorizations = d.stats.factorizations;
  out.cpu_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace armdyn
