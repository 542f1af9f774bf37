// SPDX-License-Identifier: BSD-3-Clause
// The constraints stage (armdyn/algorithm/constraints.hpp): on the manifold of a spatial tree
// f = 0 and zeta v = 0 for joint-space velocities, zeta v' = -xi for the accelerations of a
// joint-space motion (central differences), a hinge point displaced by a known distance, and a
// drive row's residual and right-hand side from its profile.
#include <cmath>

#include "armdyn/algorithm/constraints.hpp"
#include "armdyn/algorithm/kinematics.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

TEST_CASE(on_the_manifold_of_a_tree) {
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  Data d(*m);
  VecX q(4), qd(4), qdd(4);
  q << 0.3, -0.4, 0.05, 1.1;
  qd << 0.7, -1.2, 0.3, 2.0;
  qdd << -0.5, 0.8, 0.2, -1.5;
  VecX u, v;
  state_from_joints(*m, q, qd, u, v);
  load_kinematics(*m, d, u.data(), v.data());
  evaluate_constraints(*m, d, 0.0, true);
  CHECK(d.ce.f.size() == m->nc);
  CHECK(d.ce.f.cwiseAbs().maxCoeff() < 1e-14);
  const MatX z = dense_zeta(*m, d.ce);
  CHECK_MAT_NEAR(z * v, VecX::Zero(m->nc), 1e-13);
  CHECK_MAT_NEAR(d.ce.rhs, VecX::Zero(m->nc), 0.0);
  // the acceleration level: zeta v' + xi = 0 along the joint-space motion
  const VecX vdot = armdyn_test::cartesian_acceleration_fd(*m, q, qd, qdd);
  CHECK_MAT_NEAR(z * vdot, -d.ce.xi, 1e-7);
}

TEST_CASE(a_displaced_hinge_point) {
  // the bob moved by 0.01 along x off its circle: the point rows see exactly that
  const armdyn_test::Pendulum p;
  const ModelPtr m = p.model();
  Data d(*m);
  VecX u = m->u0;
  u[0] += 0.01;
  load_kinematics(*m, d, u.data(), nullptr);
  evaluate_constraints(*m, d, 0.0, false);
  CHECK_NEAR(d.ce.f.head<3>().cwiseAbs().maxCoeff(), 0.01, 1e-15);
  CHECK_NEAR(d.ce.f.tail(m->nc - 3).cwiseAbs().maxCoeff(), 0.0, 1e-15);
}

TEST_CASE(drive_row_from_its_profile) {
  // a hinge driven by q(t) = 0.2 + 0.5 sin(3 t): at time t the drive row's residual is the
  // difference of the angle and the profile, and zeta v = rhs holds for qd = q'(t)
  ModelBuilder b = armdyn_test::Pendulum().builder();
  const Profile prof = Profile::sine(0.5, 3.0 / (2 * M_PI), 0.0, 0.2);
  b.add_drive("hinge", prof);
  const ModelPtr m = b.finalize();
  CHECK(m->nc == m->nc_joint + 1);
  Data d(*m);
  const double t = 0.37;
  const ProfileValue pv = prof.eval(t);
  CHECK_NEAR(pv.y, 0.2 + 0.5 * std::sin(3.0 * t), 1e-14);
  // on the prescribed motion: every row satisfied
  VecX u, v;
  state_from_joints(*m, VecX::Constant(1, pv.y), VecX::Constant(1, pv.yd), u, v);
  load_kinematics(*m, d, u.data(), v.data());
  evaluate_constraints(*m, d, t, true);
  CHECK(d.ce.f.cwiseAbs().maxCoeff() < 1e-14);
  const MatX z = dense_zeta(*m, d.ce);
  CHECK_MAT_NEAR(z * v, d.ce.rhs, 1e-14);
  CHECK(std::abs(d.ce.rhs[m->nc_joint]) > 0.1);
  // 0.1 rad off the profile: the drive row alone reports it
  state_from_joints(*m, VecX::Constant(1, pv.y + 0.1), VecX::Zero(1), u, v);
  load_kinematics(*m, d, u.data(), v.data());
  evaluate_constraints(*m, d, t, false);
  CHECK_NEAR(std::abs(d.ce.f[m->nc_joint]), 0.1, 1e-14);
  CHECK(d.ce.f.head(m->nc_joint).cwiseAbs().maxCoeff() < 1e-14);
}

ARMDYN_TEST_MAIN()
