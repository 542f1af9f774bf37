// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/kernels/joint_space.hpp"

#include <cmath>
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

void check_base_quaternions(const Model& m, Eigen::Ref<const VecX> q, const char* fn) {
  if (m.n_free == 0) return;
  for (const Joint& j : m.joints) {
    if (j.type != JointType::Free || j.q0 < 0) continue;
    const double n = q.segment<4>(j.q0 + 3).norm();
    if (!(std::abs(n - 1.0) <= 1e-6))
      throw ModelError(msg(fn, ": q[", j.q0 + 3, ":", j.q0 + 7, "], the quaternion of free joint '",
                           j.name, "' (scalar first), has norm ", n,
                           "; expected a unit quaternion"));
  }
}

void configuration_rate(const Model& m, const double* q, const double* qd, double* qdot) {
  const int F = m.n_free, nc = static_cast<int>(m.coords.size());
  for (int c = 0; c < nc; ++c) qdot[7 * F + c] = qd[6 * F + c];
  for (const Joint& j : m.joints) {
    if (j.type != JointType::Free || j.q0 < 0) continue;
    const Vec4 e(q[j.q0 + 3], q[j.q0 + 4], q[j.q0 + 5], q[j.q0 + 6]);
    const Vec3 v(qd[j.dof0], qd[j.dof0 + 1], qd[j.dof0 + 2]);
    const Vec3 w(qd[j.dof0 + 3], qd[j.dof0 + 4], qd[j.dof0 + 5]);
    Eigen::Map<Vec3>(qdot + j.q0) = quat_to_rot(e.normalized()) * v;
    Eigen::Map<Vec4>(qdot + j.q0 + 3) = quat_rate(e, w);  // w in the base frame
  }
}

void normalize_bases(const Model& m, double* q) {
  for (const Joint& j : m.joints) {
    if (j.type != JointType::Free || j.q0 < 0) continue;
    Eigen::Map<Vec4> e(q + j.q0 + 3);
    e.normalize();
  }
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
    if (j.type == JointType::Free) {
      // a floating base: its frame's origin P and rotation B from q, its velocity (v, w) in B
      const int i0 = j.q0;
      const Vec3 P(q[i0], q[i0 + 1], q[i0 + 2]);
      const Mat3 B = quat_to_rot(Vec4(q[i0 + 3], q[i0 + 4], q[i0 + 5], q[i0 + 6]).normalized());
      if (frames) {
        frames->point[ji] = P;
        frames->axis[ji] = B.col(2);
      }
      BodyKin& c = kin[j.child];
      c.R.noalias() = B * j.frame_child.transpose();
      c.x = P - c.R * j.point_child;
      if constexpr (Velocities) {
        const double* v = qd + j.dof0;
        c.W = B * Vec3(v[3], v[4], v[5]);
        c.xd = B * Vec3(v[0], v[1], v[2]) + c.W.cross(c.x - P);
        c.w.noalias() = c.R.transpose() * c.W;
      } else {
        c.W = c.xd = c.w = Vec3::Zero();
      }
      continue;
    }
    const BodyKin& p = j.parent != kGround ? kin[j.parent] : ground;
    const Mat3 A = p.R * j.frame_parent;
    const Vec3 z = A.col(2);
    double th, d;
    joint_components(j, q.data(), j.q0, th, d);
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
      joint_components(j, qd, j.dof0, thd, dd);
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
    const BodyKin& c = kin[j.child];
    const Vec3& pc = w.point[ji];
    if (j.type == JointType::Free) {
      // a floating base: alpha = B w', the origin's acceleration W x (B v) + B v'
      const Mat3 B = free_frame(j, c);
      const double* a = qdd.data() + j.dof0;
      const double* v = qd.data() + j.dof0;
      Vec3& alpha = w.alpha[j.child];
      alpha.noalias() = B * Vec3(a[3], a[4], a[5]);
      const Vec3 acc = c.W.cross(B * Vec3(v[0], v[1], v[2])) + B * Vec3(a[0], a[1], a[2]);
      const Vec3 e = c.x - pc;
      w.acc[j.child] = acc + alpha.cross(e) + c.W.cross(c.W.cross(e));
      continue;
    }
    const bool on_ground = j.parent == kGround;
    double thd, thdd, dd, ddd;
    joint_components(j, qd.data(), j.dof0, thd, dd);
    joint_components(j, qdd.data(), j.dof0, thdd, ddd);
    const Vec3& z = w.axis[ji];
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
        tau[j.dof0] = z.dot(w.moment[c] + arm.cross(w.force[c]));
        break;
      case JointType::Prismatic:
        tau[j.dof0] = z.dot(w.force[c]);
        break;
      case JointType::Cylindrical:
        tau[j.dof0] = z.dot(w.moment[c] + arm.cross(w.force[c]));
        tau[j.dof0 + 1] = z.dot(w.force[c]);
        break;
      case JointType::Free: {
        // the subtree's wrench at the base frame's origin, in the base frame's axes
        const Mat3 B = free_frame(j, kin[c]);
        tau.segment<3>(j.dof0).noalias() = B.transpose() * w.force[c];
        tau.segment<3>(j.dof0 + 3).noalias() =
            B.transpose() * (w.moment[c] + arm.cross(w.force[c]));
        break;
      }
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
  check_joint_vector(q, m.nq_joint, "state_from_joints", "q");
  check_joint_vector(qd, m.nv_joint, "state_from_joints", "qd");
  check_base_quaternions(m, q, "state_from_joints");
  u.resize(m.nq);
  v.resize(m.nv);
  joint_space_kinematics(m, q, qd, work.kin);
  cartesian_state(m, work.kin, u.data(), v.data());
  base_orientations(m, q.data(), u.data());
}

