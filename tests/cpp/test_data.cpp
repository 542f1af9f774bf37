// SPDX-License-Identifier: BSD-3-Clause
// Data (armdyn/data.hpp): buffers sized from the model; one Data evaluates repeatedly with the
// same answers; a Data belongs to one model.
#include "armdyn/algorithm/dynamics.hpp"
#include "armdyn/data.hpp"
#include "armdyn/errors.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

TEST_CASE(sized_for_the_model) {
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  Data d(*m);
  CHECK(d.model == m.get());
  CHECK(d.n == 4);
  CHECK(static_cast<int>(d.kin.size()) == m->nb);
  check_data(*m, d, "test");  // does not throw
  const ModelPtr other = armdyn_test::spatial_arm_builder().finalize();
  CHECK_THROWS(check_data(*other, d, "test"), ModelError);
}

TEST_CASE(repeated_evaluations_agree) {
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  Data d(*m), fresh(*m);
  VecX q(4), qd(4), tau(4);
  q << 0.1, 0.2, 0.03, 0.4;
  qd << -0.5, 0.6, 0.1, 0.8;
  tau << 1.0, 2.0, 3.0, 4.0;
  const VecX a = forward_dynamics(*m, d, q, qd, tau);
  // another state in between leaves nothing behind
  forward_dynamics(*m, d, -q, 2 * qd, VecX::Zero(4), 0.0, DynamicsMethod::Cartesian);
  const VecX b = forward_dynamics(*m, d, q, qd, tau);
  CHECK_MAT_NEAR(a, b, 0.0);
  CHECK_MAT_NEAR(forward_dynamics(*m, fresh, q, qd, tau), a, 0.0);
}

ARMDYN_TEST_MAIN()
