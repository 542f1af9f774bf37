// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/analysis/tree_dynamics.hpp"

#include <Eigen/QR>
#include <cmath>

#include "armdyn/errors.hpp"
#include "armdyn/math/quaternion.hpp"

namespace armdyn {

TreeDynamics::TreeDynamics(const Model& m, bool ignore_drives) : m_(m), e_(m) {
  const std::string why = m.joint_path_reason(ignore_drives);
  if (!why.empty()) throw ModelError(msg("joint-space dynamics: ", why));
  e_.set_coordinate_forces(false);
  n_ = static_cast<int>(m.coords.size());
  // each coordinate's ancestors: the coordinates of its joint and of the joints towards ground
  std::vector<int> joint_of_child(m.nb, -1);
  for (size_t j = 0; j < m.joints.size(); ++j) joint_of_child[m.joints[j].child] = int(j);
  anc_.assign(n_, {});
  for (int c = 0; c < n_; ++c) {
    const int ji = m.coords[c].joint;
    for (int jj = ji; jj >= 0;) {
      const Joint& j = m.joints[jj];
      for (int k = 0; k < joint_coords(j.type); ++k) anc_[c].push_back(j.coord0 + k);
      jj = j.parent == kGround ? -1 : joint_of_child[j.parent];
    }
  }
  rne_.resize(m);
  ic_.assign(m.nb, Mat6::Zero());
  s_.assign(n_, Vec6::Zero());
  M_ = MatX::Zero(n_, n_);
  zero_ = VecX::Zero(n_);
  rhs_ = VecX::Zero(n_);
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
  }
  dof_ = n_ - rank_;
  MT_ = MatX::Zero(n_, dof_);
  Mr_ = MatX::Zero(dof_, dof_);
  y_ = VecX::Zero(dof_);
  w_ = VecX::Zero(rank_);
  llt_ = Eigen::LLT<MatX>(rank_ > 0 ? dof_ : n_);
}

std::string TreeDynamics::description() const {
  if (rank_ == 0) return msg("joint space: ", n_, " coordinates, mass matrix by CRBA, Cholesky");
  return msg("joint space: ", n_, " coordinates, ", m_.gear_constraints.size(),
             " ideal-gear rows (rank ", rank_, ") eliminated by their null space: ", dof_,
             " independent; mass matrix by CRBA, Cholesky of the reduced matrix");
}

void TreeDynamics::crba() {
  const Model& m = m_;
  const std::vector<BodyKin>& kin = e_.kin_in();
  // each body's spatial inertia about the world origin: angular momentum I_O w + h x v_O,
  // linear momentum m v_O - h x w, with h = m c
  for (int i = 0; i < m.nb; ++i) {
    const Body& b = m.bodies[i];
    const BodyKin& k = kin[i];
    const Vec3& c = k.x;
    const Mat3 Sc = skew(c);
    Mat6& I = ic_[i];
    I.topLeftCorner<3, 3>().noalias() = k.R * b.inertia * k.R.transpose();
    I.topLeftCorner<3, 3>() -= b.mass * Sc * Sc;
    I.topRightCorner<3, 3>() = b.mass * Sc;
    I.bottomLeftCorner<3, 3>() = -b.mass * Sc;
    I.bottomRightCorner<3, 3>() = b.mass * Mat3::Identity();
  }
  // composites, children first
  for (auto it = m.tree_order.rbegin(); it != m.tree_order.rend(); ++it) {
    const Joint& j = m.joints[*it];
    if (j.parent != kGround) ic_[j.parent] += ic_[j.child];
  }
  // each coordinate's motion: a turn about the axis through the joint point, or a slide (the
  // joint frames of the Newton-Euler sweep)
  for (int ji : m.tree_order) {
    const Joint& j = m.joints[ji];
    if (j.coord0 < 0) continue;
    const Vec3& z = rne_.axis[ji];
    const Vec3& p = rne_.point[ji];
    for (int k = 0; k < joint_coords(j.type); ++k) {
      Vec6& s = s_[j.coord0 + k];
      const bool slide = j.type == JointType::Prismatic || k == 1;
      if (slide) {
        s << Vec3::Zero(), z;
      } else {
        s << z, p.cross(z);
      }
    }
  }
  for (int k = 0; k < n_; ++k) {
    const Vec6 f = ic_[m.joints[m.coords[k].joint].child] * s_[k];
    for (int j : anc_[k]) M_(j, k) = M_(k, j) = s_[j].dot(f);
  }
}

