// SPDX-License-Identifier: BSD-3-Clause
// Energy stage of the Cartesian pipeline: the kinetic energy sum 1/2 m |x'|^2 + 1/2 w^T J w of
// the bodies and the potential energy of gravity, the point-to-point springs and the
// joint-coordinate springs, at the bodies' state (u, v).
#pragma once

#include "armdyn/data.hpp"

namespace armdyn {

/// Kinetic energy ke and potential energy pe (gravity + springs) at (u, v); loads the
/// kinematics into data.kin.
void energy(const Model& m, Data& d, const double* u, const double* v, double& ke, double& pe);

}  // namespace armdyn
