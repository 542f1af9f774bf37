// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/energy.hpp"

#include "armdyn/algorithm/kinematics.hpp"
#include "armdyn/math/angles.hpp"

namespace armdyn {

void energy(const Model& m, Data& d, const double* u, const double* v, double& ke, double& pe) {
  load_kinematics(m, d, u, v);
  const std::vector<BodyKin>& kin = d.kin;
  ke = pe = 0.0;
  for (int i = 0; i < m.nb; ++i) {
    const Body& b = m.bodies[i];
    const BodyKin& k = kin[i];
    ke += 0.5 * b.mass * k.xd.squaredNorm() + 0.5 * k.w.dot(b.inertia * k.w);
    pe -= b.mass * m.gravity.dot(k.x);
  }
  for (const SpringDamper& sd : m.springs) {
    const Vec3 pa = kin_of(kin, sd.body_a).x + kin_of(kin, sd.body_a).R * sd.point_a;
    const Vec3 pb = kin_of(kin, sd.body_b).x + kin_of(kin, sd.body_b).R * sd.point_b;
    const double e = (pb - pa).norm() - sd.rest_length;
    pe += 0.5 * sd.stiffness * e * e;
  }
  for (const CoordForce& cf : m.coord_forces) {
    if (cf.stiffness == 0.0) continue;
    const double q = coord_value(m, kin, cf.coord);
    const double dq = m.coords[cf.coord].angular ? wrap_angle(q - cf.rest) : q - cf.rest;
    pe += 0.5 * cf.stiffness * dq * dq;
  }
}

}  // namespace armdyn
