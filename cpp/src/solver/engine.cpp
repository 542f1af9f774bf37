// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/solver/engine.hpp"

#include <cmath>
#include <cstdio>

#include "armdyn/algorithm/forces.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/math/quaternion.hpp"

namespace armdyn {

namespace {
std::string short_number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", x);
  return buf;
}
}  // namespace

Engine::Engine(const Model& m)
    : m_(m),
      kkt_(m),
      eta_(VecX::Zero(m.nv)),
      delta_(VecX::Zero(m.nc)),
      tmp_nv_(VecX::Zero(m.nv)),
      tmp_nc_(VecX::Zero(m.nc)),
      mu_(VecX::Zero(m.nc)),
      vd_(VecX::Zero(m.nv)),
      track_ref_(VecX::Zero(static_cast<long>(m.coords.size()))),
      cq_(VecX::Zero(static_cast<long>(m.coords.size()))),
      cqd_(VecX::Zero(static_cast<long>(m.coords.size()))),
      ctau_(VecX::Zero(static_cast<long>(m.coords.size()))),
      nrows_(m.nc) {
  kin_.resize(m.nb);
  ce_.init(m);
  jets_.init(m);
  ce_.coord_cache = &jets_;
  sweep_.plan(m, ce_);
  ce_.track_ref = &track_ref_;
  tol_f_ = 1e-13 * std::max(1.0, m.length_scale);
}

void Engine::load(const double* u, const double* v) {
  body_kinematics(m_, u, v, kin_);
  jets_.reset();
}

void Engine::scatter(const Row12& g, int pa, int pb) {
  if (pa != kGround) eta_.segment<6>(6 * pa) += g.segment<6>(0).transpose();
  if (pb != kGround) eta_.segment<6>(6 * pb) += g.segment<6>(6).transpose();
}

void Engine::coordinate_forces(double t) {
  if (m_.coord_forces.empty() && m_.gears.empty()) return;
  // the coordinates the laws read, from their jets (gear angles unwrapped over turns)
  for (const CoordForce& cf : m_.coord_forces) {
    const ScalarJet& q = jets_.get(m_, kin_, cf.coord);
    cq_[cf.coord] = q.val;
    cqd_[cf.coord] = q.rate;
  }
  for (const GearPair& g : m_.gears) {
    for (const int c : {g.coord_a, g.coord_b}) {
      const ScalarJet& q = jets_.get(m_, kin_, c);
      cq_[c] = tracked(c, q.val);
      cqd_[c] = q.rate;
    }
  }
  // the joint-space generalised forces (the laws of armdyn/algorithm/forces.hpp), mapped onto
  // the bodies through each coordinate's Jacobian
  armdyn::coordinate_forces(m_, cq_.data(), cqd_.data(), aux_, t, ctau_);
  for (int c = 0; c < static_cast<int>(m_.coords.size()); ++c) {
    if (ctau_[c] == 0.0) continue;
    const Joint& j = m_.joints[m_.coords[c].joint];
    scatter(ctau_[c] * jets_.get(m_, kin_, c).J, j.parent, j.child);
  }
}

void Engine::forces(double t) {
  body_forces(m_, kin_, t, eta_);
  if (coord_forces_) coordinate_forces(t);
  // joint-space torques of a joint-space call
  if (tau_) {
    for (int c = 0; c < static_cast<int>(m_.coords.size()); ++c) {
      const ScalarJet& q = tau_jets_[c] = coord_jet(m_, kin_, c, false);
      if (tau_[c] == 0.0) continue;
      const Joint& j = m_.joints[m_.coords[c].joint];
      scatter(tau_[c] * q.J, j.parent, j.child);
    }
  }
  if (!eta_.allFinite()) {
    for (int i = 0; i < m_.nb; ++i)
      if (!eta_.segment<6>(6 * i).allFinite())
        throw SolverError(
            msg("non-finite applied force on body '", m_.bodies[i].name, "' at t=", t));
  }
}

