// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/aba.hpp"

#include <Eigen/Cholesky>
#include <cmath>

#include "armdyn/algorithm/forces.hpp"
#include "armdyn/errors.hpp"

namespace armdyn {

namespace {

// motion cross product (w, v) x (w2, v2) = (w x w2, w x v2 + v x w2)
inline Vec6 motion_cross(const Vec6& a, const Vec6& b) {
  Vec6 r;
  const Vec3 w = a.head<3>(), v = a.tail<3>(), w2 = b.head<3>(), v2 = b.tail<3>();
  r.head<3>() = w.cross(w2);
  r.tail<3>() = w.cross(v2) + v.cross(w2);
  return r;
}

// a motion (w, v) about point `from` expressed about point `to`: v_to = v_from + w x (to - from)
inline Vec6 shift_motion(const Vec6& a, const Vec3& from, const Vec3& to) {
  Vec6 r;
  r.head<3>() = a.head<3>();
  r.tail<3>() = a.tail<3>() + a.head<3>().cross(to - from);
  return r;
}

// out += X^T I X: a symmetric spatial inertia I = [A B; B^T M] about point a (angular rows
// first) moved to point b, with r = a - b; X = [1 0; -[r]x 1] maps a motion about b to one about
// a, X^T a force about a to one about b (n_b = n_a + r x f). With R = [r]x (R^T = -R):
//   X^T I X = [A - BR - (BR)^T - R M R,  B - (MR)^T;  (B - (MR)^T)^T,  M],
// the products by R as cross products (row b^T R = (b x r)^T, column R c = r x c).
inline void add_shifted_inertia(const Mat6& I, const Vec3& r, Mat6& out) {
  Mat3 BR, MR;
  for (int i = 0; i < 3; ++i) {
    BR.row(i) = I.block<1, 3>(i, 3).cross(r.transpose());
    MR.row(i) = I.block<1, 3>(3 + i, 3).cross(r.transpose());
  }
  Mat3 RMR;
  for (int k = 0; k < 3; ++k) RMR.col(k) = r.cross(MR.col(k));
  Mat3 TR = I.topRightCorner<3, 3>() - MR.transpose();
  out.topLeftCorner<3, 3>() += I.topLeftCorner<3, 3>() - BR - BR.transpose() - RMR;
  out.topRightCorner<3, 3>() += TR;
  out.bottomLeftCorner<3, 3>() += TR.transpose();
  out.bottomRightCorner<3, 3>() += I.bottomRightCorner<3, 3>();
}

// coordinate k of joint j: a turn about the axis line through the joint point (p, relative to
// the point the spatial vectors are taken about), or a slide
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
  const Eigen::Map<const VecX> qv(q, d.nq), qdv(qd, n);
  joint_space_kinematics(m, qv, qdv, d.kin, d.rne);
  body_forces(m, d.kin, t, d.eta);
  // the joint forces tau + Q
  VecX& f = d.rhs;
  if (tau)
    f = Eigen::Map<const VecX>(tau, n);
  else
    f.setZero();
  if (!m.coord_forces.empty() || !m.gears.empty()) {
    coordinate_forces(m, q + 7 * m.n_free, qd + 6 * m.n_free, z, t, d.coord_tau);
    f.tail(d.nco) += d.coord_tau;
  }
  if (!f.allFinite()) {
    for (int c = 0; c < n; ++c)
      if (!std::isfinite(f[c]))
        throw SolverError(msg("non-finite generalised force on joint coordinate '", m.dof_names[c],
                              "' at t=", t));
  }
  Data::AbaWork& w = d.aba;
  // Spatial quantities in world axes, each body's about its own centre of mass x_i (a point
  // fixed in space at this instant), not about the world origin: there the inertia of a link far
  // from the origin carries m |x|^2 terms that cancel in D = s^T I^A s, and a link whose own
  // inertia is tiny (a flange, a sensor, 1e-12 kg m^2) lost its acceleration to that cancellation
  // (UR5 wrist_3_link inertia x 1e-12: 6.6e-4 relative error; Pinocchio works in local frames).
  // About the centre of mass the body's inertia is diag(R J R^T, m), its velocity (W, xd) and its
  // bias force the residual wrench at zero spatial acceleration,
  //   p = (-R eta_tau, m W x xd - eta_f)   (eta_tau holds the gyroscopic torque).
  for (int i = 0; i < m.nb; ++i) {
    const Body& b = m.bodies[i];
    const BodyKin& k = d.kin[i];
    Mat6& I = w.IA[i];
    I.setZero();
    I.topLeftCorner<3, 3>().noalias() = k.R * b.inertia * k.R.transpose();
    I.bottomRightCorner<3, 3>().diagonal().setConstant(b.mass);
    Vec6& v = w.v[i];
    v.head<3>() = k.W;
    v.tail<3>() = k.xd;
    Vec6& p = w.pA[i];
    p.head<3>().noalias() = -(k.R * d.eta.segment<3>(6 * i + 3));
    p.tail<3>() = b.mass * k.W.cross(k.xd) - d.eta.segment<3>(6 * i);
  }
  // the coordinates' motions (about the child's centre of mass) and velocity products, parents
  // first: c = v_parent x (s qd), with the parent's velocity moved to the child's point
  for (int ji : m.tree_order) {
    const Joint& j = m.joints[ji];
    const Vec3& o = d.kin[j.child].x;
    if (j.type == JointType::Free) {
      // a floating base: slides along and turns about its frame's axes through its origin P;
      // the axes move with the body, so the velocity product v x (S qd) = v x v vanishes
      const Mat3 B = free_frame(j, d.kin[j.child]);
      const Vec3 r = d.rne.point[ji] - o;
      for (int k = 0; k < 3; ++k) {
        d.s[j.dof0 + k] << Vec3::Zero(), B.col(k);
        d.s[j.dof0 + 3 + k] << B.col(k), r.cross(B.col(k));
        w.c[j.dof0 + k].setZero();
        w.c[j.dof0 + 3 + k].setZero();
      }
      continue;
    }
    for (int k = 0; k < joint_coords(j.type); ++k) {
      const int c = j.dof0 + k;
      d.s[c] = motion_of(j, k, d.rne.axis[ji], d.rne.point[ji] - o);
      if (j.parent == kGround) {
        w.c[c].setZero();
      } else {
        const Vec6 vp = shift_motion(w.v[j.parent], d.kin[j.parent].x, o);
        w.c[c] = motion_cross(vp, d.s[c] * qd[c]);
      }
    }
  }
  // articulated inertias and bias forces, children first, each passed to the parent's point
  for (auto it = m.tree_order.rbegin(); it != m.tree_order.rend(); ++it) {
    const Joint& j = m.joints[*it];
    const int i = j.child;
    Mat6& IA = w.IA[i];
    Vec6& pA = w.pA[i];
    for (int k = joint_coords(j.type) - 1; k >= 0; --k) {
      const int c = j.dof0 + k;
      const Vec6& s = d.s[c];
      Vec6& U = w.U[c];
      U.noalias() = IA * s;
      const double D = s.dot(U);
      if (!(D > 0.0))
        throw SolverError(msg(
            "forward dynamics (articulated-body algorithm): the articulated "
            "inertia of joint '",
            j.name, "' (coordinate '", m.dof_names[c], "', body '", m.bodies[i].name,
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
      const Vec3 r = d.kin[i].x - d.kin[j.parent].x;  // from the parent's point to the child's
      add_shifted_inertia(IA, r, w.IA[j.parent]);
      Vec6& pp = w.pA[j.parent];
      pp.head<3>() += pA.head<3>() + r.cross(pA.tail<3>());
      pp.tail<3>() += pA.tail<3>();
    }
  }
  // accelerations, parents first, each moved from the parent's point to the child's
  for (int ji : m.tree_order) {
    const Joint& j = m.joints[ji];
    Vec6& a = w.a[j.child];
    if (j.type == JointType::Free) {
      // the floating base's 6 x 6 block: (S^T I^A S) qdd = f - S^T p^A, a = S qdd
      Mat6 S;
      for (int k = 0; k < 6; ++k) S.col(k) = d.s[j.dof0 + k];
      const Mat6 U = w.IA[j.child] * S;
      const Mat6 D = S.transpose() * U;
      const Eigen::LLT<Mat6> llt(D);
      if (llt.info() != Eigen::Success)
        throw SolverError(
            msg("forward dynamics (articulated-body algorithm): the articulated "
                "inertia of floating base '",
                j.name, "' (body '", m.bodies[j.child].name, "') is not positive definite at t=", t,
                ": a massless model?"));
      const Vec6 x = llt.solve(f.segment<6>(j.dof0) - S.transpose() * w.pA[j.child]);
      Eigen::Map<Vec6>(qdd + j.dof0) = x;
      a.noalias() = S * x;
      continue;
    }
    if (j.parent == kGround)
      a.setZero();
    else
      a = shift_motion(w.a[j.parent], d.kin[j.parent].x, d.kin[j.child].x);
    for (int k = 0; k < joint_coords(j.type); ++k) {
      const int c = j.dof0 + k;
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
  check_joint_vector(q, d.nq, fn, "q");
  check_joint_vector(qd, d.n, fn, "qd");
  check_joint_vector(tau, d.n, fn, "tau");
  if (!std::isfinite(t)) throw ModelError(msg(fn, ": t is not finite"));
  check_base_quaternions(m, q, fn);
  aba_accelerations(m, d, q.data(), qd.data(), nullptr, tau.data(), t, d.qdd.data());
  return d.qdd;
}

}  // namespace armdyn
