// SPDX-License-Identifier: BSD-3-Clause
// The force laws (armdyn/algorithm/forces.hpp): gravity and the gyroscopic torque, a point
// spring-damper's tension along its line, joint springs, friction, inputs and PD/PI motors
// (coord_force_value), gear contact (gear_force, its sign along the mesh and its stiffness); and
// the Cartesian forces stage: a joint spring, a PI motor and a joint torque on a pendulum as a
// torque about the hinge axis, the motor's integral rate, and a gear mesh read over turns.
#include <cmath>

#include "armdyn/algorithm/forces.hpp"
#include "armdyn/algorithm/kinematics.hpp"
#include "armdyn/math/quaternion.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

TEST_CASE(coordinate_spring_damper_friction_and_input) {
  CoordForce cf;
  cf.stiffness = 40.0;
  cf.damping = 1.5;
  cf.rest = 0.2;
  cf.coulomb = 0.3;
  cf.v_smooth = 0.01;
  cf.has_input = true;
  cf.input = Profile::constant(2.0);
  const double q = 0.5, qd = -0.7;
  const double expected = -40.0 * (q - 0.2) - 1.5 * qd - 0.3 * std::tanh(qd / 0.01) + 2.0;
  CHECK_NEAR(coord_force_value(cf, false, q, qd, 0.0), expected, 1e-13);
  // angular springs see the wrapped difference: q = rest + 2 pi + 0.1 acts as rest + 0.1
  cf.has_input = false;
  cf.coulomb = 0.0;
  CHECK_NEAR(coord_force_value(cf, true, 0.2 + 2 * M_PI + 0.1, 0.0, 0.0), -40.0 * 0.1, 1e-12);
  CHECK_NEAR(coord_force_value(cf, false, 0.2 + 2 * M_PI + 0.1, 0.0, 0.0), -40.0 * (2 * M_PI + 0.1),
             1e-12);
}

TEST_CASE(pd_motor_saturates_and_stops_integrating) {
  CoordForce cf;
  cf.motor = true;
  cf.reference = Profile::constant(1.0);
  cf.kp = 10.0;
  cf.kd = 2.0;
  cf.ki = 5.0;
  cf.torque_limit = 100.0;
  double zdot = -1.0;
  // inside the limit: kp e + kd (0 - qd) + ki z, and z' = e
  CHECK_NEAR(coord_force_value(cf, true, 0.4, 0.3, 0.0, 0.1, &zdot),
             10.0 * 0.6 + 2.0 * (-0.3) + 5.0 * 0.1, 1e-14);
  CHECK_NEAR(zdot, 0.6, 1e-15);
  // saturated in the direction of the error: clamped, the integral holds
  cf.torque_limit = 1.0;
  CHECK_NEAR(coord_force_value(cf, true, 0.4, 0.0, 0.0, 0.0, &zdot), 1.0, 0.0);
  CHECK(zdot == 0.0);
}

TEST_CASE(gear_pair_contact_law) {
  GearPair g;
  g.backlash = 0.002;
  g.stiffness = 1e6;
  g.exponent = 1.5;
  g.hc_damping = 0.4;
  double pen = 0.0;
  // inside the gap: no force, negative penetration
  CHECK(gear_force(g, 0.0005, 0.1, pen) == 0.0);
  CHECK_NEAR(pen, 0.0005 - 0.001, 1e-18);
  // in contact: k d^n (1 + alpha d'), d' the penetration rate (sign of s)
  const double s = -0.0013, sd = -0.02, d = 0.0003;
  CHECK_NEAR(gear_force(g, s, sd, pen), 1e6 * std::pow(d, 1.5) * (1 + 0.4 * 0.02), 1e-12);
  CHECK_NEAR(pen, d, 1e-18);
  // separating fast: never pulls
  CHECK(gear_force(g, 0.0013, -10.0, pen) == 0.0);
}

TEST_CASE(gear_mesh_force_signs_and_torques) {
  GearPair g;
  g.coord_a = 0;
  g.coord_b = 1;
  g.r_a = 0.02;
  g.r_b = 0.05;
  g.backlash = 0.002;
  g.stiffness = 1e6;
  g.exponent = 1.5;
  double pen = 0.0;
  // the force along s: +F for s > 0, -F for s < 0 (F = gear_force's magnitude)
  const double F = gear_force(g, 0.0013, 0.0, pen);
  CHECK(F > 0.0);
  CHECK(gear_mesh_force(g, 0.0013, 0.0) == F);
  CHECK(gear_mesh_force(g, -0.0013, 0.0) == -F);
  CHECK(gear_mesh_force(g, 0.0005, 0.0) == 0.0);
  // tau_a = -r_a f, tau_b = -r_b f, added to what is there
  double tau[2] = {1.0, -2.0};
  add_gear_torques(g, 3.0, tau);
  CHECK_NEAR(tau[0], 1.0 - 0.02 * 3.0, 1e-15);
  CHECK_NEAR(tau[1], -2.0 - 0.05 * 3.0, 1e-15);
  // the contact stiffness: the derivative of the undamped force in the penetration (central
  // difference of gear_force)
  const double d = 3e-4, e = 1e-9, s0 = 0.001 + d;
  const double fd = (gear_force(g, s0 + e, 0.0, pen) - gear_force(g, s0 - e, 0.0, pen)) / (2 * e);
  CHECK_NEAR(gear_contact_stiffness(g, d), fd, 1e-6 * fd);
  CHECK_NEAR(gear_contact_stiffness(g, d), 1e6 * 1.5 * std::sqrt(d), 1e-9);
}

