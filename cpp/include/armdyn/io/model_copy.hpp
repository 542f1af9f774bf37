// SPDX-License-Identifier: BSD-3-Clause
// A finalized model rebuilt with changes (Model::with_payloads, model_with_dynamic_parameters):
// its description as a builder's draft (the bytes of armdyn/io/serialize.hpp), changed through
// the builder, then finalized as the original was.
#pragma once

#include <string>
#include <vector>

#include "armdyn/builder/builder.hpp"

namespace armdyn {

/// m's description as a builder's draft, its derived tables made afresh and its notes
/// (Model::warnings) moved into `notes`.
/// @throws ModelError "<fn>: the model cannot be copied (...)<hint>" when m has no draft form.
Model model_draft(const Model& m, const std::string& fn, std::vector<std::string>& notes,
                  const std::string& hint = "");

/// b (holding a draft of m) finalized with m's options and KKT path; its notes are `notes` (m's)
/// followed by those finalize made that are not among them.
/// @throws ModelError "<fn>: the model with <what> does not finalize: ...".
ModelPtr finalize_like(const ModelBuilder& b, const Model& m, std::vector<std::string> notes,
                       const std::string& fn, const std::string& what);

}  // namespace armdyn