void Engine::dynamics(double t, const double* u, const double* v, double* vdot, bool reuse_factor) {
  load(u, v);
  dynamics_loaded(t, vdot, reuse_factor);
}

void Engine::dynamics_loaded(double t, double* vdot, bool reuse_factor) {
  eval_constraints(m_, kin_, t, true, ce_);
  forces(t);
  Eigen::Map<VecX> vd(vdot, m_.nv);
  swept_ = false;
  if (sweep_.ok() && nrows_ == m_.nc) {
    // square zeta of a fully driven tree: two O(n) sweeps, no KKT factorisation
    swept_ = sweep_.solve(m_, ce_, eta_, vd_, delta_);
    if (swept_) {
      ++factorizations;
      ++kkt_solves;
      vd = vd_;
      return;
    }
  }
  if (!(reuse_factor && kkt_.metric() == Metric::Mass && kkt_.nrows() == nrows_)) {
    kkt_.factor(ce_, nrows_, Metric::Mass);
    ++factorizations;
  }
  if (kkt_.used_pseudo_inverse()) {
    const int expected = nrows_ == m_.nc ? m_.rank_all : m_.rank_joint;
    if (kkt_.rank() < expected) {
      if (singular_evaluations++ == 0) {
        std::string rows;
        for (int r : kkt_.dependent_rows()) rows += (rows.empty() ? "" : "; ") + m_.row_name(r);
        singular_note = msg("singular configuration at t=", t, ": constraint rank ", kkt_.rank(),
                            " instead of ", expected, "; dependent rows: ", rows);
      }
    }
  }
  kkt_.accelerations(ce_, eta_, vd_, delta_);
  ++kkt_solves;
  if (!vd_.allFinite())
    throw SolverError(msg("non-finite accelerations at t=", t,
                          " (singular constraint Jacobian or invalid state)"));
  vd = vd_;
}

void Engine::udot(const double* u, const double* v, double* ud) const {
  for (int i = 0; i < m_.nb; ++i) {
    const double* ui = u + 7 * i;
    const double* vi = v + 6 * i;
    double* o = ud + 7 * i;
    o[0] = vi[0];
    o[1] = vi[1];
    o[2] = vi[2];
    const Vec4 ed = quat_rate(Vec4(ui[3], ui[4], ui[5], ui[6]), Vec3(vi[3], vi[4], vi[5]));
    o[3] = ed[0];
    o[4] = ed[1];
    o[5] = ed[2];
    o[6] = ed[3];
  }
}