const MatX& TreeDynamics::mass_matrix(const double* q) {
  const Eigen::Map<const VecX> qv(q, n_);
  std::vector<BodyKin>& kin = e_.kin_in();
  joint_space_kinematics(m_, qv, zero_, kin);
  // the sweep places the joint frames; its torques (rhs_, scratch here) are not used
  rne_residual(m_, kin, zero_, zero_, e_.eta(), rne_, rhs_);
  crba();
  return M_;
}

void TreeDynamics::accelerations(double t, const double* q, const double* qd, const double* z,
                                 const double* tau, double* qdd) {
  const Model& m = m_;
  const Eigen::Map<const VecX> qv(q, n_), qdv(qd, n_);
  std::vector<BodyKin>& kin = e_.kin_in();
  joint_space_kinematics(m, qv, qdv, kin);
  e_.forces(t);
  // rhs = Q - (b - J^T eta): the residual of the Newton-Euler equations at qdd = 0
  rne_residual(m, kin, qdv, zero_, e_.eta(), rne_, rhs_);
  rhs_ = -rhs_;
  if (tau) rhs_ += Eigen::Map<const VecX>(tau, n_);
  for (const CoordForce& cf : m.coord_forces) {
    const Coord& c = m.coords[cf.coord];
    double f;
    try {
      const double zi = (cf.aux >= 0 && z) ? z[cf.aux] : 0.0;
      f = coord_force_value(cf, c.angular, q[cf.coord], qd[cf.coord], t, zi);
    } catch (const SolverError& err) {
      throw SolverError(msg("force on joint coordinate '", c.name, "': ", err.what()));
    }
    if (!std::isfinite(f))
      throw SolverError(msg("non-finite force on joint coordinate '", c.name, "' at t=", t));
    rhs_[cf.coord] += f;
  }
  for (int gi = 0; gi < static_cast<int>(m.gears.size()); ++gi) {
    const GearPair& g = m.gears[gi];
    double s, sd, pen;
    gear_mesh(gi, q, qd, s, sd, pen);
    const double f = gear_force(g, s, sd, pen);
    if (f == 0.0) continue;
    const double fs = s >= 0 ? f : -f;
    rhs_[g.coord_a] -= g.r_a * fs;
    rhs_[g.coord_b] -= g.r_b * fs;
  }
  if (!rhs_.allFinite()) {
    for (int c = 0; c < n_; ++c)
      if (!std::isfinite(rhs_[c]))
        throw SolverError(msg("non-finite generalised force on joint coordinate '",
                              m.coords[c].name, "' at t=", t));
  }
  crba();
  Eigen::Map<VecX> out(qdd, n_);
  if (rank_ == 0) {
    llt_.compute(M_);
  } else {
    MT_.noalias() = M_ * T_;
    Mr_.noalias() = T_.transpose() * MT_;
    llt_.compute(Mr_);
  }
  if (llt_.info() != Eigen::Success)
    throw SolverError(msg("joint-space dynamics: the mass matrix is not positive definite at t=", t,
                          " (a massless subtree?)"));
  if (rank_ == 0) {
    out = rhs_;
    llt_.solveInPlace(out);
  } else {
    y_.noalias() = T_.transpose() * rhs_;
    llt_.solveInPlace(y_);
    out.noalias() = T_ * y_;
  }
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
  const GearPair& g = m_.gears[gi];
  s = g.r_a * q[g.coord_a] + g.r_b * q[g.coord_b];
  sd = g.r_a * qd[g.coord_a] + g.r_b * qd[g.coord_b];
  penetration = std::abs(s) - 0.5 * g.backlash;
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
