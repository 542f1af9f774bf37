// SPDX-License-Identifier: BSD-3-Clause
// A Model (finalized, or a builder's draft) as bytes and back: every field, doubles bit for bit,
// so that a restored model simulates exactly as the original (pickling, copies, a model sent to
// worker processes). The format is private to one armdyn version: it starts with a magic tag
// and a format version, checked on load. The derived caches (KKT plans, the welded model) are
// not stored: a restored model builds them again on first use, as the original did.
#pragma once

#include <string>

#include "armdyn/model/model.hpp"

namespace armdyn {

/// The bytes of `m`. @throws ModelError naming the element when a profile is a user function
/// (a Python callable cannot be stored).
std::string serialize_model(const Model& m);
/// The model serialize_model() stored. @throws ModelError on bytes that are not such a model
/// (wrong tag, other format version, truncated or inconsistent data).
Model deserialize_model(const std::string& bytes);

}  // namespace armdyn
