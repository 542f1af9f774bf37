// SPDX-License-Identifier: BSD-3-Clause
// model_draft, finalize_like (armdyn/io/model_copy.hpp).
#include "armdyn/io/model_copy.hpp"

#include <algorithm>
#include <memory>
#include <utility>

#include "armdyn/errors.hpp"
#include "armdyn/io/serialize.hpp"

namespace armdyn {

Model model_draft(const Model& m, const std::string& fn, std::vector<std::string>& notes,
                  const std::string& hint) {
  std::string bytes;
  try {
    bytes = serialize_draft(m);
  } catch (const ModelError& e) {
    throw ModelError(msg(fn, ": the model cannot be copied (", e.what(), ")", hint));
  }
  Model draft = deserialize_draft(bytes);
  notes = std::move(draft.warnings);
  draft.warnings.clear();
  return draft;
}

ModelPtr finalize_like(const ModelBuilder& b, const Model& m, std::vector<std::string> notes,
                       const std::string& fn, const std::string& what) {
  std::shared_ptr<Model> out;
  try {
    out = std::const_pointer_cast<Model>(b.finalize(m.finalize_options));
  } catch (const ModelError& e) {
    throw ModelError(msg(fn, ": the model with ", what, " does not finalize: ", e.what()));
  }
  for (const std::string& w : out->warnings)
    if (std::find(notes.begin(), notes.end(), w) == notes.end()) notes.push_back(w);
  out->warnings = std::move(notes);
  out->force_dense_kkt = m.force_dense_kkt;
  return out;
}

}  // namespace armdyn
