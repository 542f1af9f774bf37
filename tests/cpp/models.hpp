// SPDX-License-Identifier: BSD-3-Clause
// Small models with closed-form dynamics, shared by the C++ tests.
#pragma once

#include <armdyn/armdyn.hpp>
#include <cmath>
#include <string>

namespace armdyn_test {

using namespace armdyn;

inline const Vec4 kIdentityQuat(1.0, 0.0, 0.0, 0.0);
inline const char* kDataDir = ARMDYN_TEST_DATA;

/// Physical pendulum: a body of mass m (inertia diag(ixx, iyy, izz) about its centre of mass)
/// hinged to ground at the origin about +y, its centre of mass at distance L. phi0 is the angle
/// of the assembly pose: the centre of mass sits at R_y(phi0) (0, 0, -L) = (-L sin phi0, 0,
/// -L cos phi0), so that with phi = phi0 + q and I_O = iyy + m L^2:
///   I_O phi'' = -m g L sin(phi).
struct Pendulum {
  double m = 1.5, L = 0.8, g = 9.81, phi0 = 0.0;
  double ixx = 0.02, iyy = 0.03, izz = 0.04;
  double io() const { return iyy + m * L * L; }
  /// phi'' at phi (no joint torque)
  double phidd(double phi) const { return -m * g * L * std::sin(phi) / io(); }
  ModelBuilder builder() const {
    ModelBuilder b(Vec3(0, 0, -g));
    b.add_body("bob", m, Vec3(ixx, iyy, izz).asDiagonal(),
               Vec3(-L * std::sin(phi0), 0.0, -L * std::cos(phi0)), kIdentityQuat);
    b.add_revolute("hinge", "ground", "bob", Vec3::Zero(), Vec3::UnitY());
    return b;
  }
  ModelPtr model() const { return builder().finalize(); }
};

/// Planar two-link arm in the x-z plane, both hinges about +y; at q = 0 both links lie along
/// +x (hinge 1 at the origin, hinge 2 at (l1, 0, 0)), centres of mass at lc1 and l1 + lc2.
/// Link i's axis is R_y(q1 [+ q2]) x = (cos, 0, -sin), so its height is -(...) sin(...).
struct TwoLink {
  double m1 = 2.0, m2 = 1.2, l1 = 0.7, lc1 = 0.35, lc2 = 0.3, g = 9.81;
  double i1 = 0.09, i2 = 0.04;  ///< inertias about the hinge axis (y) at the centres of mass
  ModelBuilder builder() const {
    ModelBuilder b(Vec3(0, 0, -g));
    // the x and z inertias differ from y's: they must not enter the planar motion
    b.add_body("link1", m1, Vec3(0.02, i1, 0.1).asDiagonal(), Vec3(lc1, 0, 0), kIdentityQuat);
    b.add_body("link2", m2, Vec3(0.03, i2, 0.05).asDiagonal(), Vec3(l1 + lc2, 0, 0), kIdentityQuat);
    b.add_revolute("shoulder", "ground", "link1", Vec3::Zero(), Vec3::UnitY());
    b.add_revolute("elbow", "link1", "link2", Vec3(l1, 0, 0), Vec3::UnitY());
    return b;
  }
  ModelPtr model() const { return builder().finalize(); }
  /// M(q) by hand (Spong, Robot Modeling and Control, 7.4.2).
  Eigen::Matrix2d mass_matrix(double q2) const {
    const double c2 = std::cos(q2);
    Eigen::Matrix2d M;
    M(0, 0) = i1 + i2 + m1 * lc1 * lc1 + m2 * (l1 * l1 + lc2 * lc2 + 2 * l1 * lc2 * c2);
    M(0, 1) = M(1, 0) = i2 + m2 * (lc2 * lc2 + l1 * lc2 * c2);
    M(1, 1) = i2 + m2 * lc2 * lc2;
    return M;
  }
  /// tau = M qdd + C(q, qd) qd + G(q): heights z1 = -lc1 sin q1, z2 = -l1 sin q1 - lc2 sin(q1+q2)
  Eigen::Vector2d torques(const Eigen::Vector2d& q, const Eigen::Vector2d& qd,
                          const Eigen::Vector2d& qdd) const {
    const double h = -m2 * l1 * lc2 * std::sin(q[1]);
    Eigen::Vector2d c(h * qd[1] * qd[1] + 2 * h * qd[0] * qd[1], -h * qd[0] * qd[0]);
    const double c1 = std::cos(q[0]), c12 = std::cos(q[0] + q[1]);
    Eigen::Vector2d grav(-m1 * g * lc1 * c1 - m2 * g * (l1 * c1 + lc2 * c12), -m2 * g * lc2 * c12);
    return mass_matrix(q[1]) * qdd + c + grav;
  }
};

/// A spatial three-link arm with a prismatic joint and general (rotated, off-diagonal)
/// inertias: for cross-checks between independent algorithms.
/// A planar four-bar about y: crank and rocker on ground, closed at C by an inline joint (no
/// redundant rows) or, with revolute_closure, by a revolute (3 of its rows redundant).
inline ModelBuilder four_bar_builder(bool revolute_closure = false) {
  ModelBuilder b;
  const Mat3 in = Vec3(0.01, 0.02, 0.015).asDiagonal();
  b.add_body("crank", 1.0, in, Vec3(0, 0, 0.25), kIdentityQuat);
  b.add_body("coupler", 2.0, in, Vec3(0.5, 0, 0.5), kIdentityQuat);
  b.add_body("rocker", 1.5, in, Vec3(1.0, 0, 0.3), kIdentityQuat);
  b.add_revolute("A", "ground", "crank", Vec3(0, 0, 0), Vec3::UnitY());
  b.add_revolute("B", "crank", "coupler", Vec3(0, 0, 0.5), Vec3::UnitY());
  b.add_revolute("D", "ground", "rocker", Vec3(1, 0, 0.1), Vec3::UnitY());
  if (revolute_closure)
    b.add_revolute("C", "rocker", "coupler", Vec3(1, 0, 0.5), Vec3::UnitY());
  else
    b.add_inline("C", "rocker", "coupler", Vec3(1, 0, 0.5), Vec3::UnitY());
  return b;
}

inline ModelBuilder spatial_arm_builder() {
  ModelBuilder b(Vec3(0.3, -0.2, -9.81));
  Mat3 i1;
  i1 << 0.05, 0.004, -0.002, 0.004, 0.06, 0.003, -0.002, 0.003, 0.03;
  Mat3 i2;
  i2 << 0.02, -0.001, 0.0015, -0.001, 0.025, 0.002, 0.0015, 0.002, 0.01;
  const Vec4 e1 = quat_exp(Vec3(0.1, -0.3, 0.2));
  const Vec4 e2 = quat_exp(Vec3(-0.4, 0.2, 0.5));
  b.add_body("base", 3.0, i1, Vec3(0.0, 0.02, 0.2), e1);
  b.add_body("upper", 2.0, i2, Vec3(0.2, 0.05, 0.45), e2);
  b.add_body("slide", 0.8, 0.5 * i2, Vec3(0.45, 0.1, 0.5), kIdentityQuat);
  b.add_body("wrist", 0.5, 0.3 * i1, Vec3(0.55, 0.12, 0.45), e1);
  b.add_revolute("yaw", "ground", "base", Vec3(0, 0, 0.1), Vec3(0, 0, 1));
  b.add_revolute("pitch", "base", "upper", Vec3(0.0, 0.03, 0.4), Vec3(0.1, 1, 0).normalized());
  b.add_prismatic("reach", "upper", "slide", Vec3(0.4, 0.08, 0.5), Vec3(1, 0.1, 0).normalized());
  b.add_revolute("roll", "slide", "wrist", Vec3(0.5, 0.1, 0.48), Vec3(1, 0, -0.2).normalized());
  return b;
}

/// The Cartesian accelerations vdot of a joint-space tree moving with (q, qd, qdd), by central
/// differences of v along q(t) = q + qd t + qdd t^2 / 2 (error O(h^2)); v's angular part is in
/// the body frame, so its derivative is the body-frame angular acceleration.
inline VecX cartesian_acceleration_fd(const Model& m, const VecX& q, const VecX& qd,
                                      const VecX& qdd, double h = 1e-5) {
  VecX u, vp, vm;
  state_from_joints(m, q + h * qd + 0.5 * h * h * qdd, qd + h * qdd, u, vp);
  state_from_joints(m, q - h * qd + 0.5 * h * h * qdd, qd - h * qdd, u, vm);
  return (vp - vm) / (2 * h);
}

/// Move u along velocity v for a time h: x + h xd, e (x) exp(h w) (w in the body frame).
inline VecX advance(const Model& m, const VecX& u, const VecX& v, double h) {
  VecX out = u;
  for (int b = 0; b < m.nb; ++b) {
    out.segment<3>(7 * b) += h * v.segment<3>(6 * b);
    out.segment<4>(7 * b + 3) =
        quat_mul(u.segment<4>(7 * b + 3), quat_exp(h * v.segment<3>(6 * b + 3)));
  }
  return out;
}

}  // namespace armdyn_test

