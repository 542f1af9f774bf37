// SPDX-License-Identifier: BSD-3-Clause
// What a model reports about itself (armdyn/model/properties.hpp): the independent names and
// limits of a coupled model against its coordinates written out, the rotors' reflected inertia
// against the mass matrix with and without the actuators (a second method), with_kkt_path,
// and the builder's add_fixed at the child's centre of mass; Profile::eval over an array.
#include <cmath>
#include <limits>

#include "armdyn/algorithm/crba.hpp"
#include "armdyn/builder/builder.hpp"
#include "armdyn/data.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/kernels/block_sparse.hpp"
#include "armdyn/model/properties.hpp"
#include "check.hpp"

using namespace armdyn;

namespace {

const Vec4 kQ(1, 0, 0, 0);
constexpr double kInf = std::numeric_limits<double>::infinity();

bool same(const VecX& a, const VecX& b) {
  return a.size() == b.size() && (a.array() == b.array()).all();
}

// ra (revolute) -> rb (revolute, follows ra: 2 q + 0.1) -> pc (prismatic); limits on ra and pc
ModelBuilder coupled(bool actuators, bool gyroscopic = false) {
  ModelBuilder b;
  const Mat3 I = Vec3(0.01, 0.02, 0.03).asDiagonal();
  b.add_body("a", 1.0, I, Vec3(0.5, 0, 0), kQ);
  b.add_body("b", 0.7, I, Vec3(1.5, 0, 0), kQ);
  b.add_body("c", 0.4, I, Vec3(2.5, 0, 0), kQ);
  b.add_revolute("ra", "ground", "a", Vec3(0, 0, 0), Vec3(0, 1, 0));
  b.add_revolute("rb", "a", "b", Vec3(1, 0, 0), Vec3(0, 1, 0));
  b.add_prismatic("pc", "b", "c", Vec3(2, 0, 0), Vec3(1, 0, 0));
  b.add_coupling("k", "rb", "ra", 2.0, 0.1);
  b.set_joint_limits("ra", -1.0, 2.0, 5.0, 0.0);
  b.set_joint_limits("pc", -1e300, 0.5, 0.0, 3.0);
  if (actuators) {
    b.add_actuator("ra", 10.0, 2e-4);
    b.add_actuator("pc", -50.0, 1e-5, 1.0, 0.0, 0.0, nullptr, gyroscopic);
  }
  return b;
}

}  // namespace

TEST_CASE(independent_names_and_limits_skip_the_followers) {
  const ModelPtr m = coupled(false).finalize();
  CHECK(m->q_names.size() == 3);
  const std::vector<int> idx = independent_coord_indices(*m);
  CHECK(idx == std::vector<int>({0, 2}));
  const std::vector<std::string> names = independent_coord_names(*m);
  CHECK(names.size() == 2 && names[0] == m->q_names[0] && names[1] == m->q_names[2]);
  CHECK(independent_dof_names(*m) == names);
  CHECK(joint_type_names(*m) == std::vector<std::string>({"revolute", "revolute", "prismatic"}));
  CHECK(names_of(m->joints) == std::vector<std::string>({"ra", "rb", "pc"}));
  CHECK(same(coord_limits(*m, LimitKind::Lower), Eigen::Vector2d(-1.0, -kInf)));
  CHECK(same(coord_limits(*m, LimitKind::Upper), Eigen::Vector2d(2.0, 0.5)));
  CHECK(same(coord_limits(*m, LimitKind::Effort), Eigen::Vector2d(5.0, kInf)));
  CHECK(same(coord_limits(*m, LimitKind::Velocity), Eigen::Vector2d(kInf, 3.0)));
  const std::vector<CouplingInfo> cs = couplings(*m);
  CHECK(cs.size() == 1 && cs[0].name == "k" && cs[0].follower == "rb" && cs[0].leader == "ra");
  CHECK_NEAR(cs[0].multiplier, 2.0, 0.0);
  CHECK_NEAR(cs[0].offset, 0.1, 0.0);
  CHECK_MAT_NEAR(body_masses(*m), Eigen::Vector3d(1.0, 0.7, 0.4), 0.0);
}

