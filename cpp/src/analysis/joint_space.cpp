// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/analysis/joint_space.hpp"

#include <utility>

#include "armdyn/errors.hpp"
#include "armdyn/math/quaternion.hpp"

namespace armdyn {

void require_joint_space(const Model& m, const char* what, bool coupled_ok) {
  if (!m.joint_space_ok && !(coupled_ok && m.coupled_joint_space))
    throw ModelError(msg(what,
                         ": needs a tree of revolute, prismatic, cylindrical or fixed "
                         "joints defined parent -> child; here ",
                         m.joint_space_reason));
}

void check_joint_vector(Eigen::Ref<const VecX> x, long n, const char* fn, const char* name) {
  if (x.size() != n)
    throw ModelError(msg(fn, ": ", name, " has length ", x.size(), ", expected ", n));
  if (!x.allFinite()) throw ModelError(msg(fn, ": ", name, " contains NaN or inf"));
}

void state_from_joints(const Model& m, const VecX& q, const VecX& qd, VecX& u, VecX& v) {
  TreeFkWork work;
  state_from_joints(m, q, qd, u, v, work);
}

namespace {
// world pose (and, with Velocities, velocity) of each body, parent before child
template <bool Velocities>
void tree_kinematics(const Model& m, Eigen::Ref<const VecX> q, const double* qd,
                     std::vector<BodyKin>& kin, RneWork* frames) {
  kin.resize(m.nb);
  const BodyKin ground{};
  for (int ji : m.tree_order) {
    const Joint& j = m.joints[ji];
    const BodyKin& p = j.parent != kGround ? kin[j.parent] : ground;
    const Mat3 A = p.R * j.frame_parent;
    const Vec3 z = A.col(2);
    double th, d;
    joint_components(j, q, th, d);
    // child joint frame B = A Rz(th), placed at P + d z
    const double ct = std::cos(th), st = std::sin(th);
    Mat3 B;
    B.col(0) = ct * A.col(0) + st * A.col(1);
    B.col(1) = ct * A.col(1) - st * A.col(0);
    B.col(2) = z;
    const Vec3 P = p.x + p.R * j.point_parent;
    const Vec3 Pc = P + d * z;
    if (frames) {
      frames->point[ji] = Pc;
      frames->axis[ji] = z;
    }
    BodyKin& c = kin[j.child];
    c.R.noalias() = B * j.frame_child.transpose();
    c.x = Pc - c.R * j.point_child;
    if constexpr (Velocities) {
      double thd, dd;
      joint_components(j, Eigen::Map<const VecX>(qd, q.size()), thd, dd);
      c.W = p.W + thd * z;
      const Vec3 Pcd = p.xd + p.W.cross(Pc - p.x) + dd * z;
      c.xd = Pcd + c.W.cross(c.x - Pc);
      c.w.noalias() = c.R.transpose() * c.W;
    } else {
      c.W = c.xd = c.w = Vec3::Zero();
    }
  }
}
}  // namespace

void joint_space_kinematics(const Model& m, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                            std::vector<BodyKin>& kin) {
  tree_kinematics<true>(m, q, qd.data(), kin, nullptr);
}

void joint_space_kinematics(const Model& m, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                            std::vector<BodyKin>& kin, RneWork& frames) {
  tree_kinematics<true>(m, q, qd.data(), kin, &frames);
}

void joint_space_poses(const Model& m, Eigen::Ref<const VecX> q, std::vector<BodyKin>& kin) {
  tree_kinematics<false>(m, q, nullptr, kin, nullptr);
}

void joint_space_poses(const Model& m, Eigen::Ref<const VecX> q, std::vector<BodyKin>& kin,
                       RneWork& frames) {
  tree_kinematics<false>(m, q, nullptr, kin, &frames);
}

void RneWork::resize(const Model& m) {
  const size_t nb = static_cast<size_t>(m.nb), nj = m.joints.size();
  for (auto* v : {&alpha, &acc, &force, &moment}) v->assign(nb, Vec3::Zero());
  for (auto* v : {&point, &axis}) v->assign(nj, Vec3::Zero());
}

void rne_forward(const Model& m, const std::vector<BodyKin>& kin, Eigen::Ref<const VecX> qd,
                 Eigen::Ref<const VecX> qdd, RneWork& w) {
  // forward sweep, parents first: the child's joint point Pc = P + d z moves with the parent
  // plus the slide along z; the child turns about z at Pc (the derivative of the velocities
  // of joint_space_kinematics)
  for (int ji : m.tree_order) {
    const Joint& j = m.joints[ji];
    const bool on_ground = j.parent == kGround;
    const BodyKin& c = kin[j.child];
    double thd, thdd, dd, ddd;
    joint_components(j, qd, thd, dd);
    joint_components(j, qdd, thdd, ddd);
    const Vec3& z = w.axis[ji];
    const Vec3& pc = w.point[ji];
    Vec3 acc = ddd * z;
    Vec3& alpha = w.alpha[j.child];
    alpha = thdd * z;
    if (!on_ground) {
      const BodyKin& p = kin[j.parent];
      const Vec3 r = pc - p.x;
      acc += w.acc[j.parent] + w.alpha[j.parent].cross(r) + p.W.cross(p.W.cross(r)) +
             2.0 * dd * p.W.cross(z);
      alpha += w.alpha[j.parent] + thd * p.W.cross(z);
    }
    const Vec3 e = c.x - pc;
    w.acc[j.child] = acc + alpha.cross(e) + c.W.cross(c.W.cross(e));
  }
}

void tree_body_accelerations(const Model& m, const std::vector<BodyKin>& kin, const RneWork& w,
                             double* vd) {
  for (int i = 0; i < m.nb; ++i) {
    Eigen::Map<Vec3>(vd + 6 * i) = w.acc[i];
    Eigen::Map<Vec3>(vd + 6 * i + 3) = kin[i].R.transpose() * w.alpha[i];
  }
}

void rne_residual(const Model& m, const std::vector<BodyKin>& kin, Eigen::Ref<const VecX> qd,
                  Eigen::Ref<const VecX> qdd, const VecX& eta, RneWork& w, Eigen::Ref<VecX> tau) {
  rne_forward(m, kin, qd, qdd, w);
  // each body's residual Gamma v' - eta: force (world) and moment about its centre of mass
  // (world axes; eta's torque is in body axes)
  for (int i = 0; i < m.nb; ++i) {
    const Body& b = m.bodies[i];
    const BodyKin& k = kin[i];
    w.force[i] = b.mass * w.acc[i] - eta.segment<3>(6 * i);
    w.moment[i] = k.R * (b.inertia * (k.R.transpose() * w.alpha[i]) - eta.segment<3>(6 * i + 3));
  }
  // backward sweep, children first: the subtree's wrench, and its virtual work along the joint
  // coordinates (the moment about the joint point on z, the force along z)
  for (auto it = m.tree_order.rbegin(); it != m.tree_order.rend(); ++it) {
    const Joint& j = m.joints[*it];
    const int c = j.child;
    const Vec3& z = w.axis[*it];
    const Vec3 arm = kin[c].x - w.point[*it];
    switch (j.type) {
      case JointType::Revolute:
        tau[j.coord0] = z.dot(w.moment[c] + arm.cross(w.force[c]));
        break;
      case JointType::Prismatic:
        tau[j.coord0] = z.dot(w.force[c]);
        break;
      case JointType::Cylindrical:
        tau[j.coord0] = z.dot(w.moment[c] + arm.cross(w.force[c]));
        tau[j.coord0 + 1] = z.dot(w.force[c]);
        break;
      default:
        break;
    }
    if (j.parent != kGround) {
      w.force[j.parent] += w.force[c];
      w.moment[j.parent] += w.moment[c] + (kin[c].x - kin[j.parent].x).cross(w.force[c]);
    }
  }
}

void state_from_joints(const Model& m, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd, VecX& u,
                       VecX& v, TreeFkWork& work) {
  require_joint_space(m, "state_from_joints", true);
  const long nc = static_cast<long>(m.coords.size());
  check_joint_vector(q, nc, "state_from_joints", "q");
  check_joint_vector(qd, nc, "state_from_joints", "qd");
  u.resize(m.nq);
  v.resize(m.nv);
  joint_space_kinematics(m, q, qd, work.kin);
  cartesian_state(m, work.kin, u.data(), v.data());
}

void cartesian_state(const Model& m, const std::vector<BodyKin>& kin, double* u, double* v) {
  for (int i = 0; i < m.nb; ++i) {
    const BodyKin& k = kin[i];
    Eigen::Map<Vec3>(u + 7 * i) = k.x;
    Eigen::Map<Vec4>(u + 7 * i + 3) = rot_to_quat(k.R);
    Eigen::Map<Vec3>(v + 6 * i) = k.xd;
    Eigen::Map<Vec3>(v + 6 * i + 3) = k.w;
  }
}

void joint_coordinates(const Model& m, const VecX& u, const VecX& v, VecX& q, VecX& qd) {
  check_joint_vector(u, m.nq, "joint_coordinates", "u");
  check_joint_vector(v, m.nv, "joint_coordinates", "v");
  std::vector<BodyKin> kin;
  body_kinematics(m, u.data(), v.data(), kin);
  const int nc = static_cast<int>(m.coords.size());
  q.resize(nc);
  qd.resize(nc);
  for (int c = 0; c < nc; ++c) {
    const ScalarJet s = coord_jet(m, kin, c);
    q[c] = s.val;
    qd[c] = s.rate;
  }
}

}  // namespace armdyn