void Engine::project(double t, double* u, double* v, Metric metric) {
  Eigen::Map<VecX> um(u, m_.nq), vm(v, m_.nv);
  // quaternions onto the unit sphere (the normalisation rows are not part of zeta)
  for (int i = 0; i < m_.nb; ++i) {
    auto e = um.segment<4>(7 * i + 3);
    const double n = e.norm();
    if (!(n > 0.0) || !std::isfinite(n))
      throw SolverError(msg("invalid Euler parameters of body '", m_.bodies[i].name, "' at t=", t));
    e /= n;
  }
  load(u, nullptr);
  eval_constraints(m_, kin_, t, false, ce_);
  double rf = nrows_ ? ce_.f.head(nrows_).cwiseAbs().maxCoeff() : 0.0;
  if (!std::isfinite(rf)) throw SolverError(msg("non-finite constraint residual at t=", t));
  if (rf > tol_f_) {
    // simplified Newton: minimum-norm steps w = -W^-1 zeta^T A^-1 f, Jacobian refreshed when slow
    ++pstats.position_projections;
    kkt_.factor(ce_, nrows_, metric);
    ++factorizations;
    double rprev = rf;
    int it = 0;
    for (; it < 30 && rf > tol_f_; ++it) {
      kkt_.solve_schur(ce_.f, mu_);
      zeta_transpose_times(ce_, nrows_, mu_, tmp_nv_);
      kkt_.apply_winv(tmp_nv_, vd_);
      for (int i = 0; i < m_.nb; ++i) {
        um.segment<3>(7 * i) -= vd_.segment<3>(6 * i);
        const Vec4 e = um.segment<4>(7 * i + 3);
        um.segment<4>(7 * i + 3) = quat_mul(e, quat_exp(-vd_.segment<3>(6 * i + 3))).normalized();
      }
      load(u, nullptr);
      eval_constraints(m_, kin_, t, false, ce_);
      rf = ce_.f.head(nrows_).cwiseAbs().maxCoeff();
      ++pstats.newton_iterations;
      if (!std::isfinite(rf)) break;
      if (rf > 0.25 * rprev) {
        // slow contraction: stop when it stagnates at round-off, otherwise refresh the Jacobian
        if (rf >= rprev && rf < 1e-10 * std::max(1.0, m_.length_scale)) break;
        kkt_.factor(ce_, nrows_, metric);
        ++factorizations;
      }
      rprev = rf;
    }
    if (!(rf < 1e-9 * std::max(1.0, m_.length_scale))) {
      int worst = 0;
      ce_.f.head(nrows_).cwiseAbs().maxCoeff(&worst);
      throw SolverError(msg("position projection did not converge at t=", t, ": |f| = ", rf,
                            ", largest at ", m_.row_name(worst)));
    }
  }
  // velocities onto zeta v = rhs, with A at the final u
  load(u, v);
  commit_tracking();
  if (nrows_ == 0) return;
  kkt_.factor(ce_, nrows_, metric);
  ++factorizations;
  zeta_times(ce_, nrows_, vm, tmp_nc_);
  tmp_nc_.head(nrows_) -= ce_.rhs.head(nrows_);
  kkt_.solve_schur(tmp_nc_, mu_);
  zeta_transpose_times(ce_, nrows_, mu_, tmp_nv_);
  kkt_.apply_winv(tmp_nv_, vd_);
  vm -= vd_;
  ++pstats.velocity_projections;
}

std::string Engine::diagnose_singularity(double t, const double* u, const double* v,
                                         double threshold) {
  load(u, v);
  eval_constraints(m_, kin_, t, false, ce_);
  kkt_.factor_pivoted_at(ce_, nrows_, Metric::Mass, threshold);
  const int expected = nrows_ == m_.nc ? m_.rank_all : m_.rank_joint;
  if (kkt_.rank() >= expected) return "";
  std::string rows;
  for (int r : kkt_.dependent_rows()) rows += (rows.empty() ? "" : "; ") + m_.row_name(r);
  return msg("the constraint Jacobian is nearly singular at t=", t, " (rank ", kkt_.rank(), " of ",
             expected, " at a ", short_number(threshold),
             " threshold); nearly dependent rows: ", rows);
}

void Engine::aux_rates(double t, double* zdot) const {
  for (const CoordForce& cf : m_.coord_forces) {
    if (cf.aux < 0) continue;
    const ScalarJet& q = jets_.get(m_, kin_, cf.coord);
    const double z = aux_ ? aux_[cf.aux] : 0.0;
    coord_force_value(cf, m_.coords[cf.coord].angular, q.val, q.rate, t, z, &zdot[cf.aux]);
  }
}

void Engine::commit_tracking() {
  // every angle coordinate is followed over turns (gears need it; outputs use it)
  for (int c = 0; c < static_cast<int>(m_.coords.size()); ++c)
    if (m_.coords[c].angular) track_ref_[c] = tracked(c, coord_value(m_, kin_, c));
}

void Engine::gear_mesh(int gi, double& s, double& sd, double& penetration) const {
  const GearPair& g = m_.gears[gi];
  const ScalarJet& qa = jets_.get(m_, kin_, g.coord_a);
  const ScalarJet& qb = jets_.get(m_, kin_, g.coord_b);
  s = g.r_a * tracked(g.coord_a, qa.val) + g.r_b * tracked(g.coord_b, qb.val);
  sd = g.r_a * qa.rate + g.r_b * qb.rate;
  penetration = std::abs(s) - 0.5 * g.backlash;
}