TEST_CASE(reflected_inertia_is_what_the_rotors_add_to_the_mass_matrix) {
  const ModelPtr bare = coupled(false).finalize(), geared = coupled(true).finalize();
  const VecX J = reflected_inertia(*geared);
  // the armatures: N^2 J (a ball screw's N in rad/m); the gyroscopic rotor turns at N qdot
  // carrying J: the same N^2 J
  CHECK_MAT_NEAR(J, Eigen::Vector2d(100.0 * 2e-4, 2500.0 * 1e-5), 1e-18);
  CHECK_MAT_NEAR(reflected_inertia(*coupled(true, true).finalize()), J, 1e-18);
  CHECK_MAT_NEAR(reflected_inertia(*bare), Eigen::Vector2d::Zero(), 0.0);
  const Eigen::Vector2d q(0.3, -0.1);
  Data db(*bare), dg(*geared);
  const MatX diff = crba(*geared, dg, q) - crba(*bare, db, q);
  CHECK_MAT_NEAR(diff.diagonal(), J, 1e-12);
  // the actuators' dofs: the independent dof of each actuated joint
  CHECK(independent_dof(*geared, geared->joints[geared->actuators[0].joint].coord0) == 0);
  CHECK(independent_dof(*geared, geared->joints[geared->actuators[1].joint].coord0) == 1);
}

TEST_CASE(with_kkt_path_copies_the_model_on_the_dense_path_or_back) {
  const ModelPtr m = coupled(false).finalize();
  const std::shared_ptr<Model> dense = with_kkt_path(*m, "dense");
  CHECK(dense->force_dense_kkt && !m->force_dense_kkt);
  CHECK(kkt_path(*dense) == KktPath::Dense);
  CHECK(!with_kkt_path(*dense, "auto")->force_dense_kkt);
  CHECK(kkt_path(*with_kkt_path(*dense, "auto")) == kkt_path(*m));
  CHECK_THROWS(with_kkt_path(*m, "tree"), ModelError);
}

TEST_CASE(add_fixed_without_a_point_reports_at_the_childs_centre_of_mass) {
  ModelBuilder b;
  b.add_body("a", 1.0, Vec3(0.1, 0.1, 0.1).asDiagonal(), Vec3(0.2, -0.3, 0.4), kQ);
  const int k = b.add_fixed("weld", "ground", "a", nullptr);
  ModelBuilder ref;
  ref.add_body("a", 1.0, Vec3(0.1, 0.1, 0.1).asDiagonal(), Vec3(0.2, -0.3, 0.4), kQ);
  ref.add_fixed("weld", "ground", "a", Vec3(0.2, -0.3, 0.4));
  CHECK_MAT_NEAR(b.draft().joints[k].point_parent, ref.draft().joints[k].point_parent, 0.0);
  CHECK_MAT_NEAR(b.draft().joints[k].point_parent, Vec3(0.2, -0.3, 0.4), 0.0);
  CHECK_THROWS(b.add_fixed("w2", "ground", "nobody", nullptr), ModelError);
}

TEST_CASE(profile_eval_over_an_array_is_eval_at_each_time) {
  const Profile p = Profile::quintic(0.5, 2.0, 0.1, 1.1);
  const double t[4] = {0.0, 0.3, 0.8, 1.5};
  double y[4], yd[4], ydd[4];
  p.eval(t, 4, y, yd, ydd);
  for (int k = 0; k < 4; ++k) {
    const ProfileValue v = p.eval(t[k]);
    CHECK(y[k] == v.y && yd[k] == v.yd && ydd[k] == v.ydd);
  }
  // the quintic's closed form at t = 0.3: s = 0.2, y = 0.5 + 1.5 (10 s^3 - 15 s^4 + 6 s^5)
  const double s = 0.2;
  CHECK_NEAR(y[1], 0.5 + 1.5 * (10 * s * s * s - 15 * s * s * s * s + 6 * std::pow(s, 5)), 1e-15);
}

ARMDYN_TEST_MAIN()
