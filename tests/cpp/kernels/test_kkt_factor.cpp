// SPDX-License-Identifier: BSD-3-Clause
// The KKT solver (armdyn/kernels/kkt_factor.hpp) against a dense LU of the augmented system, on a
// spatial tree, a closed loop, and a model with redundant rows (the pivoted path).
#include <cmath>

#include "armdyn/algorithm/kkt.hpp"
#include "armdyn/algorithm/projection.hpp"
#include "armdyn/data.hpp"
#include "armdyn/kernels/joint_space.hpp"
#include "armdyn/kernels/kkt_factor.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

namespace {

/// A moving state of m: the assembled pose with velocities projected onto zeta v = 0.
void moving_state(const Model& m, Data& d, VecX& u, VecX& v) {
  u = m.u0;
  v.resize(m.nv);
  for (int i = 0; i < m.nv; ++i) v[i] = 0.8 * std::cos(0.9 * i + 0.4);
  project(m, d, 0.0, u.data(), v.data(), Metric::Mass);
}

void compare_with_dense(const ModelPtr& m) {
  Data d(*m);
  VecX u, v;
  moving_state(*m, d, u, v);
  // body_accelerations fills the constraints, eta and the KKT factor at (u, v)
  VecX vdot(m->nv);
  body_accelerations(*m, d, 0.0, u.data(), v.data(), vdot.data());
  VecX vref, dref;
  armdyn_test::dense_kkt(*m, d.ce, d.eta, m->nc, vref, dref);
  CHECK_MAT_NEAR(vdot, vref, 1e-10);
  // zeta^T delta is unique even when delta is not (redundant rows)
  const MatX z = dense_zeta(*m, d.ce);
  CHECK_MAT_NEAR(z.transpose() * d.delta, z.transpose() * dref, 1e-9);
  // the solver on its own, from the same evaluation
  KktSolver k(*m);
  k.factor(d.ce, m->nc, Metric::Mass);
  VecX vd2(m->nv), d2(m->nc);
  k.accelerations(d.ce, d.eta, vd2, d2);
  CHECK_MAT_NEAR(vd2, vref, 1e-10);
  // the accelerations satisfy the constraint level: zeta vdot = -xi
  CHECK_MAT_NEAR(z * vdot, -d.ce.xi, 1e-9);
}

}  // namespace

TEST_CASE(tree_matches_dense_lu) {
  compare_with_dense(armdyn_test::spatial_arm_builder().finalize());
}

TEST_CASE(closed_loop_matches_dense_lu) {
  compare_with_dense(armdyn_test::four_bar_builder().finalize());
}

TEST_CASE(redundant_rows_take_the_pivoted_path) {
  // the same loop closed by a revolute: 3 of its rows repeat what the planar loop implies
  const ModelPtr m = armdyn_test::four_bar_builder(true).finalize();
  CHECK(m->redundant);
  CHECK(m->mobility == 1);
  compare_with_dense(m);
}

TEST_CASE(schur_solve_with_identity_metric) {
  // A = zeta zeta^T (the unweighted projection's metric)
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  Data d(*m);
  VecX vdot(m->nv);
  body_accelerations(*m, d, 0.0, m->u0.data(), m->v0.data(), vdot.data());
  KktSolver k(*m);
  k.factor(d.ce, m->nc, Metric::Identity);
  CHECK(k.metric() == Metric::Identity);
  const MatX z = dense_zeta(*m, d.ce);
  const VecX b = VecX::LinSpaced(m->nc, 1.0, -0.5);
  VecX x(m->nc);
  k.solve_schur(b, x);
  CHECK_MAT_NEAR((z * z.transpose()) * x, b, 1e-10);
  VecX y = VecX::LinSpaced(m->nv, -1.0, 1.0), wy(m->nv);
  k.apply_winv(y, wy);
  CHECK_MAT_NEAR(wy, y, 0.0);
}

ARMDYN_TEST_MAIN()
