// SPDX-License-Identifier: BSD-3-Clause
// Welded bodies: bodies joined by fixed joints form one rigid composite (welded to ground: part
// of ground). welding(m) is m with each composite as one body and those fixed joints removed --
// the same motion with fewer bodies and rows -- and the maps back to m's bodies and joints.
// simulate() integrates it and reports every body and joint of m (poses from the composites,
// fixed-joint reactions from the members' Newton-Euler balances). Derived from m on first use
// and kept with it (Model::derived).
#pragma once

#include <memory>
#include <utility>
#include <vector>

#include "armdyn/model/model.hpp"

namespace armdyn {

/// Where a body of the full model sits in its composite.
struct Weld {
  int composite = kGround;           ///< body of the welded model (kGround: welded to ground)
  Vec3 offset = Vec3::Zero();        ///< the body's centre of mass in the composite's frame
  Mat3 rotation = Mat3::Identity();  ///< the body's axes in the composite's frame
};

struct Welding {
  std::shared_ptr<const Model> model;  ///< the welded model
  std::vector<Weld> weld;              ///< per body of the full model
  std::vector<int> weld_joint;         ///< per joint: its index in `model`, -1 when merged away
  /// the merged fixed joints, each body farther from its composite's root first:
  /// (joint, the body on the far side)
  std::vector<std::pair<int, int>> sweep;
  std::vector<int> roots;  ///< per composite: the body whose state defines it
  std::vector<Vec4> qrel;  ///< per body: its Euler parameters in its composite's frame
  /// per row of the full model: its row in `model` (-1: a merged fixed joint's)
  std::vector<int> row_map;
  /// per coordinate of the full model: its coordinate in `model` (fixed joints have none)
  std::vector<int> coord_map;
};

/// m's welding, or nullptr when no fixed joint can be merged.
const Welding* welding(const Model& m);

}  // namespace armdyn
