// SPDX-License-Identifier: BSD-3-Clause
// Inverse dynamics of driven models (armdyn/algorithm/driven_inverse_dynamics.hpp): a pendulum
// driven along a quintic needs I_O phi'' + m g L sin(phi); a fully driven arm's efforts equal the
// joint-space RNEA; a model the drives leave free is refused.
#include <cmath>

#include "armdyn/algorithm/driven_inverse_dynamics.hpp"
#include "armdyn/algorithm/rnea.hpp"
#include "armdyn/errors.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

TEST_CASE(driven_pendulum_efforts) {
  armdyn_test::Pendulum p;
  p.phi0 = 0.3;
  ModelBuilder b = p.builder();
  const Profile prof = Profile::quintic(0.0, 1.2, 0.0, 1.0);
  b.add_drive("hinge", prof);
  const ModelPtr m = b.finalize();
  std::vector<double> times;
  for (int k = 0; k <= 20; ++k) times.push_back(0.06 * k);
  const InverseDynamicsResult r = inverse_dynamics_driven(*m, times);
  CHECK(r.n == 21);
  for (long k = 0; k < r.n; ++k) {
    const ProfileValue v = prof.eval(times[k]);
    const double phi = p.phi0 + v.y;
    CHECK_NEAR(r.q[k], v.y, 1e-10);
    CHECK_NEAR(r.qd[k], v.yd, 1e-10);
    CHECK_NEAR(r.qdd[k], v.ydd, 1e-9);
    CHECK_NEAR(r.drive_forces[k], p.io() * v.ydd + p.m * p.g * p.L * std::sin(phi), 1e-9);
    CHECK(r.position_residual[k] < 1e-12);
  }
}

TEST_CASE(fully_driven_arm_matches_rnea) {
  ModelBuilder b = armdyn_test::spatial_arm_builder();
  const ModelPtr free_model = b.finalize();
  const Profile p[4] = {Profile::sine(0.4, 0.5, 0.0, 0.1), Profile::sine(0.3, 0.8, 1.0, -0.2),
                        Profile::sine(0.03, 1.1, 0.5, 0.02), Profile::quintic(0.0, 2.0, 0.0, 1.0)};
  const char* joints[4] = {"yaw", "pitch", "reach", "roll"};
  for (int k = 0; k < 4; ++k) b.add_drive(joints[k], p[k]);
  const ModelPtr m = b.finalize();
  const std::vector<double> times = {0.0, 0.25, 0.5, 0.9};
  const InverseDynamicsResult r = inverse_dynamics_driven(*m, times);
  Data d(*free_model);
  for (size_t k = 0; k < times.size(); ++k) {
    VecX q(4), qd(4), qdd(4);
    for (int c = 0; c < 4; ++c) {
      const ProfileValue v = p[c].eval(times[k]);
      q[c] = v.y;
      qd[c] = v.yd;
      qdd[c] = v.ydd;
    }
    const VecX tau = rnea(*free_model, d, q, qd, qdd);
    const Eigen::Map<const VecX> eff(r.drive_forces.data() + 4 * k, 4);
    CHECK_MAT_NEAR(eff, tau, 1e-9);
  }
}

TEST_CASE(refuses_free_coordinates) {
  const ModelPtr m = armdyn_test::TwoLink().model();
  const std::string why = THROWN_MESSAGE(inverse_dynamics_driven(*m, {0.0, 1.0}), ModelError);
  CHECK(why.find("shoulder") != std::string::npos || why.find("elbow") != std::string::npos);
}

ARMDYN_TEST_MAIN()