TEST_CASE(gravity_and_gyroscopic_torque) {
  ModelBuilder b(Vec3(0.2, -0.1, -9.81));
  const Mat3 J = Vec3(0.1, 0.2, 0.25).asDiagonal();
  b.add_body("b", 2.0, J, Vec3(0, 0, 1), quat_exp(Vec3(0.3, 0.1, 0.2)));
  b.add_free("free", "b");
  const ModelPtr m = b.finalize();
  VecX v(6);
  v << 0.1, 0.2, 0.3, 1.0, -2.0, 0.5;
  std::vector<BodyKin> kin(1);
  body_kinematics(*m, m->u0.data(), v.data(), kin);
  VecX eta(6);
  body_forces(*m, kin, 0.0, eta);
  CHECK_MAT_NEAR(eta.head<3>(), 2.0 * Vec3(0.2, -0.1, -9.81), 1e-14);
  const Vec3 w = v.tail<3>();
  CHECK_MAT_NEAR(eta.tail<3>(), Vec3(-w.cross(J * w)), 1e-14);
}

TEST_CASE(point_spring_damper_tension) {
  // a spring from a ground point to a body, stretched by 0.1 beyond its rest length and
  // lengthening at 0.5 m/s: tension k dL + c dL/dt pulls the body towards the anchor
  ModelBuilder b(Vec3::Zero());
  b.add_body("b", 1.0, Vec3(0.1, 0.1, 0.1).asDiagonal(), Vec3(1.0, 0, 0),
             armdyn_test::kIdentityQuat);
  b.add_free("free", "b");
  b.add_spring_damper("s", "ground", Vec3(0, 0, 0), "b", Vec3(1.0, 0, 0), 200.0, 3.0, 0.9);
  const ModelPtr m = b.finalize();
  VecX v = VecX::Zero(6);
  v[0] = 0.5;
  std::vector<BodyKin> kin(1);
  body_kinematics(*m, m->u0.data(), v.data(), kin);
  VecX eta(6);
  body_forces(*m, kin, 0.0, eta);
  CHECK_MAT_NEAR(eta.head<3>(), Vec3(-(200.0 * 0.1 + 3.0 * 0.5), 0, 0), 1e-12);
  CHECK_MAT_NEAR(eta.tail<3>(), Vec3::Zero(), 1e-12);  // acts at the centre of mass
}

TEST_CASE(joint_spring_and_gear_contact) {
  ModelBuilder b(Vec3::Zero());
  const Mat3 in = Vec3(0.01, 0.01, 0.02).asDiagonal();
  b.add_body("a", 1.0, in, Vec3(0, 0, 0), armdyn_test::kIdentityQuat);
  b.add_body("c", 1.0, in, Vec3(0.3, 0, 0), armdyn_test::kIdentityQuat);
  b.add_revolute("ja", "ground", "a", Vec3(0, 0, 0), Vec3::UnitZ());
  b.add_revolute("jc", "ground", "c", Vec3(0.3, 0, 0), Vec3::UnitZ());
  b.add_joint_spring_damper("ja", 50.0, 2.0, 0.1);
  b.add_gear_pair("g", "ja", "jc", 0.1, 0.2, 0.002, 1e5, 1.0, 0.0);
  const ModelPtr m = b.finalize();
  // s = 0.1 qa + 0.2 qc = 0.1 * 0.3 + 0.2 * 0.0 = 0.03: penetration 0.029, F = 1e5 * 0.029
  const double q[2] = {0.3, 0.0}, qd[2] = {0.4, 0.0};
  double s, sd, pen;
  gear_mesh(*m, 0, q, qd, s, sd, pen);
  CHECK_NEAR(s, 0.03, 1e-15);
  CHECK_NEAR(sd, 0.04, 1e-15);
  CHECK_NEAR(pen, 0.029, 1e-15);
  VecX tau(2);
  coordinate_forces(*m, q, qd, nullptr, 0.0, tau);
  const double f = 1e5 * 0.029;
  CHECK_NEAR(tau[0], -50.0 * (0.3 - 0.1) - 2.0 * 0.4 - 0.1 * f, 1e-10);
  CHECK_NEAR(tau[1], -0.2 * f, 1e-10);
}

