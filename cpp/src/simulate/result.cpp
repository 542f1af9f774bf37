// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/simulate/result.hpp"

namespace armdyn {

const char* limit_side_name(int side) { return side > 0 ? "lower" : "upper"; }

const char* limit_event_kind_name(int kind) {
  static const char* kinds[] = {"rest", "bounce", "release"};
  return kinds[kind];
}

size_t output_row_bytes(const Model& m) {
  const long nj = static_cast<long>(m.joints.size());
  long cols = 0;
#define ARMDYN_ADD_COLUMNS(name, columns, doc) cols += row_size(m, Columns::columns, nj);
  ARMDYN_SIM_TABLES(ARMDYN_ADD_COLUMNS)
  ARMDYN_SIM_NAMED_TABLES(ARMDYN_ADD_COLUMNS)
#undef ARMDYN_ADD_COLUMNS
  return static_cast<size_t>(cols) * sizeof(double);
}

}  // namespace armdyn
