// SPDX-License-Identifier: BSD-3-Clause
// Couplings (ModelBuilder::add_coupling) and the independent coordinates (IndependentCoords):
// the map q_full = G q + shift against the explicit G, the reductions G^T f and G^T M G, the
// assembly at the offsets, the public joint-space functions against the full ones, and the
// builder's refusals.
#include <cmath>

#include "armdyn/algorithm/crba.hpp"
#include "armdyn/algorithm/rnea.hpp"
#include "armdyn/builder/builder.hpp"
#include "armdyn/data.hpp"
#include "armdyn/errors.hpp"
#include "check.hpp"

using namespace armdyn;

namespace {

const Vec4 kQ(1, 0, 0, 0);

// ra (revolute) -> rb (revolute, follows ra: 2 q + 0.1) -> rc (revolute, follows rb: -0.5 q)
// and a free-standing slider pd
ModelBuilder chain() {
  ModelBuilder b;
  const Mat3 I = Vec3(0.01, 0.02, 0.03).asDiagonal();
  b.add_body("a", 1.0, I, Vec3(0.5, 0, 0), kQ);
  b.add_body("b", 0.7, I, Vec3(1.5, 0, 0), kQ);
  b.add_body("c", 0.4, I, Vec3(2.5, 0, 0), kQ);
  b.add_body("d", 0.3, I, Vec3(3.5, 0, 0), kQ);
  b.add_revolute("ra", "ground", "a", Vec3(0, 0, 0), Vec3(0, 1, 0));
  b.add_revolute("rb", "a", "b", Vec3(1, 0, 0), Vec3(0, 1, 0));
  b.add_revolute("rc", "b", "c", Vec3(2, 0, 0), Vec3(0, 1, 0));
  b.add_prismatic("pd", "c", "d", Vec3(3, 0, 0), Vec3(1, 0, 0));
  b.add_coupling("k1", "rb", "ra", 2.0, 0.1);
  b.add_coupling("k2", "rc", "rb", -0.5, 0.0);
  return b;
}

}  // namespace

TEST_CASE(chain_of_couplings_resolves_to_the_root_leader) {
  const ModelPtr m = chain().finalize();
  const IndependentCoords& ic = m->independent;
  CHECK(ic.n == 2 && !ic.identity());
  CHECK(ic.full.size() == 2 && ic.full[0] == 0 && ic.full[1] == 3);
  CHECK(m->coupled_joint_space && !m->joint_space_ok);
  // q_rc = -0.5 (2 q_ra + 0.1) = -q_ra - 0.05
  MatX G = MatX::Zero(4, 2);
  G << 1, 0, 2, 0, -1, 0, 0, 1;
  const VecX shift = (VecX(4) << 0, 0.1, -0.05, 0).finished();
  const VecX q = (VecX(2) << 0.3, -0.2).finished();
  VecX qf(4);
  ic.expand_q(q.data(), qf.data());
  CHECK_MAT_NEAR(qf, G * q + shift, 1e-15);
  ic.expand_v(q.data(), qf.data());
  CHECK_MAT_NEAR(qf, G * q, 1e-15);
  const VecX f = (VecX(4) << 1.0, -2.0, 3.0, 0.5).finished();
  VecX fr(2);
  ic.reduce(f.data(), fr.data());
  CHECK_MAT_NEAR(fr, G.transpose() * f, 1e-15);
  MatX M = MatX::Random(4, 4);
  M = (M * M.transpose()).eval();
  MatX Mr(2, 2);
  ic.reduce(M, Mr);
  CHECK_MAT_NEAR(Mr, G.transpose() * M * G, 1e-14);
  // the assembly satisfies the offsets: at q_ra = 0, rb = 0.1 and rc = -0.05
  VecX q0, qd0;
  joint_coordinates(*m, m->u0, m->v0, q0, qd0);
  CHECK_MAT_NEAR(q0, shift, 1e-13);
  Data d(*m);
  CHECK(d.n == 4 && d.ni == 2);
}

TEST_CASE(public_functions_reduce_the_full_ones) {
  const ModelPtr m = chain().finalize();
  Data d(*m);
  const VecX q = (VecX(2) << 0.3, -0.2).finished(), qd = (VecX(2) << -0.4, 0.6).finished(),
             qdd = (VecX(2) << 1.1, 0.2).finished();
  const MatX Mr = crba(*m, d, q);
  const VecX tau = rnea(*m, d, q, qd, qdd);
  VecX qf(4), qdf(4), qddf(4);
  m->independent.expand_q(q.data(), qf.data());
  m->independent.expand_v(qd.data(), qdf.data());
  m->independent.expand_v(qdd.data(), qddf.data());
  const MatX M = mass_matrix_at(*m, d, qf);
  rnea_full(*m, d, qf, qdf, qddf, 0.0);
  VecX tr(2);
  m->independent.reduce(d.tau.data(), tr.data());
  CHECK_MAT_NEAR(tau, tr, 1e-13);
  MatX Mref(2, 2);
  m->independent.reduce(M, Mref);
  CHECK_MAT_NEAR(Mr, Mref, 1e-14);
  CHECK(Mr.rows() == 2 && Mr.cols() == 2);
  CHECK_THROWS(crba(*m, d, VecX::Zero(4)), ModelError);
}

TEST_CASE(add_coupling_refusals_leave_the_builder_intact) {
  ModelBuilder b = chain();
  const std::string twice = THROWN_MESSAGE(b.add_coupling("k3", "rb", "pd", 1.0, 0.0), ModelError);
  CHECK(twice.find("coupling 'k3'") != std::string::npos);
  const std::string cycle = THROWN_MESSAGE(b.add_coupling("k3", "ra", "rc", 1.0, 0.0), ModelError);
  CHECK(cycle.find("cycle 'ra' -> 'rc' -> 'rb' -> 'ra'") != std::string::npos);
  const std::string type = THROWN_MESSAGE(b.add_coupling("k3", "pd", "ra", 1.0, 0.0), ModelError);
  CHECK(type.find("prismatic but leader joint 'ra' is revolute") != std::string::npos);
  CHECK_THROWS(b.add_coupling("k3", "pd", "nope", 1.0, 0.0), ModelError);
  CHECK_THROWS(b.add_coupling("k3", "ra", "ra", 1.0, 0.0), ModelError);
  CHECK(b.finalize()->independent.n == 2);
}

ARMDYN_TEST_MAIN()
