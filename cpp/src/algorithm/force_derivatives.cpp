// SPDX-License-Identifier: BSD-3-Clause
// The force elements' generalised force F = J^T eta_elements + Q and its derivatives along the
// rates. Each degree of freedom k moves the bodies at and below its joint with a world twist S_k
// = (w_k, v_k) about the world origin: a point p fixed on them moves as dp/dq_k = w_k x p + v_k
// (S_k(p) below). A world force f at p (and a world torque tau) on body i adds F_j = f . S_j(p) +
// tau . w_j for every j on i's chain (the joints from i to the root), and along the rates
//   dS_j/dq_k = S_k x S_j            (k at or above j on the chain: same joint included),
//   dp/dq_k = S_k(p),                (k on i's chain)
//   dV_i/dq_k = S_k x (V_i - V_par)  (V the bodies' twists, V_par that of k's joint's parent).
// A floating base's six degrees of freedom are the world twists of its frame's axes B e_m:
// translations (0, B e_m) and rotations (B e_m, P x B e_m) about its origin P; their q-derivative
// is along qd's base-frame velocity (Pinocchio's free flyer), and the rule above holds inside the
// joint's block too. The coordinate forces and gear pairs act on their coordinates directly.
#include "armdyn/algorithm/force_derivatives.hpp"

#include <algorithm>
#include <cmath>
#include <exception>

#include "armdyn/algorithm/forces.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/math/angles.hpp"

