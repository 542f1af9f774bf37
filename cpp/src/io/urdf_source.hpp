// SPDX-License-Identifier: BSD-3-Clause
// Private to cpp/src/io: the URDF reader's stage 0, the text. The source is read (a file path
// or an XML string) and its raw text pre-scanned before any XML parser sees it; the quoting of
// names and excerpts in every URDF message.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace armdyn::urdf_import {

// s with its control characters and invalid UTF-8 bytes escaped as \xNN, cut to at most about
// `max_chars` characters (an ellipsis marks the cut): always valid UTF-8, always short
std::string excerpt(std::string_view s, std::size_t max_chars = 40);

// a name as quoted in messages: escaped and at most 80 characters
std::string nm(const std::string& name);

// The XML text, and in *where a description of where it came from for error messages: a string
// starting with '<' (after whitespace and a byte order mark) is the XML itself; anything else
// is a path, which must name a regular file (checked with stat before it is opened, so that a
// FIFO or a device never blocks or streams) of at most kUrdfMaxBytes.
std::string read_source(const std::string& path_or_xml, std::string* where);

// Linear pre-scan of the raw text before tinyxml2 (whose duplicate-attribute check is quadratic
// in the attributes of one element): refuses an element with more than kUrdfMaxAttributes
// attributes, and NUL bytes (urdfdom would read the text only up to the first).
void prescan(const std::string& xml, const std::string& where);

}  // namespace armdyn::urdf_import
