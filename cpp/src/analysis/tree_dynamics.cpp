// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/analysis/tree_dynamics.hpp"

#include <Eigen/QR>
#include <cmath>

#include "armdyn/algorithm/crba.hpp"
#include "armdyn/algorithm/dynamics.hpp"
#include "armdyn/algorithm/forces.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/math/cholesky.hpp"

namespace armdyn {

namespace {
[[noreturn]] void not_positive_definite(double t) {
  throw SolverError(msg("joint-space dynamics: the mass matrix is not positive definite at t=", t,
                        " (a massless subtree?)"));
}
}  // namespace

TreeDynamics::TreeDynamics(const Model& m, bool ignore_drives) : m_(m), d_(m) {
  const std::string why = m.joint_path_reason(ignore_drives);
  if (!why.empty()) throw ModelError(msg("joint-space dynamics: ", why));
  n_ = d_.n;
  // the ideal gears' rows and an orthonormal basis of their null space
  const int ng = static_cast<int>(m.gear_constraints.size());
  if (ng > 0) {
    MatX Gt = MatX::Zero(n_, ng);
    for (int g = 0; g < ng; ++g) {
      Gt(m.gear_constraints[g].coord_a, g) += m.gear_constraints[g].r_a;
      Gt(m.gear_constraints[g].coord_b, g) += m.gear_constraints[g].r_b;
    }
    Eigen::ColPivHouseholderQR<MatX> qr(Gt);
    qr.setThreshold(1e-12);
    rank_ = static_cast<int>(qr.rank());
    const MatX Q = qr.householderQ() * MatX::Identity(n_, n_);
    range_ = Q.leftCols(rank_);
    T_ = Q.rightCols(n_ - rank_);
    Eigen::CompleteOrthogonalDecomposition<MatX> cod(Gt);
    cod.setThreshold(1e-12);
    Gt_pinv_ = cod.pseudoInverse();
  }
  res_ = VecX::Zero(n_);
  gear_delta_ = VecX::Zero(ng);
  dof_ = n_ - rank_;
  MT_ = MatX::Zero(n_, dof_);
  Mr_ = MatX::Zero(dof_, dof_);
  y_ = VecX::Zero(dof_);
  w_ = VecX::Zero(rank_);
  Lr_ = MatX::Zero(dof_, dof_);
}

std::string TreeDynamics::description() const {
  if (rank_ == 0) return msg("joint space: ", n_, " coordinates, mass matrix by CRBA, Cholesky");
  return msg("joint space: ", n_, " coordinates, ", m_.gear_constraints.size(),
             " ideal-gear rows (rank ", rank_, ") eliminated by their null space: ", dof_,
             " independent; mass matrix by CRBA, Cholesky of the reduced matrix");
}

const MatX& TreeDynamics::mass_matrix(const double* q) {
  return mass_matrix_at(m_, d_, Eigen::Map<const VecX>(q, n_));
}

void TreeDynamics::accelerations(double t, const double* q, const double* qd, const double* z,
                                 const double* tau, double* qdd) {
  joint_space_equations(m_, d_, q, qd, z, tau, t);
  const VecX& rhs = d_.rhs;
  const MatX& M = d_.M;
  Eigen::Map<VecX> out(qdd, n_);
  if (rank_ == 0) {
    if (!cholesky_factor(M, d_.L)) not_positive_definite(t);
    out = rhs;
    cholesky_solve(d_.L, out);
  } else {
    MT_.noalias() = M * T_;
    Mr_.noalias() = T_.transpose() * MT_;
    if (!cholesky_factor(Mr_, Lr_)) not_positive_definite(t);
    y_.noalias() = T_.transpose() * rhs;
    cholesky_solve(Lr_, y_);
    out.noalias() = T_ * y_;
  }
}

const VecX& TreeDynamics::gear_multipliers(const double* qdd) {
  if (gear_delta_.size() == 0) return gear_delta_;
  res_ = d_.rhs;
  res_.noalias() -= d_.M * Eigen::Map<const VecX>(qdd, n_);
  gear_delta_.noalias() = Gt_pinv_ * res_;
  return gear_delta_;
}

void TreeDynamics::aux_rates(double t, const double* q, const double* qd, const double* z,
                             double* zdot) const {
  for (const CoordForce& cf : m_.coord_forces) {
    if (cf.aux < 0) continue;
    coord_force_value(cf, m_.coords[cf.coord].angular, q[cf.coord], qd[cf.coord], t,
                      z ? z[cf.aux] : 0.0, &zdot[cf.aux]);
  }
}

void TreeDynamics::gear_mesh(int gi, const double* q, const double* qd, double& s, double& sd,
                             double& penetration) const {
  armdyn::gear_mesh(m_, gi, q, qd, s, sd, penetration);
}

void TreeDynamics::project(double* q, double* qd) {
  if (rank_ == 0) return;
  for (double* x : {q, qd}) {
    Eigen::Map<VecX> xv(x, n_);
    w_.noalias() = range_.transpose() * xv;
    xv.noalias() -= range_ * w_;
  }
}

}  // namespace armdyn
