// SPDX-License-Identifier: BSD-3-Clause
// URDF import. Links joined by fixed joints are merged into one rigid body; revolute and
// continuous joints become revolute joints, prismatic joints prismatic ones, in the URDF
// document order. Joint coordinates are 0 at the URDF zero configuration (the assembly pose).
#pragma once

#include <string>

#include "armdyn/builder/builder.hpp"
#include "armdyn/math/types.hpp"

namespace armdyn {

/// Build a ModelBuilder from a URDF file path or an XML string (detected by a leading '<' after
/// whitespace).
///
/// - Each group of links joined by fixed joints becomes one body named after its top link, with
///   the group's total mass, centre of mass and inertia about it, in the top link's frame axes.
/// - fixed_base = true: the root link and everything fixed to it become "ground".
///   fixed_base = false: the root group becomes a body declared free (joint "root_free").
/// - Moving joints are added in document order, so it defines every joint-space array.
/// - Every link stays a named frame (ModelBuilder::add_frame) at its link frame on the body it
///   was merged into (on ground for the links of a fixed base): `tool0`, flanges, sensors.
/// - <limit> sets joint limits (continuous joints keep unbounded positions).
/// - Ignored: visual, collision, material, transmission, gazebo, mimic, safety, calibration and
///   joint dynamics (damping/friction).
///
/// @throws UrdfError on a missing file, malformed XML or URDF, floating/planar/unknown joints,
///   zero joint axes, massless moving links or invalid inertial data (naming the culprit).
ModelBuilder urdf_builder(const std::string& path_or_xml, bool fixed_base, const Vec3& gravity);

}  // namespace armdyn
