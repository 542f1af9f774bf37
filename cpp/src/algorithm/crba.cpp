// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/crba.hpp"

namespace armdyn {

namespace {
inline Mat3 skew(const Vec3& x) {
  Mat3 s;
  s << 0.0, -x.z(), x.y(), x.z(), 0.0, -x.x(), -x.y(), x.x(), 0.0;
  return s;
}
}  // namespace

void crba_loaded(const Model& m, Data& d) {
  // Spatial quantities in world axes, each subtree's about its root body's centre of mass (not
  // the world origin, where m |x|^2 terms cancel in the diagonal of a link whose own inertia is
  // tiny: UR5 wrist_3_link inertia x 1e-12 lost 6.6e-4). A composite (m, h, I) about a point a:
  // momentum (I w + h x v_a, m v_a - h x w), h = m (c - a); each body's own about its centre of
  // mass: (m, 0, R J R^T).
  for (int i = 0; i < m.nb; ++i) {
    const Body& b = m.bodies[i];
    const BodyKin& k = d.kin[i];
    Data::Composite& I = d.ic[i];
    I.m = b.mass;
    I.h.setZero();
    I.I.noalias() = k.R * b.inertia * k.R.transpose();
  }
  // composites, children first, each moved to its parent's point (r = child's point - parent's):
  //   h_b = h_a + m r,  I_b = I_a - [h_a][r] - [r][h_a] - m [r][r]
  for (auto it = m.tree_order.rbegin(); it != m.tree_order.rend(); ++it) {
    const Joint& j = m.joints[*it];
    if (j.parent == kGround) continue;
    Data::Composite& p = d.ic[j.parent];
    const Data::Composite& c = d.ic[j.child];
    const Vec3 r = d.kin[j.child].x - d.kin[j.parent].x;
    const Mat3 R = skew(r), H = skew(c.h);
    p.m += c.m;
    p.h += c.h + c.m * r;
    p.I += c.I - H * R - R * H - c.m * (R * R);
  }
  // each coordinate's motion about its joint's child's centre of mass: a turn about the axis
  // through the joint point, or a slide (the joint frames of the Newton-Euler sweep)
  for (int ji : m.tree_order) {
    const Joint& j = m.joints[ji];
    if (j.coord0 < 0) continue;
    const Vec3& z = d.rne.axis[ji];
    const Vec3 p = d.rne.point[ji] - d.kin[j.child].x;
    for (int k = 0; k < joint_coords(j.type); ++k) {
      Vec6& s = d.s[j.coord0 + k];
      if (j.type == JointType::Prismatic || k == 1) {
        s << Vec3::Zero(), z;
      } else {
        s << z, p.cross(z);
      }
    }
  }
  // M_jk for j among the coordinates of k's joint and of the joints towards ground: the
  // subtree's momentum for the motion s_k, moved to each ancestor joint's point (n_b = n_a +
  // (a - b) x f)
  for (int k = 0; k < d.n; ++k) {
    const int jk = m.coords[k].joint;
    const Data::Composite& I = d.ic[m.joints[jk].child];
    const Vec3 w = d.s[k].head<3>(), v = d.s[k].tail<3>();
    Vec6 f;
    f.head<3>().noalias() = I.I * w;
    f.head<3>() += I.h.cross(v);
    f.tail<3>() = I.m * v - I.h.cross(w);
    Vec3 at = d.kin[m.joints[jk].child].x;
    for (int ji = jk; ji >= 0;) {
      const Joint& j = m.joints[ji];
      const Vec3& to = d.kin[j.child].x;
      f.head<3>() += (at - to).cross(f.tail<3>());
      at = to;
      for (int c = j.coord0; c < j.coord0 + joint_coords(j.type); ++c)
        d.M(c, k) = d.M(k, c) = d.s[c].dot(f);
      ji = j.parent == kGround ? -1 : d.joint_of_body[j.parent];
    }
  }
}

const MatX& crba(const Model& m, Data& d, Eigen::Ref<const VecX> q) {
  require_joint_space(m, "mass_matrix");
  check_data(m, d, "mass_matrix");
  check_joint_vector(q, d.n, "mass_matrix", "q");
  return mass_matrix_at(m, d, q);
}

const MatX& mass_matrix_at(const Model& m, Data& d, Eigen::Ref<const VecX> q) {
  joint_space_poses(m, q, d.kin, d.rne);
  crba_loaded(m, d);
  return d.M;
}

}  // namespace armdyn
