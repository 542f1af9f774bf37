// SPDX-License-Identifier: BSD-3-Clause
// Named frames (model.frames: URDF links, tool flanges, sensors; ModelBuilder::add_frame): their
// world pose and their Jacobian at joint coordinates q, and the same from a Cartesian state.
//
// The frame Jacobian J (6 x n, n the joint velocities) is taken at the frame's origin, in world
// axes (Pinocchio's LOCAL_WORLD_ALIGNED): [v; w] = J qd, v the velocity of the frame's origin and
// w its angular velocity, both in world. Only the joints on the frame's path to ground have
// non-zero columns; each joint writes its own (joint_jacobian_columns).
#pragma once

#include <string>

#include "armdyn/data.hpp"

namespace armdyn {

/// A frame's world rotation (frame -> world) and origin from its body's pose (ground: identity).
inline void frame_placement(const NamedFrame& f, const BodyKin* body, Mat3& R, Vec3& p) {
  if (!body) {
    R = f.rotation;
    p = f.point;
    return;
  }
  R.noalias() = body->R * f.rotation;
  p.noalias() = body->R * f.point;
  p += body->x;
}

/// The column writer: joint j's Jacobian columns for a point p moving with its child, from the
/// joint's child-side point and world axis (RneWork::point, RneWork::axis) and the child body's
/// pose, into J (6 x n). Revolute: [axis x (p - point); axis]; prismatic: [axis; 0];
/// cylindrical: both, angle then displacement; other joint types have no columns. Columns are
/// indexed by the joint's first velocity coordinate (today coord0: a joint-space tree has as many
/// velocities as coordinates). A joint type with more velocities (a floating base's six, from the
/// child's pose) adds its case here and nowhere else.
void joint_jacobian_columns(const Joint& j, const Vec3& point, const Vec3& axis,
                            const BodyKin& child, const Vec3& p, Mat6X& J);

/// The world pose of frame `frame` (index into model.frames) at joint coordinates q, as a 4 x 4
/// homogeneous transform [R p; 0 1] into data.frame_pose. Allocates nothing.
/// @throws ModelError when the model is not a joint-space tree, on a wrong size or non-finite q,
///   or a frame index out of range.
const Mat4& frame_pose(const Model& m, Data& d, Eigen::Ref<const VecX> q, int frame);
/// The frame Jacobian (6 x n, linear rows then angular rows, world axes, at the frame's origin)
/// at joint coordinates q into data.frame_jacobian. Allocates nothing. Throws as frame_pose.
const Mat6X& frame_jacobian(const Model& m, Data& d, Eigen::Ref<const VecX> q, int frame);
/// The same by frame name (throws ModelError "unknown frame ..." otherwise).
const Mat4& frame_pose(const Model& m, Data& d, Eigen::Ref<const VecX> q, const std::string& frame);
const Mat6X& frame_jacobian(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                            const std::string& frame);

/// frame_pose and frame_jacobian from kinematics already loaded: data.kin and the joint frames
/// data.rne.point, data.rne.axis of joint_space_poses(m, q, data.kin, data.rne); no checks.
const Mat4& frame_pose_loaded(const Model& m, Data& d, int frame);
const Mat6X& frame_jacobian_loaded(const Model& m, Data& d, int frame);

/// Any model (loops included): the frame's world pose from the Cartesian state u (nq), the
/// body's Euler parameters taken as they are, into data.frame_pose.
/// @throws ModelError on a wrong size or non-finite u, or a frame index out of range.
const Mat4& frame_pose_cartesian(const Model& m, Data& d, Eigen::Ref<const VecX> u, int frame);
/// Any model: the frame Jacobian with respect to the bodies' velocities v (6 x nv; v = (centre
/// of mass velocity in world, angular velocity in the body frame) per body, the Cartesian
/// state's), linear rows then angular rows, world axes, at the frame's origin, into
/// data.frame_jacobian_v: [v_frame; w_frame] = J v. Zero for a frame on ground.
const MatX& frame_jacobian_cartesian(const Model& m, Data& d, Eigen::Ref<const VecX> u, int frame);

}  // namespace armdyn
