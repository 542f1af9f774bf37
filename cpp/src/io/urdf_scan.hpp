// SPDX-License-Identifier: BSD-3-Clause
// Private to cpp/src/io: the URDF reader's stage 1, the first pass over the XML with tinyxml2
// (before urdfdom sees it): well-formedness, valid UTF-8 names, every numeric attribute parsed
// completely as a finite double (urdfdom zeroes nan, inf and 1e400 silently), the links, the
// <joint> elements in document order (urdfdom keeps them in a std::map sorted by name) with
// their types, and the tree structure, with messages that name the culprit.
#pragma once

#include <set>
#include <string>
#include <vector>

namespace armdyn::urdf_import {

// one <joint> element as written in the document
struct JointDecl {
  std::string name, type, parent, child;
};

// what the first pass keeps
struct Document {
  std::vector<JointDecl> joints;   // in document order
  std::set<std::string> inertial;  // links with an <inertial> element
};

// the first pass over `xml` (already pre-scanned); where: the source, for messages
Document scan_document(const std::string& xml, const std::string& where);

}  // namespace armdyn::urdf_import
