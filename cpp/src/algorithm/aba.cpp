// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/aba.hpp"

#include <cmath>

#include "armdyn/algorithm/forces.hpp"
#include "armdyn/errors.hpp"

namespace armdyn {

namespace {

inline Mat3 skew(const Vec3& x) {
  Mat3 s;
  s << 0.0, -x.z(), x.y(), x.z(), 0.0, -x.x(), -x.y(), x.x(), 0.0;
  return s;
}

// motion cross product (w, v) x (w2, v2) = (w x w2, w x v2 + v x w2)
inline Vec6 motion_cross(const Vec6& a, const Vec6& b) {
  Vec6 r;
  const Vec3 w = a.head<3>(), v = a.tail<3>(), w2 = b.head<3>(), v2 = b.tail<3>();
  r.head<3>() = w.cross(w2);
  r.tail<3>() = w.cross(v2) + v.cross(w2);
  return r;
}

// coordinate k of joint j: a turn about the axis line through the joint point, or a slide
inline Vec6 motion_of(const Joint& j, int k, const Vec3& z, const Vec3& p) {
  Vec6 s;
  if (j.type == JointType::Prismatic || k == 1)
    s << Vec3::Zero(), z;
  else
    s << z, p.cross(z);
  return s;
}

}  // namespace

void aba_accelerations(const Model& m, Data& d, const double* q, const double* qd, const double* z,
                       const double* tau, double t, double* qdd) {
  const int n = d.n;
  const Eigen::Map<const VecX> qv(q, n), qdv(qd, n);
  joint_space_kinematics(m, qv, qdv, d.kin, d.rne);
  body_forces(m, d.kin, t, d.eta);
  // the joint forces tau + Q
  VecX& f = d.rhs;
  if (tau)
    f = Eigen::Map<const VecX>(tau, n);
  else
    f.setZero();
  if (!m.coord_forces.empty() || !m.gears.empty()) {
    coordinate_forces(m, q, qd, z, t, d.coord_tau);
    f += d.coord_tau;
  }
  if (!f.allFinite()) {
    for (int c = 0; c < n; ++c)
      if (!std::isfinite(f[c]))
        throw SolverError(msg("non-finite generalised force on joint coordinate '",
                              m.coords[c].name, "' at t=", t));
  }
  Data::AbaWork& w = d.aba;
  // each body's spatial inertia about the world origin, its spatial velocity, and its bias
  // force: the residual wrench about the origin at zero spatial acceleration,
  //   F = m W x xd - eta_f,  N_O = x x F - R eta_tau
  for (int i = 0; i < m.nb; ++i) {
    const Body& b = m.bodies[i];
    const BodyKin& k = d.kin[i];
    const Vec3 h = b.mass * k.x;
    Mat6& I = w.IA[i];
    const Mat3 RJ = k.R * b.inertia;
    Mat3 IO;
    IO.noalias() = RJ * k.R.transpose();
    IO.noalias() -= h * k.x.transpose();
    IO.diagonal().array() += h.dot(k.x);
    const Mat3 H = skew(h);
    I.topLeftCorner<3, 3>() = IO;
    I.topRightCorner<3, 3>() = H;
    I.bottomLeftCorner<3, 3>() = -H;
    I.bottomRightCorner<3, 3>() = Mat3::Identity() * b.mass;
    Vec6& v = w.v[i];
    v.head<3>() = k.W;
    v.tail<3>() = k.xd - k.W.cross(k.x);
    const Vec3 F = b.mass * k.W.cross(k.xd) - d.eta.segment<3>(6 * i);
    Vec6& p = w.pA[i];
    p.head<3>().noalias() = k.x.cross(F) - k.R * d.eta.segment<3>(6 * i + 3);
    p.tail<3>() = F;
  }
  // the coordinates' motions and velocity products, parents first
  for (int ji : m.tree_order) {
    const Joint& j = m.joints[ji];
    for (int k = 0; k < joint_coords(j.type); ++k) {
      const int c = j.coord0 + k;
      d.s[c] = motion_of(j, k, d.rne.axis[ji], d.rne.point[ji]);
      if (j.parent == kGround)
        w.c[c].setZero();
      else
        w.c[c] = motion_cross(w.v[j.parent], d.s[c] * qd[c]);
    }
  }
  // articulated inertias and bias forces, children first
  for (auto it = m.tree_order.rbegin(); it != m.tree_order.rend(); ++it) {
    const Joint& j = m.joints[*it];
    const int i = j.child;
    Mat6& IA = w.IA[i];
    Vec6& pA = w.pA[i];
    for (int k = joint_coords(j.type) - 1; k >= 0; --k) {
      const int c = j.coord0 + k;
      const Vec6& s = d.s[c];
      Vec6& U = w.U[c];
      U.noalias() = IA * s;
      const double D = s.dot(U);
      if (!(D > 0.0))
        throw SolverError(msg(
            "forward dynamics (articulated-body algorithm): the articulated "
            "inertia of joint '",
            j.name, "' (coordinate '", m.coords[c].name, "', body '", m.bodies[i].name,
            "') along its coordinate is not positive (", D, ") at t=", t, ": a massless subtree?"));
      const double Dinv = 1.0 / D;
      w.Dinv[c] = Dinv;
      const double u = f[c] - s.dot(pA);
      w.u[c] = u;
      IA.noalias() -= (Dinv * U) * U.transpose();
      pA.noalias() += IA * w.c[c];
      pA += (u * Dinv) * U;
    }
    if (j.parent != kGround) {
      w.IA[j.parent] += IA;
      w.pA[j.parent] += pA;
    }
  }
  // accelerations, parents first
  for (int ji : m.tree_order) {
    const Joint& j = m.joints[ji];
    Vec6& a = w.a[j.child];
    if (j.parent == kGround)
      a.setZero();
    else
      a = w.a[j.parent];
    for (int k = 0; k < joint_coords(j.type); ++k) {
      const int c = j.coord0 + k;
      a += w.c[c];
      const double x = w.Dinv[c] * (w.u[c] - w.U[c].dot(a));
      qdd[c] = x;
      a += x * d.s[c];
    }
  }
}

const VecX& aba(const Model& m, Data& d, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                Eigen::Ref<const VecX> tau, double t) {
  const char* fn = "forward_dynamics";
  require_joint_space(m, fn);
  check_data(m, d, fn);
  check_joint_vector(q, d.n, fn, "q");
  check_joint_vector(qd, d.n, fn, "qd");
  check_joint_vector(tau, d.n, fn, "tau");
  if (!std::isfinite(t)) throw ModelError(msg(fn, ": t is not finite"));
  aba_accelerations(m, d, q.data(), qd.data(), nullptr, tau.data(), t, d.qdd.data());
  return d.qdd;
}

}  // namespace armdyn
