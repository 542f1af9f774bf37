// SPDX-License-Identifier: BSD-3-Clause
// Concurrent runs on one const Model (what armdyn.rollout does): threads with a Data each, on a
// model whose derived caches (welded model, KKT plans, gear space) the threads build themselves,
// give the serial results bit for bit. Also the model's serialization (armdyn/io/serialize.hpp):
// a stored and restored model stores to the same bytes and runs bit for bit as the original.
// Built with -fsanitize=thread this is the race check of the shared caches.
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "armdyn/builder/builder.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/io/serialize.hpp"
#include "armdyn/io/urdf.hpp"
#include "armdyn/simulate/simulate.hpp"
#include "check.hpp"

using namespace armdyn;

namespace {

ModelPtr arm() {
  return urdf_builder(std::string(ARMDYN_TEST_DATA) + "/urdf/arm6.urdf", true, Vec3(0, 0, -9.81))
      .finalize();
}

SimOptions options(bool joint) {
  SimOptions o;
  o.limits = false;
  o.coordinates = joint ? Coordinates::Joint : Coordinates::Cartesian;
  o.step.output_dt = 0.05;
  return o;
}

/// Start k: the assembled state with every body's velocity scaled by k (different runs).
void start(const Model& m, int k, VecX& u, VecX& v) {
  u = m.u0;
  v = VecX::Zero(m.nv);
  for (int i = 0; i < m.nb; ++i) v[6 * i + 3 + (k % 3)] = 0.1 * (k + 1);
}

bool same(const SimResult& a, const SimResult& b) {
  return a.n == b.n && a.t == b.t && a.u == b.u && a.v == b.v && a.q == b.q && a.qd == b.qd &&
         a.qdd == b.qdd && a.reaction_forces == b.reaction_forces && a.error == b.error;
}

}  // namespace

TEST_CASE(threads_on_a_fresh_model_equal_serial_runs) {
  const int runs = 16, threads = 8;
  for (bool joint : {false, true}) {
    const ModelPtr serial_model = arm();
    std::vector<SimResult> serial(runs);
    for (int k = 0; k < runs; ++k) {
      VecX u, v;
      start(*serial_model, k, u, v);
      serial[k] = simulate(*serial_model, 0.2, options(joint), u, v);
      CHECK(serial[k].error.empty());
    }
    const ModelPtr m = arm();  // fresh: no derived cache built yet
    std::vector<SimResult> out(runs);
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t)
      pool.emplace_back([&, t] {
        Data d(*m);
        for (int k = t; k < runs; k += threads) {
          VecX u, v;
          start(*m, k, u, v);
          out[k] = simulate(*m, d, 0.2, options(joint), u, v);
        }
      });
    for (auto& th : pool) th.join();
    for (int k = 0; k < runs; ++k) CHECK(same(out[k], serial[k]));
    CHECK(!same(out[0], out[1]));
  }
}

TEST_CASE(serialized_model_runs_bit_for_bit) {
  const ModelPtr m = arm();
  const std::string bytes = serialize_model(*m);
  const Model c = deserialize_model(bytes);
  CHECK(serialize_model(c) == bytes);
  VecX u, v;
  start(*m, 2, u, v);
  CHECK(same(simulate(*m, 0.2, options(false), u, v), simulate(c, 0.2, options(false), u, v)));
  CHECK(same(simulate(*m, 0.2, options(true), u, v), simulate(c, 0.2, options(true), u, v)));
  CHECK_THROWS(deserialize_model(bytes.substr(0, bytes.size() - 1)), ModelError);
  CHECK_THROWS(deserialize_model("not a model"), ModelError);
  CHECK_THROWS(deserialize_model(bytes + "x"), ModelError);
}

TEST_CASE(a_callback_profile_is_not_stored) {
  ModelBuilder b =
      urdf_builder(std::string(ARMDYN_TEST_DATA) + "/urdf/arm6.urdf", true, Vec3(0, 0, -9.81));
  b.add_joint_torque("elbow_joint",
                     Profile::callback([](double) { return ProfileValue{}; }, "my_torque"));
  const std::string what = THROWN_MESSAGE(serialize_model(b.draft()), ModelError);
  CHECK(what.find("my_torque") != std::string::npos);
  CHECK(what.find("torque input of coordinate 'elbow_joint'") != std::string::npos);
}

ARMDYN_TEST_MAIN()
