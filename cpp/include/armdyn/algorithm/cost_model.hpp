// SPDX-License-Identifier: BSD-3-Clause
// Which joint-space forward-dynamics algorithm (CRBA + Cholesky, or the articulated-body
// algorithm) and which formulation (joint space or the Cartesian KKT system) is cheaper for a
// model, from a cost model whose constants were measured on the reference machine (2-core VM,
// Release build) by `python -m benchmarks.cost_model` (benchmarks/cost_model.py: times on spatial
// chains of 1 to 400 links, fitted by non-negative least squares on relative residuals; results
// in benchmarks/results/cost_model.json):
//   crba      = c0 + c_body nb + c_path P + c_chol n^3   (P = sum over coordinates of the
//                                                         coordinates on their path to the root)
//   aba       = a0 + a_body nb
//   cartesian = k0 + k_body nb                           (forward_dynamics through the KKT path)
//   simulate's right-hand side: joint space = min(crba, aba) + j0 + j_body nb (with ideal gears
//   crba + c_chol (n^2 dof + dof^3), the null-space reduction, an estimate); Cartesian =
//   s0 + s_body nb
// in microseconds per evaluation, nb bodies and n coordinates. Derived once per model
// (Model::derived). Only the ratios matter for the choices: a faster or slower machine scales
// all of them alike.
#pragma once

#include <string>

#include "armdyn/algorithm/dynamics.hpp"

namespace armdyn {

struct CostConstants {
  double c0, c_body, c_path, c_chol;
  double a0, a_body;
  double k0, k_body;
  double j0, j_body;
  double s0, s_body;
};
/// The measured constants (microseconds).
const CostConstants& cost_constants();

struct DynamicsCost {
  int nb = 0, n = 0, rows = 0, dof = 0;
  double path = 0.0;  ///< sum over coordinates of the coordinates on their path to the root
  /// predicted microseconds per forward_dynamics call of each method
  double crba = 0.0, aba = 0.0, cartesian = 0.0;
  /// predicted microseconds per right-hand side of simulate: joint space, Cartesian
  double joint_rhs = 0.0, cartesian_rhs = 0.0;
  DynamicsMethod joint = DynamicsMethod::Crba;  ///< the cheaper joint-space algorithm
  DynamicsMethod best = DynamicsMethod::Crba;   ///< the cheapest of crba, aba, cartesian
  bool joint_rhs_cheaper = true;                ///< simulate: joint space is predicted cheaper
  /// the model has light bodies (kernels/kkt_factor.hpp light_bodies): joint, best and an explicit
  /// "crba" take ABA, the algorithm that keeps their accelerations
  bool light = false;
  /// e.g. "predicted 41 us (ABA) vs 95 us (CRBA) vs 120 us (Cartesian) per evaluation"
  std::string forward_summary() const;
  std::string rhs_summary() const;
};

/// The cost model's prediction for m (derived once per model). Meaningful for joint trees; for
/// other models only the Cartesian figures.
const DynamicsCost& dynamics_cost(const Model& m);

/// The algorithm forward_dynamics runs for method (Auto and Joint resolved by the cost model;
/// Crba on a model with light bodies runs ABA).
DynamicsMethod resolve_method(const Model& m, DynamicsMethod method);
const char* method_name(DynamicsMethod method);
/// The method's name as dynamics_method takes it: "auto", "joint", "crba", "aba", "cartesian".
const char* method_key(DynamicsMethod method);

}  // namespace armdyn