namespace armdyn {

bool has_force_elements(const Model& m) {
  return !m.body_loads.empty() || !m.springs.empty() || !m.coord_forces.empty() || !m.gears.empty();
}

namespace {

// a world twist about the world origin: angular w, velocity v of the point at the origin
struct Twist {
  Vec3 w = Vec3::Zero(), v = Vec3::Zero();
  Vec3 at(const Vec3& p) const { return w.cross(p) + v; }  // the velocity of point p
};

// the motion cross product a x b (the rate of b carried by a)
Twist cross(const Twist& a, const Twist& b) {
  return {a.w.cross(b.w), a.w.cross(b.v) + a.v.cross(b.w)};
}

Twist body_twist(const BodyKin& k) { return {k.W, k.xd - k.W.cross(k.x)}; }

// the twist of degree of freedom `sub` of joint ji (data.rne's joint frames at q; B: a free
// joint's frame)
Twist dof_twist(const Model& m, const Data& d, int ji, int sub, const Mat3& B) {
  const Joint& j = m.joints[ji];
  const Vec3& z = d.rne.axis[ji];
  const Vec3& P = d.rne.point[ji];
  if (j.type == JointType::Free) {
    const Vec3 e = B.col(sub % 3);
    if (sub < 3) return {Vec3::Zero(), e};
    return {e, P.cross(e)};
  }
  const bool turns =
      j.type == JointType::Revolute || (j.type == JointType::Cylindrical && sub == 0);
  if (turns) return {z, P.cross(z)};
  return {Vec3::Zero(), z};
}

// every degree of freedom's twist into d.force_deriv.twist (sized here on the first call)
void load_twists(const Model& m, Data& d) {
  Data::ForceDerivScratch& w = d.force_deriv;
  if (static_cast<int>(w.twist.size()) != d.n) {
    w.twist.assign(d.n, Vec6::Zero());
    w.dofs.assign(d.n, 0);
    w.level.assign(d.n, 0);
    for (auto* v : {&w.dd, &w.fa, &w.tc}) v->assign(d.n, Vec3::Zero());
    w.g = VecX::Zero(d.n);
    w.dT = VecX::Zero(d.n);
  }
  for (int ji = 0; ji < static_cast<int>(m.joints.size()); ++ji) {
    const Joint& j = m.joints[ji];
    const int nd = j.dof0 < 0 ? 0 : joint_dofs(j.type);
    if (nd == 0) continue;
    const Mat3 B = j.type == JointType::Free ? free_frame(j, d.kin[j.child]) : Mat3::Identity();
    for (int s = 0; s < nd; ++s) {
      const Twist t = dof_twist(m, d, ji, s, B);
      w.twist[j.dof0 + s] << t.w, t.v;
    }
  }
}

Twist twist_of(const Data& d, int dof) {
  const Vec6& s = d.force_deriv.twist[dof];
  return {s.head<3>(), s.tail<3>()};
}

// f(joint, dof, twist) for each degree of freedom on body's chain, from the body to the root
template <class F>
void for_chain(const Model& m, const Data& d, int body, F&& f) {
  for (int b = body; b != kGround;) {
    const int ji = d.joint_of_body[b];
    if (ji < 0) return;
    const Joint& j = m.joints[ji];
    const int nd = j.dof0 < 0 ? 0 : joint_dofs(j.type);
    for (int s = 0; s < nd; ++s) f(ji, j.dof0 + s, twist_of(d, j.dof0 + s));
    b = j.parent;
  }
}

bool on_chain(const Model& m, const Data& d, int body, int joint) {
  for (int b = body; b != kGround;) {
    const int ji = d.joint_of_body[b];
    if (ji < 0) return false;
    if (ji == joint) return true;
    b = m.joints[ji].parent;
  }
  return false;
}

// the lowest joint with degrees of freedom on the chains of both bodies a and b (-1: none);
// every joint above it is on both (a fixed joint where the chains meet is passed over: for_union
// marks the common part at a degree of freedom)
int common_joint(const Model& m, const Data& d, int a, int b) {
  for (int c = b; c != kGround;) {
    const int ji = d.joint_of_body[c];
    if (ji < 0) return -1;
    const Joint& j = m.joints[ji];
    if (j.dof0 >= 0 && joint_dofs(j.type) > 0 && on_chain(m, d, a, ji)) return ji;
    c = j.parent;
  }
  return -1;
}

// f(joint, dof, twist, on a's chain, on b's chain) once for each degree of freedom on the chain
// of a or of b (lca: their common_joint)
template <class F>
void for_union(const Model& m, const Data& d, int a, int b, int lca, F&& f) {
  bool common = false;
  for_chain(m, d, b, [&](int ji, int k, const Twist& s) {
    if (ji == lca) common = true;
    f(ji, k, s, common, true);
  });
  bool done = false;
  for_chain(m, d, a, [&](int ji, int k, const Twist& s) {
    if (ji == lca) done = true;
    if (!done) f(ji, k, s, true, false);
  });
}

// the q-derivative of the generalised force of a world force f at point p fixed on `body` and a
// world torque tau, f and tau held fixed in world axes (their own dependence on the state is
// the caller's): dF_j/dq_k = f . (w_j x S_k(p)) + [k at or above j] (f . (S_k x S_j)(p) +
// tau . (w_k x w_j)), j and k on the body's chain; with (S_k x S_j)(p) = w_k x S_j(p) - w_j x
// S_k(p):
//   k at or above j:  S_j(p) . (f x w_k) + w_k . (w_j x tau),
//   k below j:        S_k(p) . (f x w_j)
void add_fixed_load(const Model& m, Data& d, int body, const Vec3& p, const Vec3& f,
                    const Vec3& tau, Eigen::Ref<MatX> dF_dq) {
  Data::ForceDerivScratch& w = d.force_deriv;
  int nc = 0, level = 0, last = -1;
  for_chain(m, d, body, [&](int ji, int k, const Twist& sk) {
    if (ji != last) {
      ++level;
      last = ji;
    }
    w.dofs[nc] = k;
    w.level[nc] = level;
    w.dd[nc] = sk.at(p);
    w.fa[nc] = f.cross(sk.w);
    w.tc[nc] = sk.w.cross(tau);
    ++nc;
  });
  for (int a = 0; a < nc; ++a) {
    const int j = w.dofs[a];
    for (int b = 0; b < nc; ++b) {
      const int k = w.dofs[b];
      dF_dq(j, k) += w.level[b] >= w.level[a]
                         ? w.dd[a].dot(w.fa[b]) + w.twist[k].head<3>().dot(w.tc[a])
                         : w.dd[b].dot(w.fa[a]);
    }
  }
}

void add_body_load(const Model& m, Data& d, const BodyLoad& l, double t, Eigen::Ref<MatX> dF_dq) {
  double s = 1.0;
  if (l.has_profile) {
    try {
      s = l.profile.eval(t).y;
    } catch (const SolverError& err) {
      std::throw_with_nested(
          SolverError(msg("load on body '", m.bodies[l.body].name, "': ", err.what())));
    }
    if (!std::isfinite(s))
      throw SolverError(
          msg("load on body '", m.bodies[l.body].name, "': its profile is not finite at t=", t));
  }
  const BodyKin& k = d.kin[l.body];
  add_fixed_load(m, d, l.body, k.x + k.R * l.point, s * l.force, s * l.torque, dF_dq);
}

// a point-to-point spring-damper at the loaded kinematics: its geometry and tension
struct SpringState {
  Vec3 pa, pb;        // the attachment points (world)
  Vec3 n, ddot_perp;  // the unit direction a -> b; (I - n n^T) d' / L
  double L, T;        // length and tension
  Twist va, vb;       // the bodies' twists
  const BodyKin *ka, *kb;
};

SpringState spring_state(const Data& d, const SpringDamper& sd, double t) {
  SpringState s;
  s.ka = &kin_of(d.kin, sd.body_a);
  s.kb = &kin_of(d.kin, sd.body_b);
  s.pa = s.ka->x + s.ka->R * sd.point_a;
  s.pb = s.kb->x + s.kb->R * sd.point_b;
  s.va = body_twist(*s.ka);
  s.vb = body_twist(*s.kb);
  const Vec3 dv = s.pb - s.pa, ddot = s.vb.at(s.pb) - s.va.at(s.pa);
  s.L = dv.norm();
  if (!(s.L > 1e-12))
    throw SolverError(msg("spring-damper '", sd.name, "': length became zero at t=", t));
  s.n = dv / s.L;
  const double Ld = s.n.dot(ddot);
  s.ddot_perp = (ddot - Ld * s.n) / s.L;
  s.T = sd.stiffness * (s.L - sd.rest_length) + sd.damping * Ld;
  if (!std::isfinite(s.T))
    throw SolverError(msg("spring-damper '", sd.name, "': non-finite tension at t=", t));
  return s;
}

// the q-derivative of the rate of point p fixed on the body of kinematics k and twist v, along
// degree of freedom sk of joint ji on its chain: (S_k x (V - V_parent))(p) + W x S_k(p)
Vec3 point_rate_derivative(const Model& m, const Data& d, int ji, const Twist& sk, const BodyKin& k,
                           const Twist& v, const Vec3& p) {
  const int parent = m.joints[ji].parent;
  Twist rel = v;
  if (parent != kGround) {
    const Twist vp = body_twist(d.kin[parent]);
    rel.w -= vp.w;
    rel.v -= vp.v;
  }
  return cross(sk, rel).at(p) + k.W.cross(sk.at(p));
}

// F_j = -T dL/dq_j: the tension's dependence on the state (dT/dq_k = k g_k + c dL'/dq_k, dT/dqd_k =
// c g_k, g = dL/dq) and the direction's (dn/dq_k = (I - n n^T) dd_k / L, dd_k = S_k(p_b) -
// S_k(p_a)) over the union of the two chains (its per-dof terms in d.force_deriv); the geometry
// of the two points by add_fixed_load
void add_spring_damper(const Model& m, Data& d, const SpringDamper& sd, double t,
                       Eigen::Ref<MatX> dF_dq, Eigen::Ref<MatX> dF_dqd) {
  const SpringState s = spring_state(d, sd, t);
  add_fixed_load(m, d, sd.body_b, s.pb, -s.T * s.n, Vec3::Zero(), dF_dq);
  add_fixed_load(m, d, sd.body_a, s.pa, s.T * s.n, Vec3::Zero(), dF_dq);
  // per degree of freedom of the union of the chains: dd_k, g_k, dT/dq_k
  Data::ForceDerivScratch& w = d.force_deriv;
  int nu = 0;
  const int lca = common_joint(m, d, sd.body_a, sd.body_b);
  for_union(m, d, sd.body_a, sd.body_b, lca,
            [&](int kj, int k, const Twist& sk, bool on_a, bool on_b) {
              Vec3 dd = Vec3::Zero();
              double dLd = 0.0;  // dL'/dq_k
              if (on_b) {
                dd += sk.at(s.pb);
                dLd += s.n.dot(point_rate_derivative(m, d, kj, sk, *s.kb, s.vb, s.pb));
              }
              if (on_a) {
                dd -= sk.at(s.pa);
                dLd -= s.n.dot(point_rate_derivative(m, d, kj, sk, *s.ka, s.va, s.pa));
              }
              dLd += dd.dot(s.ddot_perp);
              w.dofs[nu] = k;
              w.dd[nu] = dd;
              w.g[nu] = s.n.dot(dd);
              w.dT[nu] = sd.stiffness * w.g[nu] + sd.damping * dLd;
              ++nu;
            });
  const double c = sd.damping, k_over = s.T / s.L;
  for (int u = 0; u < nu; ++u) {
    const int k = w.dofs[u];
    for (int v = 0; v < nu; ++v) {
      const int j = w.dofs[v];
      dF_dq(j, k) -= w.dT[u] * w.g[v] + k_over * (w.dd[v].dot(w.dd[u]) - w.g[v] * w.g[u]);
      dF_dqd(j, k) -= c * w.g[v] * w.g[u];
    }
  }
}

// d tau / dq and d tau / dqd of one coordinate force (coord_force_value at z = 0)
void coordinate_force_slopes(const Model& m, const CoordForce& cf, double q, double qd, double t,
                             double& dq, double& dqd) {
  dq = -cf.stiffness;
  dqd = -cf.damping;
  if (cf.coulomb > 0) {
    const double th = std::tanh(qd / cf.v_smooth);
    dqd -= cf.coulomb / cf.v_smooth * (1.0 - th * th);
  }
  if (!cf.motor) return;
  // the motor's linear band, closed: std::clamp is the identity at |u| = limit
  const ProfileValue r = cf.reference.eval(t);
  const double e = m.coords[cf.coord].angular ? wrap_angle(r.y - q) : r.y - q;
  const double u = cf.kp * e + cf.kd * (r.yd - qd);
  if (!std::isfinite(u)) throw SolverError(msg("non-finite motor torque at t=", t));
  if (u >= -cf.torque_limit && u <= cf.torque_limit) {
    dq -= cf.kp;
    dqd -= cf.kd;
  }
}

void add_coordinate_forces(const Model& m, const double* q, const double* qd, double t,
                           Eigen::Ref<MatX> dF_dq, Eigen::Ref<MatX> dF_dqd) {
  const int off = 6 * m.n_free;
  for (const CoordForce& cf : m.coord_forces) {
    const int c = cf.coord;
    double dq = 0.0, dqd = 0.0;
    try {
      coordinate_force_slopes(m, cf, q[c], qd[c], t, dq, dqd);
    } catch (const SolverError& err) {
      std::throw_with_nested(
          SolverError(msg("force on joint coordinate '", m.coords[c].name, "': ", err.what())));
    }
    dF_dq(off + c, off + c) += dq;
    dF_dqd(off + c, off + c) += dqd;
  }
}

// gear pairs: Q_a = -r_a f, Q_b = -r_b f of the signed mesh force f(s, s'), s = r_a q_a + r_b
// q_b; the branch gear_force evaluates: no force while penetration <= 0 (the backlash edge
// included), the contact law while F = k d^n (1 + alpha d') >= 0
void add_gear_pairs(const Model& m, const double* q, const double* qd, Eigen::Ref<MatX> dF_dq,
                    Eigen::Ref<MatX> dF_dqd) {
  const int off = 6 * m.n_free;
  for (int gi = 0; gi < static_cast<int>(m.gears.size()); ++gi) {
    const GearPair& g = m.gears[gi];
    double s, sd, pen;
    gear_mesh(m, gi, q, qd, s, sd, pen);
    if (!(pen > 0.0)) continue;
    const double rate = s >= 0 ? sd : -sd;
    const double base = g.stiffness * std::pow(pen, g.exponent);
    if (!(base * (1.0 + g.hc_damping * rate) >= 0.0)) continue;
    // d(sign(s) F)/ds and d(sign(s) F)/ds', the same for either sign of s
    const double ds = gear_contact_stiffness(g, pen) * (1.0 + g.hc_damping * rate);
    const double dsd = base * g.hc_damping;
    const int ia = off + g.coord_a, ib = off + g.coord_b;
    const double r[2] = {g.r_a, g.r_b};
    const int idx[2] = {ia, ib};
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) {
        dF_dq(idx[i], idx[j]) -= r[i] * ds * r[j];
        dF_dqd(idx[i], idx[j]) -= r[i] * dsd * r[j];
      }
  }
}

}  // namespace

void add_force_element_derivatives(const Model& m, Data& d, const double* q, const double* qd,
                                   double t, Eigen::Ref<MatX> dF_dq, Eigen::Ref<MatX> dF_dqd) {
  if (!m.body_loads.empty() || !m.springs.empty()) load_twists(m, d);
  for (const BodyLoad& l : m.body_loads) add_body_load(m, d, l, t, dF_dq);
  for (const SpringDamper& sd : m.springs) add_spring_damper(m, d, sd, t, dF_dq, dF_dqd);
  // the coordinates follow the floating bases' blocks in q and qd
  const double* qc = q + 7 * m.n_free;
  const double* qdc = qd + 6 * m.n_free;
  add_coordinate_forces(m, qc, qdc, t, dF_dq, dF_dqd);
  add_gear_pairs(m, qc, qdc, dF_dq, dF_dqd);
}

}  // namespace armdyn
