// SPDX-License-Identifier: BSD-3-Clause
// The dynamics as a linear function of the model's dynamic parameters (identification):
// tau = Y(q, qd, qdd) pi, inverse_dynamics's tau exactly, for a tree in joint space (fixed or
// floating base, couplings, actuators, joint friction).
//
// pi, in this order (ParameterLayout, the one list; names by dynamic_parameter_names):
//  - per body (model order; the actuators' rotor bodies excluded), 10 numbers about the body's
//    parameter frame -- the named frame of the body's own name when there is one (a URDF link:
//    the link frame, Pinocchio's joint frame), else the body frame (centre of mass, body axes):
//      m, m c_x, m c_y, m c_z, I_xx, I_xy, I_yy, I_xz, I_yz, I_zz
//    (Pinocchio's order): the mass, its first moment (c the centre of mass in the parameter
//    frame) and the inertia about the parameter frame's origin, in its axes;
//  - per independent joint coordinate (model.coord_names, followers of couplings removed), 4:
//      fv (viscous friction, tau += fv qd), fc (Coulomb friction, tau += fc tanh(qd / v): the
//      model's own smoothing v), offset (a constant torque: a sensor's or current's offset,
//      always 0 in a model), Ia (the rotor inertia reflected to the joint, N^2 J: tau += Ia qdd
//      for a gear-reduced armature; a gyroscopic rotor's full terms).
// Friction on followers (a coupling's, a motor's on its rotor) is reflected onto its independent
// coordinate. A model whose coordinate has Coulomb sources of different smoothing gets one
// column per coordinate, sum_j c_j tanh(qd / v_j) / sum_j c_j (exact for the model's values).
// Force elements that are not parameters (springs, spring-dampers, loads, inputs, motors, gear
// pairs) are refused: ModelError naming the element.
#pragma once

#include <string>
#include <vector>

#include "armdyn/data.hpp"