TEST_CASE(cartesian_forces_map_joint_forces_onto_the_bodies) {
  // a pendulum with a joint spring-damper and a PI motor on its hinge, and a joint torque: on
  // the bob they are a torque tau R^T y about the hinge axis (body axes), nothing else
  const armdyn_test::Pendulum p;
  ModelBuilder b = p.builder();
  b.add_joint_spring_damper("hinge", 30.0, 1.5, 0.2);
  b.add_motor("hinge", Profile::constant(0.4), 5.0, 0.1, 100.0, nullptr, 0, 2.0);
  const ModelPtr m = b.finalize();
  CHECK(m->n_aux == 1);
  Data d(*m);
  const double q = 0.9, qd = -0.6, z = 0.25, tau_in = 1.75;
  VecX u, v;
  state_from_joints(*m, VecX::Constant(1, q), VecX::Constant(1, qd), u, v);
  load_kinematics(*m, d, u.data(), v.data());
  VecX eta0(6);
  body_forces(*m, d.kin, 0.0, eta0);
  d.aux = &z;
  cartesian_forces(*m, d, 0.0);
  const double tau = -30.0 * (q - 0.2) - 1.5 * qd + 5.0 * (0.4 - q) + 0.1 * (0.0 - qd) + 2.0 * z;
  const Vec3 axis_body = d.kin[0].R.transpose() * Vec3::UnitY();
  CHECK_MAT_NEAR(d.eta.head<3>(), eta0.head<3>(), 1e-12);
  CHECK_MAT_NEAR(d.eta.tail<3>(), Vec3(eta0.tail<3>() + tau * axis_body), 1e-12);
  // the motor's integral state grows at the tracking error
  double zdot = -1.0;
  aux_rates(*m, d, 0.0, &zdot);
  CHECK_NEAR(zdot, 0.4 - q, 1e-14);
  // a joint torque adds the same way; without the coordinate forces only it remains
  d.joint_torques = &tau_in;
  d.with_coordinate_forces = false;
  cartesian_forces(*m, d, 0.0);
  CHECK_MAT_NEAR(d.eta.head<3>(), eta0.head<3>(), 1e-12);
  CHECK_MAT_NEAR(d.eta.tail<3>(), Vec3(eta0.tail<3>() + tau_in * axis_body), 1e-12);
}

TEST_CASE(cartesian_gear_mesh_over_turns) {
  ModelBuilder b(Vec3::Zero());
  const Mat3 in = Vec3(0.01, 0.01, 0.02).asDiagonal();
  b.add_body("a", 1.0, in, Vec3(0, 0, 0), armdyn_test::kIdentityQuat);
  b.add_body("c", 1.0, in, Vec3(0.3, 0, 0), armdyn_test::kIdentityQuat);
  b.add_revolute("ja", "ground", "a", Vec3(0, 0, 0), Vec3::UnitZ());
  b.add_revolute("jc", "ground", "c", Vec3(0.3, 0, 0), Vec3::UnitZ());
  b.add_gear_pair("g", "ja", "jc", 0.1, 0.2, 0.002, 1e5, 1.0, 0.0);
  const ModelPtr m = b.finalize();
  Data d(*m);
  // gear a one turn and 0.3 rad on, turning at 0.4 rad/s; c at -0.1 rad, turning at -0.5 rad/s
  VecX u = m->u0, v = VecX::Zero(m->nv);
  u.segment<4>(3) = quat_exp(Vec3(0, 0, 0.3));
  u.segment<4>(7 + 3) = quat_exp(Vec3(0, 0, -0.1));
  v[5] = 0.4;
  v[11] = -0.5;
  load_kinematics(*m, d, u.data(), v.data());
  d.track_ref[0] = 2 * M_PI;  // the angle's last projected value: one turn
  double s, sd, pen;
  gear_mesh(*m, d, 0, s, sd, pen);
  const double qa = 2 * M_PI + 0.3, qc = -0.1;
  CHECK_NEAR(s, 0.1 * qa + 0.2 * qc, 1e-14);
  CHECK_NEAR(sd, 0.1 * 0.4 + 0.2 * -0.5, 1e-14);
  CHECK_NEAR(pen, std::abs(0.1 * qa + 0.2 * qc) - 0.001, 1e-14);
  // the joint-space law at the same (multi-turn) coordinates agrees
  const double q[2] = {qa, qc}, qd[2] = {0.4, -0.5};
  double s2, sd2, pen2;
  gear_mesh(*m, 0, q, qd, s2, sd2, pen2);
  CHECK_NEAR(s, s2, 1e-14);
  CHECK_NEAR(sd, sd2, 1e-14);
}

ARMDYN_TEST_MAIN()
