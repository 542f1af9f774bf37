// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/force_derivatives.hpp"

#include "armdyn/errors.hpp"

namespace armdyn {

bool has_force_elements(const Model& m) {
  return !m.body_loads.empty() || !m.springs.empty() || !m.coord_forces.empty() || !m.gears.empty();
}

void add_force_element_derivatives(const Model& m, Data&, const double*, const double*, double,
                                   Eigen::Ref<MatX>, Eigen::Ref<MatX>) {
  // placeholder of the i34 base: the branch i34-forcederiv replaces it
  if (has_force_elements(m))
    throw ModelError("dynamics derivatives: the model's force elements have no derivatives yet");
}

}  // namespace armdyn
