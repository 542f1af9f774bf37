// SPDX-License-Identifier: BSD-3-Clause
// The composite-rigid-body mass matrix (armdyn/algorithm/crba.hpp): a planar two-link arm by
// hand, and on a spatial tree the kinetic energy 1/2 qd^T M qd against sum 1/2 m |v|^2 +
// 1/2 w^T J w of the bodies' Cartesian velocities.
#include <cmath>

#include "armdyn/algorithm/crba.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/kernels/joint_space.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

TEST_CASE(two_link_arm_by_hand) {
  const armdyn_test::TwoLink arm;
  const ModelPtr m = arm.model();
  Data d(*m);
  for (double q2 : {0.0, 0.6, -2.1, 3.0}) {
    const Eigen::Vector2d q(0.4, q2);
    CHECK_MAT_NEAR(crba(*m, d, q), arm.mass_matrix(q2), 1e-13);
  }
  // M does not depend on the first joint's angle
  const MatX a = crba(*m, d, Eigen::Vector2d(0.0, 0.5));
  const MatX b = crba(*m, d, Eigen::Vector2d(2.5, 0.5));
  CHECK_MAT_NEAR(a, b, 1e-14);
}

TEST_CASE(kinetic_energy_of_a_spatial_tree) {
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  Data d(*m);
  VecX q(4), qd(4);
  q << 0.3, -1.2, 0.07, 2.0;
  qd << 0.9, -0.4, 0.25, 1.6;
  const MatX M = crba(*m, d, q);
  CHECK_MAT_NEAR(M, M.transpose(), 1e-14);
  CHECK(Eigen::LLT<MatX>(M).info() == Eigen::Success);
  VecX u, v;
  state_from_joints(*m, q, qd, u, v);
  double t = 0.0;
  for (int b = 0; b < m->nb; ++b) {
    const Vec3 xd = v.segment<3>(6 * b), w = v.segment<3>(6 * b + 3);
    t += 0.5 * m->bodies[b].mass * xd.squaredNorm() + 0.5 * w.dot(m->bodies[b].inertia * w);
  }
  CHECK_NEAR(0.5 * qd.dot(M * qd), t, 1e-13);
  // every unit rate: the diagonal is twice the kinetic energy of that joint's motion alone
  for (int c = 0; c < 4; ++c) {
    state_from_joints(*m, q, VecX::Unit(4, c), u, v);
    double tc = 0.0;
    for (int b = 0; b < m->nb; ++b) {
      const Vec3 xd = v.segment<3>(6 * b), w = v.segment<3>(6 * b + 3);
      tc += 0.5 * m->bodies[b].mass * xd.squaredNorm() + 0.5 * w.dot(m->bodies[b].inertia * w);
    }
    CHECK_NEAR(M(c, c), 2 * tc, 1e-13);
  }
  CHECK_MAT_NEAR(mass_matrix_at(*m, d, q), M, 0.0);
}

TEST_CASE(refuses_bad_input) {
  const ModelPtr m = armdyn_test::TwoLink().model();
  Data d(*m);
  CHECK_THROWS(crba(*m, d, Eigen::Vector3d(0, 0, 0)), ModelError);
  CHECK_THROWS(crba(*m, d, Eigen::Vector2d(0, NAN)), ModelError);
}

ARMDYN_TEST_MAIN()
