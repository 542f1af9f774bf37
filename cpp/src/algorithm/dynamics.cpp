// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/dynamics.hpp"

#include <cmath>

#include "armdyn/algorithm/aba.hpp"
#include "armdyn/algorithm/cost_model.hpp"
#include "armdyn/algorithm/crba.hpp"
#include "armdyn/algorithm/forces.hpp"
#include "armdyn/algorithm/kinematics.hpp"
#include "armdyn/algorithm/kkt.hpp"
#include "armdyn/algorithm/loop_coordinates.hpp"
#include "armdyn/algorithm/rnea.hpp"
#include "armdyn/algorithm/tree_dynamics.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/math/cholesky.hpp"

namespace armdyn {

namespace {

void check_inputs(const Model& m, const Data& d, Eigen::Ref<const VecX> q,
                  Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> x, double t, const char* fn,
                  const char* xname) {
  require_joint_space(m, fn, true);
  check_data(m, d, fn);
  check_joint_vector(q, d.niq, fn, "q");
  check_joint_vector(qd, d.ni, fn, "qd");
  check_joint_vector(x, d.ni, fn, xname);
  if (!std::isfinite(t)) throw ModelError(msg(fn, ": t is not finite"));
  check_base_quaternions(m, q, fn);
}

void refuse_floating_cartesian(const Model& m, const char* fn) {
  if (m.n_free)
    throw ModelError(msg(fn,
                         ": method 'cartesian' takes fixed-base models only (this one has a "
                         "floating base); use 'auto' or 'joint'"));
}

// forward dynamics of a coupled model in its independent coordinates: the Cartesian KKT path
// with the couplings' rows (the torques on the independent coordinates, none on the followers:
// G^T tau_full = tau), or the joint-space equations reduced by G (M_r = G^T M G)
const VecX& forward_coupled(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                            Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> tau, double t,
                            DynamicsMethod method);

// forward dynamics through the Cartesian KKT system, the joint torques as loads: the joint rows
// only, the coordinate forces mapped onto the bodies
void forward_cartesian(const Model& m, Data& d, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                       Eigen::Ref<const VecX> tau, double t) {
  // the call's settings, restored to the defaults on every exit (errors included)
  struct Settings {
    Data& d;
    ~Settings() {
      d.joint_torques = d.joint_q = d.joint_qd = nullptr;
      d.nrows = d.model->nc;
      d.multipliers = true;
    }
  } restore{d};
  d.nrows = m.nc_joint;
  d.multipliers = false;  // the accelerations only
  d.aux = nullptr;
  d.augmented = false;  // each call decides afresh: the result never depends on earlier calls
  d.with_coordinate_forces = true;
  d.joint_torques = d.tau_in.data();
  // the coordinate forces read the call's q and qd (the loaded state's coordinates)
  d.joint_q = q.data();
  d.joint_qd = qd.data();
  load_joint_kinematics(m, d, q, qd);
  d.tau_in = tau;
  body_accelerations_loaded(m, d, t, d.vd.data());
  // the coordinate jets of the torques, at this state; the floating bases' from their bodies
  for (int c = 0; c < d.nco; ++c)
    d.qdd[6 * m.n_free + c] = coord_acceleration(m, d.tau_jets[c], c, d.vd);
  if (m.n_free) base_accelerations(m, d.kin, d.vd.data(), d.qdd.data());
}

// inverse dynamics through the KKT system with every independent joint coordinate driven to
// (q, qd, qdd) (a coupled model: its followers through the couplings' rows); q and qd the full
// coordinates, qdd the independent ones; the torques into tau (independent)
void inverse_cartesian(const Model& m, Data& d, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                       Eigen::Ref<const VecX> qdd, double t, VecX& tau) {
  const int n = d.ni;
  const IndependentCoords& ic = m.independent;
  if (!d.driven_data) {
    auto driven = std::make_unique<Model>(m);
    driven->drives.clear();
    driven->drive_index.clear();
    for (int k = 0; k < n; ++k) {
      const int c = ic.full[k];
      Drive dr;
      dr.name = driven->coords[c].name;
      dr.joint = driven->coords[c].joint;
      dr.coord = driven->coords[c].sub;
      dr.profile = Profile::constant(0.0);
      dr.row = driven->nc_joint + k;
      driven->drive_index[dr.name] = k;
      driven->drives.push_back(dr);
    }
    driven->nc = driven->nc_joint + n;
    driven->rank_all = driven->rank_joint + n;
    driven->mobility_driven = driven->mobility - n;
    driven->redundant = false;
    driven->redundant_rows.clear();
    // (the copy plans its KKT factorisation afresh, for the new drive rows: kkt_plans)
    d.driven = std::move(driven);
    d.driven_data = std::make_unique<Data>(*d.driven);
    d.drive_ref = VecX::Zero(3 * n);
    d.driven_data->ce.drive_ref = d.drive_ref.data();
    // the state is built on the manifold from (q, qd): only zeta, rhs and xi are wanted
    d.driven_data->ce.drive_values = false;
  }
  Data& dd = *d.driven_data;
  dd.augmented = false;  // each call decides afresh
  load_joint_kinematics(m, dd, q, qd);
  for (int k = 0; k < n; ++k) {
    d.drive_ref[3 * k] = q[ic.full[k]];
    d.drive_ref[3 * k + 1] = qd[ic.full[k]];
    d.drive_ref[3 * k + 2] = qdd[k];
  }
  // square zeta: the O(n) tree sweep (KKT factorisation only when singular)
  body_accelerations_loaded(*d.driven, dd, t, d.vd.data());
  for (int k = 0; k < n; ++k) tau[k] = -dd.delta[d.driven->nc_joint + k];
}

const VecX& forward_coupled(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                            Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> tau, double t,
                            DynamicsMethod method) {
  constexpr const char* fn = "forward_dynamics";
  const IndependentCoords& ic = m.independent;
  Data::Coupled& w = d.coupled;
  // CRBA about the world origin loses light bodies' accelerations (geared_light_reason); the
  // articulated-body algorithm has no place for the couplings' rows
  const bool light = dynamics_cost(m).light;
  if (method == DynamicsMethod::Aba)
    throw ModelError(msg(fn,
                         ": method 'aba' does not apply to a model with couplings (the "
                         "articulated-body recursion has no place for their rows); use 'crba' or "
                         "'cartesian'"));
  if (method == DynamicsMethod::Auto)
    method = light ? DynamicsMethod::Cartesian : DynamicsMethod::Crba;
  if (method != DynamicsMethod::Cartesian && light)
    throw ModelError(msg(fn, ": ", geared_light_reason(m)));
  ic.expand_q(q.data(), w.q.data());
  ic.expand_v(qd.data(), w.qd.data());
  if (method == DynamicsMethod::Cartesian) {
    // the floating bases' entries as they are, the followers' torques zero
    const int lead = ic.lead_v;
    w.tau_full.setZero();
    w.tau_full.head(lead) = tau.head(lead);
    for (int k = 0; k < ic.n; ++k) w.tau_full[lead + ic.full[k]] = tau[lead + k];
    forward_cartesian(m, d, w.q, w.qd, w.tau_full, t);
    w.qdd_out.head(lead) = d.qdd.head(lead);
    for (int k = 0; k < ic.n; ++k) w.qdd_out[lead + k] = d.qdd[lead + ic.full[k]];
    return w.qdd_out;
  }
  joint_space_equations(m, d, w.q.data(), w.qd.data(), nullptr, nullptr, t);
  ic.reduce(d.rhs.data(), w.rhs.data());
  w.rhs += tau;
  ic.reduce(d.M, w.M);
  if (!cholesky_factor(w.M, w.L))
    throw SolverError(
        "forward_dynamics: the joint-space mass matrix (in the independent coordinates) is not "
        "positive definite (a massless subtree?)");
  w.qdd_out = w.rhs;
  cholesky_solve(w.L, w.qdd_out);
  return w.qdd_out;
}

}  // namespace

void joint_space_equations(const Model& m, Data& d, const double* q, const double* qd,
                           const double* z, const double* tau, double t) {
  const Eigen::Map<const VecX> qv(q, d.nq), qdv(qd, d.n);
  joint_space_kinematics(m, qv, qdv, d.kin, d.rne);
  body_forces(m, d.kin, t, d.eta);
  // rhs = tau + Q - (b - J^T eta): the residual of the Newton-Euler equations at qdd = 0
  VecX& rhs = d.rhs;
  rne_residual(m, d.kin, qdv, d.zero, d.eta, d.rne, rhs);
  rhs = -rhs;
  if (tau) rhs += Eigen::Map<const VecX>(tau, d.n);
  if (!m.coord_forces.empty() || !m.gears.empty()) {
    coordinate_forces(m, q + 7 * m.n_free, qd + 6 * m.n_free, z, t, d.coord_tau);
    rhs.tail(d.nco) += d.coord_tau;
  }
  if (!rhs.allFinite()) {
    for (int c = 0; c < d.n; ++c)
      if (!std::isfinite(rhs[c]))
        throw SolverError(msg("non-finite generalised force on joint coordinate '", m.dof_names[c],
                              "' at t=", t));
  }
  crba_loaded(m, d);
}

DynamicsMethod dynamics_method(const std::string& name, const char* fn, bool forward) {
  if (name == "auto") return DynamicsMethod::Auto;
  if (name == "joint") return DynamicsMethod::Joint;
  if (name == "cartesian") return DynamicsMethod::Cartesian;
  if (forward && name == "crba") return DynamicsMethod::Crba;
  if (forward && name == "aba") return DynamicsMethod::Aba;
  throw ModelError(msg(fn,
                       forward
                           ? ": method must be 'auto', 'joint', 'crba', 'aba' or 'cartesian', got '"
                           : ": method must be 'auto', 'joint' or 'cartesian', got '",
                       name, "'"));
}

const VecX& forward_dynamics(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                             Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> tau, double t,
                             DynamicsMethod method) {
  if (m.loop_coordinates) return loop_forward_dynamics(m, d, q, qd, tau, t, method);
  check_inputs(m, d, q, qd, tau, t, "forward_dynamics", "tau");
  if (d.ni != d.n) return forward_coupled(m, d, q, qd, tau, t, method);
  switch (resolve_method(m, method)) {
    case DynamicsMethod::Cartesian:
      forward_cartesian(m, d, q, qd, tau, t);
      return d.qdd;
    case DynamicsMethod::Aba:
      aba_accelerations(m, d, q.data(), qd.data(), nullptr, tau.data(), t, d.qdd.data());
      return d.qdd;
    default:
      break;
  }
  joint_space_equations(m, d, q.data(), qd.data(), nullptr, tau.data(), t);
  if (!cholesky_factor(d.M, d.L))
    throw SolverError(
        "forward_dynamics: the joint-space mass matrix is not positive definite (a massless "
        "subtree?)");
  d.qdd = d.rhs;
  cholesky_solve(d.L, d.qdd);
  return d.qdd;
}

const VecX& inverse_dynamics(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                             Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> qdd, double t,
                             DynamicsMethod method) {
  if (m.loop_coordinates) return loop_inverse_dynamics(m, d, q, qd, qdd, t, method);
  if (method != DynamicsMethod::Cartesian) return rnea(m, d, q, qd, qdd, t);
  check_inputs(m, d, q, qd, qdd, t, "inverse_dynamics", "qdd");
  refuse_floating_cartesian(m, "inverse_dynamics");
  if (d.ni == d.n) {
    inverse_cartesian(m, d, q, qd, qdd, t, d.tau);
    return d.tau;
  }
  Data::Coupled& w = d.coupled;
  m.independent.expand_q(q.data(), w.q.data());
  m.independent.expand_v(qd.data(), w.qd.data());
  inverse_cartesian(m, d, w.q, w.qd, qdd, t, w.tau);
  return w.tau;
}

}  // namespace armdyn
