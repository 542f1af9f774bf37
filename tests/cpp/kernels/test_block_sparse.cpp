// SPDX-License-Identifier: BSD-3-Clause
// Block-sparse Schur factorisation (armdyn/kernels/block_sparse.hpp) against Eigen's dense
// Cholesky of A = zeta W^-1 zeta^T, on a branched tree (no fill) and a closed loop (fill).
#include <Eigen/Cholesky>
#include <cmath>

#include "armdyn/kernels/block_sparse.hpp"
#include "armdyn/kernels/joint_space.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

namespace {

/// A trunk with two branches of three links each; closed: a distance joint between the tips
/// makes a loop through the trunk (a loop through ground leaves the block graph a tree).
ModelPtr branched_tree(bool closed) {
  ModelBuilder b;
  const Mat3 in = Vec3(0.02, 0.03, 0.025).asDiagonal();
  b.add_body("trunk", 2.0, in, Vec3(0, 0, 0.2), armdyn_test::kIdentityQuat);
  b.add_revolute("j0", "ground", "trunk", Vec3(0, 0, 0), Vec3::UnitZ());
  for (int side = 0; side < 2; ++side) {
    std::string parent = "trunk";
    const double s = side == 0 ? 1.0 : -1.0;
    for (int k = 0; k < 3; ++k) {
      const std::string name = "b" + std::to_string(side) + std::to_string(k);
      b.add_body(name, 1.0 + 0.1 * k, in, Vec3(s * (0.3 * k + 0.15), 0.0, 0.4),
                 armdyn_test::kIdentityQuat);
      b.add_revolute("j" + name, parent, name, Vec3(s * 0.3 * k, 0.0, 0.4),
                     k % 2 ? Vec3::UnitY() : Vec3::UnitX());
      parent = name;
    }
  }
  if (closed) b.add_distance("tie", "b02", Vec3(0.75, 0, 0.5), "b12", Vec3(-0.75, 0.1, 0.3));
  return b.finalize();
}

ModelPtr four_bar() { return armdyn_test::four_bar_builder().finalize(); }

void check_against_dense(const ModelPtr& m, bool expect_fill) {
  const KktPlan plan = plan_kkt(*m, m->nc);
  CHECK(plan.path != KktPath::Dense);
  CHECK(plan.nrows == m->nc);
  CHECK((plan.fill_blocks > 0) == expect_fill);
  // order and pos are inverse permutations
  for (size_t k = 0; k < plan.order.size(); ++k) CHECK(plan.pos[plan.order[k]] == int(k));

  // a generic configuration of the tree / the assembled loop
  VecX u = m->u0;
  if (m->joint_tree) {
    VecX q(m->coords.size()), v;
    for (int i = 0; i < q.size(); ++i) q[i] = 0.3 * std::sin(2.1 * i + 0.5);
    state_from_joints(*m, q, VecX::Zero(q.size()), u, v);
  }
  std::vector<BodyKin> kin(m->nb);
  body_kinematics(*m, u.data(), nullptr, kin);
  ConstraintEval ce;
  ce.init(*m);
  eval_constraints(*m, kin, 0.0, false, ce);
  const MatX z = dense_zeta(*m, ce);

  // identity metric
  BlockSparseSchur s(*m, plan);
  CHECK(s.factor(ce, nullptr));
  VecX b = VecX::LinSpaced(m->nc, -1.0, 1.5), x = b;
  s.solve_in_place(x);
  const MatX a = z * z.transpose();
  CHECK_MAT_NEAR(x, a.llt().solve(b), 1e-9);
  CHECK(s.min_relative_pivot() > 0.0 && s.min_relative_pivot() <= 1.0);

  // mass metric: W^-1 = diag(1/m I, J^-1)
  std::vector<Mat6> winv(m->nb, Mat6::Zero());
  for (int i = 0; i < m->nb; ++i) {
    winv[i].topLeftCorner<3, 3>() = Mat3::Identity() / m->bodies[i].mass;
    winv[i].bottomRightCorner<3, 3>() = m->bodies[i].inertia.inverse();
  }
  CHECK(s.factor(ce, &winv));
  x = b;
  s.solve_in_place(x);
  const MatX am = z * armdyn_test::body_mass_matrix(*m).inverse() * z.transpose();
  CHECK_MAT_NEAR(x, am.llt().solve(b), 1e-9);
}

}  // namespace

TEST_CASE(tree_factor_has_no_fill) { check_against_dense(branched_tree(false), false); }

TEST_CASE(loop_through_ground_has_no_fill) { check_against_dense(four_bar(), false); }

TEST_CASE(loop_through_a_body_makes_fill) { check_against_dense(branched_tree(true), true); }

TEST_CASE(kkt_path_names_are_the_python_strings) {
  // the names Model.kkt_path returns in Python (the enum stays in C++)
  CHECK(std::string(kkt_path_name(KktPath::Tree)) == "tree");
  CHECK(std::string(kkt_path_name(KktPath::TreeLoops)) == "tree+loops");
  CHECK(std::string(kkt_path_name(KktPath::Sparse)) == "sparse");
  CHECK(std::string(kkt_path_name(KktPath::Dense)) == "dense");
  CHECK(std::string(kkt_path_name(KktPath::None)).empty());
  // a plan of no rows is dense; a model without rows has no path
  ModelBuilder b;
  b.add_body("free", 1.0, Vec3(0.1, 0.1, 0.1).asDiagonal(), Vec3::Zero(),
             armdyn_test::kIdentityQuat);
  b.add_free("float", "free");
  const ModelPtr m = b.finalize();
  CHECK(m->nc == 0 && kkt_path(*m) == KktPath::None);
  CHECK(plan_kkt(*m, 0).path == KktPath::Dense);
  // the closed loop's fill makes it tree+loops; the branched tree's none makes it tree
  const ModelPtr loop = branched_tree(true);
  CHECK(plan_kkt(*loop, loop->nc).path == KktPath::TreeLoops);
  CHECK(kkt_path(*branched_tree(false)) == KktPath::Tree);
}

ARMDYN_TEST_MAIN()
