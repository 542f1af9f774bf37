// SPDX-License-Identifier: BSD-3-Clause
// A readable description of a model: sizes, topology, mobility and redundant rows, the KKT
// path, the welded form and the joint-space path simulate() would take, and its elements.
#pragma once

#include <string>

#include "armdyn/model/model.hpp"

namespace armdyn {

/// Several lines of text (the Python Model.summary()).
std::string summary(const Model& m);

}  // namespace armdyn
