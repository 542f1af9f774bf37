// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/tree_dynamics.hpp"

#include <Eigen/QR>
#include <cmath>

#include "armdyn/algorithm/aba.hpp"
#include "armdyn/algorithm/cost_model.hpp"
#include "armdyn/algorithm/crba.hpp"
#include "armdyn/algorithm/dynamics.hpp"
#include "armdyn/algorithm/forces.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/kernels/joint_space.hpp"
#include "armdyn/kernels/kkt_factor.hpp"
#include "armdyn/math/cholesky.hpp"

namespace armdyn {

namespace {
[[noreturn]] void not_positive_definite(double t) {
  throw SolverError(msg("joint-space dynamics: the mass matrix is not positive definite at t=", t,
                        " (a massless subtree?)"));
}
}  // namespace

std::string geared_light_reason(const Model& m) {
  if (m.gear_constraints.empty()) return {};
  const LightBodies& light = light_bodies(m);
  if (light.joint_space.empty()) return {};
  return msg(
      "with ideal gears the joint-space path needs the mass matrix (CRBA about the world "
      "origin), which loses the accelerations of light bodies: ",
      light.joint_space_note,
      " (the Cartesian path solves them in augmented form: coordinates 'cartesian')");
}

const GearSpace& gear_space(const Model& m) {
  return m.derived.get<GearSpace>([&] {
    GearSpace gs;
    // over the joint-space degrees of freedom (the floating bases' first: no gear rows there)
    const int n = m.nv_joint, off = 6 * m.n_free;
    const int ng = static_cast<int>(m.gear_constraints.size());
    if (ng == 0) return gs;
    MatX Gt = MatX::Zero(n, ng);
    for (int g = 0; g < ng; ++g) {
      Gt(off + m.gear_constraints[g].coord_a, g) += m.gear_constraints[g].r_a;
      Gt(off + m.gear_constraints[g].coord_b, g) += m.gear_constraints[g].r_b;
    }
    Eigen::ColPivHouseholderQR<MatX> qr(Gt);
    qr.setThreshold(1e-12);
    gs.rank = static_cast<int>(qr.rank());
    const MatX Q = qr.householderQ() * MatX::Identity(n, n);
    gs.range = Q.leftCols(gs.rank);
    gs.T = Q.rightCols(n - gs.rank);
    Eigen::CompleteOrthogonalDecomposition<MatX> cod(Gt);
    cod.setThreshold(1e-12);
    gs.Gt_pinv = cod.pseudoInverse();
    // a solution of G q = offsets (the least-norm one), seen in the range basis
    VecX offsets(ng);
    for (int g = 0; g < ng; ++g) offsets[g] = m.gear_constraints[g].offset;
    gs.range_value = gs.range.transpose() * (gs.Gt_pinv.transpose() * offsets);
    return gs;
  });
}

TreeDynamics::TreeDynamics(const Model& m, bool ignore_drives)
    : own_(std::make_unique<Data>(m)), m_(m), d_(*own_), gs_(gear_space(m)) {
  init(ignore_drives);
}

TreeDynamics::TreeDynamics(const Model& m, Data& d, bool ignore_drives)
    : m_(m), d_(d), gs_(gear_space(m)) {
  check_data(m, d, "joint-space dynamics");
  init(ignore_drives);
}

void TreeDynamics::init(bool ignore_drives) {
  const std::string why = m_.joint_path_reason(ignore_drives);
  if (!why.empty()) throw ModelError(msg("joint-space dynamics: ", why));
  if (const std::string light = geared_light_reason(m_); !light.empty())
    throw ModelError(msg("joint-space dynamics: ", light));
  n_ = d_.n;
  rank_ = gs_.rank;
  dof_ = n_ - rank_;
  // without ideal gears, the cheaper of CRBA + Cholesky and the articulated-body algorithm by
  // the measured cost model; with them, the null-space reduction needs the mass matrix
  aba_ = m_.gear_constraints.empty() && dynamics_cost(m_).joint == DynamicsMethod::Aba;
  // the reduced system's scratch (with gears), in the Data
  Data::TreeScratch& w = d_.tree;
  auto size = [](MatX& x, long r, long c) {
    if (x.rows() != r || x.cols() != c) x = MatX::Zero(r, c);
  };
  auto sizev = [](VecX& x, long r) {
    if (x.size() != r) x = VecX::Zero(r);
  };
  size(w.MT, n_, dof_);
  size(w.Mr, dof_, dof_);
  size(w.Lr, dof_, dof_);
  sizev(w.y, dof_);
  sizev(w.w, rank_);
  sizev(w.res, n_);
  sizev(w.gear_delta, static_cast<long>(m_.gear_constraints.size()));
}

std::string TreeDynamics::description() const {
  if (m_.gear_constraints.empty()) {
    const DynamicsCost& c = dynamics_cost(m_);
    return msg("joint space: ", n_, " coordinates, ",
               aba_ ? "articulated-body algorithm" : "mass matrix by CRBA, Cholesky", " (",
               c.forward_summary(), ")");
  }
  bool couplings = false;
  for (const GearConstraint& g : m_.gear_constraints) couplings = couplings || g.coupling;
  return msg("joint space: ", n_, " coordinates, ", m_.gear_constraints.size(),
             couplings ? " ideal-gear and coupling rows (rank " : " ideal-gear rows (rank ", rank_,
             ") eliminated by their null space: ", dof_,
             " independent; mass matrix by CRBA, Cholesky of the reduced matrix");
}

const MatX& TreeDynamics::mass_matrix(const double* q) {
  return mass_matrix_at(m_, d_, Eigen::Map<const VecX>(q, d_.nq));
}

void TreeDynamics::accelerations(double t, const double* q, const double* qd, const double* z,
                                 const double* tau, double* qdd) {
  if (aba_) {
    aba_accelerations(m_, d_, q, qd, z, tau, t, qdd);
    return;
  }
  joint_space_equations(m_, d_, q, qd, z, tau, t);
  const VecX& rhs = d_.rhs;
  const MatX& M = d_.M;
  Eigen::Map<VecX> out(qdd, n_);
  if (rank_ == 0) {
    if (!cholesky_factor(M, d_.L)) not_positive_definite(t);
    out = rhs;
    cholesky_solve(d_.L, out);
  } else {
    Data::TreeScratch& w = d_.tree;
    w.MT.noalias() = M * gs_.T;
    w.Mr.noalias() = gs_.T.transpose() * w.MT;
    if (!cholesky_factor(w.Mr, w.Lr)) not_positive_definite(t);
    w.y.noalias() = gs_.T.transpose() * rhs;
    cholesky_solve(w.Lr, w.y);
    out.noalias() = gs_.T * w.y;
  }
}

const VecX& TreeDynamics::gear_multipliers(const double* qdd) {
  Data::TreeScratch& w = d_.tree;
  if (w.gear_delta.size() == 0) return w.gear_delta;
  w.res = d_.rhs;
  w.res.noalias() -= d_.M * Eigen::Map<const VecX>(qdd, n_);
  w.gear_delta.noalias() = gs_.Gt_pinv * w.res;
  return w.gear_delta;
}

void TreeDynamics::aux_rates(double t, const double* q, const double* qd, const double* z,
                             double* zdot) const {
  // the coordinates follow the floating bases' blocks
  const double* qc = q + 7 * m_.n_free;
  const double* qdc = qd + 6 * m_.n_free;
  for (const CoordForce& cf : m_.coord_forces) {
    if (cf.aux < 0) continue;
    coord_force_value(cf, m_.coords[cf.coord].angular, qc[cf.coord], qdc[cf.coord], t,
                      z ? z[cf.aux] : 0.0, &zdot[cf.aux]);
  }
}

void TreeDynamics::gear_mesh(int gi, const double* q, const double* qd, double& s, double& sd,
                             double& penetration) const {
  armdyn::gear_mesh(m_, gi, q + 7 * m_.n_free, qd + 6 * m_.n_free, s, sd, penetration);
}

void TreeDynamics::project(double* q, double* qd) {
  normalize_bases(m_, q);
  if (rank_ == 0) return;
  VecX& w = d_.tree.w;
  // the gear rows touch the coordinates only (the bases' rows of range are zero); the
  // couplings' offsets on the positions
  const int nb = 6 * m_.n_free, nc = n_ - nb;
  double* qc = q + 7 * m_.n_free;
  for (double* x : {qc, qd + nb}) {
    Eigen::Map<VecX> xv(x, nc);
    w.noalias() = gs_.range.bottomRows(nc).transpose() * xv;
    if (x == qc) w -= gs_.range_value;
    xv.noalias() -= gs_.range.bottomRows(nc) * w;
  }
}

void checked_accelerations(TreeDynamics& td, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                           Eigen::Ref<const VecX> tau, double t, double* qdd) {
  const Model& m = td.model();
  const long n = td.n(), nq = m.nq_joint;
  check_joint_vector(q, nq, "TreeDynamics", "q");
  check_base_quaternions(m, q, "TreeDynamics");
  check_joint_vector(qd, n, "TreeDynamics", "qd");
  check_joint_vector(tau, n, "TreeDynamics", "tau");
  if (!std::isfinite(t)) throw ModelError("TreeDynamics: t is not finite");
  if (m.n_aux)
    throw ModelError(
        "TreeDynamics: the model's PI motors have integral states; simulate() integrates them");
  td.accelerations(t, q.data(), qd.data(), nullptr, tau.data(), qdd);
}

const MatX& checked_mass_matrix(TreeDynamics& td, Eigen::Ref<const VecX> q) {
  const Model& m = td.model();
  check_joint_vector(q, m.nq_joint, "TreeDynamics.mass_matrix", "q");
  check_base_quaternions(m, q, "TreeDynamics.mass_matrix");
  return td.mass_matrix(q.data());
}

}  // namespace armdyn
