// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/frames.hpp"

#include "armdyn/algorithm/loop_coordinates.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/math/quaternion.hpp"

namespace armdyn {

namespace {

const NamedFrame& checked_frame(const Model& m, int frame, const char* fn) {
  if (frame < 0 || frame >= static_cast<int>(m.frames.size()))
    throw ModelError(msg(fn, ": frame index ", frame, " out of range (the model has ",
                         m.frames.size(), " frames)"));
  return m.frames[frame];
}

// the checks of the joint-space calls, and the poses (with the joint frames) of every body
// (a coupled model's q holds its independent coordinates: expanded to every joint's first)
void load_poses(const Model& m, Data& d, Eigen::Ref<const VecX> q, int frame, const char* fn) {
  require_joint_space(m, fn, true);
  check_data(m, d, fn);
  checked_frame(m, frame, fn);
  check_joint_vector(q, d.niq, fn, "q");
  check_base_quaternions(m, q, fn);
  if (d.ni == d.n) {
    joint_space_poses(m, q, d.kin, d.rne);
    return;
  }
  m.independent.expand_q(q.data(), d.coupled.q.data());
  joint_space_poses(m, d.coupled.q, d.kin, d.rne);
}

void set_pose(Mat4& T, const Mat3& R, const Vec3& p) {
  T.topLeftCorner<3, 3>() = R;
  T.topRightCorner<3, 1>() = p;
  T.row(3) << 0.0, 0.0, 0.0, 1.0;
}

}  // namespace

void joint_jacobian_columns(const Joint& j, const Vec3& point, const Vec3& axis,
                            const BodyKin& child, const Vec3& p, Mat6X& J) {
  // the joint's first column in qd
  const int c = j.dof0;
  switch (j.type) {
    case JointType::Free: {
      // a floating base: slides along and turns about its frame's axes through its origin
      const Mat3 B = free_frame(j, child);
      for (int k = 0; k < 3; ++k) {
        J.col(c + k) << B.col(k), Vec3::Zero();
        J.col(c + 3 + k) << B.col(k).cross(p - point), B.col(k);
      }
      break;
    }
    case JointType::Revolute:
      J.col(c) << axis.cross(p - point), axis;
      break;
    case JointType::Prismatic:
      J.col(c) << axis, Vec3::Zero();
      break;
    case JointType::Cylindrical:
      J.col(c) << axis.cross(p - point), axis;
      J.col(c + 1) << axis, Vec3::Zero();
      break;
    default:
      break;
  }
}

const Mat4& frame_pose_loaded(const Model& m, Data& d, int frame) {
  const NamedFrame& f = m.frames[frame];
  Mat3 R;
  Vec3 p;
  frame_placement(f, f.body == kGround ? nullptr : &d.kin[f.body], R, p);
  set_pose(d.frame_pose, R, p);
  return d.frame_pose;
}

const Mat6X& frame_jacobian_loaded(const Model& m, Data& d, int frame) {
  const NamedFrame& f = m.frames[frame];
  Mat3 R;
  Vec3 p;
  frame_placement(f, f.body == kGround ? nullptr : &d.kin[f.body], R, p);
  set_pose(d.frame_pose, R, p);
  Mat6X& J = d.frame_jacobian;
  J.setZero();
  // the joints on the frame's path to ground, children first
  for (int b = f.body; b != kGround;) {
    const int ji = d.joint_of_body[b];
    if (ji < 0) break;
    const Joint& j = m.joints[ji];
    joint_jacobian_columns(j, d.rne.point[ji], d.rne.axis[ji], d.kin[b], p, J);
    b = j.parent;
  }
  return J;
}

const Mat4& frame_pose(const Model& m, Data& d, Eigen::Ref<const VecX> q, int frame) {
  if (m.loop_coordinates)
    return loop_frame_pose(m, d, q, (checked_frame(m, frame, "frame_pose"), frame));
  load_poses(m, d, q, frame, "frame_pose");
  return frame_pose_loaded(m, d, frame);
}

const Mat6X& frame_jacobian(const Model& m, Data& d, Eigen::Ref<const VecX> q, int frame) {
  if (m.loop_coordinates)
    return loop_frame_jacobian(m, d, q, (checked_frame(m, frame, "frame_jacobian"), frame));
  load_poses(m, d, q, frame, "frame_jacobian");
  const Mat6X& J = frame_jacobian_loaded(m, d, frame);
  if (d.ni == d.n) return J;
  // a coupled model: J G, each follower's column onto its leader's (Model::independent)
  const IndependentCoords& ic = m.independent;
  Mat6X& Jr = d.frame_jacobian_independent;
  Jr.leftCols(ic.lead_v) = J.leftCols(ic.lead_v);
  Jr.rightCols(ic.n).setZero();
  for (int c = 0; c < static_cast<int>(ic.source.size()); ++c)
    Jr.col(ic.lead_v + ic.source[c]) += ic.scale[c] * J.col(ic.lead_v + c);
  return Jr;
}

const Mat4& frame_pose(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                       const std::string& frame) {
  return frame_pose(m, d, q, m.find_frame(frame));
}

const Mat6X& frame_jacobian(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                            const std::string& frame) {
  return frame_jacobian(m, d, q, m.find_frame(frame));
}

namespace {
// the checks of the Cartesian calls; the frame's body pose from u (nullptr: ground)
const BodyKin* cartesian_body(const Model& m, Data& d, Eigen::Ref<const VecX> u, int frame,
                              const char* fn, BodyKin& k) {
  check_data(m, d, fn);
  const NamedFrame& f = checked_frame(m, frame, fn);
  check_joint_vector(u, m.nq, fn, "u");
  if (f.body == kGround) return nullptr;
  k.x = u.segment<3>(7 * f.body);
  k.R = quat_to_rot(u.segment<4>(7 * f.body + 3));
  return &k;
}
}  // namespace

const Mat4& frame_pose_cartesian(const Model& m, Data& d, Eigen::Ref<const VecX> u, int frame) {
  BodyKin k;
  const BodyKin* body = cartesian_body(m, d, u, frame, "frame_pose_cartesian", k);
  Mat3 R;
  Vec3 p;
  frame_placement(m.frames[frame], body, R, p);
  set_pose(d.frame_pose, R, p);
  return d.frame_pose;
}

const MatX& frame_jacobian_cartesian(const Model& m, Data& d, Eigen::Ref<const VecX> u, int frame) {
  BodyKin k;
  const BodyKin* body = cartesian_body(m, d, u, frame, "frame_jacobian_cartesian", k);
  const NamedFrame& f = m.frames[frame];
  Mat3 R;
  Vec3 p;
  frame_placement(f, body, R, p);
  set_pose(d.frame_pose, R, p);
  MatX& J = d.frame_jacobian_v;
  J.setZero();
  if (!body) return J;
  // v_frame = xd + W x (p - x) with W = R_b w: [I, -skew(p - x) R_b; 0, R_b]
  const int c = 6 * f.body;
  J.block<3, 3>(0, c).setIdentity();
  J.block<3, 3>(0, c + 3).noalias() = -skew(p - body->x) * body->R;
  J.block<3, 3>(3, c + 3) = body->R;
  return J;
}

}  // namespace armdyn
