// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/model/columns.hpp"

namespace armdyn {

std::vector<long> row_shape(const Model& m, Columns c, long limits) {
  const long nj = static_cast<long>(m.joints.size());
  switch (c) {
    case Columns::None:
      return {};
    case Columns::Nq:
      return {m.nq};
    case Columns::Nv:
      return {m.nv};
    case Columns::NqJoint:
      return {static_cast<long>(m.nq_joint)};
    case Columns::NvJoint:
      return {static_cast<long>(m.nv_joint)};
    case Columns::Coords:
      return {static_cast<long>(m.coords.size())};
    case Columns::Drives:
      return {static_cast<long>(m.drives.size())};
    case Columns::Joints3:
      return {nj, 3};
    case Columns::Gears:
      return {static_cast<long>(m.gears.size() + m.gear_constraints.size())};
    case Columns::Limits:
      return {limits};
  }
  return {};
}

long row_size(const Model& m, Columns c, long limits) {
  long n = 1;
  for (long k : row_shape(m, c, limits)) n *= k;
  return n;
}

std::vector<std::string> gear_names(const Model& m) {
  std::vector<std::string> names;
  names.reserve(m.gears.size() + m.gear_constraints.size());
  for (const auto& g : m.gears) names.push_back(g.name);
  for (const auto& g : m.gear_constraints) names.push_back(g.name);
  return names;
}

}  // namespace armdyn
