// SPDX-License-Identifier: BSD-3-Clause
// ModelBuilder::finalize(): sizes and rows, connectivity and topology, the assembly of the
// initial state and the rank analysis at it. detail::finalize_draft (at the end) calls the
// stages in order, each a function of this file above it.
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <numeric>

#include "armdyn/algorithm/kinematics.hpp"
#include "armdyn/algorithm/loop_coordinates.hpp"
#include "armdyn/algorithm/projection.hpp"
#include "armdyn/builder/builder.hpp"
#include "armdyn/data.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/kernels/block_sparse.hpp"
#include "armdyn/kernels/constraint_rows.hpp"
#include "armdyn/kernels/jets.hpp"
#include "armdyn/kernels/joint_space.hpp"
#include "armdyn/math/quaternion.hpp"

namespace armdyn {

namespace {

Vec3 principal_moments(const Model& m, int b) {
  return Vec3(Eigen::SelfAdjointEigenSolver<Mat3>(m.bodies[b].inertia).eigenvalues());
}

// some body massless or with a singular inertia (else every motion carries inertia)
bool has_weak_body(const Model& m) {
  for (int b = 0; b < m.nb; ++b) {
    const Vec3 p = principal_moments(m, b);
    if (!(m.bodies[b].mass > 0.0) || !(p[0] > 1e-12 * p[2])) return true;
  }
  return false;
}

// An orthonormal basis N of the velocities the joint rows allow at kin (angular ones scaled by
// the length scale l): the complement of zeta^T's range by column-pivoted QR at the rank
// analysis' threshold
MatX allowed_motions(const Model& m, const std::vector<BodyKin>& kin) {
  if (m.nc_joint == 0) return MatX::Identity(m.nv, m.nv);
  ConstraintEval ce;
  ce.init(m);
  eval_constraints(m, kin, 0.0, false, ce);
  MatX zt = dense_zeta(m, ce).topRows(m.nc_joint).transpose();
  for (int b = 0; b < m.nb; ++b) zt.middleRows<3>(6 * b + 3) /= m.length_scale;
  Eigen::ColPivHouseholderQR<MatX> qr(zt);
  qr.setThreshold(1e-6);
  const int r = static_cast<int>(qr.rank());
  const MatX Q = qr.householderQ();
  return Q.rightCols(m.nv - r);
}

// the inertia of the (scaled) motion v as a sum of the bodies' (non-negative) shares
double motion_inertia(const Model& m, const VecX& v) {
  const double l = m.length_scale;
  double rq = 0.0;
  for (int b = 0; b < m.nb; ++b)
    rq += m.bodies[b].mass * v.segment<3>(6 * b).squaredNorm() +
          v.segment<3>(6 * b + 3).dot(m.bodies[b].inertia * v.segment<3>(6 * b + 3)) / (l * l);
  return rq;
}

// Mark the joints and bodies that the (scaled) motion v moves: those whose relative velocity,
// or velocity, exceeds 1e-6 of the largest.
void mark_moving(const Model& m, const std::vector<BodyKin>& kin, const VecX& v,
                 std::vector<char>& joint_moves, std::vector<char>& body_moves) {
  const int nb = m.nb;
  const double l = m.length_scale;
  auto W = [&](int b) {
    return b == kGround ? Vec3(Vec3::Zero()) : Vec3(kin[b].R * v.segment<3>(6 * b + 3) / l);
  };
  auto xd = [&](int b) { return b == kGround ? Vec3(Vec3::Zero()) : Vec3(v.segment<3>(6 * b)); };
  auto x = [&](int b) { return b == kGround ? Vec3(Vec3::Zero()) : kin[b].x; };
  std::vector<double> jm(m.joints.size(), 0.0), bm(nb, 0.0);
  for (size_t j = 0; j < m.joints.size(); ++j) {
    const Joint& jt = m.joints[j];
    const Vec3 P = jt.child == kGround ? jt.point_child
                                       : Vec3(kin[jt.child].x + kin[jt.child].R * jt.point_child);
    const Vec3 w_rel = W(jt.child) - W(jt.parent);
    const Vec3 v_rel = xd(jt.child) + W(jt.child).cross(P - x(jt.child)) - xd(jt.parent) -
                       W(jt.parent).cross(P - x(jt.parent));
    jm[j] = v_rel.norm() + l * w_rel.norm();
  }
  for (int b = 0; b < nb; ++b) bm[b] = xd(b).norm() + l * W(b).norm();
  const double jmax = jm.empty() ? 0.0 : *std::max_element(jm.begin(), jm.end());
  const double bmax = *std::max_element(bm.begin(), bm.end());
  for (size_t j = 0; j < jm.size(); ++j)
    if (jm[j] > 1e-6 * jmax) joint_moves[j] = 1;
  for (int b = 0; b < nb; ++b)
    if (bm[b] > 1e-6 * bmax) body_moves[b] = 1;
}

// The refusal: names the joints that move in the motions without inertia and the bodies they
// move (eight of each at most)
[[noreturn]] void refuse_motion_without_inertia(const Model& m,
                                                const std::vector<char>& joint_moves,
                                                const std::vector<char>& body_moves) {
  std::string joints, bodies;
  int nj = 0, nbod = 0;
  for (size_t j = 0; j < joint_moves.size(); ++j)
    if (joint_moves[j] && nj++ < 8) joints += msg(nj > 1 ? ", '" : "'", m.joints[j].name, "'");
  if (nj > 8) joints += ", ...";
  for (int b = 0; b < m.nb; ++b)
    if (body_moves[b] && nbod++ < 8) {
      const Vec3 p = principal_moments(m, b).cwiseMax(0.0);
      bodies += msg(nbod > 1 ? ", '" : "'", m.bodies[b].name, "' (mass ", m.bodies[b].mass,
                    " kg, principal moments ", p[0], ", ", p[1], ", ", p[2], " kg m^2)");
    }
  if (nbod > 8) bodies += ", ...";
  throw ModelError(msg("finalize: the motion of joint", nj > 1 ? "s " : " ", joints,
                       " carries no inertia: it moves only ", nbod > 1 ? "bodies " : "body ",
                       bodies,
                       ", so the mass matrix is singular (give the body mass or inertia about "
                       "that motion, or make the joint fixed)"));
}

// A model with a massless body or a singular inertia (a point mass, a thin rod) is well posed
// when every motion its joints allow still carries inertia: Gamma positive definite on the null
// space of the joint rows' Jacobian zeta at the assembled state (on a tree of joint coordinates:
// the joint-space mass matrix positive definite). Velocities are scaled to one unit (angular
// ones by the length scale l), the null space is the orthonormal complement of zeta^T's range
// (column-pivoted QR at the rank analysis' threshold), and a motion carries no inertia when
// N^T Gamma N has an eigenvalue below 1e-10 of its largest whose eigenvector's inertia, summed
// body by body, is below 1e-14 of it: exact degeneracies sit at (eps lmax / gap)^2, genuine
// ones at the ratio of the motion's inertia to the heaviest body's.
// The message names the joints that move in such a motion and the bodies it moves.
void check_motions_carry_inertia(const Model& m, const VecX& u) {
  const int nb = m.nb, nv = m.nv;
  if (!has_weak_body(m)) return;  // every body has mass and a definite inertia: nothing to check
  const double l = m.length_scale;
  std::vector<BodyKin> kin;
  body_kinematics(m, u.data(), nullptr, kin);
  const MatX N = allowed_motions(m, kin);
  if (N.cols() == 0) return;  // nothing moves
  MatX GN(nv, N.cols());
  for (int b = 0; b < nb; ++b) {
    GN.middleRows<3>(6 * b) = m.bodies[b].mass * N.middleRows<3>(6 * b);
    GN.middleRows<3>(6 * b + 3) = (m.bodies[b].inertia / (l * l)) * N.middleRows<3>(6 * b + 3);
  }
  const MatX K = N.transpose() * GN;
  Eigen::SelfAdjointEigenSolver<MatX> es(0.5 * (K + K.transpose()));
  const VecX& lam = es.eigenvalues();
  const double lmax = std::max(lam.maxCoeff(), 0.0);
  if (lam[0] > 1e-10 * lmax) return;
  // the motions that carry no inertia: the joints they move and the bodies they move
  std::vector<char> joint_moves(m.joints.size(), 0), body_moves(nb, 0);
  bool degenerate = false;
  for (int k = 0; k < lam.size() && lam[k] <= 1e-10 * lmax; ++k) {
    const VecX v = N * es.eigenvectors().col(k);
    // the candidate's inertia, exact to round-off relative to itself (the eigenvalue is so only
    // relative to the largest): below 1e-14 of the largest the mass matrix is singular to
    // round-off (romeo's massless fingers: 1e-29; icub's neck, two point masses on nearly one
    // axis: 1.7e-16; a 1 g bead 0.1 mm off its axis on a 1000 kg arm, accepted: 2e-13)
    if (lmax > 0.0 && motion_inertia(m, v) > 1e-14 * lmax) continue;
    degenerate = true;
    mark_moving(m, kin, v, joint_moves, body_moves);
  }
  if (degenerate) refuse_motion_without_inertia(m, joint_moves, body_moves);
}

// A tree's joints in breadth-first order from ground (Model::tree_order): from each node, the
// joints that touch it in index order, through per-node lists (linear in the joints). False,
// with Model::joint_space_reason, when a joint points from child to parent.
bool order_tree_from_ground(Model& m) {
  auto node = [&](int b) { return b == kGround ? m.nb : b; };
  std::vector<std::vector<int>> touching(m.nb + 1);
  for (size_t ji = 0; ji < m.joints.size(); ++ji) {
    const Joint& j = m.joints[ji];
    touching[node(j.parent)].push_back(static_cast<int>(ji));
    touching[node(j.child)].push_back(static_cast<int>(ji));
  }
  std::deque<int> queue{m.nb};
  std::vector<char> used(m.joints.size(), 0);
  bool ok = true;
  while (!queue.empty()) {
    const int n = queue.front();
    queue.pop_front();
    for (const int ji : touching[n]) {
      if (used[ji]) continue;
      const Joint& j = m.joints[ji];
      const int p = node(j.parent), c = node(j.child);
      used[ji] = 1;
      if (p != n && ok) {
        ok = false;
        m.joint_space_reason = msg("joint '", j.name, "' points from child to parent");
      }
      queue.push_back(p == n ? c : p);
      m.tree_order.push_back(ji);
    }
  }
  return ok;
}

// Bounds on the model's scales: masses, squared lengths and inertias (a body's mass times the
// square of its distance from the world origin, or of a joint point's) at most 1e150, so that
// the products of two of them that the mass matrix, its factorisation and the energies form stay
// finite (sqrt of the largest double: 1.3e154, with room for sums over the bodies); a positive
// mass or inertia at least 1e-150, so that the same holds for their reciprocals (the Cartesian
// solver's, and the accelerations of a finite force)
constexpr double kMaxScale = 1e150;
constexpr double kMinScale = 1e-150;

// a number as messages quote it: four significant digits
std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

void refuse_scale(const std::string& who, const std::string& what, double value, const char* unit,
                  const std::string& from, bool small = false) {
  throw ModelError(msg("finalize: ", who, ": ", what, " = ", num(value), " ", unit, from,
                       small ? " is below " : " exceeds ", num(small ? kMinScale : kMaxScale),
                       ": the dynamics multiplies such quantities, which would overflow (express "
                       "the model in units that keep masses, lengths and inertias moderate",
                       small ? "; a massless body has mass 0)" : ")"));
}

// Every body's mass, inertia and position, and every joint point (at the build pose, with the
// larger mass of the bodies it joins), within kMaxScale, and a positive mass or inertia trace
// at least kMinScale; names the first element out of bounds and the quantity.
void check_model_scales(const Model& m) {
  auto mass_of = [&](int b) { return b == kGround ? 0.0 : m.bodies[b].mass; };
  for (const Body& b : m.bodies) {
    const std::string who = msg("body '", b.name, "'");
    const double r2 = b.position.squaredNorm();
    const double tr = b.inertia.trace();
    if (!(b.mass <= kMaxScale)) refuse_scale(who, "mass", b.mass, "kg", "");
    if (b.mass > 0.0 && b.mass < kMinScale) refuse_scale(who, "mass", b.mass, "kg", "", true);
    if (!(tr <= kMaxScale)) refuse_scale(who, "trace of the inertia", tr, "kg m^2", "");
    if (tr > 0.0 && tr < kMinScale)
      refuse_scale(who, "trace of the inertia", tr, "kg m^2", "", true);
    if (!(r2 <= kMaxScale))
      refuse_scale(who, "squared distance from the world origin", r2, "m^2",
                   msg(" (position ", num(b.position.norm()), " m)"));
    if (!(b.mass * r2 <= kMaxScale))
      refuse_scale(who, "inertia about the world origin, mass x distance^2", b.mass * r2, "kg m^2",
                   msg(" (", num(b.mass), " kg at ", num(std::sqrt(r2)), " m)"));
  }
  for (const Joint& j : m.joints) {
    const std::string who = msg("joint '", j.name, "'");
    for (const int side : {0, 1}) {
      const int b = side == 0 ? j.parent : j.child;
      const Vec3& local = side == 0 ? j.point_parent : j.point_child;
      const Vec3 p =
          b == kGround ? local
                       : Vec3(m.bodies[b].position + quat_to_rot(m.bodies[b].orientation) * local);
      const double r2 = p.squaredNorm(), mass = std::max(mass_of(j.parent), mass_of(j.child));
      if (!(r2 <= kMaxScale))
        refuse_scale(who, "squared distance of its point from the world origin", r2, "m^2",
                     msg(" (point ", num(p.norm()), " m from the origin)"));
      if (!(mass * r2 <= kMaxScale))
        refuse_scale(who, "mass x squared distance of its point from the world origin", mass * r2,
                     "kg m^2", msg(" (", num(mass), " kg, point ", num(std::sqrt(r2)), " m)"));
    }
  }
}

// The assembled state u0, v0 finite: else names the first non-finite entry and its body.
void check_assembled_state(const Model& m) {
  for (int i = 0; i < m.nq; ++i)
    if (!std::isfinite(m.u0[i]))
      throw ModelError(msg("finalize: the assembly produced a non-finite ",
                           i % 7 < 3 ? "position" : "orientation", " of body '",
                           m.bodies[i / 7].name, "' (u0[", i, "] = ", m.u0[i],
                           ") from finite data: the joints' points and the bodies' poses are too "
                           "far apart in scale to be assembled"));
  for (int i = 0; i < m.nv; ++i)
    if (!std::isfinite(m.v0[i]))
      throw ModelError(msg("finalize: the assembly produced a non-finite velocity of body '",
                           m.bodies[i / 6].name, "' (v0[", i, "] = ", m.v0[i], ")"));
}

// The stages of finalize_draft, in the order it calls them. Each reads what the earlier ones
// set on the model and throws ModelError naming the culprit.

// sizes and row numbers: ideal gear rows follow the joint rows; drives come last. No bodies is a
// zero-DOF model (a URDF structure fixed to ground): nq = nv = nc = 0
void number_rows(Model& m) {
  m.nb = static_cast<int>(m.bodies.size());
  m.nq = 7 * m.nb;
  m.nv = 6 * m.nb;
  for (GearConstraint& g : m.gear_constraints) g.row = m.nc_joint++;
  for (size_t k = 0; k < m.drives.size(); ++k) m.drives[k].row = m.nc_joint + static_cast<int>(k);
  m.nc = m.nc_joint + static_cast<int>(m.drives.size());
}

// connectivity: every body must reach ground through joints (node nb = ground)
void check_connected_to_ground(const Model& m) {
  std::vector<int> uf(m.nb + 1);
  std::iota(uf.begin(), uf.end(), 0);
  auto find = [&](int x) {
    while (uf[x] != x) x = uf[x] = uf[uf[x]];
    return x;
  };
  auto node = [&](int b) { return b == kGround ? m.nb : b; };
  for (const Joint& j : m.joints) uf[find(node(j.parent))] = find(node(j.child));
  std::vector<std::string> loose;
  for (int i = 0; i < m.nb; ++i)
    if (find(i) != find(m.nb)) loose.push_back(m.bodies[i].name);
  if (loose.empty()) return;
  std::string names;
  for (size_t k = 0; k < loose.size() && k < 8; ++k) names += (k ? ", '" : "'") + loose[k] + "'";
  if (loose.size() > 8) names += ", ...";
  throw ModelError(msg("finalize: bodies not connected to ground: ", names,
                       " (add a joint, or add_free for a free-floating body)"));
}

// A tree's joints without joint coordinates (spherical, universal, inline, distance, a free
// joint not from ground; a free joint from ground is a floating base: 7 entries of q, 6 of qd):
// false, with the first one's reason unless `ok` was false already.
bool joints_have_coordinates(Model& m, bool ok) {
  for (const Joint& j : m.joints) {
    if (j.type == JointType::Spherical || j.type == JointType::Universal ||
        (j.type == JointType::Free && j.parent != kGround) || j.type == JointType::Inline ||
        j.type == JointType::Distance) {
      if (ok)
        m.joint_space_reason =
            msg(joint_type_name(j.type), " joint '", j.name, "' has no joint coordinates");
      ok = false;
    }
  }
  return ok;
}

// A joint tree with ideal gears or couplings: an ideal gear has no joint-space path; couplings
// alone make a coupled joint space (Model::coupled_joint_space). Always false (the plain joint
// space is out), with the reason.
bool gears_leave_joint_space(Model& m) {
  const GearConstraint* gear = nullptr;
  for (const GearConstraint& g : m.gear_constraints)
    if (!g.coupling && !gear) gear = &g;
  if (gear) {
    m.joint_space_reason = msg("ideal gear '", gear->name, "' couples joint coordinates");
    return false;
  }
  const GearConstraint& g = m.gear_constraints[0];
  m.coupled_joint_space = true;
  m.joint_space_reason =
      msg("coupling '", g.name, "' makes joint '", m.joints[m.coords[g.coord_a].joint].name,
          "' follow joint '", m.joints[m.coords[g.coord_b].joint].name,
          "' (forward_dynamics, inverse_dynamics, mass_matrix and state_from_joints take "
          "the independent coordinates of a coupled model)");
  return false;
}

// topology: a tree has exactly nb joints; its joints ordered parent-before-child from ground
// (Model::tree_order); whether the joint-space path applies, and why not
void analyse_topology(Model& m) {
  m.is_tree = static_cast<int>(m.joints.size()) == m.nb;
  m.joint_space_ok = false;
  m.joint_tree = false;
  if (!m.is_tree) {
    m.joint_space_reason = "the model has closed loops";
    return;
  }
  bool ok = joints_have_coordinates(m, order_tree_from_ground(m));
  m.joint_tree = ok;
  if (ok && !m.gear_constraints.empty()) ok = gears_leave_joint_space(m);
  m.joint_space_ok = ok;
}

// the joint-space layout: the free joints' blocks first (7 entries of q, 6 of qd each), then
// the coordinates in Model::coords order
void lay_out_joint_space(Model& m) {
  m.n_free = 0;
  for (const Joint& j : m.joints)
    if (j.type == JointType::Free) ++m.n_free;
  int qi = 0, vi = 0;
  m.q_names.clear();
  m.dof_names.clear();
  m.dof_joint.clear();
  for (size_t ji = 0; ji < m.joints.size(); ++ji) {
    Joint& j = m.joints[ji];
    j.q0 = j.dof0 = -1;
    if (j.type != JointType::Free) continue;
    j.q0 = qi;
    j.dof0 = vi;
    qi += 7;
    vi += 6;
    for (const char* s : {":x", ":y", ":z", ":e0", ":e1", ":e2", ":e3"})
      m.q_names.push_back(j.name + s);
    for (const char* s : {":vx", ":vy", ":vz", ":wx", ":wy", ":wz"}) {
      m.dof_names.push_back(j.name + s);
      m.dof_joint.push_back(static_cast<int>(ji));
    }
  }
  for (Joint& j : m.joints)
    if (j.coord0 >= 0) {
      j.q0 = qi + j.coord0;
      j.dof0 = vi + j.coord0;
    }
  for (const Coord& c : m.coords) {
    m.q_names.push_back(c.name);
    m.dof_names.push_back(c.name);
    m.dof_joint.push_back(c.joint);
  }
  m.nq_joint = qi + static_cast<int>(m.coords.size());
  m.nv_joint = vi + static_cast<int>(m.coords.size());
}

// the independent coordinates: every coupling's follower expressed in its chain's leader
void resolve_independent_coords(Model& m) {
  IndependentCoords& ic = m.independent;
  const int nf = static_cast<int>(m.coords.size());
  std::vector<const GearConstraint*> follows(nf, nullptr);
  for (const GearConstraint& g : m.gear_constraints)
    if (g.coupling) follows[g.coord_a] = &g;
  ic = IndependentCoords();
  ic.lead_q = 7 * m.n_free;
  ic.lead_v = 6 * m.n_free;
  ic.source.assign(nf, -1);
  ic.scale.assign(nf, 1.0);
  ic.shift.assign(nf, 0.0);
  std::vector<int> index(nf, -1);
  for (int c = 0; c < nf; ++c) {
    if (follows[c]) continue;
    index[c] = ic.n++;
    ic.full.push_back(c);
  }
  for (int c = 0; c < nf; ++c) {
    double scale = 1.0, shift = 0.0;
    int k = c;
    // q_c = scale q_k + shift; q_k = multiplier q_leader + offset (chains; no cycles)
    for (int steps = 0; follows[k]; ++steps) {
      if (steps > nf) throw ModelError("finalize: the couplings form a cycle");
      const GearConstraint& g = *follows[k];
      shift += scale * g.offset;
      scale *= g.multiplier();
      k = g.coord_b;
    }
    ic.source[c] = index[k];
    ic.scale[c] = scale;
    ic.shift[c] = shift;
  }
}

// characteristic length for tolerances: the farthest joint point from its body's origin
void set_length_scale(Model& m) {
  double ls = 0.0;
  for (const Joint& j : m.joints) {
    if (j.parent != kGround) ls = std::max(ls, j.point_parent.norm());
    if (j.child != kGround) ls = std::max(ls, j.point_child.norm());
  }
  m.length_scale = std::max(ls, 1e-3);
}

// The state the assembly starts from: the bodies' build poses, at rest. A driven joint-space
// tree starts from the forward kinematics of the drives' initial values: Newton from the build
// pose could otherwise land on a flipped branch of the joint rows (a coupled tree: from its
// followers at their offsets, each q_f = multiplier q_l + offset)
void set_build_state(Model& m) {
  m.u0 = VecX(m.nq);
  for (int i = 0; i < m.nb; ++i) {
    m.u0.segment<3>(7 * i) = m.bodies[i].position;
    m.u0.segment<4>(7 * i + 3) = m.bodies[i].orientation;
  }
  m.v0 = VecX::Zero(m.nv);
  if (!(m.joint_space_ok && !m.drives.empty()) && !m.coupled_joint_space) return;
  VecX q, qd;
  joint_coordinates(m, m.u0, m.v0, q, qd);
  for (const Drive& d : m.drives) q[m.joints[d.joint].q0 + d.coord] = d.profile.eval(0.0).y;
  if (m.coupled_joint_space) {
    // each follower at its coupling's value (the coordinates follow the bases' blocks)
    const IndependentCoords& ic = m.independent;
    double* qc = q.data() + ic.lead_q;
    for (int k = 0; k < static_cast<int>(ic.source.size()); ++k)
      if (ic.full[ic.source[k]] != k) qc[k] = ic.scale[k] * qc[ic.full[ic.source[k]]] + ic.shift[k];
  }
  if (q.allFinite()) {
    VecX u, v;
    state_from_joints(m, q, VecX::Zero(m.nv_joint), u, v);
    m.u0 = u;
  }
}

// assembly: project the start state onto f(u, 0) = 0, then rest velocities onto zeta v = rhs;
// refused when it fails or lands on a flipped configuration of a joint
void assemble(Model& m, Metric metric) {
  Data d(m);
  try {
    project(m, d, 0.0, m.u0.data(), m.v0.data(), metric);
  } catch (const SolverError& err) {
    throw ModelError(
        msg("finalize: assembly failed (the joints cannot all be satisfied): ", err.what()));
  }
  load_kinematics(m, d, m.u0.data(), nullptr);
  const int bad = flipped_joint(m, d.kin);
  if (bad >= 0)
    throw ModelError(msg("finalize: assembly converged to a flipped configuration of joint '",
                         m.joints[bad].name,
                         "' (its child frame is turned half a revolution against the parent's); "
                         "give body poses closer to the joints' configuration"));
}

// The rows dependent at the assembled state, found by a column-pivoted QR of zeta^T.
// Rows whose pivot falls below 1e-6 of the largest are dependent: the threshold of the
// block-sparse factor of zeta zeta^T (1e-12 on the squared pivots) and of the KKT solver's
// pivoted path, so that axes or points that agree to 1e-6 (CAD round-off: two bearings of one
// shaft whose axes differ by 1e-9 rad) are taken as aligned rather than leaving the mechanism
// immobile. Those above round-off (1e-12) are named in a warning.
// The rows dependent only to round-off go to Model::aligned_rows as they are found.
struct RankAnalysis {
  Model& m;
  const ConstraintEval& ce;
  MatX z;                         // the dense zeta, made on first use
  std::vector<std::string> near;  // rows dependent only to round-off, by name
  double near_level = 0.0;

