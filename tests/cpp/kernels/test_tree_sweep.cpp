// SPDX-License-Identifier: BSD-3-Clause
// The square-system sweep of fully driven trees (armdyn/kernels/tree_sweep.hpp): the
// accelerations are the drives' second derivatives, and vdot and delta equal the dense KKT
// solution.
#include <cmath>

#include "armdyn/algorithm/kkt.hpp"
#include "armdyn/data.hpp"
#include "armdyn/kernels/joint_space.hpp"
#include "armdyn/kernels/tree_sweep.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

TEST_CASE(fully_driven_tree_follows_its_drives) {
  ModelBuilder b = armdyn_test::spatial_arm_builder();
  const ModelPtr free_model = b.finalize();  // the same bodies and joints, undriven
  const Profile p[4] = {Profile::sine(0.5, 0.3, 0.1, 0.0), Profile::quintic(0.0, 0.8, 0.0, 2.0),
                        Profile::sine(0.05, 0.7, 0.0, 0.0), Profile::cubic(0.0, -1.0, 0.0, 2.0)};
  const char* joints[4] = {"yaw", "pitch", "reach", "roll"};
  for (int k = 0; k < 4; ++k) b.add_drive(joints[k], p[k]);
  const ModelPtr m = b.finalize();
  CHECK(m->mobility_driven == 0);

  const double t = 0.83;
  VecX q(4), qd(4), qdd(4);
  for (int k = 0; k < 4; ++k) {
    const ProfileValue pv = p[k].eval(t);
    q[k] = pv.y;
    qd[k] = pv.yd;
    qdd[k] = pv.ydd;
  }
  VecX u, v;
  state_from_joints(*free_model, q, qd, u, v);

  Data d(*m);
  VecX vdot(m->nv);
  body_accelerations(*m, d, t, u.data(), v.data(), vdot.data());
  CHECK(d.swept);
  // the accelerations of the prescribed motion
  CHECK_MAT_NEAR(vdot, armdyn_test::cartesian_acceleration_fd(*free_model, q, qd, qdd), 1e-7);
  // vdot and the multipliers against the dense KKT solve
  VecX vref, dref;
  armdyn_test::dense_kkt(*m, d.ce, d.eta, m->nc, vref, dref);
  CHECK_MAT_NEAR(vdot, vref, 1e-10);
  CHECK_MAT_NEAR(d.delta, dref, 1e-9 * (1.0 + dref.lpNorm<Eigen::Infinity>()));

  // the sweep on its own
  TreeSweep s;
  s.plan(*m, d.ce);
  CHECK(s.ok());
  VecX vd2(m->nv), d2(m->nc);
  CHECK(s.solve(*m, d.ce, d.eta, vd2, d2));
  CHECK_MAT_NEAR(vd2, vref, 1e-10);
  CHECK_MAT_NEAR(d2, dref, 1e-9 * (1.0 + dref.lpNorm<Eigen::Infinity>()));
}

TEST_CASE(plan_refuses_partly_driven_trees) {
  ModelBuilder b = armdyn_test::spatial_arm_builder();
  b.add_drive("yaw", Profile::constant(0.0));
  const ModelPtr m = b.finalize();
  ConstraintEval ce;
  ce.init(*m);
  TreeSweep s;
  s.plan(*m, ce);
  CHECK(!s.ok());
}

ARMDYN_TEST_MAIN()