void Engine::residuals(double t, const double* u, const double* v, double& rf, double& rv) {
  load(u, v);
  eval_constraints(m_, kin_, t, false, ce_);
  loaded_residuals(v, rf, rv);
}

void Engine::loaded_residuals(const double* v, double& rf, double& rv) {
  if (nrows_ == 0) {
    rf = rv = 0.0;
    return;
  }
  rf = ce_.f.head(nrows_).cwiseAbs().maxCoeff();
  Eigen::Map<const VecX> vm(v, m_.nv);
  zeta_times(ce_, nrows_, vm, tmp_nc_);
  rv = (tmp_nc_.head(nrows_) - ce_.rhs.head(nrows_)).cwiseAbs().maxCoeff();
}

void Engine::energy(const double* u, const double* v, double& ke, double& pe) {
  load(u, v);
  ke = pe = 0.0;
  for (int i = 0; i < m_.nb; ++i) {
    const Body& b = m_.bodies[i];
    const BodyKin& k = kin_[i];
    ke += 0.5 * b.mass * k.xd.squaredNorm() + 0.5 * k.w.dot(b.inertia * k.w);
    pe -= b.mass * m_.gravity.dot(k.x);
  }
  for (const SpringDamper& sd : m_.springs) {
    const Vec3 pa = kin_of(kin_, sd.body_a).x + kin_of(kin_, sd.body_a).R * sd.point_a;
    const Vec3 pb = kin_of(kin_, sd.body_b).x + kin_of(kin_, sd.body_b).R * sd.point_b;
    const double e = (pb - pa).norm() - sd.rest_length;
    pe += 0.5 * sd.stiffness * e * e;
  }
  for (const CoordForce& cf : m_.coord_forces) {
    if (cf.stiffness == 0.0) continue;
    const double q = coord_value(m_, kin_, cf.coord);
    const double dq = m_.coords[cf.coord].angular ? wrap_angle(q - cf.rest) : q - cf.rest;
    pe += 0.5 * cf.stiffness * dq * dq;
  }
}

void Engine::joint_reaction(int j, Vec3& force, Vec3& torque) const {
  const Joint& jt = m_.joints[j];
  force.setZero();
  torque.setZero();
  const int r = joint_rows(jt.type);
  if (r == 0 || jt.row0 >= nrows_) return;
  // find the joint's block (blocks are in joint order, rowless joints skipped)
  const ConstraintBlock* blk = nullptr;
  for (const ConstraintBlock& b : ce_.blocks)
    if (b.row0 == jt.row0) {
      blk = &b;
      break;
    }
  // constraint force on a body: -zeta_b^T delta = (force world, torque body frame about the CoM)
  const bool on_child = jt.child != kGround;
  const int slot = on_child ? 1 : 0;
  const int body = on_child ? jt.child : jt.parent;
  const Eigen::Matrix<double, 6, 1> g =
      -blk->J.middleCols<6>(6 * slot).transpose() * delta_.segment(jt.row0, r);
  const BodyKin& k = kin_[body];
  const Vec3 F = g.head<3>();
  const Vec3 s = on_child ? jt.point_child : jt.point_parent;
  const Mat3& fr = on_child ? jt.frame_child : jt.frame_parent;
  // torque about the joint point: T_P = T_cm - (P - x) x F, with P - x = R s
  const Vec3 Tw = k.R * g.tail<3>() - (k.R * s).cross(F);
  const Mat3 B = k.R * fr;
  force = B.transpose() * F;
  torque = B.transpose() * Tw;
  if (!on_child) {
    force = -force;
    torque = -torque;
  }
}

}  // namespace armdyn
