// SPDX-License-Identifier: BSD-3-Clause
// Massless bodies and singular inertias (finalize's check that every joint motion carries
// inertia) and the physical_inertia option of ModelBuilder.
#include <cmath>
#include <string>

#include "armdyn/algorithm/crba.hpp"
#include "armdyn/algorithm/dynamics.hpp"
#include "armdyn/algorithm/kkt.hpp"
#include "armdyn/builder/builder.hpp"
#include "armdyn/builder/weld.hpp"
#include "armdyn/data.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/kernels/joint_space.hpp"
#include "armdyn/kernels/kkt_factor.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;
using armdyn_test::kIdentityQuat;

namespace {

constexpr double kMass = 2.0;
const Vec3 kCom(0.1, 0.2, -0.5);
const Mat3 kInertia = Vec3(0.03, 0.02, 0.01).asDiagonal();

Mat3 rot_z(double a) { return Eigen::AngleAxisd(a, Vec3::UnitZ()).toRotationMatrix(); }
Mat3 rot_x(double a) { return Eigen::AngleAxisd(a, Vec3::UnitX()).toRotationMatrix(); }

/// A 2-DOF universal-like chain: yaw (z, in ground) and roll (x, in the massless link) through
/// the origin, a massless link between them (split in `pieces` massless bodies welded together)
/// and an arm below.
ModelBuilder gimbal(int pieces = 1) {
  ModelBuilder b;
  const Mat3 zero = Mat3::Zero();
  b.add_body("virtual", 0.0, zero, Vec3::Zero(), kIdentityQuat);
  b.add_revolute("yaw", "ground", "virtual", Vec3::Zero(), Vec3::UnitZ());
  std::string last = "virtual";
  for (int k = 1; k < pieces; ++k) {
    const std::string name = "virtual_" + std::to_string(k);
    b.add_body(name, 0.0, zero, Vec3(0.0, 0.0, 0.01 * k), kIdentityQuat);
    b.add_fixed(name + "_weld", last, name, Vec3::Zero());
    last = name;
  }
  b.add_body("arm", kMass, kInertia, kCom, kIdentityQuat);
  b.add_revolute("roll", last, "arm", Vec3::Zero(), Vec3::UnitX());
  return b;
}

/// The closed form: R = Rz(q1) Rx(q2), angular velocity q1' z + q2' Rz(q1) x, M = J^T I_O J with
/// I_O the arm's inertia about the pivot in world axes.
Eigen::Matrix2d gimbal_mass_matrix(double q1, double q2) {
  const Mat3 R = rot_z(q1) * rot_x(q2);
  const Mat3 pivot =
      kInertia + kMass * (kCom.squaredNorm() * Mat3::Identity() - kCom * kCom.transpose());
  const Mat3 io = R * pivot * R.transpose();
  Eigen::Matrix<double, 3, 2> J;
  J.col(0) = Vec3::UnitZ();
  J.col(1) = rot_z(q1) * Vec3::UnitX();
  return J.transpose() * io * J;
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

}  // namespace

TEST_CASE(massless_intermediate_link_gives_the_closed_form_mass_matrix) {
  const ModelPtr m = gimbal().finalize();
  CHECK(m->bodies[0].mass == 0.0);
  CHECK(m->mobility == 2 && m->joint_space_ok);
  Data d(*m);
  for (const auto& q :
       {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(0.7, -1.1), Eigen::Vector2d(-2.5, 2.9)}) {
    const VecX qv = q;
    const MatX M = crba(*m, d, qv);
    CHECK_MAT_NEAR(M, MatX(gimbal_mass_matrix(q[0], q[1])), 1e-14);
  }
}

TEST_CASE(massless_links_welded_together_merge_into_a_massless_composite) {
  const ModelPtr m = gimbal(3).finalize();
  const Welding* w = welding(*m);
  CHECK(w != nullptr);
  if (!w) return;
  const Model& wm = *w->model;
  CHECK(wm.nb == 2);
  CHECK(wm.bodies[0].mass == 0.0);
  CHECK(wm.bodies[0].position.allFinite());
  Data d(wm);
  const VecX q = Eigen::Vector2d(0.4, -0.3);
  CHECK_MAT_NEAR(MatX(crba(wm, d, q)), MatX(gimbal_mass_matrix(0.4, -0.3)), 1e-14);
}

TEST_CASE(massless_leaf_is_refused_naming_the_joint_and_the_body) {
  ModelBuilder b = armdyn_test::Pendulum().builder();
  b.add_body("tip", 0.0, Mat3::Zero(), Vec3(0, 0, -1.0), kIdentityQuat);
  b.add_revolute("tip_joint", "bob", "tip", Vec3(0, 0, -1.0), Vec3::UnitX());
  const std::string why = THROWN_MESSAGE(b.finalize(), ModelError);
  CHECK(contains(why, "joint 'tip_joint' carries no inertia"));
  CHECK(contains(why, "body 'tip' (mass 0 kg"));
  // the builder is unchanged: made fixed, the massless tip is accepted
  ModelBuilder ok = armdyn_test::Pendulum().builder();
  ok.add_body("tip", 0.0, Mat3::Zero(), Vec3(0, 0, -1.0), kIdentityQuat);
  ok.add_fixed("tip_joint", "bob", "tip", Vec3(0, 0, -1.0));
  CHECK(ok.finalize()->mobility == 1);
}

TEST_CASE(point_mass_on_its_own_axis_is_refused) {
  ModelBuilder b;
  b.add_body("bead", 1.0, Mat3::Zero(), Vec3(0, 0, -1.0), kIdentityQuat);
  b.add_revolute("spin", "ground", "bead", Vec3(0, 0, 0), Vec3::UnitZ());
  const std::string why = THROWN_MESSAGE(b.finalize(), ModelError);
  CHECK(contains(why, "'spin'") && contains(why, "'bead'"));
}

TEST_CASE(physical_inertia_option) {
  const Mat3 bad = Vec3(0.1, 0.1, 0.3).asDiagonal();  // 0.1 + 0.1 < 0.3
  ModelBuilder b;
  CHECK(b.physical_inertia());
  const std::string why =
      THROWN_MESSAGE(b.add_body("weird", 1.0, bad, Vec3::Zero(), kIdentityQuat), ModelError);
  CHECK(contains(why, "weird") && contains(why, "triangle") &&
        contains(why, "physical_inertia=False"));
  b.set_physical_inertia(false);
  CHECK(b.add_body("weird", 1.0, bad, Vec3(0, 0, -1), kIdentityQuat) == 0);
  // a round-off negative moment is clamped, with a warning in the model
  b.add_body("rod", 1.0, Vec3(1.0, 1.0, -5e-13).asDiagonal(), Vec3(0, 0, -2), kIdentityQuat);
  // beyond round-off it is refused in either mode
  CHECK_THROWS(
      b.add_body("flat", 1.0, Vec3(1.0, 1.0, -1e-9).asDiagonal(), Vec3::Zero(), kIdentityQuat),
      ModelError);
  b.add_revolute("hinge", "ground", "weird", Vec3::Zero(), Vec3::UnitX());
  b.add_revolute("hinge2", "weird", "rod", Vec3(0, 0, -1), Vec3::UnitY());
  const ModelPtr m = b.finalize();
  CHECK(m->bodies[1].inertia(2, 2) == 0.0);
  CHECK(m->warnings.size() == 1 && contains(m->warnings[0], "body 'rod'") &&
        contains(m->warnings[0], "clamped"));
  // hinge about x through the origin: J_xx + m l^2 = 0.1 + 1, plus the rod (1 kg at 2 m:
  // 4 + its J_xx 1)
  Data d(*m);
  const VecX q = VecX::Zero(2);
  CHECK_NEAR(crba(*m, d, q)(0, 0), 0.1 + 1.0 + 4.0 + 1.0, 1e-13);
}

TEST_CASE(massless_link_dynamics_refined_range_space_equals_the_augmented_solve) {
  const ModelPtr m = gimbal().finalize();
  CHECK(light_bodies(*m).massless_only);
  Data d(*m);
  const VecX q = Eigen::Vector2d(0.4, -1.1), qd = Eigen::Vector2d(1.3, -0.7);
  VecX u, v, vd(m->nv);
  state_from_joints(*m, q, qd, u, v);
  body_accelerations(*m, d, 0.0, u.data(), v.data(), vd.data());
  CHECK(d.stats.augmented_solves == 0);  // the refined solve converged
  CHECK(constraint_residual(d.ce, m->nc, vd) < 1e-14);
  // the dense LU of [Gamma zeta^T; zeta 0] at the same evaluation
  VecX vd2(m->nv), delta2(m->nc);
  CHECK(d.kkt.accelerations_augmented(d.ce, m->nc, d.eta, vd2, delta2));
  CHECK_MAT_NEAR(vd.tail<6>(), vd2.tail<6>(), 1e-13 * vd2.cwiseAbs().maxCoeff());
  // and the joint-space path
  Data dj(*m);
  const VecX qdd = forward_dynamics(*m, dj, q, qd, VecX::Zero(2), 0.0, DynamicsMethod::Aba);
  VecX qdd2 = forward_dynamics(*m, dj, q, qd, VecX::Zero(2), 0.0, DynamicsMethod::Cartesian);
  CHECK_MAT_NEAR(qdd2, qdd, 1e-12 * qdd.cwiseAbs().maxCoeff());
}

ARMDYN_TEST_MAIN()
