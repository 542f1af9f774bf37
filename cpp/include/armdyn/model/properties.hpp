// SPDX-License-Identifier: BSD-3-Clause
// What a finalized model reports about itself, derived from its fields: the independent
// joint-space names and limits (a coupled model's followers removed, IndependentCoords), the
// couplings and actuators as named lists, the rotors' reflected inertia. The Python Model's
// properties (cpp/bindings/bind_model.cpp) read these; they allocate and are not for hot paths.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "armdyn/model/model.hpp"

namespace armdyn {

/// The names of a list of named elements (bodies, joints, frames, drives), in order.
template <class T>
std::vector<std::string> names_of(const std::vector<T>& items) {
  std::vector<std::string> r;
  r.reserve(items.size());
  for (const T& x : items) r.push_back(x.name);
  return r;
}

/// The type of each joint ("revolute", "prismatic", ...: joint_type_name), in order.
std::vector<std::string> joint_type_names(const Model& m);

/// Index of each entry of the independent q into Model::q_names (every joint's coordinate).
std::vector<int> independent_coord_indices(const Model& m);
/// Names of the entries of the independent q (n_coords) and of qd (n_dofs).
std::vector<std::string> independent_coord_names(const Model& m);
std::vector<std::string> independent_dof_names(const Model& m);
/// The independent degree of freedom (into the independent qd) that moves coordinate `coord`
/// (-1 for a dependent coordinate of a loop model, Model::loop_coordinates).
int independent_dof(const Model& m, int coord);

/// Which joint limit coord_limits() reports.
enum class LimitKind { Lower, Upper, Effort, Velocity };
/// One limit per entry of the independent q (Lower, Upper) or qd (Effort, Velocity): a joint's
/// limits belong to its first coordinate; -inf / inf where none (the joints store +-1e300 for
/// no position limit, 0 or less for no effort or velocity limit) and on the floating bases.
VecX coord_limits(const Model& m, LimitKind which);

/// A coupling (ModelBuilder::add_coupling, URDF <mimic>) by its joints' names:
/// q_follower = multiplier q_leader + offset.
struct CouplingInfo {
  std::string name, follower, leader;
  double multiplier = 1.0, offset = 0.0;
};
std::vector<CouplingInfo> couplings(const Model& m);

/// (n_dofs) the rotors' inertia reflected through their gears, G^T diag(J) G over the rotor
/// joints: N^2 J at each actuated dof (scaled by the actuated joint's own coupling scale), 0
/// elsewhere [kg m^2, or kg for a prismatic joint].
VecX reflected_inertia(const Model& m);

/// Index into the joint dofs (Model::dof_names) of each drive's coordinate.
std::vector<int> drive_dofs(const Model& m);
/// (nb) body masses [kg].
VecX body_masses(const Model& m);

/// A copy of `m` on KKT path `path`: "dense" (Model::force_dense_kkt, the reference path) or
/// "auto" (the plan finalize() picks). The copy derives its plans and welded form afresh.
/// @throws ModelError for any other path.
std::shared_ptr<Model> with_kkt_path(const Model& m, const std::string& path);

}  // namespace armdyn
