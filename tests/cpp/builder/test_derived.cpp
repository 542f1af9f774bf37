// SPDX-License-Identifier: BSD-3-Clause
// What the layers above the model derive from it: the KKT plans (kkt_plans, kkt_path), the
// welded form simulate() integrates (welding) and the summary.
#include <string>

#include "armdyn/builder/builder.hpp"
#include "armdyn/builder/summary.hpp"
#include "armdyn/builder/weld.hpp"
#include "armdyn/kernels/block_sparse.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

namespace {
/// The two-link arm with a tool welded to link 2 (its centre of mass 0.1 m beyond the elbow's
/// link, rotated) and a bracket welded to ground.
ModelPtr two_link_with_tool() {
  ModelBuilder b = armdyn_test::TwoLink().builder();
  b.add_body("tool", 0.4, Vec3(1e-3, 2e-3, 3e-3).asDiagonal(), Vec3(1.1, 0.0, 0.05),
             quat_exp(Vec3(0.3, -0.2, 0.1)));
  b.add_fixed("tool_mount", "link2", "tool", Vec3(1.0, 0, 0));
  b.add_body("bracket", 1.0, Vec3(1e-2, 1e-2, 1e-2).asDiagonal(), Vec3(0, 0, -0.2),
             armdyn_test::kIdentityQuat);
  b.add_fixed("bracket_mount", "ground", "bracket", Vec3(0, 0, -0.1));
  return b.finalize();
}
}  // namespace

TEST_CASE(kkt_plans_are_made_once_per_model) {
  const ModelPtr m = armdyn_test::TwoLink().model();
  const KktPlans& p = kkt_plans(*m);
  CHECK(&kkt_plans(*m) == &p);
  CHECK(p.all.path == KktPath::Tree && kkt_path(*m) == KktPath::Tree);
  CHECK(p.joint.path == KktPath::None);  // no drives: no separate plan of the joint rows
  // a copy forced onto the dense reference path
  Model c(*m);
  c.force_dense_kkt = true;
  CHECK(kkt_path(c) == KktPath::Dense && kkt_path(*m) == KktPath::Tree);
  CHECK(kkt_path_description(c).find("forced") != std::string::npos);
}

TEST_CASE(welding_merges_fixed_joints_into_composites) {
  const ModelPtr m = two_link_with_tool();
  const Welding* w = welding(*m);
  CHECK(w != nullptr);
  CHECK(welding(*m) == w);  // made once
  const Model& wm = *w->model;
  // tool -> link2's composite, bracket -> ground: 2 bodies, the two revolutes' 10 rows
  CHECK(wm.nb == 2 && wm.nc == 10);
  CHECK(w->weld[m->find_body("bracket")].composite == kGround);
  CHECK(w->weld[m->find_body("tool")].composite == w->weld[m->find_body("link2")].composite);
  CHECK(w->weld_joint[m->find_joint("tool_mount")] == -1);
  // the composite keeps the mass of its members
  const int c = w->weld[m->find_body("link2")].composite;
  CHECK_NEAR(wm.bodies[c].mass, 1.2 + 0.4, 1e-15);
  // a model without fixed joints has none
  CHECK(welding(*armdyn_test::TwoLink().model()) == nullptr);
}

TEST_CASE(summary_states_sizes_topology_and_paths) {
  const std::string s = summary(*armdyn_test::TwoLink().model());
  CHECK(s.find("2 bodies, 2 joints, 0 drives") != std::string::npos);
  CHECK(s.find("nq=14 nv=12 nc=10") != std::string::npos);
  CHECK(s.find("tree; mobility 2 DOF") != std::string::npos);
  CHECK(s.find("KKT path: tree") != std::string::npos);
  const std::string w = summary(*two_link_with_tool());
  CHECK(w.find("welded: 2 fixed joints merged") != std::string::npos);
  CHECK(w.find("integrates 2 bodies and 10 rows") != std::string::npos);
}

ARMDYN_TEST_MAIN()