void base_orientations(const Model& m, const double* q, double* u) {
  for (const Joint& j : m.joints) {
    if (j.type != JointType::Free || j.q0 < 0) continue;
    // R(e_body) = B frame_child^T: e_body = e_B (x) conj(e_frame), e_B's sign kept
    const Vec4 ef = rot_to_quat(j.frame_child);
    Eigen::Map<Vec4>(u + 7 * j.child + 3) = quat_mul(
        Eigen::Map<const Vec4>(q + j.q0 + 3).normalized(), Vec4(ef[0], -ef[1], -ef[2], -ef[3]));
  }
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

void base_coordinates(const Model& m, const std::vector<BodyKin>& kin, const double* u, double* q,
                      double* qd) {
  for (const Joint& j : m.joints) {
    if (j.type != JointType::Free || j.q0 < 0) continue;
    const BodyKin& c = kin[j.child];
    const Mat3 B = free_frame(j, c);
    const Vec3 P = c.x + c.R * j.point_child;
    Eigen::Map<Vec3>(q + j.q0) = P;
    // from the body's Euler parameters when given: continuous along a run (no sign flips)
    Eigen::Map<Vec4>(q + j.q0 + 3) =
        u ? quat_mul(Eigen::Map<const Vec4>(u + 7 * j.child + 3).normalized(),
                     rot_to_quat(j.frame_child))
          : rot_to_quat(B);
    if (qd) {
      Eigen::Map<Vec3>(qd + j.dof0) = B.transpose() * (c.xd + c.W.cross(P - c.x));
      Eigen::Map<Vec3>(qd + j.dof0 + 3) = B.transpose() * c.W;
    }
  }
}

void base_accelerations(const Model& m, const std::vector<BodyKin>& kin, const double* vd,
                        double* qdd) {
  for (const Joint& j : m.joints) {
    if (j.type != JointType::Free || j.dof0 < 0) continue;
    const BodyKin& c = kin[j.child];
    const Mat3 B = free_frame(j, c);
    const Vec3 r = c.R * j.point_child;  // from the centre of mass to the frame's origin P
    const Vec3 alpha = c.R * Vec3(vd[6 * j.child + 3], vd[6 * j.child + 4], vd[6 * j.child + 5]);
    const Vec3 vP = c.xd + c.W.cross(r);
    const Vec3 aP = Vec3(vd[6 * j.child], vd[6 * j.child + 1], vd[6 * j.child + 2]) +
                    alpha.cross(r) + c.W.cross(c.W.cross(r));
    // d/dt (B^T vP) = B^T (aP - W x vP), d/dt (B^T W) = B^T alpha
    Eigen::Map<Vec3>(qdd + j.dof0) = B.transpose() * (aP - c.W.cross(vP));
    Eigen::Map<Vec3>(qdd + j.dof0 + 3) = B.transpose() * alpha;
  }
}

void joint_coordinates(const Model& m, const VecX& u, const VecX& v, VecX& q, VecX& qd) {
  check_joint_vector(u, m.nq, "joint_coordinates", "u");
  check_joint_vector(v, m.nv, "joint_coordinates", "v");
  std::vector<BodyKin> kin;
  body_kinematics(m, u.data(), v.data(), kin);
  const int nc = static_cast<int>(m.coords.size());
  q.resize(m.nq_joint);
  qd.resize(m.nv_joint);
  for (int c = 0; c < nc; ++c) {
    const ScalarJet s = coord_jet(m, kin, c);
    q[7 * m.n_free + c] = s.val;
    qd[6 * m.n_free + c] = s.rate;
  }
  base_coordinates(m, kin, u.data(), q.data(), qd.data());
}

void state_from_independent(const Model& m, const VecX& q, const VecX& qd, VecX& u, VecX& v,
                            const char* fn) {
  require_joint_space(m, fn, true);
  const IndependentCoords& ic = m.independent;
  check_joint_vector(q, ic.nq(), fn, "q");
  check_joint_vector(qd, ic.nv(), fn, "qd");
  VecX qf(m.nq_joint), qdf(m.nv_joint);
  ic.expand_q(q.data(), qf.data());
  ic.expand_v(qd.data(), qdf.data());
  state_from_joints(m, qf, qdf, u, v);
}

void independent_joint_coordinates(const Model& m, const VecX& u, const VecX& v, VecX& q,
                                   VecX& qd) {
  VecX qf, qdf;
  joint_coordinates(m, u, v, qf, qdf);
  const IndependentCoords& ic = m.independent;
  q.resize(ic.nq());
  qd.resize(ic.nv());
  q.head(ic.lead_q) = qf.head(ic.lead_q);
  qd.head(ic.lead_v) = qdf.head(ic.lead_v);
  for (int k = 0; k < ic.n; ++k) {
    q[ic.lead_q + k] = qf[ic.lead_q + ic.full[k]];
    qd[ic.lead_v + k] = qdf[ic.lead_v + ic.full[k]];
  }
}

}  // namespace armdyn
