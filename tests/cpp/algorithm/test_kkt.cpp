// SPDX-License-Identifier: BSD-3-Clause
// The KKT stage (armdyn/algorithm/kkt.hpp) on closed forms: a physical pendulum's angular
// acceleration -m g L sin(phi) / I_O at any rate, with a joint torque added, its drive's effort
// I_O phi'' + m g L sin(phi) on the square (swept) system, the joint rows alone ignoring the
// drive, and a free body falling at g and spinning by Euler's equations.
#include <cmath>

#include "armdyn/algorithm/dynamics.hpp"
#include "armdyn/algorithm/kkt.hpp"
#include "armdyn/kernels/joint_space.hpp"
#include "armdyn/math/quaternion.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

TEST_CASE(pendulum_acceleration_is_the_closed_form) {
  armdyn_test::Pendulum p;
  p.phi0 = 0.9;
  const ModelPtr m = p.model();
  Data d(*m);
  long solves = 0;
  for (double qd : {0.0, 1.7, -2.4}) {
    VecX u, v;
    state_from_joints(*m, VecX::Constant(1, 0.0), VecX::Constant(1, qd), u, v);
    VecX vdot(m->nv);
    body_accelerations(*m, d, 0.0, u.data(), v.data(), vdot.data());
    CHECK(d.stats.kkt_solves == ++solves);
    // a tree: the articulated-body recursion over the Cartesian coordinates, no factorisation
    CHECK(d.stats.articulated_solves == solves && d.stats.factorizations == 0);
    const double alpha = p.phidd(p.phi0);  // -g/L sin(phi) for a point mass; independent of qd
    // the centre of mass, r = x - hinge, moves on a circle about y:
    // a = alpha (y x r) + omega^2 (y x (y x r))
    const Vec3 r = u.head<3>(), y = Vec3::UnitY();
    const Vec3 a = alpha * y.cross(r) + qd * qd * y.cross(y.cross(r));
    CHECK_MAT_NEAR(vdot.head<3>(), a, 1e-12);
    // body-frame angular acceleration: alpha about y (the body frame turns about y too)
    const Mat3 R = quat_to_rot(u.segment<4>(3));
    CHECK_MAT_NEAR(R * vdot.tail<3>(), alpha * y, 1e-12);
  }
}

TEST_CASE(joint_torque_adds_to_the_pendulum) {
  armdyn_test::Pendulum p;
  p.phi0 = -0.6;
  const ModelPtr m = p.model();
  Data d(*m);
  const double tau = 2.5;
  d.joint_torques = &tau;
  VecX vdot(m->nv);
  body_accelerations(*m, d, 0.0, m->u0.data(), m->v0.data(), vdot.data());
  const double phidd = (tau - p.m * p.g * p.L * std::sin(p.phi0)) / p.io();
  const Mat3 R = quat_to_rot(m->u0.segment<4>(3));
  CHECK_MAT_NEAR(R * vdot.tail<3>(), Vec3(0.0, phidd, 0.0), 1e-12);
  // the torque's coordinate jet: the angle's rate is y . w
  CHECK_NEAR(coord_acceleration(*m, d.tau_jets[0], 0, vdot), phidd, 1e-12);
}

TEST_CASE(driven_pendulum_effort_and_joint_rows_only) {
  // the hinge driven by q(t) = 0.3 sin(2 pi t): square zeta, swept; the drive's effort is the
  // torque of the prescribed motion
  const armdyn_test::Pendulum p;
  ModelBuilder b = p.builder();
  const Profile prof = Profile::sine(0.3, 1.0, 0.0, 0.0);
  b.add_drive("hinge", prof);
  const ModelPtr m = b.finalize();
  Data d(*m);
  const double t = 0.2;
  const ProfileValue pv = prof.eval(t);
  VecX u, v;
  state_from_joints(*m, VecX::Constant(1, pv.y), VecX::Constant(1, pv.yd), u, v);
  VecX vdot(m->nv);
  body_accelerations(*m, d, t, u.data(), v.data(), vdot.data());
  CHECK(d.swept);
  const Mat3 R = quat_to_rot(u.segment<4>(3));
  CHECK_MAT_NEAR(R * vdot.tail<3>(), Vec3(0.0, pv.ydd, 0.0), 1e-12);
  const double effort = p.io() * pv.ydd + p.m * p.g * p.L * std::sin(pv.y);
  CHECK_NEAR(-d.delta[m->drives[0].row], effort, 1e-12);
  // the joint rows alone: the free pendulum, the drive ignored
  d.nrows = m->nc_joint;
  body_accelerations(*m, d, t, u.data(), v.data(), vdot.data());
  CHECK(d.stats.articulated_solves == 1);
  CHECK_MAT_NEAR(R * vdot.tail<3>(), Vec3(0.0, p.phidd(pv.y), 0.0), 1e-12);
}

TEST_CASE(free_body_falls_at_g_and_spins_by_euler) {
  // a free body: xdd = g, and Euler's equations J w' = -w x J w
  ModelBuilder b(Vec3(0.5, 0.0, -9.81));
  const Mat3 J = Vec3(0.1, 0.2, 0.25).asDiagonal();
  b.add_body("b", 2.0, J, Vec3(0, 0, 1), quat_exp(Vec3(0.2, 0.1, -0.3)));
  b.add_free("free", "b");
  const ModelPtr m = b.finalize();
  CHECK(m->nc == 0);
  Data d(*m);
  VecX v(6);
  v << 1.0, 0.0, 2.0, 0.7, -1.3, 2.2;
  VecX vdot(6);
  body_accelerations(*m, d, 0.0, m->u0.data(), v.data(), vdot.data());
  CHECK_MAT_NEAR(vdot.head<3>(), Vec3(0.5, 0.0, -9.81), 1e-14);
  const Vec3 w = v.tail<3>();
  CHECK_MAT_NEAR(vdot.tail<3>(), Vec3(J.inverse() * (-w.cross(J * w))), 1e-13);
}

