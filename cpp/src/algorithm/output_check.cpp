// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/output_check.hpp"

#include <cmath>

#include "armdyn/errors.hpp"

namespace armdyn {

std::string largest_input(std::initializer_list<NamedInput> inputs, double* peak_out) {
  const NamedInput* big = nullptr;
  long at = 0;
  double peak = -1.0;
  for (const NamedInput& in : inputs)
    for (long i = 0; i < in.size; ++i)
      if (std::abs(in.data[i]) > peak) {
        peak = std::abs(in.data[i]);
        big = &in;
        at = i;
      }
  if (peak_out) *peak_out = peak;
  return big ? msg("; the largest input is ", big->name, "[", at, "] = ", big->data[at]) : "";
}

void check_finite_output(const char* fn, const char* out_name, const double* out, long size,
                         std::initializer_list<NamedInput> inputs) {
  long bad = -1;
  for (long i = 0; i < size; ++i)
    if (!std::isfinite(out[i])) {
      bad = i;
      break;
    }
  if (bad < 0) return;
  throw SolverError(msg(fn, ": finite inputs overflow double precision: ", out_name, "[", bad,
                        "] = ", out[bad], largest_input(inputs), " (scale the inputs down)"));
}

}  // namespace armdyn
