// SPDX-License-Identifier: BSD-3-Clause
// The kinematics stage (armdyn/algorithm/kinematics.hpp): a pendulum's centre of mass on its
// circle from (u, v) and from its joint angle, the state rate u' = S(u) v against differences,
// and the multi-turn tracking of an angle over several revolutions.
#include <cmath>

#include "armdyn/algorithm/kinematics.hpp"
#include "armdyn/math/quaternion.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

TEST_CASE(pendulum_pose_and_velocity_on_its_circle) {
  armdyn_test::Pendulum p;
  p.phi0 = 0.4;
  const ModelPtr m = p.model();
  Data d(*m);
  const double q = 0.7, qd = -1.3, phi = p.phi0 + q;
  // from the joint coordinate
  load_joint_kinematics(*m, d, VecX::Constant(1, q), VecX::Constant(1, qd));
  const Vec3 r(-p.L * std::sin(phi), 0.0, -p.L * std::cos(phi));
  CHECK_MAT_NEAR(d.kin[0].x, r, 1e-14);
  CHECK_MAT_NEAR(d.kin[0].xd, Vec3(qd * Vec3::UnitY().cross(r)), 1e-14);
  // the body turned by phi about y (its assembly orientation is the identity at phi0)
  const Mat3 Ry = Eigen::AngleAxisd(q, Vec3::UnitY()).toRotationMatrix();
  CHECK_MAT_NEAR(d.kin[0].R, Ry, 1e-14);
  CHECK_MAT_NEAR(d.kin[0].w, Vec3(0.0, qd, 0.0), 1e-14);
  // the same from the Cartesian state (u, v), and the angle read back from it
  VecX u, v;
  state_from_joints(*m, VecX::Constant(1, q), VecX::Constant(1, qd), u, v);
  load_kinematics(*m, d, u.data(), v.data());
  CHECK_MAT_NEAR(d.kin[0].x, r, 1e-14);
  CHECK_MAT_NEAR(d.kin[0].xd, Vec3(qd * Vec3::UnitY().cross(r)), 1e-14);
  CHECK_NEAR(d.jets.get(*m, d.kin, 0).val, q, 1e-14);
  CHECK_NEAR(d.jets.get(*m, d.kin, 0).rate, qd, 1e-14);
  // at rest
  load_kinematics(*m, d, u.data(), nullptr);
  CHECK(d.kin[0].xd.norm() == 0.0 && d.kin[0].w.norm() == 0.0);
  CHECK_NEAR(d.jets.get(*m, d.kin, 0).rate, 0.0, 0.0);
}

TEST_CASE(udot_is_the_state_rate) {
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  VecX v(m->nv), ud(m->nq);
  for (int i = 0; i < m->nv; ++i) v[i] = std::cos(0.4 * i);
  udot(*m, m->u0.data(), v.data(), ud.data());
  const double h = 1e-6;
  const VecX fd =
      (armdyn_test::advance(*m, m->u0, v, h) - armdyn_test::advance(*m, m->u0, v, -h)) / (2 * h);
  CHECK_MAT_NEAR(ud, fd, 1e-9);
}

TEST_CASE(tracking_follows_an_angle_over_turns) {
  const armdyn_test::Pendulum p;
  const ModelPtr m = p.model();
  Data d(*m);
  CHECK(d.track_ref.size() == 1 && d.track_ref[0] == 0.0);
  // steps of less than half a turn: the tracked angle is the unwrapped one, the raw one is not
  for (double q = 0.0; q < 4.0 * M_PI; q += 0.9) {
    VecX u, v;
    state_from_joints(*m, VecX::Constant(1, q), VecX::Zero(1), u, v);
    load_kinematics(*m, d, u.data(), nullptr);
    const double raw = coord_value(*m, d.kin, 0);
    CHECK(std::abs(raw) <= M_PI + 1e-12);
    CHECK_NEAR(tracked(d, 0, raw), q, 1e-12);
    commit_tracking(*m, d);
    CHECK_NEAR(d.track_ref[0], q, 1e-12);
  }
}

ARMDYN_TEST_MAIN()
