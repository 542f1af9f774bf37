// SPDX-License-Identifier: BSD-3-Clause
// Reactions stage of the Cartesian pipeline: the force and torque a joint transmits to its child
// at the joint point, in the child's joint frame, from the multipliers (data.delta) of the rows
// of the joint at the loaded kinematics: the constraint force on a body is -zeta_b^T delta.
#pragma once

#include "armdyn/data.hpp"

namespace armdyn {

/// Reaction on joint j's child (on its parent, negated, when the child is ground) at the joint
/// point, in the child's joint frame. Zero for a joint without rows or with rows outside
/// data.nrows. Needs the kinematics and constraints of the evaluation that gave data.delta.
void joint_reaction(const Model& m, const Data& d, int j, Vec3& force, Vec3& torque);

}  // namespace armdyn
