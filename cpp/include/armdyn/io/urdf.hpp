// SPDX-License-Identifier: BSD-3-Clause
// URDF import. Links joined by fixed joints are merged into one rigid body; revolute and
// continuous joints become revolute joints, prismatic joints prismatic ones, in the URDF
// document order. Joint coordinates are 0 at the URDF zero configuration (the assembly pose).
#pragma once

#include <cstddef>
#include <string>

#include "armdyn/builder/builder.hpp"
#include "armdyn/math/types.hpp"

namespace armdyn {

/// Largest URDF accepted, as a file or as an XML string [bytes] (64 MiB).
constexpr std::size_t kUrdfMaxBytes = std::size_t(64) << 20;
/// Most attributes one XML element may carry. tinyxml2's duplicate-attribute check is quadratic
/// in the attributes of an element (40k attributes: 8 s); a linear pre-scan of the raw text
/// refuses more than this before tinyxml2 sees the document.
constexpr int kUrdfMaxAttributes = 1000;
/// Smoothing velocity of the Coulomb term imported from <dynamics friction>: the joint friction
/// tau = -damping qdot - friction tanh(qdot / v_s) [rad/s or m/s] (the builder's default).
constexpr double kUrdfCoulombSmoothing = 1e-3;

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
/// - <dynamics damping friction> becomes joint friction (add_joint_friction: viscous damping,
///   Coulomb friction smoothed with kUrdfCoulombSmoothing).
/// - <mimic joint multiplier offset> (with mimic = true, the default): a coupling
///   q = multiplier q_joint + offset (ModelBuilder::add_coupling, named after the mimicking
///   joint; both joints revolute/continuous or both prismatic); the joint-space functions then
///   take the independent coordinates, as Pinocchio's mimic=True models. mimic = false: each
///   mimicking joint keeps its own coordinate (Pinocchio's default).
/// - Massless links (no <inertial>, or mass 0) are massless bodies: accepted wherever every
///   joint motion still carries inertia (finalize() checks it and names the joint otherwise).
/// - physical_inertia = true: every moving link's inertia must be physically consistent
///   (positive semidefinite, triangle inequality); the refusal lists every offending link with
///   its principal moments. false: any positive semidefinite tensor (round-off negatives down to
///   -1e-12 of the largest moment clamped to zero, with a warning); the returned builder keeps
///   the setting (ModelBuilder::set_physical_inertia).
/// - Ignored: visual, collision, material, transmission, gazebo, safety_controller and
///   calibration (their numbers are still checked).
/// - No moving joint with fixed_base = true: a builder with no bodies (a zero-DOF model).
/// - Input checks before urdfdom: a path must name a regular file of at most kUrdfMaxBytes; an
///   element has at most kUrdfMaxAttributes attributes; every numeric attribute parses completely
///   as a finite double; names are valid UTF-8; no NUL bytes. Messages quote short excerpts only
///   and are valid UTF-8.
///
/// @throws UrdfError on a bad source (missing, not a regular file, too large), malformed XML or
///   URDF, bad numbers or names, floating/planar/unknown joints, zero joint axes or invalid
///   inertial data (naming the culprit); a <mimic> naming an unknown or fixed joint, or one
///   add_coupling refuses (naming both joints).
ModelBuilder urdf_builder(const std::string& path_or_xml, bool fixed_base, const Vec3& gravity,
                          bool physical_inertia = true, bool mimic = true);

}  // namespace armdyn
