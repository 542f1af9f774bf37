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

/// Generalised force of a coordinate force element at (q, qdot, t), angle differences wrapped;
/// z is the element's integral state (PI motors), 0 otherwise. When `zdot` is given it receives
/// the rate of z (the tracking error, or 0 while saturated).
double coord_force_value(const CoordForce& cf, bool angular, double q, double qdot, double t,
                         double z = 0.0, double* zdot = nullptr);
/// The actuation part of coord_force_value: input(t) + motor (after its torque limit), without
/// the spring, damper and friction terms (the applied joint torque a run reports).
double coord_actuation_value(const CoordForce& cf, bool angular, double q, double qdot, double t,
                             double z = 0.0, double* zdot = nullptr);

/// Mesh force F >= 0 of a gear pair for mesh displacement s and rate sd; also returns the
/// penetration (negative inside the gap).
double gear_force(const GearPair& g, double s, double sd, double& penetration);
/// Gear pair g's mesh force along the line of action, signed as the mesh displacement s:
/// sign(s) F, F = gear_force(g, s, sd) (positive when s > 0: it pushes q_a and q_b back).
double gear_mesh_force(const GearPair& g, double s, double sd);
/// The generalised forces of gear pair g's signed mesh force f (gear_mesh_force) on its two
/// coordinates, -r_a f and -r_b f, added to tau (indexed by coordinate).
inline void add_gear_torques(const GearPair& g, double f, double* tau) {
  tau[g.coord_a] -= g.r_a * f;
  tau[g.coord_b] -= g.r_b * f;
}
/// The contact stiffness dF/dd of gear pair g at penetration d > 0, without damping:
/// n k d^(n-1).
double gear_contact_stiffness(const GearPair& g, double penetration);

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
