// SPDX-License-Identifier: BSD-3-Clause
// The articulated-body algorithm (armdyn/algorithm/aba.hpp) against the CRBA path
// (joint_space_equations + Cholesky) on branched trees of revolute, prismatic, cylindrical and
// fixed joints with gravity, point-to-point and joint springs, a body load and a PI motor; its
// errors (a massless subtree, a non-finite force); and forward_dynamics' methods.
#include <cmath>

#include "armdyn/algorithm/aba.hpp"
#include "armdyn/algorithm/cost_model.hpp"
#include "armdyn/algorithm/dynamics.hpp"
#include "armdyn/builder/builder.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/math/cholesky.hpp"
#include "armdyn/math/quaternion.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;
using armdyn_test::kIdentityQuat;

namespace {

Mat3 inertia(double a, double b, double c, double off) {
  Mat3 i;
  i << a, off, -0.5 * off, off, b, 0.3 * off, -0.5 * off, 0.3 * off, c;
  return i;
}

// a branched tree: every joint type of a joint tree, gravity off the axes, springs, a load,
// friction, a joint torque input and a PI motor
ModelBuilder mixed_tree() {
  ModelBuilder b(Vec3(0.4, -0.3, -9.81));
  b.add_body("base", 3.0, inertia(0.05, 0.06, 0.03, 0.004), Vec3(0.0, 0.02, 0.2),
             quat_exp(Vec3(0.1, -0.3, 0.2)));
  b.add_body("upper", 2.0, inertia(0.02, 0.025, 0.01, -0.001), Vec3(0.2, 0.05, 0.45),
             quat_exp(Vec3(-0.4, 0.2, 0.5)));
  b.add_body("slide", 0.8, inertia(0.01, 0.012, 0.005, 0.0005), Vec3(0.45, 0.1, 0.5),
             kIdentityQuat);
  b.add_body("sleeve", 0.6, inertia(0.004, 0.005, 0.003, 0.0002), Vec3(0.6, 0.12, 0.55),
             quat_exp(Vec3(0.3, 0.1, -0.2)));
  b.add_body("tool", 0.3, inertia(0.002, 0.001, 0.0015, 0.0001), Vec3(0.7, 0.15, 0.5),
             quat_exp(Vec3(-0.2, 0.4, 0.1)));
  b.add_body("side", 1.1, inertia(0.01, 0.02, 0.015, 0.001), Vec3(-0.2, 0.1, 0.35),
             quat_exp(Vec3(0.0, 0.5, 0.3)));
  b.add_body("tip", 0.4, inertia(0.001, 0.002, 0.0012, 0.0001), Vec3(-0.35, 0.15, 0.3),
             kIdentityQuat);
  b.add_revolute("yaw", "ground", "base", Vec3(0, 0, 0.1), Vec3(0, 0, 1));
  b.add_revolute("pitch", "base", "upper", Vec3(0.0, 0.03, 0.4), Vec3(0.1, 1, 0).normalized());
  b.add_prismatic("reach", "upper", "slide", Vec3(0.4, 0.08, 0.5), Vec3(1, 0.1, 0).normalized());
  b.add_cylindrical("twist", "slide", "sleeve", Vec3(0.55, 0.1, 0.52),
                    Vec3(1, -0.2, 0.3).normalized());
  b.add_fixed("weld", "sleeve", "tool", Vec3(0.65, 0.13, 0.52));
  b.add_revolute("side", "base", "side", Vec3(-0.1, 0.05, 0.3), Vec3(0.2, 0.3, 1).normalized());
  b.add_prismatic("tip", "side", "tip", Vec3(-0.3, 0.12, 0.32), Vec3(0, 1, 0.1).normalized());
  b.add_spring_damper("cable", "upper", Vec3(0.25, 0.05, 0.5), "tool", Vec3(0.7, 0.15, 0.55), 80.0,
                      1.5, -1.0);
  b.add_joint_spring_damper("pitch", 12.0, 0.4, 0.1);
  b.add_joint_spring_damper("twist", 30.0, 0.2, 0.02, 1);
  b.add_joint_friction("yaw", 0.05, 0.3, 0.01);
  const Vec3 at(0.7, 0.15, 0.5);
  b.add_body_load("tool", Vec3(1.0, -2.0, 0.5), Vec3(0.1, 0.0, -0.2), &at, nullptr);
  b.add_joint_torque("reach", Profile::constant(0.7));
  b.add_motor("side", Profile::constant(0.3), 20.0, 1.0, 5.0, nullptr, 0, 4.0);
  return b;
}

// qdd by the CRBA path: M qdd = rhs
VecX crba_qdd(const Model& m, Data& d, const VecX& q, const VecX& qd, const double* z,
              const VecX& tau, double t) {
  joint_space_equations(m, d, q.data(), qd.data(), z, tau.data(), t);
  MatX L = d.M;
  CHECK(cholesky_factor(d.M, L));
  VecX x = d.rhs;
  cholesky_solve(L, x);
  return x;
}

double rel_err(const VecX& a, const VecX& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

}  // namespace

TEST_CASE(equals_crba_on_a_mixed_tree) {
  const ModelPtr m = mixed_tree().finalize();
  CHECK(m->joint_space_ok);
  Data d(*m);
  const int n = d.n;
  CHECK(n == 7);
  CHECK(m->n_aux == 1);
  for (int trial = 0; trial < 20; ++trial) {
    const VecX q = 1.5 * VecX::Random(n), qd = 2.0 * VecX::Random(n), tau = VecX::Random(n);
    const double z = 0.3 * trial - 2.0, t = 0.05 * trial;
    const VecX ref = crba_qdd(*m, d, q, qd, &z, tau, t);
    VecX qdd(n);
    aba_accelerations(*m, d, q.data(), qd.data(), &z, tau.data(), t, qdd.data());
    CHECK(rel_err(qdd, ref) < 1e-12);
    // without tau and z
    const VecX ref0 = crba_qdd(*m, d, q, qd, nullptr, VecX::Zero(n), t);
    aba_accelerations(*m, d, q.data(), qd.data(), nullptr, nullptr, t, d.qdd.data());
    CHECK(rel_err(d.qdd, ref0) < 1e-12);
  }
}

TEST_CASE(equals_crba_on_a_long_chain) {
  // a 40-link spatial chain, alternating revolute axes, a prismatic and a fixed joint inside
  ModelBuilder b(Vec3(0.0, 0.5, -9.81));
  std::string parent = "ground";
  for (int i = 0; i < 40; ++i) {
    const std::string name = "l" + std::to_string(i);
    const Vec3 x(0.1 * i + 0.05, 0.01 * (i % 3), 0.0);
    b.add_body(name, 0.5 + 0.05 * (i % 7), inertia(0.003, 0.004, 0.002, 0.0003), x,
               quat_exp(Vec3(0.1 * (i % 4), -0.05 * (i % 5), 0.2)));
    const Vec3 p(0.1 * i, 0.01 * (i % 3), 0.0);
    const Vec3 axis = i % 3 == 0 ? Vec3(0, 0, 1) : i % 3 == 1 ? Vec3(0, 1, 0.2) : Vec3(1, 0.1, 0);
    if (i == 17)
      b.add_prismatic("j" + std::to_string(i), parent, name, p, Vec3(1, 0, 0));
    else if (i == 23)
      b.add_fixed("j" + std::to_string(i), parent, name, p);
    else if (i == 31)
      b.add_cylindrical("j" + std::to_string(i), parent, name, p, axis.normalized());
    else
      b.add_revolute("j" + std::to_string(i), parent, name, p, axis.normalized());
    parent = name;
  }
  b.add_joint_spring_damper("j5", 3.0, 0.1, 0.0);
  const ModelPtr m = b.finalize();
  Data d(*m);
  const int n = d.n;
  for (int trial = 0; trial < 5; ++trial) {
    const VecX q = VecX::Random(n), qd = VecX::Random(n), tau = VecX::Random(n);
    const VecX ref = crba_qdd(*m, d, q, qd, nullptr, tau, 0.0);
    const VecX& qdd = aba(*m, d, q, qd, tau, 0.0);
    CHECK(rel_err(qdd, ref) < 1e-10);
  }
}

TEST_CASE(forward_dynamics_methods_agree) {
  const ModelPtr m = armdyn_test::spatial_arm_builder().finalize();
  Data d(*m);
  VecX q(4), qd(4), tau(4);
  q << 0.3, -1.2, 0.07, 2.0;
  qd << 0.9, -0.4, 0.25, 1.6;
  tau << 1.0, -2.0, 0.5, 0.1;
  const VecX crba = forward_dynamics(*m, d, q, qd, tau, 0.0, DynamicsMethod::Crba);
  const VecX aba_ = forward_dynamics(*m, d, q, qd, tau, 0.0, DynamicsMethod::Aba);
  const VecX cart = forward_dynamics(*m, d, q, qd, tau, 0.0, DynamicsMethod::Cartesian);
  const VecX joint = forward_dynamics(*m, d, q, qd, tau, 0.0, DynamicsMethod::Joint);
  const VecX autom = forward_dynamics(*m, d, q, qd, tau, 0.0, DynamicsMethod::Auto);
  CHECK(rel_err(aba_, crba) < 1e-12);
  CHECK(rel_err(cart, crba) < 1e-9);
  CHECK(rel_err(joint, crba) < 1e-12);
  CHECK(rel_err(autom, crba) < 1e-9);
  // the names
  CHECK(dynamics_method("aba", "f") == DynamicsMethod::Aba);
  CHECK(dynamics_method("crba", "f") == DynamicsMethod::Crba);
  CHECK_THROWS(dynamics_method("aba", "inverse_dynamics", false), ModelError);
  CHECK_THROWS(dynamics_method("lu", "f"), ModelError);
  // the cost model: joint resolves to crba or aba, and auto to the cheapest
  const DynamicsCost& c = dynamics_cost(*m);
  const DynamicsMethod j = resolve_method(*m, DynamicsMethod::Joint);
  CHECK(j == (c.aba < c.crba ? DynamicsMethod::Aba : DynamicsMethod::Crba));
  CHECK(&dynamics_cost(*m) == &c);  // derived once
}

TEST_CASE(massless_subtree_is_named) {
  // the builder refuses massless bodies: make one in a copy of a finalized model
  Model m = *mixed_tree().finalize();
  const int tip = m.find_body("tip");
  m.bodies[tip].mass = 0.0;
  m.bodies[tip].inertia.setZero();
  Data d(m);
  const VecX q = VecX::Zero(d.n), qd = VecX::Zero(d.n);
  try {
    aba(m, d, q, qd, q, 0.0);
    CHECK(false);
  } catch (const SolverError& e) {
    const std::string w = e.what();
    CHECK(w.find("joint 'tip'") != std::string::npos);
    CHECK(w.find("body 'tip'") != std::string::npos);
  }
}

TEST_CASE(non_finite_force_is_named) {
  const ModelPtr m = mixed_tree().finalize();
  Data d(*m);
  VecX q = VecX::Zero(d.n), qd = VecX::Zero(d.n), tau = VecX::Zero(d.n);
  tau[2] = std::nan("");
  try {
    aba_accelerations(*m, d, q.data(), qd.data(), nullptr, tau.data(), 0.0, d.qdd.data());
    CHECK(false);
  } catch (const SolverError& e) {
    CHECK(std::string(e.what()).find("coordinate '" + m->coords[2].name + "'") !=
          std::string::npos);
  }
  // the public call checks its inputs
  CHECK_THROWS(aba(*m, d, q, qd, tau, 0.0), ModelError);
}

ARMDYN_TEST_MAIN()
