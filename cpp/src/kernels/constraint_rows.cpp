// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/kernels/constraint_rows.hpp"

#include <algorithm>
#include <cmath>

#include "armdyn/math/angles.hpp"

namespace armdyn {

namespace {

// write one scalar constraint row into block row r (all 12 columns; rhs stays 0 from init)
inline void put_row(ConstraintEval& ce, ConstraintBlock& b, int r, const ScalarJet& s,
                    bool with_xi) {
  ce.f[b.row0 + r] = s.val;
  b.J.row(r).head<12>() = s.J;
  if (with_xi) ce.xi[b.row0 + r] = s.bias;
}

// block row r: p . q for p fixed in the parent (rotation Ra) and q fixed in the child (Rb),
// written in place: d/dt (p . q) = omega_a . Ra^T (p x q) - omega_b . Rb^T (p x q), bias
// p'' . q + 2 p' . q' + p . q''; its translational columns are zero from init and stay so
inline void put_axes_row(ConstraintEval& ce, ConstraintBlock& b, int r, const AxisJet& p,
                         const AxisJet& q, const Mat3& Ra, const Mat3& Rb, bool with_xi) {
  ce.f[b.row0 + r] = p.val.dot(q.val);
  const Eigen::Matrix<double, 1, 3> c = p.val.cross(q.val).transpose();
  auto row = b.J.row(r);
  row.segment<3>(3).noalias() = c * Ra;
  row.segment<3>(9).noalias() = -c * Rb;
  if (with_xi) ce.xi[b.row0 + r] = p.bias.dot(q.val) + 2.0 * p.rate.dot(q.rate) + p.val.dot(q.bias);
}

// the three rows x_b + R_b s_b - x_a - R_a s_a = 0 (coincident joint points) in block rows 0..2:
// Jacobian [-I, skew(r_a) R_a | I, -skew(r_b) R_b] with the world levers r = R s (the constant
// -I and I written once by init)
inline void put_point_rows(ConstraintEval& ce, ConstraintBlock& b, const BodyKin& ka,
                           const BodyKin& kb, const SepJet& d, bool with_xi) {
  for (int c = 0; c < 3; ++c) {
    const Vec3 ma = d.ra.cross(ka.R.col(c)), mb = kb.R.col(c).cross(d.rb);
    for (int k = 0; k < 3; ++k) {
      b.J(k, 3 + c) = ma[k];
      b.J(k, 9 + c) = mb[k];
    }
  }
  ce.f.segment<3>(b.row0) = d.val;
  if (with_xi) ce.xi.segment<3>(b.row0) = d.bias;
}

}  // namespace

void ConstraintEval::init(const Model& m) {
  f = VecX::Zero(m.nc);
  rhs = VecX::Zero(m.nc);
  xi = VecX::Zero(m.nc);
  blocks.clear();
  body_blocks.assign(m.nb, {});
  auto add_block_n = [&](int row0, int nrows, const std::vector<int>& bodies) {
    ConstraintBlock b;
    b.row0 = row0;
    b.nrows = nrows;
    b.nbody = static_cast<int>(bodies.size());
    for (int k = 0; k < b.nbody; ++k) b.body[k] = bodies[k];
    b.J = BlockMat::Zero(nrows, 6 * kMaxBlockBodies);
    const int idx = static_cast<int>(blocks.size());
    blocks.push_back(b);
    for (int k = 0; k < b.nbody; ++k)
      if (bodies[k] != kGround) body_blocks[bodies[k]].push_back({idx, k});
  };
  auto add_block = [&](int row0, int nrows, int pa, int pb) { add_block_n(row0, nrows, {pa, pb}); };
  for (const Joint& j : m.joints) {
    const int r = joint_rows(j.type);
    if (r == 0) continue;
    add_block(j.row0, r, j.parent, j.child);
    ConstraintBlock& b = blocks.back();
    b.point_rows = j.type == JointType::Spherical || j.type == JointType::Revolute ||
                   j.type == JointType::Universal || j.type == JointType::Fixed;
    // the point rows' constant translational columns (eval_constraints writes the rest)
    if (b.point_rows)
      for (int k = 0; k < 3; ++k) {
        b.J(k, k) = -1.0;
        b.J(k, 6 + k) = 1.0;
      }
  }
  for (const GearConstraint& g : m.gear_constraints) add_block_n(g.row, 1, gear_bodies(m, g));
  for (const Drive& d : m.drives) {
    const Joint& j = m.joints[d.joint];
    add_block(d.row, 1, j.parent, j.child);
  }
}

std::vector<int> gear_bodies(const Model& m, const GearConstraint& g) {
  std::vector<int> bodies;
  for (int c : {g.coord_a, g.coord_b}) {
    const Joint& j = m.joints[m.coords[c].joint];
    for (int b : {j.parent, j.child})
      if (b != kGround && std::find(bodies.begin(), bodies.end(), b) == bodies.end())
        bodies.push_back(b);
  }
  return bodies;
}

namespace {

// The rows of joint j into its block b (kinematics ka of the parent, kb of the child): the
// coincident points of a spherical, revolute, universal or fixed joint, then the axis rows of
// its type
inline void eval_joint_rows(const Joint& j, const BodyKin& ka, const BodyKin& kb, bool with_xi,
                            ConstraintEval& ce, ConstraintBlock& b) {
  // separation of the joint points, and the joint frames' axes in world
  auto sep = [&] { return sep_jet(ka, j.point_parent, kb, j.point_child); };
  auto pa = [&](int k) { return axis_jet(ka, j.frame_parent.col(k)); };
  auto pb = [&](int k) { return axis_jet(kb, j.frame_child.col(k)); };
  // a parent axis dotted with a child axis, or with the separation
  // the child's joint point on the parent's joint axis line: no separation along the
  // parent's x and y axes (2 rows from row r)
  auto on_axis_rows = [&](int r) {
    const SepJet d = sep();
    put_row(ce, b, r, dot_axis_sep(pa(0), ka.R, d, kb.R), with_xi);
    put_row(ce, b, r + 1, dot_axis_sep(pa(1), ka.R, d, kb.R), with_xi);
    return r + 2;
  };
  int r = 0;
  switch (j.type) {
    case JointType::Spherical:
    case JointType::Revolute:
    case JointType::Universal:
    case JointType::Fixed:
      // coincident joint points: 3 rows
      put_point_rows(ce, b, ka, kb, sep(), with_xi);
      r = 3;
      break;
    default:
      break;
  }
  switch (j.type) {
    case JointType::Revolute:
    case JointType::Cylindrical: {
      // child x and y axes perpendicular to the parent's z axis
      const AxisJet za = pa(2);
      put_axes_row(ce, b, r++, za, pb(0), ka.R, kb.R, with_xi);
      put_axes_row(ce, b, r++, za, pb(1), ka.R, kb.R, with_xi);
      if (j.type == JointType::Cylindrical) r = on_axis_rows(r);
      break;
    }
    case JointType::Universal:
      put_axes_row(ce, b, r++, pa(2), pb(2), ka.R, kb.R, with_xi);
      break;
    case JointType::Fixed:
    case JointType::Prismatic: {
      // relative rotation locked: z_a.x_b = z_a.y_b = x_a.y_b = 0
      const AxisJet za = pa(2), yb = pb(1);
      put_axes_row(ce, b, r++, za, pb(0), ka.R, kb.R, with_xi);
      put_axes_row(ce, b, r++, za, yb, ka.R, kb.R, with_xi);
      put_axes_row(ce, b, r++, pa(0), yb, ka.R, kb.R, with_xi);
      if (j.type == JointType::Prismatic) r = on_axis_rows(r);  // sliding along z_a only
      break;
    }
    case JointType::Distance: {
      // (|d|^2 - L^2) / (2 L): zero on the sphere, gradient the unit direction there
      const VecJet d =
          difference(point_jet(kb, j.point_child, 1), point_jet(ka, j.point_parent, 0));
      ScalarJet s = dot(d, d);
      const double k = 0.5 / j.length;
      s.val = k * (s.val - j.length * j.length);
      s.rate *= k;
      s.J *= k;
      s.bias *= k;
      put_row(ce, b, r++, s, with_xi);
      break;
    }
    case JointType::Inline:
      r = on_axis_rows(r);
      break;
    default:
      break;
  }
}

// An ideal gear's or coupling's row r_a q_a + r_b q_b = offset (multi-turn angles), over up to
// four bodies, into its block b
inline void eval_gear_row(const Model& m, const std::vector<BodyKin>& kin, const GearConstraint& g,
                          bool with_xi, ConstraintEval& ce, ConstraintBlock& b) {
  double f = -g.offset, xi = 0.0;
  b.J.setZero();
  const bool angular = m.coords[g.coord_a].angular;
  for (int k = 0; k < 2; ++k) {
    const int c = k == 0 ? g.coord_a : g.coord_b;
    const double r = k == 0 ? g.r_a : g.r_b;
    const ScalarJet& q = ce.coord_cache ? ce.coord_cache->get(m, kin, c) : coord_jet(m, kin, c);
    // per coordinate: an actuator's revolute rotor may follow a prismatic joint
    const bool ang_c = m.coords[c].angular;
    const double ref = ce.track_ref && ang_c ? (*ce.track_ref)[c] : 0.0;
    f += r * (ang_c ? ref + wrap_angle(q.val - ref) : q.val);
    xi += r * q.bias;
    const Joint& j = m.joints[m.coords[c].joint];
    const int ends[2] = {j.parent, j.child};
    for (int e = 0; e < 2; ++e) {
      if (ends[e] == kGround) continue;
      int slot = 0;
      while (b.body[slot] != ends[e]) ++slot;
      b.J.block<1, 6>(0, 6 * slot) += r * q.J.segment<6>(6 * e);
    }
  }
  // a revolute follower's pose gives its angle only modulo a turn (r_a = 1): the row is
  // the follower's angle error, wrapped
  ce.f[b.row0] = g.coupling && angular ? wrap_angle(f) : f;
  ce.rhs[b.row0] = 0.0;
  if (with_xi) ce.xi[b.row0] = xi;
}

// Drive di's row q_c(u) - q_ref(t) = 0 into its block b; zeta v = q_ref', xi = bias - q_ref''
inline void eval_drive_row(const Model& m, const std::vector<BodyKin>& kin, size_t di, double t,
                           bool with_xi, ConstraintEval& ce, ConstraintBlock& b) {
  const Drive& dr = m.drives[di];
  const ScalarJet q = coord_jet(m, kin, m.joints[dr.joint].coord0 + dr.coord, ce.drive_values);
  ProfileValue p;
  if (ce.drive_ref) {
    p.y = ce.drive_ref[3 * di];
    p.yd = ce.drive_ref[3 * di + 1];
    p.ydd = ce.drive_ref[3 * di + 2];
  } else {
    p = dr.profile.eval(t);
  }
  const bool angular = m.coords[m.joints[dr.joint].coord0 + dr.coord].angular;
  if (!ce.drive_values)
    ce.f[b.row0] = 0.0;
  else
    ce.f[b.row0] = angular ? wrap_angle(q.val - p.y) : q.val - p.y;
  ce.rhs[b.row0] = p.yd;
  b.J.row(0).head<12>() = q.J;
  if (with_xi) ce.xi[b.row0] = q.bias - p.ydd;
}

}  // namespace

// The rows in block order: the joints', the ideal gears' and couplings', the drives'
void eval_constraints(const Model& m, const std::vector<BodyKin>& kin, double t, bool with_xi,
                      ConstraintEval& ce) {
  int bi = 0;
  for (const Joint& j : m.joints) {
    if (joint_rows(j.type) == 0) continue;
    eval_joint_rows(j, kin_of(kin, j.parent), kin_of(kin, j.child), with_xi, ce, ce.blocks[bi++]);
  }
  for (const GearConstraint& g : m.gear_constraints)
    eval_gear_row(m, kin, g, with_xi, ce, ce.blocks[bi++]);
  for (size_t di = 0; di < m.drives.size(); ++di)
    eval_drive_row(m, kin, di, t, with_xi, ce, ce.blocks[bi++]);
}

namespace {
// the rows of slot s of a block (R rows at compile time, 0: at run time), row-major, rows
// 6 kMaxBlockBodies apart
template <int R>
using SlotMap = Eigen::Map<
    const Eigen::Matrix<double, R == 0 ? Eigen::Dynamic : R, 6, Eigen::RowMajor, R == 0 ? 6 : R, 6>,
    0, Eigen::OuterStride<6 * kMaxBlockBodies>>;

template <int R>
inline void block_times(const ConstraintBlock& b, const double* x, double* y) {
  const int n = R > 0 ? R : b.nrows;
  Eigen::Map<Eigen::Matrix<double, R == 0 ? Eigen::Dynamic : R, 1, 0, R == 0 ? 6 : R, 1>> yb(y, n);
  yb.setZero();
  for (int s = 0; s < b.nbody; ++s)
    if (b.body[s] != kGround)
      yb.noalias() +=
          SlotMap<R>(b.J.data() + 6 * s, n, 6) * Eigen::Map<const Vec6>(x + 6 * b.body[s]);
}

template <int R>
inline void block_transpose_times(const ConstraintBlock& b, const double* y, double* x) {
  const int n = R > 0 ? R : b.nrows;
  Eigen::Map<const Eigen::Matrix<double, R == 0 ? Eigen::Dynamic : R, 1, 0, R == 0 ? 6 : R, 1>> yb(
      y, n);
  for (int s = 0; s < b.nbody; ++s)
    if (b.body[s] != kGround)
      Eigen::Map<Vec6>(x + 6 * b.body[s]).noalias() +=
          SlotMap<R>(b.J.data() + 6 * s, n, 6).transpose() * yb;
}
}  // namespace

void zeta_times(const ConstraintEval& ce, int nrows, Eigen::Ref<const VecX> x, VecX& y) {
  // fixed-size kernels for the row counts of the common blocks (revolute and prismatic joints,
  // gears and drives)
  for (const ConstraintBlock& b : ce.blocks) {
    if (b.row0 >= nrows) continue;
    double* yb = y.data() + b.row0;
    if (b.nrows == 5)
      block_times<5>(b, x.data(), yb);
    else if (b.nrows == 1)
      block_times<1>(b, x.data(), yb);
    else
      block_times<0>(b, x.data(), yb);
  }
}

void zeta_transpose_times(const ConstraintEval& ce, int nrows, Eigen::Ref<const VecX> y, VecX& x) {
  x.setZero();
  for (const ConstraintBlock& b : ce.blocks) {
    if (b.row0 >= nrows) continue;
    const double* yb = y.data() + b.row0;
    if (b.nrows == 5)
      block_transpose_times<5>(b, yb, x.data());
    else if (b.nrows == 1)
      block_transpose_times<1>(b, yb, x.data());
    else
      block_transpose_times<0>(b, yb, x.data());
  }
}

int flipped_joint(const Model& m, const std::vector<BodyKin>& kin) {
  for (int ji = 0; ji < static_cast<int>(m.joints.size()); ++ji) {
    const Joint& j = m.joints[ji];
    int first = 2, last = 2;  // revolute, cylindrical: the joint axes
    if (j.type == JointType::Prismatic || j.type == JointType::Fixed)
      first = 0;  // all three axes
    else if (j.type != JointType::Revolute && j.type != JointType::Cylindrical)
      continue;
    const Mat3 A = kin_of(kin, j.parent).R * j.frame_parent;
    const Mat3 B = kin_of(kin, j.child).R * j.frame_child;
    for (int k = first; k <= last; ++k)
      if (!(A.col(k).dot(B.col(k)) > 0.0)) return ji;
  }
  return -1;
}

MatX dense_zeta(const Model& m, const ConstraintEval& ce) {
  MatX z = MatX::Zero(m.nc, m.nv);
  for (const ConstraintBlock& b : ce.blocks)
    for (int s = 0; s < b.nbody; ++s)
      if (b.body[s] != kGround)
        z.block(b.row0, 6 * b.body[s], b.nrows, 6) = b.J.middleCols<6>(6 * s);
  return z;
}

}  // namespace armdyn
