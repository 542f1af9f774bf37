// SPDX-License-Identifier: BSD-3-Clause
// Private to cpp/src/io: the URDF reader's stages 3 and 4, on urdfdom's model. The link tree:
// every link frame's world pose at q = 0 and the groups of links joined by fixed joints (one
// body each); then each group's mass, centre of mass and inertia, merged from its links'.
#pragma once

#include <urdf_model/model.h>

#include <map>
#include <string>
#include <vector>

#include "armdyn/math/types.hpp"
#include "urdf_scan.hpp"

namespace armdyn::urdf_import {

// a rigid frame: origin and rotation (frame -> world)
struct Frame {
  Vec3 p = Vec3::Zero();
  Mat3 R = Mat3::Identity();
};

// a group of links welded by fixed joints: one body
struct Group {
  std::string top;                 // its first (top) link: names the body, gives its frame
  std::vector<std::string> links;  // top first
  double mass = 0.0;
  Vec3 com = Vec3::Zero();      // world
  Mat3 inertia = Mat3::Zero();  // about com, in the top link's axes
};

// the links at q = 0, from the root: a child link frame is its joint frame (parent link frame
// composed with the joint origin)
struct LinkTree {
  std::string root;
  bool fixed_base = true;
  std::map<std::string, Frame> frame;         // link -> its world pose
  std::map<std::string, std::string> top_of;  // link -> the top link of its group
  std::map<std::string, Group> groups;        // by top link
  std::vector<std::string> group_order;       // tops in depth-first order from the root

  // the ground group (fixed base) needs no mass; every other group becomes a body with mass
  bool is_ground(const std::string& top) const { return fixed_base && top == root; }
  // the body a link belongs to: its group's top link, or "ground"
  std::string body_of(const std::string& link) const {
    const std::string& top = top_of.at(link);
    return is_ground(top) ? std::string("ground") : top;
  }
};

// " (merged with 'b', 'c')" after a group's top link when it has other links, else ""
std::string merged_with(const Group& g);

// urdfdom logs an <inertial> it cannot read and drops it: never take that as "massless"
void check_inertials_read(const Document& document, const urdf::ModelInterface& model);

// the link frames and the fixed groups; refuses a link reached twice, a non-finite joint origin
// and links not connected to the root
LinkTree link_tree(const urdf::ModelInterface& model, bool fixed_base);

// Sets each body group's mass, centre of mass and inertia (xml: the text, read again only to
// tell urdfdom's massless links from the file's). Checks every link's inertial data; refuses
// every offending tensor at once (naming `where`); returns the warnings of round-off clamped.
std::vector<std::string> merge_inertias(LinkTree& tree, const urdf::ModelInterface& model,
                                        const std::string& xml, const std::string& where,
                                        bool physical_inertia);

}  // namespace armdyn::urdf_import