TEST_CASE(light_link_takes_the_augmented_solve_and_keeps_its_accuracy) {
  // the two-link arm with link 2's inertia scaled by 1e-12 (about its centre of mass, off the
  // elbow: the joint-space mass matrix stays well conditioned)
  armdyn_test::TwoLink arm;
  ModelBuilder b(Vec3(0, 0, -arm.g));
  b.add_body("link1", arm.m1, Vec3(0.02, arm.i1, 0.1).asDiagonal(), Vec3(arm.lc1, 0, 0),
             armdyn_test::kIdentityQuat);
  b.add_body("link2", arm.m2, 1e-12 * Vec3(0.03, arm.i2, 0.05).asDiagonal(),
             Vec3(arm.l1 + arm.lc2, 0, 0), armdyn_test::kIdentityQuat);
  b.add_revolute("shoulder", "ground", "link1", Vec3::Zero(), Vec3::UnitY());
  b.add_revolute("elbow", "link1", "link2", Vec3(arm.l1, 0, 0), Vec3::UnitY());
  const ModelPtr m = b.finalize();
  CHECK(light_bodies(*m).bodies == std::vector<int>{1});
  CHECK(light_bodies(*arm.model()).bodies.empty());
  Data d(*m);
  const VecX q = (VecX(2) << 0.4, -1.1).finished(), qd = (VecX(2) << 1.3, -0.7).finished();
  VecX u, v, vd(m->nv);
  state_from_joints(*m, q, qd, u, v);
  body_accelerations(*m, d, 0.0, u.data(), v.data(), vd.data());
  CHECK(d.stats.augmented_solves == 1);
  CHECK(d.stats.augmented_note.find("'link2'") != std::string::npos);
  CHECK(constraint_residual(d.ce, m->nc, vd) < 1e-14);
  // the elbow's angular acceleration against the joint-space path (CRBA, no Gamma^-1)
  Data dj(*m);
  const VecX qdd = forward_dynamics(*m, dj, q, qd, VecX::Zero(2), 0.0, DynamicsMethod::Joint);
  CHECK_NEAR(vd[6 * 1 + 4], qdd[0] + qdd[1], 1e-12 * qdd.cwiseAbs().maxCoeff());
}

TEST_CASE(augmented_and_range_space_solves_agree_on_a_normal_model) {
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  Data d(*m);
  VecX u, v;
  state_from_joints(*m, (VecX(4) << 0.3, -0.6, 0.05, 1.1).finished(),
                    (VecX(4) << 0.9, -1.4, 0.2, 2.0).finished(), u, v);
  VecX vd(m->nv);
  body_accelerations(*m, d, 0.0, u.data(), v.data(), vd.data());
  CHECK(d.stats.augmented_solves == 0);  // no light body, residual at round-off
  CHECK(constraint_residual(d.ce, m->nc, vd) < 1e-13);
  const VecX delta = d.delta;
  VecX vd2(m->nv), delta2(m->nc);
  CHECK(d.kkt.accelerations_augmented(d.ce, m->nc, d.eta, vd2, delta2));
  CHECK_MAT_NEAR(vd2, vd, 1e-12 * vd.cwiseAbs().maxCoeff());
  CHECK_MAT_NEAR(delta2, delta, 1e-12 * delta.cwiseAbs().maxCoeff());
  // accelerations that break the constraints show in the residual
  VecX wrong = vd;
  wrong[3] += 1e-3 * vd.cwiseAbs().maxCoeff();
  CHECK(constraint_residual(d.ce, m->nc, wrong) > 1e-5);
}

TEST_CASE(a_driven_loop_at_rest_keeps_the_range_space_solve) {
  // a four-bar held by a drive on its crank, at rest under gravity: the accelerations are zero,
  // so the solve's are round-off of g's. Measured against their own size, that read as a lost
  // solve and sent every call to the augmented LU (inverse_dynamics of the geared arm at rest:
  // 8.2 ms per state instead of 70 us); against the loads' accelerations it is round-off
  ModelBuilder b = armdyn_test::four_bar_builder();
  b.add_drive("A", Profile::constant(0.0));
  const ModelPtr m = b.finalize();
  Data d(*m);
  VecX vd(m->nv);
  const VecX v = VecX::Zero(m->nv);
  body_accelerations(*m, d, 0.0, m->u0.data(), v.data(), vd.data());
  CHECK(d.stats.augmented_solves == 0);
  CHECK(vd.cwiseAbs().maxCoeff() < 1e-13 * 9.81);
  const double a = load_acceleration_scale(*m, d.eta);
  CHECK_NEAR(a, 9.81, 1e-12);  // gravity, the bodies' only load
  CHECK(constraint_residual(d.ce, m->nc, vd, a) < 1e-14);
  // the same state through the augmented solve: the same (zero) accelerations, the same
  // multipliers (the joints carry the bodies' 44 N)
  VecX vd2(m->nv), delta2(m->nc);
  CHECK(d.kkt.accelerations_augmented(d.ce, m->nc, d.eta, vd2, delta2));
  CHECK_MAT_NEAR(vd2, vd, 1e-12);
  CHECK_MAT_NEAR(delta2, d.delta, 1e-10 * d.delta.cwiseAbs().maxCoeff());
  CHECK(d.delta.cwiseAbs().maxCoeff() > 10.0);
}

ARMDYN_TEST_MAIN()
