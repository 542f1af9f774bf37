// SPDX-License-Identifier: BSD-3-Clause
// Joint-space dynamics of trees with ideal gears (armdyn/algorithm/tree_dynamics.hpp): a gear
// train's reflected inertia in closed form, the gear rows kept by the accelerations, and the
// mass matrix equal to crba().
#include <cmath>

#include "armdyn/algorithm/crba.hpp"
#include "armdyn/algorithm/dynamics.hpp"
#include "armdyn/algorithm/tree_dynamics.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

TEST_CASE(gear_train_reflected_inertia) {
  // two wheels on fixed axes about z joined by an ideal gear r_a qa + r_b qb = 0, a torque tau on
  // a: power balance tau qa' = (J_a + J_b (r_a/r_b)^2) qa' qa''
  const double ja = 0.02, jb = 0.08, ra = 0.05, rb = 0.15, tau = 1.7;
  ModelBuilder b(Vec3(0, 0, -9.81));
  b.add_body("a", 1.0, Vec3(0.015, 0.015, ja).asDiagonal(), Vec3(0, 0, 0),
             armdyn_test::kIdentityQuat);
  b.add_body("b", 2.0, Vec3(0.05, 0.05, jb).asDiagonal(), Vec3(ra + rb, 0, 0),
             armdyn_test::kIdentityQuat);
  b.add_revolute("ja", "ground", "a", Vec3(0, 0, 0), Vec3::UnitZ());
  b.add_revolute("jb", "ground", "b", Vec3(ra + rb, 0, 0), Vec3::UnitZ());
  b.add_gear("g", "ja", "jb", ra, rb);
  b.add_joint_torque("ja", Profile::constant(tau));
  const ModelPtr m = b.finalize();
  TreeDynamics td(*m);
  CHECK(td.n() == 2);
  CHECK(td.dof() == 1);
  const double q[2] = {0.3, -0.3 * ra / rb}, qd[2] = {2.0, -2.0 * ra / rb};
  double qdd[2];
  td.accelerations(0.0, q, qd, nullptr, nullptr, qdd);
  const double expected = tau / (ja + jb * (ra / rb) * (ra / rb));
  CHECK_NEAR(qdd[0], expected, 1e-12);
  CHECK_NEAR(ra * qdd[0] + rb * qdd[1], 0.0, 1e-13);  // the gear row holds
  // an extra joint torque on b reflects through the ratio: tau_b (-ra/rb) on a
  const double extra[2] = {0.0, 0.9};
  td.accelerations(0.0, q, qd, nullptr, extra, qdd);
  CHECK_NEAR(qdd[0], (tau - 0.9 * ra / rb) / (ja + jb * (ra / rb) * (ra / rb)), 1e-12);
  // project() removes a violation of the gear rows
  double qp[2] = {0.3, 0.0}, qdp[2] = {1.0, 0.0};
  td.project(qp, qdp);
  CHECK_NEAR(ra * qp[0] + rb * qp[1], 0.0, 1e-15);
  CHECK_NEAR(ra * qdp[0] + rb * qdp[1], 0.0, 1e-15);
}

TEST_CASE(without_gears_equals_the_joint_space_algorithms) {
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  TreeDynamics td(*m);
  Data d(*m);
  VecX q(4), qd(4);
  q << 0.2, -0.5, 0.04, 1.0;
  qd << 1.0, 0.5, -0.2, -0.7;
  CHECK_MAT_NEAR(td.mass_matrix(q.data()), crba(*m, d, q), 1e-13);
  VecX qdd(4);
  td.accelerations(0.0, q.data(), qd.data(), nullptr, nullptr, qdd.data());
  CHECK_MAT_NEAR(qdd, forward_dynamics(*m, d, q, qd, VecX::Zero(4)), 1e-12);
}

ARMDYN_TEST_MAIN()
