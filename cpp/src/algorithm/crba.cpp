// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/crba.hpp"

#include "armdyn/algorithm/loop_coordinates.hpp"

namespace armdyn {

void ensure_mass_matrix(Data& d) {
  if (d.M.rows() == d.n) return;
  d.M = MatX::Zero(d.n, d.n);
  d.L = MatX::Zero(d.n, d.n);
  if (d.ni != d.n) {
    d.coupled.M = MatX::Zero(d.ni, d.ni);
    d.coupled.L = MatX::Zero(d.ni, d.ni);
  }
}

namespace {
// The point the spatial quantities below are taken about. M does not depend on it; about the
// world origin the products m |c|^2 lose precision with the square of a floating base's distance
// from it (1e-3 relative at 1e6 m, overflow past 1e154 m), so with a floating base they are
// taken about the first base's centre of mass. Without one, about the world origin.
Vec3 reference_point(const Model& m, const Data& d) {
  if (m.n_free == 0) return Vec3::Zero();
  for (int ji : m.tree_order)
    if (m.joints[ji].type == JointType::Free) return d.kin[m.joints[ji].child].x;
  return Vec3::Zero();
}
}  // namespace

void crba_loaded(const Model& m, Data& d) {
  ensure_mass_matrix(d);
  const Vec3 o = reference_point(m, d);
  // each body's spatial inertia about o: I_o = R J R^T + m (|c|^2 1 - c c^T), c = x - o
  for (int i = 0; i < m.nb; ++i) {
    const Body& b = m.bodies[i];
    const BodyKin& k = d.kin[i];
    Data::Composite& I = d.ic[i];
    const Vec3 c = k.x - o;
    I.m = b.mass;
    I.h = b.mass * c;
    const Mat3 RJ = k.R * b.inertia;
    I.I.noalias() = RJ * k.R.transpose();
    I.I.noalias() -= I.h * c.transpose();
    I.I.diagonal().array() += I.h.dot(c);
  }
  // composites, children first
  for (auto it = m.tree_order.rbegin(); it != m.tree_order.rend(); ++it) {
    const Joint& j = m.joints[*it];
    if (j.parent == kGround) continue;
    Data::Composite& p = d.ic[j.parent];
    const Data::Composite& c = d.ic[j.child];
    p.m += c.m;
    p.h += c.h;
    p.I += c.I;
  }
  // each coordinate's motion: a turn about the axis through the joint point, or a slide (the
  // joint frames of the Newton-Euler sweep)
  for (int ji : m.tree_order) {
    const Joint& j = m.joints[ji];
    if (j.dof0 < 0) continue;
    const Vec3& z = d.rne.axis[ji];
    const Vec3 p = d.rne.point[ji] - o;
    if (j.type == JointType::Free) {
      // a floating base: slides along, then turns about, its frame's axes through its origin
      const Mat3 B = free_frame(j, d.kin[j.child]);
      for (int k = 0; k < 3; ++k) {
        d.s[j.dof0 + k] << Vec3::Zero(), B.col(k);
        d.s[j.dof0 + 3 + k] << B.col(k), p.cross(B.col(k));
      }
      continue;
    }
    for (int k = 0; k < joint_coords(j.type); ++k) {
      Vec6& s = d.s[j.dof0 + k];
      if (j.type == JointType::Prismatic || k == 1) {
        s << Vec3::Zero(), z;
      } else {
        s << z, p.cross(z);
      }
    }
  }
  // M_jk for j among the degrees of freedom of k's joint and of the joints towards ground
  for (int k = 0; k < d.n; ++k) {
    const int jk = m.dof_joint[k];
    // the subtree's momentum for the motion s = (w, v_o)
    const Data::Composite& I = d.ic[m.joints[jk].child];
    const Vec3 w = d.s[k].head<3>(), v = d.s[k].tail<3>();
    Vec6 f;
    f.head<3>().noalias() = I.I * w;
    f.head<3>() += I.h.cross(v);
    f.tail<3>() = I.m * v - I.h.cross(w);
    for (int ji = jk; ji >= 0;) {
      const Joint& j = m.joints[ji];
      for (int c = j.dof0; c < j.dof0 + joint_dofs(j.type); ++c)
        d.M(c, k) = d.M(k, c) = d.s[c].dot(f);
      ji = j.parent == kGround ? -1 : d.joint_of_body[j.parent];
    }
  }
}

const MatX& crba(const Model& m, Data& d, Eigen::Ref<const VecX> q) {
  if (m.loop_coordinates) return loop_mass_matrix(m, d, q);
  require_joint_space(m, "mass_matrix", true);
  check_data(m, d, "mass_matrix");
  check_joint_vector(q, d.niq, "mass_matrix", "q");
  check_base_quaternions(m, q, "mass_matrix");
  if (d.ni == d.n) return mass_matrix_at(m, d, q);
  // a coupled model: M_r = G^T M G in the independent coordinates (Model::independent)
  m.independent.expand_q(q.data(), d.coupled.q.data());
  m.independent.reduce(mass_matrix_at(m, d, d.coupled.q), d.coupled.M);
  return d.coupled.M;
}

const MatX& mass_matrix_at(const Model& m, Data& d, Eigen::Ref<const VecX> q) {
  joint_space_poses(m, q, d.kin, d.rne);
  crba_loaded(m, d);
  return d.M;
}

Eigen::Ref<const VecX> bases_at_origin(const Model& m, Eigen::Ref<const VecX> q, VecX& buf) {
  if (m.n_free == 0) return q;
  buf = q;
  for (int k = 0; k < m.n_free; ++k) buf.segment<3>(7 * k).setZero();
  return buf;
}

}  // namespace armdyn
