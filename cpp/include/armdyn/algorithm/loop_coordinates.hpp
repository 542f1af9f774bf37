// SPDX-License-Identifier: BSD-3-Clause
// The joint-level functions of a model with closed loops or of a fixed-base tree with ideal
// gears, in independent coordinates, on the Cartesian formulation (methods.md's constrained
// Newton-Euler system).
//
// A model whose joints close loops (any joint closing a cycle, add_distance, bodies held only by
// constraints; ideal gears inside it included), or a fixed-base tree with ideal gears (each gear
// row ties two coordinates as a loop closure does; simulate's joint space still integrates every
// coordinate, the gear rows eliminated by their null space), has `mobility` degrees of freedom
// but more joint coordinates. finalize() chooses `mobility` of them as its
// independent coordinates (Model::independent, Model::loop_coordinates): the user's (ModelBuilder::
// set_independent_coordinates) or, by default, the joint coordinates in model order, each taken
// when it is independent of those taken before at the assembled state (a pivoted rank test of the
// coordinates' velocity rows on the null space of the joint rows). The joint-level functions then
// take q, qd, qdd, tau of the independent coordinates:
//  - the state: the position problem f(u) = 0 with the independent coordinates prescribed
//    (the model's joint rows plus one drive row per independent coordinate), by Newton from the
//    Data's last solution with continuation along the straight path of q from its last value
//    (so the assembly branch stays the one the Data was on; the first call starts from the
//    assembled state), in steps that turn no body more than 0.5 rad (the tracked angles, which
//    the gear rows read, keep their turns; with ideal gears the path goes the whole way, without
//    them a loop's angles are taken modulo a turn), then the velocity problem;
//  - inverse dynamics: the acceleration problem with the independent coordinates driven to qdd,
//    the torques tau = -delta of their drive rows (driven_inverse_dynamics' convention), every
//    joint's reaction from the same multipliers;
//  - forward dynamics: the KKT system of the joint rows with tau on the independent coordinates
//    as loads (forward_dynamics(method="cartesian")'s), qdd from the coordinates' jets;
//  - the mass matrix T^T Gamma T and frame Jacobians J_frame T, T = dv/dqd the velocity map.
// A configuration where the prescribed rows and the joint rows lose rank (a dead centre), or
// where Newton fails, is a SolverError naming the dependent rows; the Data keeps its last state.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "armdyn/algorithm/dynamics.hpp"
#include "armdyn/data.hpp"

namespace armdyn {

/// finalize's stage: Model::loop_coordinates and Model::independent for a model with loops (the
/// user's Model::independent_request, or the default choice), else nothing.
/// @throws ModelError on an invalid request (unknown or duplicate name, too few or too many, a
///   dependent coordinate, a model that is a tree), naming it.
void choose_loop_coordinates(Model& m);

/// A Data's workspace for the loop functions (Data::loop, made on first use): the model with a
/// drive row on every independent coordinate, its Data, and the last solved state.
struct LoopWork {
  explicit LoopWork(const Model& m);
  std::unique_ptr<Model> driven;
  std::unique_ptr<Data> dd;
  VecX ref;       ///< (3 n) drive values (q, qd, qdd)
  VecX u, v, vd;  ///< the solved state and accelerations
  VecX u_start, v_start, u_save, v_save, u_pred, u_step, ud, track_start, track_save, zero_v;
  VecX q_last, q_from, dq;  ///< (n) the last solved q, the path's start, step
  VecX tau_full;            ///< (n_dofs of the model) loads of forward dynamics
  VecX out;                 ///< (n) qdd or tau
  VecX qs, unit, zero_n;    ///< (n) scratch
  MatX T, GT, M;            ///< (nv, n), (nv, n) Gamma T, (n, n)
  Mat6X J;                  ///< (6, n) frame Jacobian
  bool have = false;        ///< a state was solved on this Data
  /// A fixed-base tree whose only other rows are ideal gears and couplings forming a forest, each
  /// of its trees holding one independent coordinate: every coordinate is then
  /// q_c = lin_scale[c] q[lin_source[c]] + lin_shift[c] (multi-turn, exact), and the state is
  /// placed by the tree's kinematics, with no position or velocity problem to solve.
  bool linear = false;
  std::vector<int> lin_source;
  std::vector<double> lin_scale, lin_shift;
  VecX q_full, qd_full, qdd_full;  ///< (nco) the coordinates of the placed state
  std::vector<BodyKin> kin;        ///< its bodies' kinematics (linear: scratch of the placement)
};

/// The loop functions (Model::loop_coordinates): inputs checked (sizes, finite), then the
/// state solved as above. Each returns a buffer of d (valid until the next call on d).
const VecX& loop_forward_dynamics(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                                  Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> tau, double t,
                                  DynamicsMethod method);
const VecX& loop_inverse_dynamics(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                                  Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> qdd, double t,
                                  DynamicsMethod method);
/// The mass matrix of the independent coordinates, T^T Gamma T.
const MatX& loop_mass_matrix(const Model& m, Data& d, Eigen::Ref<const VecX> q);
/// Every joint's reaction (joint_reaction) along the motion (q, qd, qdd) of the independent
/// coordinates: forces and torques 3 n_joints each.
void loop_joint_reactions(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                          Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> qdd, double t,
                          double* forces, double* torques);
/// The Cartesian state (u, v) at the independent coordinates (q, qd).
void loop_state(const Model& m, Data& d, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                VecX& u, VecX& v, const char* fn);
/// A frame's pose at the independent coordinates q; its Jacobian (6 x n, columns: the
/// independent dofs; LOCAL_WORLD_ALIGNED as frame_jacobian).
const Mat4& loop_frame_pose(const Model& m, Data& d, Eigen::Ref<const VecX> q, int frame);
const Mat6X& loop_frame_jacobian(const Model& m, Data& d, Eigen::Ref<const VecX> q, int frame);
/// Every joint coordinate (Model::coords; nq_joint entries, no floating base) at the independent
/// coordinates qi, those keeping qi's turns (simulate's q0 of a loop model). Allocates.
VecX loop_full_coordinates(const Model& m, const VecX& qi);
/// The independent coordinates and rates of a Cartesian state (u, v).
void loop_joint_coordinates(const Model& m, const VecX& u, const VecX& v, VecX& q, VecX& qd);

}  // namespace armdyn
