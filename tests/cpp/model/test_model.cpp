// SPDX-License-Identifier: BSD-3-Clause
// Model (armdyn/model/model.hpp): the force laws of coordinate force elements and gear pairs,
// row names, and the store of values derived from a model.
#include <cmath>
#include <thread>
#include <vector>

#include "armdyn/model/model.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

TEST_CASE(coordinate_spring_damper_friction_and_input) {
  CoordForce cf;
  cf.stiffness = 40.0;
  cf.damping = 1.5;
  cf.rest = 0.2;
  cf.coulomb = 0.3;
  cf.v_smooth = 0.01;
  cf.has_input = true;
  cf.input = Profile::constant(2.0);
  const double q = 0.5, qd = -0.7;
  const double expected = -40.0 * (q - 0.2) - 1.5 * qd - 0.3 * std::tanh(qd / 0.01) + 2.0;
  CHECK_NEAR(coord_force_value(cf, false, q, qd, 0.0), expected, 1e-13);
  // angular springs see the wrapped difference: q = rest + 2 pi + 0.1 acts as rest + 0.1
  cf.has_input = false;
  cf.coulomb = 0.0;
  CHECK_NEAR(coord_force_value(cf, true, 0.2 + 2 * M_PI + 0.1, 0.0, 0.0), -40.0 * 0.1, 1e-12);
  CHECK_NEAR(coord_force_value(cf, false, 0.2 + 2 * M_PI + 0.1, 0.0, 0.0), -40.0 * (2 * M_PI + 0.1),
             1e-12);
}

TEST_CASE(pd_motor_saturates_and_stops_integrating) {
  CoordForce cf;
  cf.motor = true;
  cf.reference = Profile::constant(1.0);
  cf.kp = 10.0;
  cf.kd = 2.0;
  cf.ki = 5.0;
  cf.torque_limit = 100.0;
  double zdot = -1.0;
  // inside the limit: kp e + kd (0 - qd) + ki z, and z' = e
  CHECK_NEAR(coord_force_value(cf, true, 0.4, 0.3, 0.0, 0.1, &zdot),
             10.0 * 0.6 + 2.0 * (-0.3) + 5.0 * 0.1, 1e-14);
  CHECK_NEAR(zdot, 0.6, 1e-15);
  // saturated in the direction of the error: clamped, the integral holds
  cf.torque_limit = 1.0;
  CHECK_NEAR(coord_force_value(cf, true, 0.4, 0.0, 0.0, 0.0, &zdot), 1.0, 0.0);
  CHECK(zdot == 0.0);
}

TEST_CASE(gear_pair_contact_law) {
  GearPair g;
  g.backlash = 0.002;
  g.stiffness = 1e6;
  g.exponent = 1.5;
  g.hc_damping = 0.4;
  double pen = 0.0;
  // inside the gap: no force, negative penetration
  CHECK(gear_force(g, 0.0005, 0.1, pen) == 0.0);
  CHECK_NEAR(pen, 0.0005 - 0.001, 1e-18);
  // in contact: k d^n (1 + alpha d'), d' the penetration rate (sign of s)
  const double s = -0.0013, sd = -0.02, d = 0.0003;
  CHECK_NEAR(gear_force(g, s, sd, pen), 1e6 * std::pow(d, 1.5) * (1 + 0.4 * 0.02), 1e-12);
  CHECK_NEAR(pen, d, 1e-18);
  // separating fast: never pulls
  CHECK(gear_force(g, 0.0013, -10.0, pen) == 0.0);
}

TEST_CASE(row_names) {
  const ModelPtr m = armdyn_test::TwoLink().model();
  // rows 0..4: shoulder, 5..9: elbow
  CHECK(m->row_name(0).find("shoulder") != std::string::npos);
  CHECK(m->row_name(7).find("elbow") != std::string::npos);
  CHECK(m->body_name(kGround) == "ground");
  CHECK(m->body_name(1) == "link2");
}

TEST_CASE(derived_values_are_built_once_and_not_copied) {
  const ModelPtr m = armdyn_test::TwoLink().model();
  int builds = 0;
  auto make = [&] {
    ++builds;
    return 42;
  };
  const int& a = m->derived.get<int>(make);
  const int& b = m->derived.get<int>(make);
  CHECK(&a == &b && a == 42 && builds == 1);
  // a copy (which a caller may change) derives afresh
  Model c(*m);
  const int& e = c.derived.get<int>(make);
  CHECK(&e != &a && builds == 2);
  // many threads asking at once: one build, one value
  Model d(*m);
  std::vector<std::thread> threads;
  std::vector<const int*> seen(8, nullptr);
  for (int k = 0; k < 8; ++k) threads.emplace_back([&, k] { seen[k] = &d.derived.get<int>(make); });
  for (std::thread& t : threads) t.join();
  CHECK(builds == 3);
  for (const int* p : seen) CHECK(p == seen[0]);
}

ARMDYN_TEST_MAIN()
