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

/// The names of pi: "<body>.m", "<body>.mcx", "<body>.mcy", "<body>.mcz", "<body>.Ixx",
/// "<body>.Ixy", "<body>.Iyy", "<body>.Ixz", "<body>.Iyz", "<body>.Izz", then "<coord>.fv",
/// "<coord>.fc", "<coord>.offset", "<coord>.Ia".
std::vector<std::string> dynamic_parameter_names(const Model& m);

/// The model's own pi (offsets 0).
VecX dynamic_parameters(const Model& m);

/// Y (n_dofs x n_params) at (q, qd, qdd): a coupled model's independent coordinates (Y = G^T
/// Y_full), a floating base's six rows first. tau = Y pi equals inverse_dynamics(q, qd, qdd)
/// (with pi's offsets zero). Into Y (resized when needed).
/// @throws ModelError as inverse_dynamics (model, sizes, non-finite inputs, quaternions) and
///   as dynamic_parameter_layout.
void joint_torque_regressor(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                            Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> qdd, MatX& Y);

}  // namespace armdyn
