// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/forces.hpp"

#include <cmath>

#include "armdyn/errors.hpp"

namespace armdyn {

namespace {
void add_pair(Eigen::Ref<VecX> eta, const Row12& g, int pa, int pb) {
  if (pa != kGround) eta.segment<6>(6 * pa) += g.segment<6>(0).transpose();
  if (pb != kGround) eta.segment<6>(6 * pb) += g.segment<6>(6).transpose();
}
}  // namespace

void body_forces(const Model& m, const std::vector<BodyKin>& kin, double t, Eigen::Ref<VecX> eta) {
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
        throw SolverError(msg("load on body '", m.bodies[l.body].name, "': ", err.what()));
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
  if (!eta.allFinite()) {
    for (int i = 0; i < m.nb; ++i)
      if (!eta.segment<6>(6 * i).allFinite())
        throw SolverError(
            msg("non-finite applied force on body '", m.bodies[i].name, "' at t=", t));
  }
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
      throw SolverError(msg("force on joint coordinate '", c.name, "': ", err.what()));
    }
    if (!std::isfinite(f))
      throw SolverError(msg("non-finite force on joint coordinate '", c.name, "' at t=", t));
    out[cf.coord] += f;
  }
  for (int gi = 0; gi < static_cast<int>(m.gears.size()); ++gi) {
    const GearPair& g = m.gears[gi];
    double s, sd, pen;
    gear_mesh(m, gi, q, qd, s, sd, pen);
    const double f = gear_force(g, s, sd, pen);
    if (f == 0.0) continue;
    const double fs = s >= 0 ? f : -f;
    out[g.coord_a] -= g.r_a * fs;
    out[g.coord_b] -= g.r_b * fs;
  }
}

}  // namespace armdyn
