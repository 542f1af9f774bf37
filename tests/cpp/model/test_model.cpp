// SPDX-License-Identifier: BSD-3-Clause
// Model (armdyn/model/model.hpp): row names, and the store of values derived from a model (the
// force laws' tests are in tests/cpp/algorithm/test_forces.cpp).
#include <cmath>
#include <thread>
#include <vector>

#include "armdyn/model/model.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

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
