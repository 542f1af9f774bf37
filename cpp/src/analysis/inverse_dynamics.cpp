// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/analysis/inverse_dynamics.hpp"

#include <chrono>
#include <cmath>

#include "armdyn/analysis/joint_space.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/solver/engine.hpp"

namespace armdyn {

namespace {

// qdd of coordinate c from the Cartesian accelerations: J vdot + bias
double coord_acceleration(const Model& m, const ScalarJet& s, int c, const VecX& vd) {
  const Joint& j = m.joints[m.coords[c].joint];
  double a = s.bias;
  if (j.parent != kGround) a += s.J.segment<6>(0).dot(vd.segment<6>(6 * j.parent));
  if (j.child != kGround) a += s.J.segment<6>(6).dot(vd.segment<6>(6 * j.child));
  return a;
}

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
  for (size_t k = 0; k < times.size(); ++k) {
    const double t = times[k];
    if (k > 0) {
      // first-order prediction of the next configuration from the previous solution
      const double h = t - times[k - 1];
      e.udot(u.data(), v.data(), ud.data());
      u += h * ud;
      v += h * vd;
    }
    // position and velocity problems (Newton; exact solves when zeta is square)
    try {
      e.project(t, u.data(), v.data(), Metric::Mass);
    } catch (const SolverError& err) {
      KktSolver& kkt = e.kkt();
      std::string why;
      if (kkt.used_pseudo_inverse() && kkt.rank() < m.rank_all) {
        std::string rows;
        for (int r : kkt.dependent_rows()) rows += (rows.empty() ? "" : "; ") + m.row_name(r);
        why = msg(" The driven constraints are kinematically singular there: rank ", kkt.rank(),
                  " instead of ", m.rank_all, "; dependent rows: ", rows, ".");
      }
      throw SolverError(
          msg("inverse_dynamics: ", err.what(), ".", why, " Times solved before this one: ", k));
    }
    if (const int bad = flipped_joint(m, e.kin()); bad >= 0)
      throw SolverError(msg("inverse_dynamics: the position problem at t=", t,
                            " converged to a flipped configuration of joint '", m.joints[bad].name,
                            "' (use a finer time grid)"));
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
  e_ = std::make_unique<Engine>(driven_);
  u_ = VecX::Zero(driven_.nq);
  v_ = VecX::Zero(driven_.nv);
  vd_ = VecX::Zero(driven_.nv);
  ref_ = VecX::Zero(3 * nco);
  e_->constraints().drive_ref = ref_.data();
}

JointSpaceInverseDynamics::~JointSpaceInverseDynamics() = default;

VecX JointSpaceInverseDynamics::compute(const VecX& q, const VecX& qd, const VecX& qdd, double t) {
  const long nco = static_cast<long>(driven_.coords.size());
  if (qdd.size() != nco)
    throw ModelError(msg("inverse_dynamics: qdd has length ", qdd.size(), ", expected ", nco));
  if (!qdd.allFinite()) throw ModelError("inverse_dynamics: qdd contains NaN or inf");
  if (!std::isfinite(t)) throw ModelError("inverse_dynamics: t is not finite");
  state_from_joints(*src_, q, qd, u_, v_);  // checks q, qd
  for (long c = 0; c < nco; ++c) {
    ref_[3 * c] = q[c];
    ref_[3 * c + 1] = qd[c];
    ref_[3 * c + 2] = qdd[c];
  }
  e_->dynamics(t, u_.data(), v_.data(), vd_.data());
  VecX tau(nco);
  for (long c = 0; c < nco; ++c) tau[c] = -e_->delta()[driven_.nc_joint + c];
  return tau;
}

}  // namespace armdyn
