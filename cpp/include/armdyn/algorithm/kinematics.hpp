// SPDX-License-Identifier: BSD-3-Clause
// Kinematics stage of the Cartesian pipeline: the bodies' poses and velocities in data.kin, from
// the Cartesian state (u, v) or from the joint coordinates of a tree; the state rate
// u' = S(u) v; and the multi-turn tracking of the angle coordinates (gear rows, gear meshes and
// outputs read an angle continuous over turns, referred to its value at the last projection).
#pragma once

#include "armdyn/data.hpp"
#include "armdyn/math/angles.hpp"

namespace armdyn {

/// data.kin from (u, v); v may be nullptr (at rest). The coordinate jets (data.jets) are
/// recomputed on demand at this state.
void load_kinematics(const Model& m, Data& d, const double* u, const double* v);

/// data.kin from the joint coordinates (q, qd) of a joint-space tree (joint_space_kinematics):
/// poses and velocities straight from the joints, on the constraint manifold.
void load_joint_kinematics(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                           Eigen::Ref<const VecX> qd);

/// u' = S(u) v per body: xdot and 1/2 e (x) [0, omega].
void udot(const Model& m, const double* u, const double* v, double* ud);

/// The unwrapped value of angle coordinate `coord` from its raw (wrapped) value, continuous
/// with data.track_ref.
inline double tracked(const Data& d, int coord, double raw) {
  return d.track_ref[coord] + wrap_angle(raw - d.track_ref[coord]);
}

/// data.track_ref from the loaded kinematics: every angle coordinate followed over turns (done
/// by project after each projection).
void commit_tracking(const Model& m, Data& d);
/// commit_tracking at time t; with data.track_by_rates, also data.track_commit (the references,
/// the angles' rates from the loaded velocities, t).
void commit_tracking(const Model& m, Data& d, double t);
/// With data.track_by_rates and track_ref still the last commit's: track_ref moved on to time t
/// by the committed rates (each angle's reference then its predicted value, so the nearest
/// branch of its raw value is the one its rate leads to).
void advance_tracking(const Model& m, Data& d, double t);

/// Check a Cartesian state (u: nq, v: nv) before evaluating at it: finite, and every body's Euler
/// parameters non-zero; throws ModelError "fn: ..." naming the body.
void check_cartesian_state(const Model& m, const VecX& u, const VecX& v, const char* fn);

}  // namespace armdyn
