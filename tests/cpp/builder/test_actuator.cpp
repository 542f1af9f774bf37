// SPDX-License-Identifier: BSD-3-Clause
// Actuators (ModelBuilder::add_actuator): the gear-reduced rotor adds N^2 J to the joint-space
// mass matrix's diagonal (Pinocchio's armature) and nothing else, the gyroscopic rotor adds
// J [[1, N], [N, N^2]] on coaxial joints, a ball-screw rotor follows a prismatic joint, the
// refusals leave the builder unchanged, and coord_actuation_value is the input and motor part of
// coord_force_value.
#include <cmath>

#include "armdyn/algorithm/crba.hpp"
#include "armdyn/algorithm/forces.hpp"
#include "armdyn/builder/builder.hpp"
#include "armdyn/data.hpp"
#include "armdyn/errors.hpp"
#include "check.hpp"

using namespace armdyn;

namespace {

const Vec4 kQ(1, 0, 0, 0);

// two links on joints about world y (or z, coaxial), then a slider along x
ModelBuilder arm(const Vec3& axis2) {
  ModelBuilder b;
  b.add_body("a", 1.0, Vec3(0.01, 0.02, 0.02).asDiagonal(), Vec3(0.25, 0, 0), kQ);
  b.add_body("b", 0.5, Vec3(0.005, 0.01, 0.01).asDiagonal(), Vec3(0.75, 0, 0), kQ);
  b.add_body("c", 0.3, Vec3(0.001, 0.001, 0.001).asDiagonal(), Vec3(1.2, 0, 0), kQ);
  b.add_revolute("j1", "ground", "a", Vec3(0, 0, 0), axis2);
  b.add_revolute("j2", "a", "b", Vec3(0.5, 0, 0), axis2);
  b.add_prismatic("s", "b", "c", Vec3(1.0, 0, 0), Vec3(1, 0, 0));
  return b;
}

MatX mass(const ModelPtr& m, const VecX& q) {
  Data d(*m);
  return crba(*m, d, q);
}

}  // namespace

TEST_CASE(reduced_rotors_add_the_armature_to_the_diagonal) {
  const VecX q = (VecX(3) << 0.4, -0.9, 0.05).finished();
  ModelBuilder b = arm(Vec3(0, 1, 0));
  const MatX M0 = mass(b.finalize(), q);
  const double lead = 4e-3;
  b.add_actuator("j1", 100.0, 5e-5);
  b.add_actuator("j2", -60.0, 2e-5);
  b.add_actuator("s", 2 * M_PI / lead, 1e-6);  // ball screw: rad/m
  const ModelPtr m = b.finalize();
  CHECK(m->actuators.size() == 3);
  CHECK(m->independent.n == 3 && m->coords.size() == 6);
  MatX armature = MatX::Zero(3, 3);
  armature.diagonal() << 100.0 * 100.0 * 5e-5, 60.0 * 60.0 * 2e-5,
      std::pow(2 * M_PI / lead, 2) * 1e-6;
  CHECK_MAT_NEAR(mass(m, q), M0 + armature, 1e-14);
}

TEST_CASE(a_gyroscopic_rotor_on_a_coaxial_carrier_couples_to_it) {
  const VecX q = (VecX(3) << 0.4, -0.9, 0.05).finished();
  ModelBuilder b = arm(Vec3(0, 0, 1));
  const MatX M0 = mass(b.finalize(), q);
  const double N = 30.0, J = 3e-4;
  b.add_actuator("j2", N, J, 1.0, 0.0, 0.0, nullptr, true);
  MatX extra = MatX::Zero(3, 3);
  extra.topLeftCorner<2, 2>() << J, N * J, N * J, N * N * J;
  CHECK_MAT_NEAR(mass(b.finalize(), q), M0 + extra, 1e-15);
}

TEST_CASE(refusals_leave_the_builder_unchanged) {
  ModelBuilder b = arm(Vec3(0, 1, 0));
  b.add_actuator("j1", 10.0, 1e-4);
  const size_t nb = b.draft().bodies.size(), nj = b.draft().joints.size(),
               ng = b.draft().gear_constraints.size(), nf = b.draft().coord_forces.size();
  MotorSpec bad;
  bad.voltage = -24.0;
  CHECK_THROWS(b.add_actuator("nope", 10.0, 1e-4), ModelError);
  CHECK_THROWS(b.add_actuator("j1", 10.0, 1e-4), ModelError);
  CHECK_THROWS(b.add_actuator("j2", 0.0, 1e-4), ModelError);
  CHECK_THROWS(b.add_actuator("j2", INFINITY, 1e-4), ModelError);
  CHECK_THROWS(b.add_actuator("j2", 10.0, -1e-4), ModelError);
  CHECK_THROWS(b.add_actuator("j2", 10.0, 1e-4, 0.0), ModelError);
  CHECK_THROWS(b.add_actuator("j2", 10.0, 1e-4, 1.5), ModelError);
  CHECK_THROWS(b.add_actuator("j2", 10.0, 1e-4, 1.0, -1.0), ModelError);
  CHECK_THROWS(b.add_actuator("j2", 10.0, 1e-4, 1.0, 0.0, NAN), ModelError);
  CHECK_THROWS(b.add_actuator("j2", 10.0, 1e-4, 1.0, 0.0, 0.0, &bad), ModelError);
  CHECK(b.draft().bodies.size() == nb && b.draft().joints.size() == nj);
  CHECK(b.draft().gear_constraints.size() == ng && b.draft().coord_forces.size() == nf);
  CHECK(b.draft().actuators.size() == 1);
}

TEST_CASE(coord_actuation_value_is_the_input_and_motor_part) {
  CoordForce cf;
  cf.stiffness = 3.0;
  cf.damping = 0.5;
  cf.coulomb = 0.2;
  cf.has_input = true;
  cf.input = Profile::constant(1.5);
  cf.motor = true;
  cf.reference = Profile::constant(0.4);
  cf.kp = 10.0;
  cf.kd = 2.0;
  cf.torque_limit = 3.0;
  const double q = 0.1, qd = -0.3;
  const double act = coord_actuation_value(cf, true, q, qd, 0.0);
  // input 1.5, motor 10 (0.4 - 0.1) + 2 (0 + 0.3) = 3.6 clamped at 3
  CHECK_NEAR(act, 4.5, 1e-15);
  const double passive = -3.0 * q - 0.5 * qd - 0.2 * std::tanh(qd / cf.v_smooth);
  CHECK_NEAR(coord_force_value(cf, true, q, qd, 0.0), passive + act, 1e-15);
}

ARMDYN_TEST_MAIN()
