// SPDX-License-Identifier: BSD-3-Clause
// Joint-space entry points for tree models whose joints define coordinates (revolute, prismatic,
// cylindrical, fixed): the Cartesian state from joint coordinates (forward kinematics along the
// tree), joint coordinates from the Cartesian state, and the recursive Newton-Euler residual
// (the sweep of armdyn/algorithm/rnea.hpp and of forward dynamics).
#pragma once

#include "armdyn/kernels/jets.hpp"
#include "armdyn/model/model.hpp"

namespace armdyn {

/// Per-body scratch of state_from_joints (the bodies' kinematics), kept by callers that evaluate
/// repeatedly so that no call allocates.
struct TreeFkWork {
  std::vector<BodyKin> kin;
};

/// Joint j's turn and slide about/along its axis from a joint-space vector x, its entries from
/// index i0 (j.q0 in q, j.dof0 in qd, qdd): revolute (x, 0), prismatic (0, x), cylindrical
/// (angle, displacement), otherwise (0, 0).
inline void joint_components(const Joint& j, const double* x, int i0, double& turn, double& slide) {
  turn = slide = 0.0;
  switch (j.type) {
    case JointType::Revolute:
      turn = x[i0];
      break;
    case JointType::Prismatic:
      slide = x[i0];
      break;
    case JointType::Cylindrical:
      turn = x[i0];
      slide = x[i0 + 1];
      break;
    default:
      break;
  }
}

/// The world rotation of free joint j's frame (a floating base) from its body's rotation.
inline Mat3 free_frame(const Joint& j, const BodyKin& child) { return child.R * j.frame_child; }

/// Scratch of rne_residual: per body (alpha, acc, force, moment), per joint (point, axis; a
/// free joint's point is its frame's origin).
struct RneWork {
  std::vector<Vec3> alpha, acc, force, moment, point, axis;
  void resize(const Model& m);
};

/// Body poses and velocities (R, x, xd, w, W) of a joint-space tree from joint coordinates q and
/// rates qd, straight into a kinematic cache (size nb). Sizes and values are not checked.
void joint_space_kinematics(const Model& m, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                            std::vector<BodyKin>& kin);

/// The same without velocities: poses only (R, x), velocities zero.
void joint_space_poses(const Model& m, Eigen::Ref<const VecX> q, std::vector<BodyKin>& kin);
/// Both of the above, and also each joint's child-side point and world axis into frames.point
/// and frames.axis, which rne_residual and crba_loaded read.
void joint_space_kinematics(const Model& m, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                            std::vector<BodyKin>& kin, RneWork& frames);
void joint_space_poses(const Model& m, Eigen::Ref<const VecX> q, std::vector<BodyKin>& kin,
                       RneWork& frames);

/// The forward sweep of rne_residual alone: each body's angular acceleration (w.alpha) and
/// centre-of-mass acceleration (w.acc), world axes, at (q, qd, qdd), parents first. O(n).
void rne_forward(const Model& m, const std::vector<BodyKin>& kin, Eigen::Ref<const VecX> qd,
                 Eigen::Ref<const VecX> qdd, RneWork& w);
/// The bodies' Cartesian accelerations vd (nv: centre of mass in world, angular in the body
/// frame) from rne_forward's sweep.
void tree_body_accelerations(const Model& m, const std::vector<BodyKin>& kin, const RneWork& w,
                             double* vd);

/// The joint-space residual of the Newton-Euler equations of a tree,
///   tau = M(q) qdd + b(q, qd) - J(q)^T eta,
/// with kin and w's joint frames (w.point, w.axis) filled by joint_space_kinematics(..., w) at
/// (q, qd), and eta the bodies' applied and gyroscopic forces there (body_forces). Forward,
/// parents first, each body's angular and centre-of-mass accelerations; backward, children
/// first, each subtree's residual wrench (Gamma v' - eta) and its virtual work along the joint's
/// coordinates. O(n).
void rne_residual(const Model& m, const std::vector<BodyKin>& kin, Eigen::Ref<const VecX> qd,
                  Eigen::Ref<const VecX> qdd, const VecX& eta, RneWork& w, Eigen::Ref<VecX> tau);

/// Cartesian (u, v) from joint-space q (model.nq_joint) and qd (model.nv_joint): every
/// coordinate of the model, followers of couplings included (expand independent ones by
/// Model::independent first).
/// @throws ModelError when the model is not a joint-space tree or sizes are wrong.
void state_from_joints(const Model& m, const VecX& q, const VecX& qd, VecX& u, VecX& v);
/// The same with caller-owned scratch (no allocation once u, v and work are sized).
void state_from_joints(const Model& m, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd, VecX& u,
                       VecX& v, TreeFkWork& work);
/// The Cartesian state (u: nq, v: nv) of a kinematic cache.
void cartesian_state(const Model& m, const std::vector<BodyKin>& kin, double* u, double* v);
/// Joint-space q (model.nq_joint) and qd (model.nv_joint) at (u, v): the floating bases' poses
/// and velocities (scalar-first quaternions, velocities in the base frame), then the
/// coordinates (angles in (-pi, pi]; a run reports them unwrapped).
void joint_coordinates(const Model& m, const VecX& u, const VecX& v, VecX& q, VecX& qd);
/// The floating bases' entries of q and qd (when not nullptr) from the bodies' kinematics; with
/// u (the Cartesian positions) the quaternions follow the bodies' Euler parameters' signs.
void base_coordinates(const Model& m, const std::vector<BodyKin>& kin, const double* u, double* q,
                      double* qd);
/// The floating bases' entries of qdd from the bodies' kinematics and Cartesian accelerations vd
/// (nv: centre of mass in world, angular in the body frame).
void base_accelerations(const Model& m, const std::vector<BodyKin>& kin, const double* vd,
                        double* qdd);
/// The floating bases' bodies' Euler parameters in u from the quaternions in q, with their
/// signs (cartesian_state takes e0 >= 0): a run reports q's quaternion as given.
void base_orientations(const Model& m, const double* q, double* u);
/// Check the floating bases' quaternions in q (unit norm to 1e-6); throws ModelError naming fn
/// and the joint.
void check_base_quaternions(const Model& m, Eigen::Ref<const VecX> q, const char* fn);
/// The time derivative of q for rates qd (joint-space sizes): the coordinates' rates, and for
/// each floating base R v and e' = e (0, w) / 2.
void configuration_rate(const Model& m, const double* q, const double* qd, double* qdot);
/// Normalise the floating bases' quaternions in q.
void normalize_bases(const Model& m, double* q);
/// Check that the model supports joint-space calls; throws ModelError naming the reason.
/// coupled_ok: a coupled tree (Model::coupled_joint_space) is accepted too (the caller maps
/// its independent coordinates by Model::independent).
void require_joint_space(const Model& m, const char* what, bool coupled_ok = false);
/// Check a joint-space vector's length (n) and values; throws ModelError "fn: name ...".
void check_joint_vector(Eigen::Ref<const VecX> x, long n, const char* fn, const char* name);

/// Cartesian (u, v) of a joint-space tree from its independent joint-space q
/// (model.independent.nq()) and qd (nv()): a coupled model's followers set by their couplings.
/// @throws ModelError "fn: ..." on a model without a joint space or non-finite values.
void state_from_independent(const Model& m, const VecX& q, const VecX& qd, VecX& u, VecX& v,
                            const char* fn);
/// joint_coordinates reduced to the independent coordinates (Model::independent): q
/// (independent.nq()) and qd (independent.nv()).
void independent_joint_coordinates(const Model& m, const VecX& u, const VecX& v, VecX& q, VecX& qd);

}  // namespace armdyn
