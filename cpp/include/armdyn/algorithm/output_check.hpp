// SPDX-License-Identifier: BSD-3-Clause
// The check after a call from outside (the dynamics functions of the Python API): finite inputs
// that gave a non-finite output overflowed double precision; the message names the output's
// first offending entry and the input entry of largest magnitude, the usual culprit.
#pragma once

#include <initializer_list>
#include <string>

namespace armdyn {

/// One input of a call, for the messages: its name and values.
struct NamedInput {
  const char* name;
  const double* data;
  long size;
};

template <class V>
NamedInput named_input(const char* name, const V& v) {
  return NamedInput{name, v.data(), static_cast<long>(v.size())};
}

/// "; the largest input is tau[1] = 1.7e+308": the input entry of largest magnitude ("" with no
/// inputs); its magnitude into *peak when peak is not null.
std::string largest_input(std::initializer_list<NamedInput> inputs, double* peak = nullptr);

/// A SolverError when out (size entries) is not finite (the inputs are checked finite before the
/// call): "fn: finite inputs overflow double precision: out_name[i] = x; the largest input is
/// ...". A pass over the output only.
void check_finite_output(const char* fn, const char* out_name, const double* out, long size,
                         std::initializer_list<NamedInput> inputs);

}  // namespace armdyn