namespace armdyn {

/// The Coulomb column's smoothing velocity on a coordinate without Coulomb friction in the model
/// (tanh(qd / v)): the URDF importer's (kUrdfCoulombSmoothing) [rad/s or m/s].
constexpr double kRegressorCoulombSmoothing = 1e-3;

/// Where each dynamic parameter lives (one per model; dynamic_parameter_layout).
struct ParameterLayout {
  static constexpr int kBody = 10;   ///< parameters per body
  static constexpr int kCoord = 4;   ///< parameters per independent coordinate
  std::vector<int> bodies;           ///< the bodies with parameters (model order, no rotors)
  std::vector<Vec3> frame_point;     ///< per such body: its parameter frame's origin (body frame)
  std::vector<Mat3> frame_rotation;  ///< per such body: its axes in the body's (frame -> body)
  std::vector<std::string> frame_name;  ///< per such body: the frame's name ("" = body frame)
  /// per independent coordinate: Coulomb sources (reflected coefficient, smoothing velocity)
  std::vector<std::vector<std::pair<double, double>>> coulomb;
  /// per independent coordinate: reflected viscous friction (the nominal fv)
  std::vector<double> viscous;
  /// per independent coordinate: the actuators (indices of Model::actuators) acting on it
  std::vector<std::vector<int>> actuators;
  /// per actuator (Model::actuators): its Ia per unit rotor inertia J, N^2 (times s^2 for a
  /// gear-reduced rotor on a coupling follower of scale s: reflected to the independent
  /// coordinate)
  std::vector<double> reflection;
  /// per independent coordinate: its actuators are gyroscopic (rotor bodies carry Ia; else the
  /// reflected inertia is Ia qdd)
  std::vector<char> gyroscopic;
  /// per independent coordinate: the sum of its Coulomb coefficients (0: no Coulomb friction)
  std::vector<double> coulomb_sum;
  /// per full degree of freedom (Model::nv_joint): the independent row it reduces to (G^T) and
  /// its scale there (a coupling follower's; 1 otherwise)
  std::vector<int> dof_row;
  std::vector<double> dof_scale;
  /// per gyroscopic actuator: (its rotor body, its coordinate's Ia column, the weights of the
  /// rotor body's 10 parameters per unit Ia: a thin disc of axial inertia Ia / N^2)
  struct Rotor {
    int body = 0, column = 0;
    Eigen::Matrix<double, 10, 1> weights = Eigen::Matrix<double, 10, 1>::Zero();
  };
  std::vector<Rotor> rotors;
  int n_params = 0;
  int body_offset(int k) const { return kBody * k; }  ///< k-th parameter body's first column
  int coord_offset(int c) const {                     ///< independent coordinate c's first column
    return kBody * static_cast<int>(bodies.size()) + kCoord * c;
  }
};

/// The layout of a finalized joint-space model's parameters.
/// @throws ModelError for a model without a joint-space form, or with a force element that is
///   not a parameter (named).
ParameterLayout dynamic_parameter_layout(const Model& m);

/// dynamic_parameter_layout(m), made on the first request and kept with the model
/// (Model::derived): what the regressors read per call (a Data keeps the pointer).
/// @throws ModelError as dynamic_parameter_layout (then nothing is kept).
const ParameterLayout& cached_parameter_layout(const Model& m);

/// The names of pi: "<body>.m", "<body>.mcx", "<body>.mcy", "<body>.mcz", "<body>.Ixx",
/// "<body>.Ixy", "<body>.Iyy", "<body>.Ixz", "<body>.Iyz", "<body>.Izz", then "<coord>.fv",
/// "<coord>.fc", "<coord>.offset", "<coord>.Ia".
std::vector<std::string> dynamic_parameter_names(const Model& m);

/// The model's own pi (offsets 0).
VecX dynamic_parameters(const Model& m);

/// Y (n_dofs x n_params) at (q, qd, qdd): a coupled model's independent coordinates (Y = G^T
/// Y_full), a floating base's six rows first (the base frame's force, then its moment about the
/// frame's origin, in its axes: inverse_dynamics's rows). tau = Y pi equals inverse_dynamics(q,
/// qd, qdd) (with pi's offsets zero). Into Y (resized when needed).
///
/// The recursion (Atkeson, An, Hollerbach 1986; Pinocchio's computeJointTorqueRegressor): the
/// forward Newton-Euler sweep gives every body's velocity and acceleration; then per body its
/// 6 x 10 block F of the Newton-Euler wrench per unit parameter, about its parameter frame's
/// origin (kept in factors, in the frame's axes), and for each degree of freedom of the joints
/// on its path to the root one row block S^T F (S that degree of freedom's motion about the same
/// origin; a free joint's six rows as one block). O(n d) for n bodies at depth d; no allocation
/// once Y has its size and the Data its layout (the first call).
/// @throws ModelError as inverse_dynamics (model, sizes, non-finite inputs, quaternions) and
///   as dynamic_parameter_layout.
void joint_torque_regressor(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                            Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> qdd, MatX& Y);

/// The same into out, row-major (n_dofs rows of n_params, every entry written): the bindings'
/// arrays, a batch's rows straight into the output.
void joint_torque_regressor_into(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                                 Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> qdd,
                                 double* out);

/// The energy regressor h (n_params) at (q, qd): the kinetic plus potential energy of the
/// bodies and rotors is h . pi (the potential -m g . c about the world origin, as energy();
/// friction and offset entries 0). Per body: 0.5 |v|^2, v x w, -g . p and -R^T g, 0.5 w^T U w
/// for the unit inertias U (v, w the velocity of its parameter frame's origin and its angular
/// velocity in the frame's axes, p and R the frame's world pose); per coordinate's Ia: 0.5 qd^2
/// for a gear-reduced armature, the rotor's kinetic energy per unit Ia for a gyroscopic one.
/// Identification from energy: h(t1) - h(t0) = integral of (tau - friction) . qd dt, without
/// accelerations. Into h (resized when needed); no allocation once sized.
/// @throws ModelError as joint_torque_regressor (qd as the rates).
void energy_regressor(const Model& m, Data& d, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                      VecX& h);

/// The same into out (n_params entries, every one written).
void energy_regressor_into(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                           Eigen::Ref<const VecX> qd, double* out);

}  // namespace armdyn
