// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/derivatives.hpp"

#include <cmath>

#include "armdyn/algorithm/crba.hpp"
#include "armdyn/algorithm/dynamics.hpp"
#include "armdyn/algorithm/force_derivatives.hpp"
#include "armdyn/algorithm/forces.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/kernels/joint_space.hpp"
#include "armdyn/kernels/kkt_factor.hpp"
#include "armdyn/math/cholesky.hpp"
#include "armdyn/math/quaternion.hpp"

namespace armdyn {

// (a named namespace: the algorithm sources share one unity translation unit)
namespace derivatives_detail {

// motion cross product (w, v) x (w2, v2) = (w x w2, w x v2 + v x w2)
inline Vec6 mcross(const Vec6& a, const Vec6& b) {
  Vec6 r;
  r.head<3>() = a.head<3>().cross(b.head<3>());
  r.tail<3>() = a.head<3>().cross(b.tail<3>()) + a.tail<3>().cross(b.head<3>());
  return r;
}

// force cross product (w, v) x* (n, f) = (w x n + v x f, w x f)
inline Vec6 fcross(const Vec6& a, const Vec6& f) {
  Vec6 r;
  r.head<3>() = a.head<3>().cross(f.head<3>()) + a.tail<3>().cross(f.tail<3>());
  r.tail<3>() = a.head<3>().cross(f.tail<3>());
  return r;
}

// The fixed point o the spatial quantities are taken about: the world origin, or with a floating
// base its first base's centre of mass at this instant (crba_loaded's choice: products m |c|^2
// about a far origin lose precision). The derivatives do not depend on it (o is fixed in space).
Vec3 about_point(const Model& m, const Data& d) {
  if (m.n_free == 0) return Vec3::Zero();
  for (int ji : m.tree_order)
    if (m.joints[ji].type == JointType::Free) return d.kin[m.joints[ji].child].x;
  return Vec3::Zero();
}

// a spatial inertia (m, h, I about o) times a motion x: (I x_w + h x x_v, m x_v - h x x_w)
inline Vec6 inertia_times(const Data::Composite& Y, const Vec6& x) {
  Vec6 r;
  r.head<3>().noalias() = Y.I * x.head<3>();
  r.head<3>() += Y.h.cross(x.tail<3>());
  r.tail<3>() = Y.m * x.tail<3>() - Y.h.cross(x.head<3>());
  return r;
}

// the velocity variation B u = (Bc u_w, -2 L x u_w) (Data::Derivatives)
inline Vec6 variation_times(const Mat3& B, const Vec3& L, const Vec6& u) {
  Vec6 r;
  r.head<3>().noalias() = B * u.head<3>();
  r.tail<3>() = -2.0 * L.cross(u.head<3>());
  return r;
}

// B^T s = (Bc^T s_w + 2 L x s_v, 0)
inline Vec6 variation_transpose_times(const Mat3& B, const Vec3& L, const Vec6& s) {
  Vec6 r;
  r.head<3>().noalias() = B.transpose() * s.head<3>();
  r.head<3>() += 2.0 * L.cross(s.tail<3>());
  r.tail<3>().setZero();
  return r;
}

// body i's spatial inertia Y about o, velocity V = (W, v) and acceleration A = (alpha, a)
// (gravity offset) give its Newton-Euler wrench f = Y A + V x* Y V and its velocity variation
// B = crf(V) Y - Y crm(V) + X(Y V): with Y = [I, [h]; -[h], m] and the momentum (n, L) = Y V,
// B = [[W, I] - ([v][h] + [h][v]) - [n], 0; -2 [L], 0] (W = [w]: its two right blocks cancel)
void body_terms(const Body& b, const BodyKin& k, const Vec3& o, Data::Derivatives& w, int i) {
  Data::Composite& Y = w.Yc[i];
  const Vec3 c = k.x - o;
  Y.m = b.mass;
  Y.h = b.mass * c;
  const Mat3 RJ = k.R * b.inertia;
  Y.I.noalias() = RJ * k.R.transpose();
  Y.I.noalias() -= Y.h * c.transpose();
  Y.I.diagonal().array() += Y.h.dot(c);
  const Vec6& V = w.V[i];
  const Vec3 om = V.head<3>(), v = V.tail<3>();
  const Vec6 hm = inertia_times(Y, V);
  const Vec3 n = hm.head<3>(), L = hm.tail<3>();
  Vec6& f = w.Fc[i];
  f = inertia_times(Y, w.A[i]);
  f.head<3>() += om.cross(n) + v.cross(L);
  f.tail<3>() += om.cross(L);
  Mat3& B = w.Bc[i];
  // [W, I] = W I + (W I)^T (I symmetric, W skew), W I by columns w x I_k
  for (int k = 0; k < 3; ++k) B.col(k) = om.cross(Y.I.col(k));
  B += B.transpose().eval();
  B.noalias() -= Y.h * v.transpose();
  B.noalias() -= v * Y.h.transpose();
  B.diagonal().array() += 2.0 * v.dot(Y.h);
  B -= skew(n);
  w.Lc[i] = L;
}

// degree of freedom k of joint j (the k-th of its own): its world motion about o (crba_loaded's)
Vec6 dof_motion(const Joint& j, int k, const BodyKin& child, const Vec3& point, const Vec3& axis,
                const Vec3& o) {
  Vec6 s;
  const Vec3 p = point - o;
  if (j.type == JointType::Free) {
    const Vec3 e = free_frame(j, child).col(k % 3);
    if (k < 3)
      s << Vec3::Zero(), e;
    else
      s << e, p.cross(e);
    return s;
  }
  if (j.type == JointType::Prismatic || k == 1)
    s << Vec3::Zero(), axis;
  else
    s << axis, p.cross(axis);
  return s;
}

// forward, per body: the spatial inertia, velocity, acceleration (gravity offset) and the
// Newton-Euler wrench; per degree of freedom: S, u, w and a (derivatives.hpp)
void forward_pass(const Model& m, Data& d, Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> qdd,
                  const Vec3& o) {
  Data::Derivatives& w = d.deriv;
  rne_forward(m, d.kin, qd, qdd, d.rne);
  for (int i = 0; i < m.nb; ++i) {
    const BodyKin& k = d.kin[i];
    const Vec3 c = k.x - o;
    const Vec3& alpha = d.rne.alpha[i];
    Vec6& V = w.V[i];
    V << k.W, k.xd - k.W.cross(c);
    Vec6& A = w.A[i];
    A << alpha, d.rne.acc[i] - alpha.cross(c) - k.W.cross(k.xd) - m.gravity;
    body_terms(m.bodies[i], k, o, w, i);
  }
  Vec6 ground_a;
  ground_a << Vec3::Zero(), -m.gravity;
  for (int ji : m.tree_order) {
    const Joint& j = m.joints[ji];
    if (j.dof0 < 0) continue;
    const bool root = j.parent == kGround;
    const Vec6 Vp = root ? Vec6::Zero() : w.V[j.parent];
    const Vec6& Ap = root ? ground_a : w.A[j.parent];
    const Vec6 Vpc = Vp + w.V[j.child];
    for (int k = 0; k < joint_dofs(j.type); ++k) {
      const int c = j.dof0 + k;
      w.S[c] = dof_motion(j, k, d.kin[j.child], d.rne.point[ji], d.rne.axis[ji], o);
      w.u[c] = mcross(Vp, w.S[c]);
      w.w[c] = mcross(Ap, w.S[c]) + mcross(Vp, w.u[c]);
      w.av[c] = mcross(Vpc, w.S[c]);
    }
  }
}

// backward, children first: the subtree sums and each degree of freedom's terms
void backward_pass(const Model& m, Data& d) {
  Data::Derivatives& w = d.deriv;
  for (auto it = m.tree_order.rbegin(); it != m.tree_order.rend(); ++it) {
    const Joint& j = m.joints[*it];
    const int b = j.child;
    const Data::Composite& Y = w.Yc[b];
    const Mat3& B = w.Bc[b];
    const Vec3& L = w.Lc[b];
    for (int c = j.dof0; c < j.dof0 + joint_dofs(j.type); ++c) {
      const Vec6& S = w.S[c];
      w.YS[c] = inertia_times(Y, S);
      w.BS[c] = variation_transpose_times(B, L, S);
      w.dFq[c] = inertia_times(Y, w.w[c]);
      if (j.parent != kGround) w.dFq[c] += variation_times(B, L, w.u[c]);  // (u = 0 on ground)
      w.dFqx[c] = w.dFq[c] + fcross(S, w.Fc[b]);
      w.dFv[c] = inertia_times(Y, w.av[c]) + variation_times(B, L, S);
    }
    if (j.parent != kGround) {
      Data::Composite& P = w.Yc[j.parent];
      P.m += Y.m;
      P.h += Y.h;
      P.I += Y.I;
      w.Bc[j.parent] += B;
      w.Lc[j.parent] += L;
      w.Fc[j.parent] += w.Fc[b];
    }
  }
}

// the entries: (j, k) for j's joint at or above k's, and (k, j) for j's strictly above
void fill_matrices(const Model& m, Data& d) {
  Data::Derivatives& w = d.deriv;
  w.dq.setZero();
  w.dqd.setZero();
  for (int k = 0; k < d.n; ++k) {
    const Joint& jk = m.joints[m.dof_joint[k]];
    for (int r = jk.dof0; r < jk.dof0 + joint_dofs(jk.type); ++r) {
      w.dq(r, k) = w.S[r].dot(w.dFq[k]);
      w.dqd(r, k) = w.S[r].dot(w.dFv[k]);
    }
    for (int ja = jk.parent == kGround ? -1 : d.joint_of_body[jk.parent]; ja >= 0;) {
      const Joint& j = m.joints[ja];
      for (int r = j.dof0; r < j.dof0 + joint_dofs(j.type); ++r) {
        w.dq(r, k) = w.S[r].dot(w.dFqx[k]);
        w.dqd(r, k) = w.S[r].dot(w.dFv[k]);
        // (BS's linear half is zero)
        w.dq(k, r) = w.YS[k].dot(w.w[r]) + w.BS[k].head<3>().dot(w.u[r].head<3>());
        w.dqd(k, r) = w.YS[k].dot(w.av[r]) + w.BS[k].head<3>().dot(w.S[r].head<3>());
      }
      ja = j.parent == kGround ? -1 : d.joint_of_body[j.parent];
    }
  }
}

// the checks of inverse_dynamics / forward_dynamics (dynamics.cpp), naming fn
void check_state(const Model& m, const Data& d, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                 Eigen::Ref<const VecX> x, double t, const char* fn, const char* xname) {
  require_joint_space(m, fn, true);
  check_data(m, d, fn);
  check_joint_vector(q, d.niq, fn, "q");
  check_joint_vector(qd, d.ni, fn, "qd");
  check_joint_vector(x, d.ni, fn, xname);
  if (!std::isfinite(t)) throw ModelError(msg(fn, ": t is not finite"));
  check_base_quaternions(m, q, fn);
}

// d.deriv.dq, dqd at the loaded kinematics: the rigid-body derivatives less the force elements'
// (tau = ... - F)
void full_derivatives(const Model& m, Data& d, const double* q, Eigen::Ref<const VecX> qd,
                      Eigen::Ref<const VecX> qdd, double t);

// the force elements' share of d.deriv.dq, dqd (tau = ... - F), after fill_matrices
void element_derivatives(const Model& m, Data& d, const double* q, Eigen::Ref<const VecX> qd,
                         double t) {
  if (!has_force_elements(m)) return;
  Data::Derivatives& w = d.deriv;
  w.dq = -w.dq;
  w.dqd = -w.dqd;
  add_force_element_derivatives(m, d, q, qd.data(), t, w.dq, w.dqd);
  w.dq = -w.dq;
  w.dqd = -w.dqd;
}

void full_derivatives(const Model& m, Data& d, const double* q, Eigen::Ref<const VecX> qd,
                      Eigen::Ref<const VecX> qdd, double t) {
  rnea_derivatives_loaded(m, d, qd, qdd);
  element_derivatives(m, d, q, qd, t);
}

// the public (independent) results from the full ones: G^T X G (a copy without couplings)
void reduce_pair(const Model& m, const Data& d, MatX& a, MatX& b, MatX& ar, MatX& br) {
  if (d.ni == d.n) {
    // the same sizes: the buffers trade places (no copy; fill_matrices rewrites a and b whole)
    a.swap(ar);
    b.swap(br);
    return;
  }
  m.independent.reduce(a, ar);
  m.independent.reduce(b, br);
}

// each degree of freedom's parent and ancestors (Data::Derivatives::dof_parent, anc0, anc)
void dof_tree(const Model& m, const Data& d, Data::Derivatives& w) {
  const int n = d.n;
  w.dof_parent.assign(static_cast<size_t>(n), -1);
  for (const Joint& j : m.joints) {
    if (j.dof0 < 0) continue;
    int up = -1;
    for (int b = j.parent; b != kGround && up < 0;) {
      const int ja = d.joint_of_body[b];
      if (ja < 0) break;
      const Joint& a = m.joints[ja];
      if (a.dof0 >= 0 && joint_dofs(a.type) > 0) up = a.dof0 + joint_dofs(a.type) - 1;
      b = a.parent;
    }
    for (int k = 0; k < joint_dofs(j.type); ++k)
      w.dof_parent[j.dof0 + k] = k == 0 ? up : j.dof0 + k - 1;
  }
  w.tree_sparse = true;
  w.anc0.assign(1, 0);
  w.anc.clear();
  for (int k = 0; k < n; ++k) {
    if (w.dof_parent[k] >= k) w.tree_sparse = false;
    for (int i = w.dof_parent[k]; i >= 0 && w.tree_sparse; i = w.dof_parent[i]) w.anc.push_back(i);
    w.anc0.push_back(static_cast<int>(w.anc.size()));
  }
  w.lval.assign(w.anc.size(), 0.0);
  w.ltd = VecX::Zero(n);
  w.ltd_inv = VecX::Zero(n);
  w.solves.setZero(n, 3 * n);
}

// whether M's entries off the tree's pattern (between dofs neither of which is the other's
// ancestor) are all zero: the LTDL factor (ltdl_factor) then has no fill-in
bool tree_pattern(const MatX& M, const Data::Derivatives& w) {
  if (!w.tree_sparse) return false;
  for (long k = 0; k < M.rows(); ++k) {
    int p = w.anc0[k];
    for (long i = k - 1; i >= 0; --i) {
      if (p < w.anc0[k + 1] && w.anc[p] == i)
        ++p;
      else if (M(k, i) != 0.0)
        return false;
    }
  }
  return true;
}

// M = L^T D L (Featherstone's LTDL, children first: no fill-in on a tree) into w.lval and w.ltd;
// false when a pivot is not positive (M is not positive definite)
bool ltdl_factor(const MatX& M, Data::Derivatives& w) {
  const int n = static_cast<int>(M.rows());
  for (int k = 0; k < n; ++k) {
    w.ltd[k] = M(k, k);
    for (int p = w.anc0[k]; p < w.anc0[k + 1]; ++p) w.lval[p] = M(k, w.anc[p]);
  }
  for (int k = n - 1; k >= 0; --k) {
    const double dk = w.ltd[k];
    if (!(dk > 0.0)) return false;
    const int* a = w.anc.data() + w.anc0[k];
    double* lk = w.lval.data() + w.anc0[k];
    const int na = w.anc0[k + 1] - w.anc0[k];
    for (int p = 0; p < na; ++p) {
      const double alpha = lk[p] / dk;
      w.ltd[a[p]] -= alpha * lk[p];
      double* li = w.lval.data() + w.anc0[a[p]];  // a[p]'s ancestors are a[p + 1 ..]
      for (int r = p + 1; r < na; ++r) li[r - p - 1] -= alpha * lk[r];
      lk[p] = alpha;
    }
    w.ltd_inv[k] = 1.0 / dk;
  }
  return true;
}

// x <- M^-1 x by ltdl_factor's factor: L^T y = x (children first, zeros skipped), then
// L x = D^-1 y (parents first)
inline void ltdl_solve(const Data::Derivatives& w, double* x, int n) {
  const int* anc = w.anc.data();
  const double* l = w.lval.data();
  for (int k = n - 1; k >= 0; --k) {
    const double xk = x[k];
    if (xk == 0.0) continue;
    for (int p = w.anc0[k]; p < w.anc0[k + 1]; ++p) x[anc[p]] -= l[p] * xk;
  }
  for (int k = 0; k < n; ++k) {
    double s = x[k] * w.ltd_inv[k];
    for (int p = w.anc0[k]; p < w.anc0[k + 1]; ++p) s -= l[p] * x[anc[p]];
    x[k] = s;
  }
}

}  // namespace derivatives_detail

using namespace derivatives_detail;

void ensure_derivatives(const Model& m, Data& d) {
  Data::Derivatives& w = d.deriv;
  if (w.sized) return;
  const size_t nb = static_cast<size_t>(m.nb), n = static_cast<size_t>(d.n);
  w.Yc.assign(nb, Data::Composite{});
  w.Bc.assign(nb, Mat3::Zero());
  w.Lc.assign(nb, Vec3::Zero());
  for (auto* v : {&w.V, &w.A, &w.Fc, &w.dA, &w.dH}) v->assign(nb, Vec6::Zero());
  for (auto* v : {&w.S, &w.u, &w.w, &w.av, &w.YS, &w.BS, &w.dFq, &w.dFqx, &w.dFv})
    v->assign(n, Vec6::Zero());
  w.dq = MatX::Zero(d.n, d.n);
  w.dqd = MatX::Zero(d.n, d.n);
  for (MatX* x : {&w.tau_q, &w.tau_qd, &w.qdd_q, &w.qdd_qd, &w.qdd_tau})
    *x = MatX::Zero(d.ni, d.ni);
  w.qdd_full = VecX::Zero(d.n);
  w.qdd = VecX::Zero(d.ni);
  dof_tree(m, d, w);
  w.sized = true;
}

void rnea_derivatives_loaded(const Model& m, Data& d, Eigen::Ref<const VecX> qd,
                             Eigen::Ref<const VecX> qdd) {
  const Vec3 o = about_point(m, d);
  forward_pass(m, d, qd, qdd, o);
  backward_pass(m, d);
  fill_matrices(m, d);
}

void inverse_dynamics_derivatives(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                                  Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> qdd, double t) {
  constexpr const char* fn = "inverse_dynamics_derivatives";
  check_state(m, d, q, qd, qdd, t, fn, "qdd");
  ensure_derivatives(m, d);
  Data::Derivatives& w = d.deriv;
  if (d.ni != d.n) {
    // a coupled model: the full coordinates (Model::independent)
    Data::Coupled& c = d.coupled;
    m.independent.expand_q(q.data(), c.q.data());
    m.independent.expand_v(qd.data(), c.qd.data());
    m.independent.expand_v(qdd.data(), c.qdd.data());
    joint_space_kinematics(m, c.q, c.qd, d.kin, d.rne);
    full_derivatives(m, d, c.q.data(), c.qd, c.qdd, t);
  } else {
    joint_space_kinematics(m, q, qd, d.kin, d.rne);
    full_derivatives(m, d, q.data(), qd, qdd, t);
  }
  reduce_pair(m, d, w.dq, w.dqd, w.tau_q, w.tau_qd);
}

namespace derivatives_detail {

// whether the derivative passes give M qdd = tau + Q - b themselves (equations_from_passes):
// without loads and spring-dampers, whose wrenches enter b only through joint_space_equations'
// body forces
bool passes_give_equations(const Model& m) { return m.body_loads.empty() && m.springs.empty(); }

// M qdd = tau + Q - b (without tau) into d.M and d.rhs from the derivative passes at qdd = 0 on
// the loaded kinematics, instead of joint_space_equations' CRBA and Newton-Euler residual:
// M[r, k] = S_r . Yc S_k for r at or above k (crba_loaded's entries), b_k = S_k . Fc (the
// subtree's wrench at qdd = 0), Q the joint-coordinate forces and gear pairs
void equations_from_passes(const Model& m, Data& d, const double* q, const double* qd, double t) {
  forward_pass(m, d, Eigen::Map<const VecX>(qd, d.n), d.zero, about_point(m, d));
  backward_pass(m, d);
  const Data::Derivatives& w = d.deriv;
  for (int k = 0; k < d.n; ++k) {
    d.rhs[k] = -w.S[k].dot(w.Fc[m.joints[m.dof_joint[k]].child]);
    for (int ji = m.dof_joint[k]; ji >= 0;) {
      const Joint& j = m.joints[ji];
      for (int r = j.dof0; r < j.dof0 + joint_dofs(j.type); ++r)
        d.M(r, k) = d.M(k, r) = w.S[r].dot(w.YS[k]);
      ji = j.parent == kGround ? -1 : d.joint_of_body[j.parent];
    }
  }
  if (!m.coord_forces.empty() || !m.gears.empty()) {
    coordinate_forces(m, q + 7 * m.n_free, qd + 6 * m.n_free, nullptr, t, d.coord_tau);
    d.rhs.tail(d.nco) += d.coord_tau;
  }
  if (!d.rhs.allFinite()) {
    for (int c = 0; c < d.n; ++c)
      if (!std::isfinite(d.rhs[c]))
        throw SolverError(msg("non-finite generalised force on joint coordinate '", m.dof_names[c],
                              "' at t=", t));
  }
}

// the passes at qdd = 0 (equations_from_passes) brought to qdd (full): each body's acceleration
// gains dA = dA_parent + S qdd over its joint, each dof's w and dFq their parent's dA x S terms,
// each subtree wrench Yc dA + dH (YS qdd summed over the dofs below), and dFqx follows
void add_accelerations(const Model& m, Data& d, const VecX& qdd) {
  Data::Derivatives& w = d.deriv;
  for (int ji : m.tree_order) {
    const Joint& j = m.joints[ji];
    const bool root = j.parent == kGround;
    const Vec6 dAp = root ? Vec6::Zero() : w.dA[j.parent];
    Vec6& dA = w.dA[j.child];
    dA = dAp;
    for (int c = j.dof0; c < j.dof0 + joint_dofs(j.type); ++c) {
      if (!root) {
        const Vec6 x = mcross(dAp, w.S[c]);
        w.w[c] += x;
        w.dFq[c] += inertia_times(w.Yc[j.child], x);
      }
      dA += w.S[c] * qdd[c];
    }
  }
  for (Vec6& h : w.dH) h.setZero();
  for (auto it = m.tree_order.rbegin(); it != m.tree_order.rend(); ++it) {
    const Joint& j = m.joints[*it];
    const int b = j.child;
    Vec6& F = w.Fc[b];
    F += inertia_times(w.Yc[b], w.dA[b]) + w.dH[b];
    Vec6* up = j.parent == kGround ? nullptr : &w.dH[j.parent];
    if (up) *up += w.dH[b];
    for (int c = j.dof0; c < j.dof0 + joint_dofs(j.type); ++c) {
      w.dFqx[c] = w.dFq[c] + fcross(w.S[c], F);
      if (up) *up += w.YS[c] * qdd[c];
    }
  }
  fill_matrices(m, d);
}

[[noreturn]] void not_positive_definite(const char* fn, double t) {
  throw SolverError(msg(fn, ": the joint-space mass matrix is not positive definite at t=", t,
                        " (a massless subtree?)"));
}

// w.qdd = M^-1 w.qdd by the LTDL factor of d.M when the model has no couplings and M the tree's
// pattern (true; then w.ltdl holds the factor), else false (nothing done)
bool solve_sparse(const Data& d, Data::Derivatives& w, const char* fn, double t) {
  if (d.ni != d.n || !tree_pattern(d.M, w)) return false;
  if (!ltdl_factor(d.M, w)) not_positive_definite(fn, t);
  ltdl_solve(w, w.qdd.data(), d.n);
  return true;
}

// M^-1, -M^-1 dtau/dq and -M^-1 dtau/dqd by the LTDL factor, the three right-hand sides side by
// side in the rows of w.solves (each step of the two triangular solves one row update, 3n long)
void inverse_products_sparse(Data::Derivatives& w, int n) {
  auto& X = w.solves;
  X.leftCols(n).setIdentity();
  X.middleCols(n, n) = -w.tau_q;
  X.rightCols(n) = -w.tau_qd;
  const long cols = 3L * n;
  const int* anc = w.anc.data();
  const double* l = w.lval.data();
  for (int k = n - 1; k >= 0; --k) {  // L^T Y = X, children first
    const double* xk = X.row(k).data();
    for (int p = w.anc0[k]; p < w.anc0[k + 1]; ++p) {
      double* xi = X.row(anc[p]).data();
      const double a = l[p];
      for (long c = 0; c < cols; ++c) xi[c] -= a * xk[c];
    }
  }
  for (int k = 0; k < n; ++k) {  // L X = D^-1 Y, parents first
    double* xk = X.row(k).data();
    const double dinv = w.ltd_inv[k];
    for (long c = 0; c < cols; ++c) xk[c] *= dinv;
    for (int p = w.anc0[k]; p < w.anc0[k + 1]; ++p) {
      const double* xi = X.row(anc[p]).data();
      const double a = l[p];
      for (long c = 0; c < cols; ++c) xk[c] -= a * xi[c];
    }
  }
  w.qdd_tau = X.leftCols(n);
  w.qdd_q = X.middleCols(n, n);
  w.qdd_qd = X.rightCols(n);
}

// the same by the dense Cholesky factor L of M: M^-1 by two triangular solves, then the products
// (small sizes: coefficient-wise, larger: blocked on the stack; no heap allocation either way)
void inverse_products_dense(Data::Derivatives& w, const MatX& L) {
  w.qdd_tau.setIdentity();
  L.triangularView<Eigen::Lower>().solveInPlace(w.qdd_tau);
  L.transpose().triangularView<Eigen::Upper>().solveInPlace(w.qdd_tau);
  w.qdd_q.noalias() = -w.qdd_tau * w.tau_q;
  w.qdd_qd.noalias() = -w.qdd_tau * w.tau_qd;
}

}  // namespace derivatives_detail

void forward_dynamics_derivatives(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                                  Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> tau, double t) {
  constexpr const char* fn = "forward_dynamics_derivatives";
  check_state(m, d, q, qd, tau, t, fn, "tau");
  if (const LightBodies& light = light_bodies(m); !light.joint_space.empty())
    throw ModelError(msg(fn,
                         ": needs the mass matrix (CRBA about the world origin), which loses the "
                         "accelerations of light bodies: ",
                         light.joint_space_note));
  ensure_derivatives(m, d);
  ensure_mass_matrix(d);
  Data::Derivatives& w = d.deriv;
  const bool coupled = d.ni != d.n;
  Data::Coupled& c = d.coupled;
  if (coupled) {
    m.independent.expand_q(q.data(), c.q.data());
    m.independent.expand_v(qd.data(), c.qd.data());
  }
  const double* qf = coupled ? c.q.data() : q.data();
  const Eigen::Map<const VecX> qdf(coupled ? c.qd.data() : qd.data(), d.n);
  // M qdd = tau + Q - b: from the derivative passes at qdd = 0 where they give it, else by
  // joint_space_equations (CRBA, and the Newton-Euler residual at qdd = 0)
  const bool from_passes = passes_give_equations(m);
  if (from_passes) {
    joint_space_kinematics(m, Eigen::Map<const VecX>(qf, d.nq), qdf, d.kin, d.rne);
    equations_from_passes(m, d, qf, qdf.data(), t);
  } else {
    joint_space_equations(m, d, qf, qdf.data(), nullptr, nullptr, t);
  }
  MatX& M = coupled ? c.M : d.M;
  MatX& L = coupled ? c.L : d.L;
  if (coupled) {
    m.independent.reduce(d.rhs.data(), w.qdd.data());
    m.independent.reduce(d.M, c.M);
  } else {
    w.qdd = d.rhs;
  }
  w.qdd += tau;
  const bool sparse = solve_sparse(d, w, fn, t);
  if (!sparse) {
    if (!cholesky_factor(M, L)) not_positive_definite(fn, t);
    cholesky_solve(L, w.qdd);
  }
  if (coupled)
    m.independent.expand_v(w.qdd.data(), w.qdd_full.data());
  else
    w.qdd_full = w.qdd;
  // dtau/dq, dtau/dqd at (q, qd, qdd), then M^-1 applied
  if (from_passes) {
    add_accelerations(m, d, w.qdd_full);
    element_derivatives(m, d, qf, qdf, t);
  } else {
    full_derivatives(m, d, qf, qdf, w.qdd_full, t);
  }
  reduce_pair(m, d, w.dq, w.dqd, w.tau_q, w.tau_qd);
  if (sparse)
    inverse_products_sparse(w, d.n);
  else
    inverse_products_dense(w, L);
}

}  // namespace armdyn
