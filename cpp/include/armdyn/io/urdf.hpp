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
/// - <limit> sets joint limits (continuous joints keep unbounded positions).
/// - Massless links (no <inertial>, or mass 0) are massless bodies: accepted wherever every
///   joint motion still carries inertia (finalize() checks it and names the joint otherwise).
/// - physical_inertia = true: every moving link's inertia must be physically consistent
///   (positive semidefinite, triangle inequality); the refusal lists every offending link with
///   its principal moments. false: any positive semidefinite tensor (round-off negatives down to
///   -1e-12 of the largest moment clamped to zero, with a warning); the returned builder keeps
///   the setting (ModelBuilder::set_physical_inertia).
/// - Ignored: visual, collision, material, transmission, gazebo, mimic, safety, calibration and
///   joint dynamics (damping/friction).
///
/// @throws UrdfError on a missing file, malformed XML or URDF, floating/planar/unknown joints,
///   zero joint axes or invalid inertial data (naming the culprit).
ModelBuilder urdf_builder(const std::string& path_or_xml, bool fixed_base, const Vec3& gravity,
                          bool physical_inertia = true);

}  // namespace armdyn
