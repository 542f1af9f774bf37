// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/cost_model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "armdyn/algorithm/tree_dynamics.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/kernels/kkt_factor.hpp"

namespace armdyn {

const CostConstants& cost_constants() {
  // measured by `python -m benchmarks.cost_model` (benchmarks/results/cost_model.json)
  // measured on 2026-11-29 (2-core VM, Release build, spatial chains of 1 to 400 links, the
  // Cartesian forward dynamics of trees on the articulated sweep without its multipliers; the
  // largest relative misfit of the fits is 3 % (Cartesian) to 23 % (CRBA): noise of a shared
  // machine and cache effects beyond 300 links)
  static const CostConstants k{/*c0*/ 0.08896,       /*c_body*/ 0.1334, /*c_path*/ 0.002699,
                               /*c_chol*/ 0.0001262, /*a0*/ 0.0206,     /*a_body*/ 0.1818,
                               /*k0*/ 0.01455,       /*k_body*/ 0.3205, /*j0*/ 0.0,
                               /*j_body*/ 0.2696,    /*s0*/ 0.0,        /*s_body*/ 0.6096};
  return k;
}

namespace {
std::string us(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g us", x);
  return buf;
}
}  // namespace

const char* method_name(DynamicsMethod method) {
  switch (method) {
    case DynamicsMethod::Auto:
      return "auto";
    case DynamicsMethod::Joint:
      return "joint";
    case DynamicsMethod::Crba:
      return "CRBA";
    case DynamicsMethod::Aba:
      return "ABA";
    case DynamicsMethod::Cartesian:
      return "Cartesian";
  }
  return "?";
}

std::string DynamicsCost::forward_summary() const {
  return msg("predicted ", us(crba), " (CRBA), ", us(aba), " (ABA), ", us(cartesian),
             " (Cartesian) per call");
}

std::string DynamicsCost::rhs_summary() const {
  return msg("cost model: ", us(joint_rhs), " (joint space, ", method_name(joint), ") vs ",
             us(cartesian_rhs), " (cartesian) per right-hand side");
}

const DynamicsCost& dynamics_cost(const Model& m) {
  return m.derived.get<DynamicsCost>([&] {
    const CostConstants& k = cost_constants();
    DynamicsCost c;
    c.nb = m.nb;
    c.n = m.nv_joint;
    c.rows = m.nc_joint;
    // coordinates on each coordinate's path to the root (the CRBA's inner loop)
    if (m.is_tree && !m.tree_order.empty()) {
      std::vector<int> depth(m.joints.size(), 0), joint_of(m.nb, -1);
      for (size_t j = 0; j < m.joints.size(); ++j)
        if (m.joints[j].child != kGround) joint_of[m.joints[j].child] = static_cast<int>(j);
      for (int ji : m.tree_order) {
        const Joint& j = m.joints[ji];
        const int up = j.parent == kGround ? -1 : joint_of[j.parent];
        depth[ji] = (up >= 0 ? depth[up] : 0) + joint_dofs(j.type);
        c.path += joint_coords(j.type) * static_cast<double>(depth[ji]);
      }
    }
    const double n = c.n, nb = c.nb;
    c.crba = k.c0 + k.c_body * nb + k.c_path * c.path + k.c_chol * n * n * n;
    c.aba = k.a0 + k.a_body * nb;
    c.cartesian = k.k0 + k.k_body * nb;
    c.joint = c.aba < c.crba ? DynamicsMethod::Aba : DynamicsMethod::Crba;
    const double jc = std::min(c.crba, c.aba);
    c.best = c.cartesian < jc ? DynamicsMethod::Cartesian : c.joint;
    // light bodies (kernels/kkt_factor.hpp): ABA, about each body's centre of mass, keeps their
    // accelerations; CRBA's composites about the world origin lose a light leaf link's (UR5
    // wrist_3_link inertia x 1e-12: 6.6e-4), and the Cartesian path turns to a dense LU
    // (actuator rotors, massless coupling followers, are exact in CRBA: LightBodies)
    c.light = !light_bodies(m).joint_space.empty();
    if (c.light) c.joint = c.best = DynamicsMethod::Aba;
    c.dof = c.n;
    if (!m.gear_constraints.empty() && m.joint_tree) {
      // the null-space reduction needs the mass matrix: CRBA
      c.dof = c.n - gear_space(m).rank;
      const double dof = c.dof;
      c.joint = DynamicsMethod::Crba;
      c.joint_rhs = c.crba + k.c_chol * (n * n * dof + dof * dof * dof);
    } else {
      c.joint_rhs = jc;
    }
    c.joint_rhs += k.j0 + k.j_body * nb;
    c.cartesian_rhs = k.s0 + k.s_body * nb;
    c.joint_rhs_cheaper = c.joint_rhs <= c.cartesian_rhs;
    return c;
  });
}

DynamicsMethod resolve_method(const Model& m, DynamicsMethod method) {
  switch (method) {
    case DynamicsMethod::Auto:
      // floating bases: the joint-space methods (the Cartesian method takes fixed bases only)
      return m.n_free ? dynamics_cost(m).joint : dynamics_cost(m).best;
    case DynamicsMethod::Joint:
      return dynamics_cost(m).joint;
    case DynamicsMethod::Crba:
      // a model with light bodies: ABA instead (dynamics_cost), documented
      return dynamics_cost(m).light ? DynamicsMethod::Aba : method;
    default:
      return method;
  }
}

const char* method_key(DynamicsMethod method) {
  switch (method) {
    case DynamicsMethod::Auto:
      return "auto";
    case DynamicsMethod::Joint:
      return "joint";
    case DynamicsMethod::Crba:
      return "crba";
    case DynamicsMethod::Aba:
      return "aba";
    case DynamicsMethod::Cartesian:
      return "cartesian";
  }
  return "cartesian";
}

}  // namespace armdyn
