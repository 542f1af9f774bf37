// SPDX-License-Identifier: BSD-3-Clause
// The energy stage (armdyn/algorithm/energy.hpp): kinetic and potential energy by hand on a
// spatial arm (1/2 m |v|^2 + 1/2 w^T J w, -m g . x), a pendulum's 1/2 I_O phi'^2 and
// -m g L cos(phi), and the elastic energy of a point spring and a joint spring.
#include <cmath>

#include "armdyn/algorithm/energy.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

TEST_CASE(energy_by_hand) {
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  Data d(*m);
  VecX v(m->nv);
  for (int i = 0; i < m->nv; ++i) v[i] = std::sin(0.7 * i + 0.2);
  double ke = 0.0, pe = 0.0;
  energy(*m, d, m->u0.data(), v.data(), ke, pe);
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

TEST_CASE(pendulum_energy) {
  const armdyn_test::Pendulum p;
  const ModelPtr m = p.model();
  Data d(*m);
  const double phi = 1.1, w = -2.7;
  VecX u, v;
  state_from_joints(*m, VecX::Constant(1, phi), VecX::Constant(1, w), u, v);
  double ke, pe;
  energy(*m, d, u.data(), v.data(), ke, pe);
  CHECK_NEAR(ke, 0.5 * p.io() * w * w, 1e-13);
  CHECK_NEAR(pe, -p.m * p.g * p.L * std::cos(phi), 1e-13);
}

TEST_CASE(spring_energy) {
  // no gravity: a point spring stretched by 0.1 beyond its rest length, and a joint spring
  // turned 3 rad + one turn past its rest angle (the energy of the wrapped difference)
  ModelBuilder b(Vec3::Zero());
  const Mat3 in = Vec3(0.1, 0.1, 0.1).asDiagonal();
  b.add_body("slider", 1.0, in, Vec3(1.0, 0, 0), armdyn_test::kIdentityQuat);
  b.add_free("free", "slider");
  b.add_spring_damper("s", "ground", Vec3(0, 0, 0), "slider", Vec3(1.0, 0, 0), 200.0, 3.0, 0.9);
  b.add_body("wheel", 1.0, in, Vec3(0, 2.0, 0), armdyn_test::kIdentityQuat);
  b.add_revolute("axle", "ground", "wheel", Vec3(0, 2.0, 0), Vec3::UnitZ());
  b.add_joint_spring_damper("axle", 40.0, 0.0, 0.5);
  const ModelPtr m = b.finalize();
  Data d(*m);
  VecX u = m->u0;
  const Vec3 axis = Vec3::UnitZ();
  u.segment<4>(7 * 1 + 3) = quat_exp(Vec3((3.0 + 2 * M_PI) * axis));
  double ke, pe;
  energy(*m, d, u.data(), nullptr, ke, pe);  // at rest
  const double dq = 3.0 - 0.5;
  CHECK_NEAR(ke, 0.0, 0.0);
  CHECK_NEAR(pe, 0.5 * 200.0 * 0.1 * 0.1 + 0.5 * 40.0 * dq * dq, 1e-11);
}

ARMDYN_TEST_MAIN()
