// SPDX-License-Identifier: BSD-3-Clause
// The columns of the row-major output tables of a run (SimResult) and of driven inverse dynamics
// (InverseDynamicsResult): each table of their field lists (ARMDYN_SIM_TABLES,
// ARMDYN_DRIVEN_ID_TABLES) names its columns by one of these, so that the result structs, the
// Python dicts the bindings make of them and the bound on an output row's size follow one list.
#pragma once

#include <string>
#include <vector>

#include "armdyn/model/model.hpp"

namespace armdyn {

enum class Columns {
  None,     ///< one value per row: a table of shape (n,)
  Nq,       ///< the Cartesian positions (Model::nq)
  Nv,       ///< the Cartesian velocities (Model::nv)
  NqJoint,  ///< every joint-space coordinate (Model::nq_joint)
  NvJoint,  ///< every joint-space dof (Model::nv_joint)
  Coords,   ///< every coordinate of Model::coords
  Drives,   ///< one per drive
  Joints3,  ///< three per joint: a table of shape (n, n_joints, 3)
  Gears,    ///< one per gear pair, then one per ideal gear (gear_names)
  Limits,   ///< one per joint held by a stop (the result's limit joints: at most one per joint)
};

/// The shape of one row of a table: {} for None, {n_joints, 3} for Joints3, else {columns}.
/// limits: the number of joints held by stops (Columns::Limits).
std::vector<long> row_shape(const Model& m, Columns c, long limits = 0);
/// The number of values in one row (the product of row_shape).
long row_size(const Model& m, Columns c, long limits = 0);
/// The names of the Columns::Gears columns: the gear pairs', then the ideal gears'.
std::vector<std::string> gear_names(const Model& m);

}  // namespace armdyn
