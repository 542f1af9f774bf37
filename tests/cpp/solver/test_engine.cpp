// SPDX-License-Identifier: BSD-3-Clause
// The engine pipeline (armdyn/solver/engine.hpp) on closed forms: a physical pendulum's angular
// acceleration and its centre of mass as a point on a rotating body, the hinge reaction at rest,
// kinetic and potential energy by hand, a free body in flight, and the projection.
#include <cmath>

#include "armdyn/analysis/joint_space.hpp"
#include "armdyn/math/quaternion.hpp"
#include "armdyn/solver/engine.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

TEST_CASE(pendulum_acceleration_is_the_closed_form) {
  armdyn_test::Pendulum p;
  p.phi0 = 0.9;
  const ModelPtr m = p.model();
  Engine e(*m);
  for (double qd : {0.0, 1.7, -2.4}) {
    VecX u, v;
    state_from_joints(*m, VecX::Constant(1, 0.0), VecX::Constant(1, qd), u, v);
    VecX vdot(m->nv);
    e.dynamics(0.0, u.data(), v.data(), vdot.data());
    const double alpha = p.phidd(p.phi0);  // independent of the rate
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

TEST_CASE(hinge_reaction_of_a_hanging_pendulum) {
  // at rest straight down the hinge carries the weight: m g up, no torque about the axis
  const armdyn_test::Pendulum p;
  const ModelPtr m = p.model();
  Engine e(*m);
  VecX vdot(m->nv);
  e.dynamics(0.0, m->u0.data(), m->v0.data(), vdot.data());
  CHECK(vdot.norm() < 1e-12);
  Vec3 f, t;
  e.joint_reaction(0, f, t);
  const Joint& j = m->joints[0];
  const Mat3 B = quat_to_rot(m->u0.segment<4>(3)) * j.frame_child;  // joint frame in world
  CHECK_MAT_NEAR(B * f, Vec3(0, 0, p.m * p.g), 1e-12);
  CHECK_NEAR((B * t).dot(Vec3::UnitY()), 0.0, 1e-12);
}

TEST_CASE(energy_by_hand) {
  // T = sum 1/2 m |xd|^2 + 1/2 w^T J w (w in the body frame), V = -sum m g . x
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  Engine e(*m);
  VecX v(m->nv);
  for (int i = 0; i < m->nv; ++i) v[i] = std::sin(0.7 * i + 0.2);
  double ke = 0.0, pe = 0.0;
  e.energy(m->u0.data(), v.data(), ke, pe);
  double t = 0.0, u = 0.0;
  for (int b = 0; b < m->nb; ++b) {
    const Body& body = m->bodies[b];
    const Vec3 xd = v.segment<3>(6 * b), w = v.segment<3>(6 * b + 3);
    t += 0.5 * body.mass * xd.squaredNorm() + 0.5 * w.dot(body.inertia * w);
    u -= body.mass * m->gravity.dot(m->u0.segment<3>(7 * b));
  }
  CHECK_NEAR(ke, t, 1e-13);
  CHECK_NEAR(pe, u, 1e-13);
}

TEST_CASE(free_body_falls_at_g_and_spins_by_euler) {
  // a free body: xdd = g, and Euler's equations J w' = -w x J w
  ModelBuilder b(Vec3(0.5, 0.0, -9.81));
  const Mat3 J = Vec3(0.1, 0.2, 0.25).asDiagonal();
  b.add_body("b", 2.0, J, Vec3(0, 0, 1), quat_exp(Vec3(0.2, 0.1, -0.3)));
  b.add_free("free", "b");
  const ModelPtr m = b.finalize();
  CHECK(m->nc == 0);
  Engine e(*m);
  VecX v(6);
  v << 1.0, 0.0, 2.0, 0.7, -1.3, 2.2;
  VecX vdot(6);
  e.dynamics(0.0, m->u0.data(), v.data(), vdot.data());
  CHECK_MAT_NEAR(vdot.head<3>(), Vec3(0.5, 0.0, -9.81), 1e-14);
  const Vec3 w = v.tail<3>();
  CHECK_MAT_NEAR(vdot.tail<3>(), Vec3(J.inverse() * (-w.cross(J * w))), 1e-13);
}

TEST_CASE(projection_restores_the_constraints) {
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  Engine e(*m);
  VecX u = m->u0, v(m->nv);
  for (int i = 0; i < m->nq; ++i) u[i] += 1e-3 * std::cos(3.1 * i);
  for (int i = 0; i < m->nv; ++i) v[i] = std::sin(1.3 * i);
  double rf = 0, rv = 0;
  e.residuals(0.0, u.data(), v.data(), rf, rv);
  CHECK(rf > 1e-5 && rv > 1e-2);
  e.project(0.0, u.data(), v.data(), Metric::Mass);
  e.residuals(0.0, u.data(), v.data(), rf, rv);
  CHECK(rf < 1e-12);
  CHECK(rv < 1e-12);
  for (int b = 0; b < m->nb; ++b) CHECK_NEAR(u.segment<4>(7 * b + 3).norm(), 1.0, 1e-14);
  // projecting again moves nothing
  const VecX u1 = u, v1 = v;
  e.project(0.0, u.data(), v.data(), Metric::Mass);
  CHECK_MAT_NEAR(u, u1, 1e-13);
  CHECK_MAT_NEAR(v, v1, 1e-12);
}

TEST_CASE(udot_is_the_state_rate) {
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  Engine e(*m);
  VecX v(m->nv), ud(m->nq);
  for (int i = 0; i < m->nv; ++i) v[i] = std::cos(0.4 * i);
  e.udot(m->u0.data(), v.data(), ud.data());
  const double h = 1e-6;
  const VecX fd =
      (armdyn_test::advance(*m, m->u0, v, h) - armdyn_test::advance(*m, m->u0, v, -h)) / (2 * h);
  CHECK_MAT_NEAR(ud, fd, 1e-9);
}

ARMDYN_TEST_MAIN()
