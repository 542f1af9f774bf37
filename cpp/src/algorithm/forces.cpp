// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/forces.hpp"

#include <algorithm>
#include <cmath>
#include <exception>

#include "armdyn/algorithm/kinematics.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/math/angles.hpp"

namespace armdyn {

namespace {
void add_pair(Eigen::Ref<VecX> eta, const Row12& g, int pa, int pb) {
  if (pa != kGround) eta.segment<6>(6 * pa) += g.segment<6>(0).transpose();
  if (pb != kGround) eta.segment<6>(6 * pb) += g.segment<6>(6).transpose();
}

// a non-finite entry of eta is an error naming its body (x * 0 is 0 for finite x, NaN
// otherwise: one vectorised sum instead of allFinite's comparisons)
void check_finite(const Model& m, Eigen::Ref<const VecX> eta, double t) {
  if ((eta.array() * 0.0).sum() == 0.0) return;
  for (int i = 0; i < m.nb; ++i)
    if (!eta.segment<6>(6 * i).allFinite())
      throw SolverError(msg("non-finite applied force on body '", m.bodies[i].name, "' at t=", t));
}

// the coordinates of gear pair g into d.cq, d.cqd from their jets, the angles tracked over turns
void load_gear_coordinates(const Model& m, Data& d, const GearPair& g) {
  for (const int c : {g.coord_a, g.coord_b}) {
    const ScalarJet& q = d.jets.get(m, d.kin, c);
    d.cq[c] = tracked(d, c, q.val);
    d.cqd[c] = q.rate;
  }
}
}  // namespace

double gear_force(const GearPair& g, double s, double sd, double& penetration) {
  penetration = std::abs(s) - 0.5 * g.backlash;
  if (penetration <= 0.0) return 0.0;
  const double rate = s >= 0 ? sd : -sd;  // penetration rate
  const double f = g.stiffness * std::pow(penetration, g.exponent) * (1.0 + g.hc_damping * rate);
  return std::max(f, 0.0);
}

namespace {
// the PD/PI motor's torque after its limit (0 without a motor), and the rate of its integral
double motor_value(const CoordForce& cf, bool angular, double q, double qdot, double t, double z,
                   double* zdot) {
  if (!cf.motor) {
    if (zdot) *zdot = 0.0;
    return 0.0;
  }
  const ProfileValue r = cf.reference.eval(t);
  const double e = angular ? wrap_angle(r.y - q) : r.y - q;
  const double u = cf.kp * e + cf.kd * (r.yd - qdot) + cf.ki * z;
  const double uc = std::clamp(u, -cf.torque_limit, cf.torque_limit);
  if (zdot) *zdot = (uc != u && e * u > 0) ? 0.0 : e;  // stop integrating into saturation
  return uc;
}
}  // namespace

double coord_actuation_value(const CoordForce& cf, bool angular, double q, double qdot, double t,
                             double z, double* zdot) {
  double tau = 0.0;
  if (cf.has_input) tau += cf.input.eval(t).y;
  if (cf.motor)
    tau += motor_value(cf, angular, q, qdot, t, z, zdot);
  else if (zdot)
    *zdot = 0.0;
  return tau;
}

double coord_force_value(const CoordForce& cf, bool angular, double q, double qdot, double t,
                         double z, double* zdot) {
  double tau = -cf.damping * qdot;
  if (cf.stiffness != 0.0) tau -= cf.stiffness * (angular ? wrap_angle(q - cf.rest) : q - cf.rest);
  if (cf.coulomb > 0) tau -= cf.coulomb * std::tanh(qdot / cf.v_smooth);
  if (cf.has_input) tau += cf.input.eval(t).y;
  if (cf.motor)
    tau += motor_value(cf, angular, q, qdot, t, z, zdot);
  else if (zdot)
    *zdot = 0.0;
  return tau;
}

double gear_mesh_force(const GearPair& g, double s, double sd) {
  double pen;
  const double f = gear_force(g, s, sd, pen);
  return s >= 0 ? f : -f;
}

double gear_contact_stiffness(const GearPair& g, double penetration) {
  return g.stiffness * g.exponent * std::pow(penetration, g.exponent - 1.0);
}

namespace {
// body_forces without its final finiteness check (cartesian_forces checks the sum once)
void body_forces_unchecked(const Model& m, const std::vector<BodyKin>& kin, double t,
                           Eigen::Ref<VecX> eta) {
  // gravity and gyroscopic terms, per body
  for (int i = 0; i < m.nb; ++i) {
    const Body& b = m.bodies[i];
    const BodyKin& k = kin[i];
    eta.segment<3>(6 * i) = b.mass * m.gravity;
    eta.segment<3>(6 * i + 3) = -k.w.cross(b.inertia * k.w);
  }
  // applied loads: force at a body point and torque, world axes
  for (const BodyLoad& l : m.body_loads) {
    double s = 1.0;
    if (l.has_profile) {
      try {
        s = l.profile.eval(t).y;
      } catch (const SolverError& err) {
        // (nested: a Python callback's exception stays reachable as the cause)
        std::throw_with_nested(
            SolverError(msg("load on body '", m.bodies[l.body].name, "': ", err.what())));
      }
    }
    const BodyKin& k = kin[l.body];
    const Vec3 fb = k.R.transpose() * (s * l.force);
    eta.segment<3>(6 * l.body) += s * l.force;
    eta.segment<3>(6 * l.body + 3) += k.R.transpose() * (s * l.torque) + l.point.cross(fb);
  }
  // point-to-point spring-dampers: generalised force -tension * dL/dv
  for (const SpringDamper& sd : m.springs) {
    const VecJet d = difference(point_jet(kin_of(kin, sd.body_b), sd.point_b, 1),
                                point_jet(kin_of(kin, sd.body_a), sd.point_a, 0));
    const double L = d.val.norm();
    if (!(L > 1e-12))
      throw SolverError(msg("spring-damper '", sd.name, "': length became zero at t=", t));
    const Vec3 n = d.val / L;
    const double Ld = n.dot(d.rate);
    const double tension = sd.stiffness * (L - sd.rest_length) + sd.damping * Ld;
    add_pair(eta, -tension * d.left(n), sd.body_a, sd.body_b);
  }
}
}  // namespace

void body_forces(const Model& m, const std::vector<BodyKin>& kin, double t, Eigen::Ref<VecX> eta) {
  body_forces_unchecked(m, kin, t, eta);
  check_finite(m, eta, t);
}

void gear_mesh(const Model& m, int gi, const double* q, const double* qd, double& s, double& sd,
               double& penetration) {
  const GearPair& g = m.gears[gi];
  s = g.r_a * q[g.coord_a] + g.r_b * q[g.coord_b];
  sd = g.r_a * qd[g.coord_a] + g.r_b * qd[g.coord_b];
  penetration = std::abs(s) - 0.5 * g.backlash;
}

void coordinate_forces(const Model& m, const double* q, const double* qd, const double* z, double t,
                       Eigen::Ref<VecX> out) {
  out.setZero();
  for (const CoordForce& cf : m.coord_forces) {
    const Coord& c = m.coords[cf.coord];
    double f;
    try {
      const double zi = (cf.aux >= 0 && z) ? z[cf.aux] : 0.0;
      f = coord_force_value(cf, c.angular, q[cf.coord], qd[cf.coord], t, zi);
    } catch (const SolverError& err) {
      std::throw_with_nested(
          SolverError(msg("force on joint coordinate '", c.name, "': ", err.what())));
    }
    if (!std::isfinite(f))
      throw SolverError(msg("non-finite force on joint coordinate '", c.name, "' at t=", t));
    out[cf.coord] += f;
  }
  for (int gi = 0; gi < static_cast<int>(m.gears.size()); ++gi) {
    const GearPair& g = m.gears[gi];
    double s, sd, pen;
    gear_mesh(m, gi, q, qd, s, sd, pen);
    const double f = gear_mesh_force(g, s, sd);
    if (f != 0.0) add_gear_torques(g, f, out.data());
  }
}

namespace {
// the joint-coordinate forces and gear pairs of the Cartesian pipeline into d.eta
void coordinate_forces_on_bodies(const Model& m, Data& d, double t) {
  if (m.coord_forces.empty() && m.gears.empty()) return;
  // the coordinates the laws read, from their jets (gear angles unwrapped over turns)
  for (const CoordForce& cf : m.coord_forces) {
    const ScalarJet& q = d.jets.get(m, d.kin, cf.coord);
    d.cq[cf.coord] = q.val;
    d.cqd[cf.coord] = q.rate;
  }
  for (const GearPair& g : m.gears) load_gear_coordinates(m, d, g);
  // the joint-space generalised forces, mapped onto the bodies through each coordinate's
  // Jacobian
  coordinate_forces(m, d.cq.data(), d.cqd.data(), d.aux, t, d.coord_tau);
  for (int c = 0; c < static_cast<int>(m.coords.size()); ++c) {
    if (d.coord_tau[c] == 0.0) continue;
    const Joint& j = m.joints[m.coords[c].joint];
    add_pair(d.eta, d.coord_tau[c] * d.jets.get(m, d.kin, c).J, j.parent, j.child);
  }
}
}  // namespace

void cartesian_forces(const Model& m, Data& d, double t) {
  body_forces_unchecked(m, d.kin, t, d.eta);
  // the joint-coordinate forces at the caller's coordinates, added to the joint torques below
  bool coord_tau_pending = false;
  if (d.with_coordinate_forces && (!m.coord_forces.empty() || !m.gears.empty())) {
    check_finite(m, d.eta, t);  // (the body forces' error before the coordinate forces')
    if (d.joint_torques && d.joint_q) {
      coordinate_forces(m, d.joint_q + 7 * m.n_free, d.joint_qd + 6 * m.n_free, d.aux, t,
                        d.coord_tau);
      coord_tau_pending = true;
    } else {
      coordinate_forces_on_bodies(m, d, t);
    }
  }
  // joint-space torques of a joint-space call
  if (d.joint_torques) {
    const double* tau = d.joint_torques + 6 * m.n_free;
    // a state placed from joint coordinates is on every joint's manifold: revolute jets in
    // closed form (revolute_jet_on_manifold)
    const double* qd_joint = d.joint_q ? d.joint_qd + 6 * m.n_free : nullptr;
    for (int c = 0; c < static_cast<int>(m.coords.size()); ++c) {
      // (the coordinate forces' jet of this state when there is one: the same but its value)
      ScalarJet& q = d.tau_jets[c];
      const Joint& j = m.joints[m.coords[c].joint];
      if (qd_joint && j.type == JointType::Revolute)
        revolute_jet_on_manifold(m, c, qd_joint[c], q);
      else if (const ScalarJet* cached = d.jets.cached(c))
        q = *cached;
      else
        coord_jet_into(m, d.kin, c, false, q);
      const double tc = coord_tau_pending ? tau[c] + d.coord_tau[c] : tau[c];
      if (tc == 0.0) continue;
      add_pair(d.eta, tc * q.J, j.parent, j.child);
    }
    // a floating base's wrench (force, torque in its frame's axes, at its origin P)
    for (const Joint& j : m.joints) {
      if (j.type != JointType::Free || j.dof0 < 0) continue;
      const double* w = d.joint_torques + j.dof0;
      const BodyKin& k = d.kin[j.child];
      const Mat3 B = k.R * j.frame_child;
      const Vec3 f = B * Vec3(w[0], w[1], w[2]);
      d.eta.segment<3>(6 * j.child) += f;
      // torque about the centre of mass, body axes: R^T (B n) + s x (R^T f), s = P - x in body
      d.eta.segment<3>(6 * j.child + 3) +=
          j.frame_child * Vec3(w[3], w[4], w[5]) + j.point_child.cross(k.R.transpose() * f);
    }
  }
  check_finite(m, d.eta, t);
}

void aux_rates(const Model& m, Data& d, double t, double* zdot) {
  for (const CoordForce& cf : m.coord_forces) {
    if (cf.aux < 0) continue;
    const ScalarJet& q = d.jets.get(m, d.kin, cf.coord);
    const double z = d.aux ? d.aux[cf.aux] : 0.0;
    coord_force_value(cf, m.coords[cf.coord].angular, q.val, q.rate, t, z, &zdot[cf.aux]);
  }
}

void gear_mesh(const Model& m, Data& d, int gi, double& s, double& sd, double& penetration) {
  load_gear_coordinates(m, d, m.gears[gi]);
  gear_mesh(m, gi, d.cq.data(), d.cqd.data(), s, sd, penetration);
}

const VecX& cartesian_forces_at(const Model& m, Data& d, const double* u, const double* v,
                                double t) {
  load_kinematics(m, d, u, v);
  cartesian_forces(m, d, t);
  return d.eta;
}

}  // namespace armdyn
