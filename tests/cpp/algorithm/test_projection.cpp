// SPDX-License-Identifier: BSD-3-Clause
// The projection stage (armdyn/algorithm/projection.hpp): residuals of known violations, the
// projection landing on f = 0 and zeta v = rhs to round-off (and staying there), the drive rows
// enforced only when they take part, and the singularity diagnosis of a regular model.
#include <cmath>

#include "armdyn/algorithm/kinematics.hpp"
#include "armdyn/algorithm/projection.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

TEST_CASE(residuals_of_a_known_violation) {
  // the bob 0.02 off its hinge along x, moving at 0.3 m/s along z: the hinge point rows
  // are off by exactly that (the body does not turn, so the rotation rows hold)
  const armdyn_test::Pendulum p;
  const ModelPtr m = p.model();
  Data d(*m);
  VecX u = m->u0, v = VecX::Zero(6);
  u[0] += 0.02;
  v[2] = 0.3;
  double rf = 0, rv = 0;
  residuals(*m, d, 0.0, u.data(), v.data(), rf, rv);
  CHECK_NEAR(rf, 0.02, 1e-15);
  CHECK_NEAR(rv, 0.3, 1e-15);
  // the same from the loaded evaluation, for other velocities
  v[2] = -0.7;
  loaded_residuals(*m, d, v.data(), rf, rv);
  CHECK_NEAR(rf, 0.02, 1e-15);
  CHECK_NEAR(rv, 0.7, 1e-15);
}

TEST_CASE(projection_restores_the_constraints) {
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  Data d(*m);
  VecX u = m->u0, v(m->nv);
  for (int i = 0; i < m->nq; ++i) u[i] += 1e-3 * std::cos(3.1 * i);
  for (int i = 0; i < m->nv; ++i) v[i] = std::sin(1.3 * i);
  double rf = 0, rv = 0;
  residuals(*m, d, 0.0, u.data(), v.data(), rf, rv);
  CHECK(rf > 1e-5 && rv > 1e-2);
  project(*m, d, 0.0, u.data(), v.data(), Metric::Mass);
  CHECK(d.stats.position_projections == 1 && d.stats.velocity_projections == 1);
  CHECK(d.stats.newton_iterations >= 1);
  residuals(*m, d, 0.0, u.data(), v.data(), rf, rv);
  CHECK(rf < 1e-12);
  CHECK(rv < 1e-12);
  for (int b = 0; b < m->nb; ++b) CHECK_NEAR(u.segment<4>(7 * b + 3).norm(), 1.0, 1e-14);
  // projecting again moves nothing
  const VecX u1 = u, v1 = v;
  project(*m, d, 0.0, u.data(), v.data(), Metric::Identity);
  CHECK_MAT_NEAR(u, u1, 1e-13);
  CHECK_MAT_NEAR(v, v1, 1e-12);
}

TEST_CASE(pendulum_projected_onto_its_circle) {
  // the bob pushed off its circle and given a radial velocity: afterwards the centre of mass
  // is at distance L from the hinge and moves perpendicular to the rod
  const armdyn_test::Pendulum p;
  const ModelPtr m = p.model();
  Data d(*m);
  VecX u = m->u0, v = VecX::Zero(6);
  u.head<3>() += Vec3(0.05, -0.03, 0.04);
  v.head<3>() = Vec3(0.4, 0.2, -0.5);
  project(*m, d, 0.0, u.data(), v.data(), Metric::Mass);
  const Vec3 r = u.head<3>();
  CHECK_NEAR(r.norm(), p.L, 1e-12);
  CHECK_NEAR(r.y(), 0.0, 1e-12);
  CHECK_NEAR(r.dot(v.head<3>()), 0.0, 1e-12);
  CHECK_NEAR(v[1], 0.0, 1e-12);
}

TEST_CASE(drive_rows_only_when_they_take_part) {
  ModelBuilder b = armdyn_test::Pendulum().builder();
  b.add_drive("hinge", Profile::constant(0.5));
  const ModelPtr m = b.finalize();
  Data d(*m);
  VecX u, v;
  state_from_joints(*m, VecX::Constant(1, 0.2), VecX::Zero(1), u, v);
  // joint rows only: the state is on them already and stays at 0.2
  d.nrows = m->nc_joint;
  VecX uj = u, vj = v;
  project(*m, d, 0.0, uj.data(), vj.data(), Metric::Mass);
  load_kinematics(*m, d, uj.data(), nullptr);
  CHECK_NEAR(coord_value(*m, d.kin, 0), 0.2, 1e-13);
  // all rows: onto the drive's value
  d.nrows = m->nc;
  project(*m, d, 0.0, u.data(), v.data(), Metric::Mass);
  load_kinematics(*m, d, u.data(), nullptr);
  CHECK_NEAR(coord_value(*m, d.kin, 0), 0.5, 1e-12);
}

TEST_CASE(no_diagnosis_for_a_regular_jacobian) {
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  Data d(*m);
  CHECK(diagnose_singularity(*m, d, 0.0, m->u0.data(), m->v0.data()).empty());
}

ARMDYN_TEST_MAIN()
