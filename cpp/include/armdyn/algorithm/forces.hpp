// SPDX-License-Identifier: BSD-3-Clause
// The force laws, in one place: the bodies' applied and gyroscopic forces (gravity, -w x J w,
// body loads, point-to-point spring-dampers) as the Cartesian generalised force eta, and the
// joint-coordinate forces (springs, dampers, friction, inputs, PD/PI motors: coord_force_value)
// with the gear pairs' contact forces (gear_force) as joint-space generalised forces; and the
// forces stage of the Cartesian pipeline, which maps the joint-space ones onto the bodies
// through each coordinate's Jacobian (cartesian_forces).
#pragma once

#include <vector>

#include "armdyn/data.hpp"
#include "armdyn/kernels/jets.hpp"
#include "armdyn/model/model.hpp"

namespace armdyn {

/// eta (nv) at the kinematics kin and time t: per body (force in world axes, torque in body
/// axes). Overwrites eta.
/// @throws SolverError naming the element (a profile that fails, a spring of zero length) or the
///   body (a non-finite force).
void body_forces(const Model& m, const std::vector<BodyKin>& kin, double t, Eigen::Ref<VecX> eta);

/// The joint-coordinate forces and gear-pair contact forces (n_coords) at joint coordinates q
/// (multi-turn), rates qd, auxiliary states z (model.n_aux, nullptr: all zero) and time t.
/// Overwrites out.
/// @throws SolverError naming the coordinate when a force is not finite.
void coordinate_forces(const Model& m, const double* q, const double* qd, const double* z, double t,
                       Eigen::Ref<VecX> out);

/// Gear pair g's mesh displacement s = r_a q_a + r_b q_b, its rate, and the penetration
/// |s| - backlash/2, at joint coordinates q (multi-turn) and rates qd.
void gear_mesh(const Model& m, int g, const double* q, const double* qd, double& s, double& sd,
               double& penetration);

/// The forces stage of the Cartesian pipeline: data.eta at the loaded kinematics (data.kin) and
/// time t: body_forces; with data.with_coordinate_forces, the joint-coordinate forces and gear
/// pairs (coordinate_forces at the coordinates' jets, gear angles tracked over turns, the
/// auxiliary states data.aux) mapped onto the bodies through each coordinate's Jacobian; and
/// the joint torques data.joint_torques likewise (their jets kept in data.tau_jets).
/// @throws SolverError as body_forces and coordinate_forces.
void cartesian_forces(const Model& m, Data& d, double t);

/// Rates of the auxiliary states (model.n_aux: PI-motor integrals) into zdot, at the loaded
/// kinematics and auxiliary states data.aux.
void aux_rates(const Model& m, Data& d, double t, double* zdot);

/// gear_mesh at the loaded kinematics, the angles tracked over turns (data.track_ref).
void gear_mesh(const Model& m, Data& d, int g, double& s, double& sd, double& penetration);

/// data.eta (nv) at the Cartesian state (u, v) and time t: loads the kinematics, then
/// cartesian_forces.
const VecX& cartesian_forces_at(const Model& m, Data& d, const double* u, const double* v,
                                double t);

}  // namespace armdyn
