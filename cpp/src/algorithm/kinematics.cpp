// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/kinematics.hpp"

#include <cmath>

#include "armdyn/errors.hpp"
#include "armdyn/math/quaternion.hpp"

namespace armdyn {

void load_kinematics(const Model& m, Data& d, const double* u, const double* v) {
  body_kinematics(m, u, v, d.kin);
  d.jets.reset();
}

void load_joint_kinematics(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                           Eigen::Ref<const VecX> qd) {
  d.jets.reset();
  joint_space_kinematics(m, q, qd, d.kin);
}

void udot(const Model& m, const double* u, const double* v, double* ud) {
  for (int i = 0; i < m.nb; ++i) {
    const double* ui = u + 7 * i;
    const double* vi = v + 6 * i;
    double* o = ud + 7 * i;
    o[0] = vi[0];
    o[1] = vi[1];
    o[2] = vi[2];
    const Vec4 ed = quat_rate(Vec4(ui[3], ui[4], ui[5], ui[6]), Vec3(vi[3], vi[4], vi[5]));
    o[3] = ed[0];
    o[4] = ed[1];
    o[5] = ed[2];
    o[6] = ed[3];
  }
}

void commit_tracking(const Model& m, Data& d) {
  // every angle coordinate is followed over turns (gears need it; outputs use it)
  for (int c = 0; c < static_cast<int>(m.coords.size()); ++c)
    if (m.coords[c].angular) d.track_ref[c] = tracked(d, c, coord_value(m, d.kin, c));
}

namespace {
// the rate of angle coordinate c at the loaded kinematics (velocities loaded): for a revolute
// joint z . (omega_c - omega_p), z the parent's joint axis in world; other angles from their jet
double angle_rate(const Model& m, const Data& d, int c) {
  const Joint& j = m.joints[m.coords[c].joint];
  if (j.type != JointType::Revolute) return coord_jet(m, d.kin, c, false).rate;
  const BodyKin& p = kin_of(d.kin, j.parent);
  const BodyKin& k = kin_of(d.kin, j.child);
  return (p.R * j.frame_parent.col(2)).dot(k.W - p.W);
}
}  // namespace

void commit_tracking(const Model& m, Data& d, double t) {
  commit_tracking(m, d);
  if (!d.track_by_rates) return;
  Data::TrackCommit& tc = d.track_commit;
  const int nco = static_cast<int>(m.coords.size());
  tc.rate.resize(nco);  // (sized once: every projection of a run commits)
  tc.rate.setZero();
  for (int c = 0; c < nco; ++c)
    if (m.coords[c].angular) tc.rate[c] = angle_rate(m, d, c);
  // a rate that is not finite predicts nothing (the step that led there fails elsewhere)
  if (!tc.rate.allFinite()) tc.rate.setZero();
  tc.ref = d.track_ref;
  tc.t = t;
}

void advance_tracking(const Model& m, Data& d, double t) {
  const Data::TrackCommit& tc = d.track_commit;
  if (!d.track_by_rates || !std::isfinite(tc.t) || !std::isfinite(t) ||
      tc.ref.size() != d.track_ref.size() || tc.ref != d.track_ref)
    return;
  const double dt = t - tc.t;
  for (int c = 0; c < static_cast<int>(m.coords.size()); ++c)
    if (m.coords[c].angular) d.track_ref[c] = tc.ref[c] + tc.rate[c] * dt;
}

void check_cartesian_state(const Model& m, const VecX& u, const VecX& v, const char* fn) {
  if (!u.allFinite()) throw ModelError(msg(fn, ": u contains NaN or inf"));
  if (!v.allFinite()) throw ModelError(msg(fn, ": v contains NaN or inf"));
  for (int i = 0; i < m.nb; ++i)
    if (!(u.segment<4>(7 * i + 3).norm() > 0))
      throw ModelError(msg(fn, ": zero Euler parameters for body '", m.bodies[i].name, "'"));
}

}  // namespace armdyn
