// SPDX-License-Identifier: BSD-3-Clause
// Validators independent of the Cartesian Newton-Euler/KKT path.
//
// LagrangeValidator: the complete Euler-Lagrange equations d/dt dL/dqdot - dL/dq = Q of a tree
// model in its joint coordinates, L = T - V with
//   T = 1/2 qdot^T M(q) qdot,  M = sum_i m_i Jv_i^T Jv_i + Jw_i^T R_i J_i R_i^T Jw_i,
//   V = -sum_i m_i g . x_i + point springs,
// from the joint-space kinematics (joint_fk.hpp) differentiated by forward-mode automatic
// differentiation: tau = M qdd + Mdot qdot - 1/2 d(qdot^T M qdot)/dq + dV/dq - Q_other,
// where Q_other collects joint springs/dampers/inputs, point-spring damping and body loads.
// With rotational_inertia = false the bodies are point masses (a simplified model).
//
// The paper's printed 3-DOF equations (9)-(11) are offered as the "paper model": they are
// exactly -dL/dtheta_i of a planar arm with point masses at the link ends in absolute angles;
// the d/dt dL/dthetadot terms are missing.
//
// Geometric validator: end-effector position of a body point from joint coordinates (composed
// joint transforms) and the paper's equations (22)-(25).
#pragma once

#include <memory>
#include <string>

#include "armdyn/model/model.hpp"

namespace armdyn {

class LagrangeValidator {
 public:
  /// @throws ModelError when the model is not a joint-space tree.
  explicit LagrangeValidator(std::shared_ptr<const Model> m, bool rotational_inertia = true);
  /// Generalised actuator forces (n_dofs) for q (n_coords), qd, qdd (n_dofs) at time t; a
  /// floating base by a local chart about its pose in q (cpp/src/validate/joint_fk.hpp); a coupled
  /// model's in its independent coordinates (G^T tau_full at the expanded state).
  VecX torques(const VecX& q, const VecX& qd, const VecX& qdd, double t = 0.0) const;
  /// torques() of every row of Q (rows, nq()), QD and QDD (rows, nv()) at t[row]: (rows, nv()).
  /// @throws ModelError when the row counts differ.
  MatX torques(const MatX& Q, const MatX& QD, const MatX& QDD, const VecX& t) const;
  /// Joint-space mass matrix M(q) (a coupled model's G^T M G).
  MatX mass_matrix(const VecX& q) const;
  const Model& model() const { return *m_; }
  bool rotational_inertia() const { return rot_; }
  /// Lengths of q and of qd the calls take (a coupled model's independent ones).
  long nq() const;
  long nv() const;

 private:
  bool coupled() const;
  VecX full_torques(const VecX& q, const VecX& qd, const VecX& qdd, double t) const;
  MatX full_mass_matrix(const VecX& q) const;
  std::shared_ptr<const Model> m_;
  bool rot_;
};

/// The paper's printed equations (9)-(11): T_i for absolute link angles theta (from the
/// horizontal), rates thetad, link lengths L, point masses M at the link ends, gravity g > 0.
Vec3 paper_3dof_torques(const Vec3& L, const Vec3& M, double g, const Vec3& theta,
                        const Vec3& thetad);
/// The same for every row of theta and thetad (rows, 3): (rows, 3).
/// @throws ModelError when the row counts differ.
MatX paper_3dof_torques(const Vec3& L, const Vec3& M, double g, const MatX& theta,
                        const MatX& thetad);

/// The paper's equations (22)-(25): end effector [X, Y, Z] (paper axes, Y up) from
/// theta = (theta1 twist, theta2, theta3, theta4 as printed), h and L1, L2, L3 + L4.
Vec3 paper_5dof_end_effector(double h, double L1, double L2, double L34, const Vec4& theta);

/// World position of `point` (body frame, relative to the CoM) on body `body` at joint
/// coordinates q, by composed joint transforms (no Cartesian state involved).
Vec3 end_effector_position(const Model& m, int body, const Vec3& point, const VecX& q);
/// The same for every row of q (rows, model.nq_joint): (rows, 3).
MatX end_effector_positions(const Model& m, int body, const Vec3& point, const MatX& q);

/// Equation (26) percentage errors |a - ref| / max|ref| * 100 per sample and joint, and their
/// equation (27) RMS and maximum per joint (columns). ref_max may override max|ref| per column.
struct TorqueErrorMetrics {
  VecX rms, max, ref_max;
  MatX percent;  ///< samples x joints
  double average = 0.0;
};
TorqueErrorMetrics torque_error_metrics(const MatX& a, const MatX& ref);

}  // namespace armdyn
