// SPDX-License-Identifier: BSD-3-Clause
// The force elements' derivatives (armdyn/algorithm/force_derivatives.hpp): central differences
// of F = rnea(model without the elements) - rnea(model with them) on the spatial arm with every
// element kind; the function adds into its outputs (not zeroing them) and allocates nothing once
// the Data exists. (tests/algorithm/test_force_derivatives.py covers each element kind, floating
// bases and the nonsmooth points through the Python binding.)
#include <atomic>
#include <cstdlib>

#include "alloc_counter.hpp"
#include "armdyn/algorithm/force_derivatives.hpp"
#include "armdyn/algorithm/rnea.hpp"
#include "armdyn/builder/builder.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

namespace {
ModelPtr arm(bool elements) {
  ModelBuilder b = armdyn_test::spatial_arm_builder();
  if (!elements) return b.finalize();
  const Profile sine = Profile::sine(0.6, 1.1, 0.3, 0.5);
  const Vec3 at(0.5, 0.2, 0.4);
  b.add_body_load("wrist", Vec3(1.0, -2.0, 3.0), Vec3(0.2, 0.1, -0.3), &at, &sine);
  b.add_spring_damper("s1", "ground", Vec3(0.3, -0.5, 0.9), "wrist", Vec3(0.6, 0.1, 0.4), 60.0, 2.5,
                      0.3);
  b.add_spring_damper("s2", "base", Vec3(0.1, 0.1, 0.3), "slide", Vec3(0.4, 0.2, 0.6), 90.0, 1.0,
                      -1.0);
  b.add_joint_spring_damper("yaw", 20.0, 1.5, 0.2);
  b.add_joint_friction("reach", 2.0, 0.7, 0.2);
  b.add_motor("roll", sine, 30.0, 2.0, 1e3, nullptr);
  return b.finalize();
}

// F = rnea(bare) - rnea(full) at qdd = 0
VecX element_force(const Model& bare, Data& db, const Model& full, Data& df, const VecX& q,
                   const VecX& qd, double t) {
  const VecX z = VecX::Zero(qd.size());
  const VecX a = rnea(bare, db, q, qd, z, t);
  return a - rnea(full, df, q, qd, z, t);
}
}  // namespace

TEST_CASE(equals_central_differences_of_inverse_dynamics) {
  const ModelPtr bare = arm(false), full = arm(true);
  Data db(*bare), df(*full);
  VecX q(4), qd(4);
  q << 0.4, -0.7, 0.05, 1.1;
  qd << 0.3, -0.2, 0.5, 0.9;
  const double t = 0.35, h = 1e-5;
  MatX dq = MatX::Zero(4, 4), dqd = MatX::Zero(4, 4), fq(4, 4), fqd(4, 4);
  joint_space_kinematics(*full, q, qd, df.kin, df.rne);
  add_force_element_derivatives(*full, df, q.data(), qd.data(), t, dq, dqd);
  for (int k = 0; k < 4; ++k) {
    const VecX e = VecX::Unit(4, k) * h;
    fq.col(k) = (element_force(*bare, db, *full, df, q + e, qd, t) -
                 element_force(*bare, db, *full, df, q - e, qd, t)) /
                (2 * h);
    fqd.col(k) = (element_force(*bare, db, *full, df, q, qd + e, t) -
                  element_force(*bare, db, *full, df, q, qd - e, t)) /
                 (2 * h);
  }
  const double scale = std::max(fq.cwiseAbs().maxCoeff(), fqd.cwiseAbs().maxCoeff());
  CHECK(scale > 1.0);
  CHECK_MAT_NEAR(dq, fq, 1e-7 * scale);
  CHECK_MAT_NEAR(dqd, fqd, 1e-7 * scale);
}

TEST_CASE(adds_into_its_outputs_and_allocates_nothing) {
  const ModelPtr full = arm(true);
  Data d(*full);
  VecX q(4), qd(4);
  q << -0.3, 0.9, 0.02, -1.4;
  qd << 0.6, 0.1, -0.4, 0.2;
  MatX dq = MatX::Zero(4, 4), dqd = MatX::Zero(4, 4);
  joint_space_kinematics(*full, q, qd, d.kin, d.rne);
  add_force_element_derivatives(*full, d, q.data(), qd.data(), 0.1, dq, dqd);
  MatX aq = MatX::Constant(4, 4, 2.0), aqd = MatX::Constant(4, 4, -1.0);
  const long before = g_allocations.load();
  for (int k = 0; k < 3; ++k) {
    joint_space_kinematics(*full, q, qd, d.kin, d.rne);
    add_force_element_derivatives(*full, d, q.data(), qd.data(), 0.1, aq, aqd);
  }
  CHECK(g_allocations.load() == before);
  CHECK_MAT_NEAR(aq, (MatX::Constant(4, 4, 2.0) + 3 * dq).eval(), 1e-12);
  CHECK_MAT_NEAR(aqd, (MatX::Constant(4, 4, -1.0) + 3 * dqd).eval(), 1e-12);
  CHECK(has_force_elements(*full));
  CHECK(!has_force_elements(*arm(false)));
}

ARMDYN_TEST_MAIN()