  RankAnalysis(Model& model, const ConstraintEval& rows) : m(model), ce(rows) {}

  // the rank of the first nrows rows; the dependent ones' names appended to *names, their
  // rows to *rows
  int rank(int nrows, std::vector<std::string>* names, std::vector<int>* rows = nullptr) {
    if (nrows == 0) return 0;
    if (z.size() == 0) z = dense_zeta(m, ce);
    Eigen::ColPivHouseholderQR<MatX> qr(z.topRows(nrows).transpose());
    qr.setThreshold(1e-6);
    const int r = static_cast<int>(qr.rank());
    const MatX& R = qr.matrixQR();
    const double r00 = std::abs(R(0, 0));
    for (int k = r; k < nrows; ++k) {
      const int row = qr.colsPermutation().indices()[k];
      const std::string name = m.row_name(row);
      if (names) names->push_back(name);
      if (rows) rows->push_back(row);
      const double level = k < R.rows() ? std::abs(R(k, k)) / r00 : 0.0;
      if (level > 1e-12 && std::find(near.begin(), near.end(), name) == near.end()) {
        near.push_back(name);
        m.aligned_rows.push_back(row);
        near_level = std::max(near_level, level);
      }
    }
    return r;
  }
};

// fast path of the rank analysis: when the block-sparse Cholesky of zeta zeta^T succeeds on all
// rows, every row is independent (its pivots pass the same relative test the solver uses) and
// the dense QR -- cubic in the rows -- is not needed
bool rows_independent_by_sparse_factor(const Model& m, const ConstraintEval& ce) {
  if (m.nc == 0 || m.force_dense_kkt || kkt_plans(m).all.path == KktPath::Dense) return false;
  BlockSparseSchur sp(m, kkt_plans(m).all);
  return sp.factor(ce, nullptr);
}

// rank analysis at the assembled configuration: mobility and redundant rows by name, and a
// warning naming the rows dependent only to round-off
void analyse_rank(Model& m) {
  std::vector<BodyKin> kin;
  body_kinematics(m, m.u0.data(), nullptr, kin);
  ConstraintEval ce;
  ce.init(m);
  eval_constraints(m, kin, 0.0, false, ce);
  RankAnalysis ra(m, ce);
  std::vector<std::string> all;  // the rows dependent among all rows, by name and row
  std::vector<int> all_rows;
  if (rows_independent_by_sparse_factor(m, ce)) {
    m.rank_joint = m.nc_joint;
    m.rank_all = m.nc;
  } else {
    m.rank_joint = ra.rank(m.nc_joint, &m.redundant_rows);
    m.rank_all = ra.rank(m.nc, &all, &all_rows);
  }
  // and the drives among them (the rows from nc_joint on) that the joint rows left independent
  for (size_t k = 0; k < all.size(); ++k)
    if (std::find(m.redundant_rows.begin(), m.redundant_rows.end(), all[k]) ==
            m.redundant_rows.end() &&
        all_rows[k] >= m.nc_joint)
      m.redundant_rows.push_back(all[k]);
  if (!ra.near.empty()) {
    std::string rows;
    for (const auto& n : ra.near) rows += (rows.empty() ? "" : "; ") + n;
    m.warnings.push_back(
        msg("finalize: constraint rows dependent only to ", ra.near_level,
            " (relative; axes or points aligned to round-off, not exactly) are treated as "
            "dependent: ",
            rows));
  }
  m.mobility = m.nv - m.rank_joint;
  m.mobility_driven = m.nv - m.rank_all;
  m.redundant = m.rank_joint < m.nc_joint || m.rank_all < m.nc;
}

// A model with redundant rows takes the dense pivoted factorisation (minimum-norm multipliers)
// throughout (KktSolver and kkt_path() read m.redundant): its assembly is projected again on it
void reassemble_if_redundant(Model& m, Metric metric) {
  if (!m.redundant) return;
  Data d(m);
  project(m, d, 0.0, m.u0.data(), m.v0.data(), metric);
}

// A tree's joint coordinates at a spread-out configuration (each 0.6 sin(phase (index + 1)),
// the free joints at the identity) as a state u
VecX spread_configuration(const Model& m, double phase) {
  VecX q = VecX::Zero(m.nq_joint), u, v;
  for (const Joint& j : m.joints) {
    if (j.type == JointType::Free) {
      q[j.q0 + 3] = 1.0;
      continue;
    }
    for (int k = 0; k < joint_coords(j.type); ++k)
      q[j.q0 + k] = 0.6 * std::sin(phase * (j.q0 + k + 1));
  }
  state_from_joints(m, q, VecX::Zero(m.nv_joint), u, v);
  return u;
}

// check_motions_carry_inertia at the assembled state. Singular there only (two joint axes
// aligned there, as icub's neck at q = 0) or everywhere (a massless leaf)? A tree is tried at
// two more configurations; well posed at either, the model is accepted with a warning
void check_inertia_of_motions(Model& m) {
  try {
    check_motions_carry_inertia(m, m.u0);
  } catch (const ModelError& at_assembly) {
    if (!m.joint_space_ok) throw;
    bool somewhere = false;
    for (const double phase : {0.37, 1.91}) {
      const VecX u = spread_configuration(m, phase);
      try {
        check_motions_carry_inertia(m, u);
        somewhere = true;
        break;
      } catch (const ModelError&) {
      }
    }
    if (!somewhere) throw;
    m.warnings.push_back(msg(at_assembly.what(),
                             " -- at the assembled configuration only: elsewhere every motion "
                             "carries inertia, but near that configuration the mass matrix is "
                             "singular and forward dynamics ill-conditioned"));
  }
}

}  // namespace

namespace detail {

std::shared_ptr<Model> finalize_draft(const Model& draft, const FinalizeOptions& options) {
  auto mp = std::make_shared<Model>(draft);
  Model& m = *mp;
  number_rows(m);
  check_connected_to_ground(m);
  analyse_topology(m);
  lay_out_joint_space(m);
  resolve_independent_coords(m);
  set_length_scale(m);
  m.finalize_options = options;
  check_model_scales(m);
  const Metric metric = options.mass_weighted_assembly ? Metric::Mass : Metric::Identity;
  set_build_state(m);
  assemble(m, metric);
  check_assembled_state(m);
  analyse_rank(m);
  reassemble_if_redundant(m, metric);
  check_inertia_of_motions(m);
  choose_loop_coordinates(m);
  return mp;
}

}  // namespace detail

ModelPtr ModelBuilder::finalize(const FinalizeOptions& options) const {
  return detail::finalize_draft(m_, options);
}

}  // namespace armdyn
