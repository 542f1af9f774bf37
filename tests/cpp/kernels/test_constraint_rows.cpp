// SPDX-License-Identifier: BSD-3-Clause
// Constraint assembly (armdyn/kernels/constraint_rows.hpp): f, zeta and xi against the motion of
// the joint-space state and against finite differences of f, on a spatial tree and a closed loop.
#include <cmath>

#include "armdyn/kernels/constraint_rows.hpp"
#include "armdyn/kernels/joint_space.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

namespace {

/// f, zeta, rhs and xi at (u, v, t).
ConstraintEval evaluate(const Model& m, const VecX& u, const VecX& v, double t) {
  std::vector<BodyKin> kin(m.nb);
  body_kinematics(m, u.data(), v.data(), kin);
  ConstraintEval ce;
  ce.init(m);
  eval_constraints(m, kin, t, true, ce);
  return ce;
}

}  // namespace

TEST_CASE(admissible_motion_satisfies_every_level) {
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  VecX q(4), qd(4), qdd(4);
  q << -0.6, 0.9, -0.05, 0.7;
  qd << 0.8, 1.3, -0.4, -1.7;
  qdd << 2.0, -1.1, 0.9, 0.5;
  VecX u, v;
  state_from_joints(*m, q, qd, u, v);
  const ConstraintEval ce = evaluate(*m, u, v, 0.0);
  CHECK(ce.f.size() == m->nc);
  CHECK(ce.f.lpNorm<Eigen::Infinity>() < 1e-14);
  const MatX z = dense_zeta(*m, ce);
  CHECK(z.rows() == m->nc && z.cols() == m->nv);
  CHECK((z * v).lpNorm<Eigen::Infinity>() < 1e-13);
  CHECK(ce.rhs.lpNorm<Eigen::Infinity>() == 0.0);
  // zeta vdot = -xi for the accelerations of the joint motion
  const VecX vdot = armdyn_test::cartesian_acceleration_fd(*m, q, qd, qdd);
  CHECK_MAT_NEAR(z * vdot, -ce.xi, 1e-7);
  std::vector<BodyKin> kin(m->nb);
  body_kinematics(*m, u.data(), v.data(), kin);
  CHECK(flipped_joint(*m, kin) == -1);
}

TEST_CASE(jacobian_is_the_derivative_of_f) {
  // an arbitrary (inadmissible) velocity: d/dt f(u(t)) = zeta v along u(t) moved by v
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  VecX v(m->nv);
  for (int i = 0; i < m->nv; ++i) v[i] = std::sin(1.7 * i + 0.3);
  const double h = 1e-6;
  const ConstraintEval c0 = evaluate(*m, m->u0, v, 0.0);
  const ConstraintEval cp = evaluate(*m, armdyn_test::advance(*m, m->u0, v, h), v, 0.0);
  const ConstraintEval cm = evaluate(*m, armdyn_test::advance(*m, m->u0, v, -h), v, 0.0);
  const MatX z = dense_zeta(*m, c0);
  CHECK_MAT_NEAR((cp.f - cm.f) / (2 * h), z * v, 1e-8);
  // the structured products agree with the dense matrix
  VecX y(m->nc), x(m->nv);
  zeta_times(c0, m->nc, v, y);
  CHECK_MAT_NEAR(y, z * v, 1e-14);
  const VecX d = VecX::LinSpaced(m->nc, -1.0, 2.0);
  zeta_transpose_times(c0, m->nc, d, x);
  CHECK_MAT_NEAR(x, z.transpose() * d, 1e-14);
  // xi is the second derivative of f with zero accelerations (v constant, u moved by v)
  CHECK_MAT_NEAR((cp.f - 2 * c0.f + cm.f) / (h * h), c0.xi, 2e-3);
}

TEST_CASE(drive_rows) {
  // a drive q_pitch(t) = sine: its row's residual is q - y(t), its rhs y'(t)
  ModelBuilder b = armdyn_test::spatial_arm_builder();
  const Profile p = Profile::sine(0.3, 0.5, 0.2, 0.1);
  b.add_drive("pitch", p);
  const ModelPtr m = b.finalize();
  CHECK(m->nc == m->nc_joint + 1);
  const int row = m->drives[0].row;
  CHECK(row == m->nc_joint);
  const double t = 0.37;
  VecX q(4), qd(4);
  q << 0.2, -0.4, 0.01, 0.3;
  qd << 0.5, 0.9, 0.2, -0.3;
  VecX u, v;
  state_from_joints(*m, q, qd, u, v);
  const ConstraintEval ce = evaluate(*m, u, v, t);
  const ProfileValue y = p.eval(t);
  CHECK_NEAR(std::abs(ce.f[row]), std::abs(q[1] - y.y), 1e-13);
  const MatX z = dense_zeta(*m, ce);
  // sign convention: the row is +-(q - y); zeta v - rhs is then +-(qd - y')
  const double s = (ce.f[row] >= 0) == (q[1] - y.y >= 0) ? 1.0 : -1.0;
  CHECK_NEAR(z.row(row).dot(v) - ce.rhs[row], s * (qd[1] - y.yd), 1e-13);
}

TEST_CASE(closed_loop_rows) {
  // a four-bar closed by an inline joint at an assembled state
  ModelBuilder b;
  const Mat3 in = Vec3(0.01, 0.02, 0.01).asDiagonal();
  b.add_body("crank", 1.0, in, Vec3(0, 0, 0.25), armdyn_test::kIdentityQuat);
  b.add_body("coupler", 1.0, in, Vec3(0.5, 0, 0.5), armdyn_test::kIdentityQuat);
  b.add_body("rocker", 1.0, in, Vec3(1.0, 0, 0.3), armdyn_test::kIdentityQuat);
  b.add_revolute("A", "ground", "crank", Vec3(0, 0, 0), Vec3::UnitY());
  b.add_revolute("B", "crank", "coupler", Vec3(0, 0, 0.5), Vec3::UnitY());
  b.add_revolute("D", "ground", "rocker", Vec3(1, 0, 0.1), Vec3::UnitY());
  b.add_inline("C", "rocker", "coupler", Vec3(1, 0, 0.5), Vec3::UnitY());
  const ModelPtr m = b.finalize();
  const ConstraintEval ce = evaluate(*m, m->u0, m->v0, 0.0);
  CHECK(ce.f.lpNorm<Eigen::Infinity>() < 1e-12);
  // full row rank: 17 independent rows
  Eigen::FullPivLU<MatX> lu(dense_zeta(*m, ce));
  CHECK(lu.rank() == 17);
}

ARMDYN_TEST_MAIN()