namespace armdyn_test {

/// Gamma = diag(m_i I, J_i) (velocities: centre-of-mass velocity in world, angular in body).
inline MatX body_mass_matrix(const Model& m) {
  MatX g = MatX::Zero(m.nv, m.nv);
  for (int i = 0; i < m.nb; ++i) {
    g.block<3, 3>(6 * i, 6 * i) = m.bodies[i].mass * Mat3::Identity();
    g.block<3, 3>(6 * i + 3, 6 * i + 3) = m.bodies[i].inertia;
  }
  return g;
}

/// vdot and delta of the KKT system [Gamma zeta^T; zeta 0] [vdot; delta] = [eta; -xi] by a dense
/// full-pivoting LU over the first nrows rows: the reference for the structured solvers.
inline void dense_kkt(const Model& m, const ConstraintEval& ce, const VecX& eta, int nrows,
                      VecX& vdot, VecX& delta) {
  const MatX z = dense_zeta(m, ce).topRows(nrows);
  MatX k = MatX::Zero(m.nv + nrows, m.nv + nrows);
  k.topLeftCorner(m.nv, m.nv) = body_mass_matrix(m);
  k.topRightCorner(m.nv, nrows) = z.transpose();
  k.bottomLeftCorner(nrows, m.nv) = z;
  VecX rhs(m.nv + nrows);
  rhs << eta, -ce.xi.head(nrows);
  const VecX x = k.fullPivLu().solve(rhs);
  vdot = x.head(m.nv);
  delta = x.tail(nrows);
}

}  // namespace armdyn_test
