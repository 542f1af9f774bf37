// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/builder/builder.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "armdyn/errors.hpp"
#include "armdyn/math/quaternion.hpp"

namespace armdyn {

namespace {

template <typename Derived>
void require_finite(const Eigen::MatrixBase<Derived>& x, const std::string& what) {
  if (!x.allFinite()) throw ModelError(msg(what, " contains NaN or inf"));
}

void require_finite(double x, const std::string& what) {
  if (!std::isfinite(x)) throw ModelError(msg(what, " must be finite, got ", x));
}

Vec3 unit_axis(const Vec3& a, const std::string& what) {
  require_finite(a, what);
  const double n = a.norm();
  if (!(n > 1e-12)) throw ModelError(msg(what, " has zero length"));
  return a / n;
}

// a position and a unit quaternion [e0, e1, e2, e3] (scalar first), checked for `who`
void require_pose(const std::string& who, const Vec3& position, const Vec4& orientation) {
  require_finite(position, who + ": position");
  require_finite(orientation, who + ": orientation");
  if (std::abs(orientation.norm() - 1.0) > 1e-6)
    throw ModelError(msg(who,
                         ": orientation must be a unit quaternion [e0, e1, e2, e3] "
                         "(scalar first), got norm ",
                         orientation.norm()));
}

const char* inertia_problem_words(InertiaProblem kind) {
  switch (kind) {
    case InertiaProblem::NotPositiveSemidefinite:
      return "is not positive semidefinite";
    case InertiaProblem::TriangleInequality:
      return "violates the triangle inequality";
    case InertiaProblem::None:
      break;
  }
  return "";
}

}  // namespace

InertiaCheck check_inertia(const Mat3& inertia, bool physical, double scale) {
  InertiaCheck c;
  c.tensor = inertia;
  Eigen::SelfAdjointEigenSolver<Mat3> es(inertia);
  const Vec3 p = es.eigenvalues();  // ascending
  c.moments = p;
  c.smallest = p[0];
  if (physical) {
    // positive semidefinite: zero moments are point masses (and thin rods), which every path
    // simulates while the joint-space mass matrix stays positive definite (finalize checks)
    const double scale = inertia.cwiseAbs().maxCoeff();
    if (!(p[0] >= -1e-12 * std::max(scale, 1e-300)))
      c.kind = InertiaProblem::NotPositiveSemidefinite;
    else if (p[0] + p[1] < p[2] * (1.0 - 1e-9))
      c.kind = InertiaProblem::TriangleInequality;
    c.problem = inertia_problem_words(c.kind);
    return c;
  }
  // any positive semidefinite tensor; negatives down to -1e-12 of the largest moment are
  // round-off, clamped to zero (a warning unless they are the round-off of a rotation)
  const double largest = std::max(p[2], 0.0);
  if (!(p[0] >= -1e-12 * std::max(largest, scale))) {
    c.kind = InertiaProblem::NotPositiveSemidefinite;
    c.problem = inertia_problem_words(c.kind);
    return c;
  }
  if (p[0] < 0.0) {
    c.clamped = true;
    c.warn = !(p[0] >= -64.0 * std::numeric_limits<double>::epsilon() * largest);
    const Vec3 q = p.cwiseMax(0.0);
    c.moments = q;
    const Mat3 t = es.eigenvectors() * q.asDiagonal() * es.eigenvectors().transpose();
    c.tensor = 0.5 * (t + t.transpose());
  }
  return c;
}

ModelBuilder::ModelBuilder(const Vec3& gravity, bool physical_inertia)
    : physical_inertia_(physical_inertia) {
  require_finite(gravity, "gravity");
  m_.gravity = gravity;
}

ModelBuilder::ModelBuilder(Model draft, bool physical_inertia)
    : m_(std::move(draft)), physical_inertia_(physical_inertia) {}

int ModelBuilder::add_body(const std::string& name, double mass, const Mat3& inertia,
                           const Vec3& position, const Vec4& orientation) {
  const std::string who = msg("body '", name, "'");
  if (name.empty()) throw ModelError("body name must not be empty");
  if (name == "ground") throw ModelError("body name 'ground' is reserved");
  if (m_.body_index.count(name)) throw ModelError(msg(who, ": duplicate body name"));
  require_finite(mass, who + ": mass");
  // mass 0: a massless link between joints (finalize checks the mass matrix stays definite)
  if (!(mass >= 0.0)) throw ModelError(msg(who, ": mass must not be negative, got ", mass));
  require_finite(inertia, who + ": inertia");
  const double scale = inertia.cwiseAbs().maxCoeff();
  if ((inertia - inertia.transpose()).cwiseAbs().maxCoeff() > 1e-9 * std::max(scale, 1e-300))
    throw ModelError(msg(who, ": inertia is not symmetric"));
  const InertiaCheck ic = check_inertia(0.5 * (inertia + inertia.transpose()), physical_inertia_);
  const Vec3& p = ic.moments;
  if (!ic.problem.empty()) {
    if (ic.kind == InertiaProblem::TriangleInequality)
      throw ModelError(msg(who, ": inertia violates the triangle inequality (principal moments ",
                           p[0], " + ", p[1], " < ", p[2],
                           "); physical_inertia=False accepts any positive semidefinite tensor"));
    throw ModelError(msg(who, ": inertia ", ic.problem, " (principal moments ", p[0], ", ", p[1],
                         ", ", p[2], ")"));
  }
  require_pose(who, position, orientation);
  Body b;
  b.name = name;
  b.mass = mass;
  b.inertia = ic.tensor;
  b.position = position;
  b.orientation = orientation.normalized();
  const int idx = static_cast<int>(m_.bodies.size());
  m_.bodies.push_back(b);
  m_.body_index[name] = idx;
  if (ic.warn)
    m_.warnings.push_back(msg(who, ": negative principal moment ", ic.smallest,
                              " kg m^2 (round-off) clamped to zero"));
  return idx;
}

int ModelBuilder::resolve_body(const std::string& name, const std::string& context) const {
  if (name == "ground") return kGround;
  auto it = m_.body_index.find(name);
  if (it == m_.body_index.end()) throw ModelError(msg(context, ": unknown body '", name, "'"));
  return it->second;
}

int ModelBuilder::add_joint(const std::string& name, JointType type, const std::string& parent,
                            const std::string& child, const Vec3& point, const Vec3& axis,
                            const Vec3* axis2, const Vec3* point_child) {
  const std::string who = msg(joint_type_name(type), " joint '", name, "'");
  if (name.empty()) throw ModelError(msg(joint_type_name(type), " joint: name must not be empty"));
  if (m_.joint_index.count(name)) throw ModelError(msg(who, ": duplicate joint name"));
  const int pa = resolve_body(parent, who);
  const int ch = resolve_body(child, who);
  if (pa == ch) throw ModelError(msg(who, ": links body '", parent, "' to itself"));
  require_finite(point, who + ": point");
  Mat3 fw_parent = Mat3::Identity(), fw_child = Mat3::Identity();
  if (type == JointType::Revolute || type == JointType::Prismatic ||
      type == JointType::Cylindrical || type == JointType::Inline) {
    fw_parent = fw_child = frame_from_z(unit_axis(axis, who + ": axis"));
  } else if (type == JointType::Free && ch != kGround) {
    // a floating base's frame: the child body's axes (at `point`)
    fw_parent = fw_child = quat_to_rot(m_.bodies[ch].orientation);
  } else if (type == JointType::Universal) {
    const Vec3 a1 = unit_axis(axis, who + ": axis1");
    const Vec3 a2 = unit_axis(*axis2, who + ": axis2");
    if (std::abs(a1.dot(a2)) > 1e-6)
      throw ModelError(
          msg(who, ": axis1 and axis2 must be perpendicular (dot = ", a1.dot(a2), ")"));
    fw_parent = frame_from_z(a1);
    fw_child = frame_from_z(a2);
  }
  Joint j;
  j.name = name;
  j.type = type;
  j.parent = pa;
  j.child = ch;
  // joint point and frame in each body's frame at the assembly pose
  // (the child's point is `point` too, except for joints between two points: distance)
  auto local = [&](int b, const Vec3& p, const Mat3& fw, Vec3& s, Mat3& f) {
    if (b == kGround) {
      s = p;
      f = fw;
    } else {
      const Body& bd = m_.bodies[b];
      const Mat3 R = quat_to_rot(bd.orientation);
      s = R.transpose() * (p - bd.position);
      f = R.transpose() * fw;
    }
  };
  local(pa, point, fw_parent, j.point_parent, j.frame_parent);
  local(ch, point_child ? *point_child : point, fw_child, j.point_child, j.frame_child);
  j.row0 = m_.nc_joint;
  const int nq = joint_coords(type);
  j.coord0 = nq ? static_cast<int>(m_.coords.size()) : -1;
  const int idx = static_cast<int>(m_.joints.size());
  // commit
  for (int k = 0; k < nq; ++k) {
    Coord c;
    c.joint = idx;
    c.sub = k;
    c.angular = (type != JointType::Prismatic) && k == 0;
    c.name = nq == 1 ? name : name + (k == 0 ? ":angle" : ":displacement");
    m_.coords.push_back(c);
  }
  m_.nc_joint += joint_rows(type);
  m_.joints.push_back(j);
  m_.joint_index[name] = idx;
  return idx;
}

int ModelBuilder::add_frame(const std::string& name, const std::string& body, const Vec3& position,
                            const Vec4& orientation) {
  const std::string who = msg("frame '", name, "'");
  if (name.empty()) throw ModelError("frame name must not be empty");
  if (m_.frame_index.count(name)) throw ModelError(msg(who, ": duplicate frame name"));
  const int b = resolve_body(body, who);
  require_pose(who, position, orientation);
  NamedFrame f;
  f.name = name;
  f.body = b;
  const Mat3 Rf = quat_to_rot(orientation.normalized());
  if (b == kGround) {
    f.point = position;
    f.rotation = Rf;
  } else {
    // relative to the body's assembly pose, as the joint points and frames (add_joint)
    const Body& bd = m_.bodies[b];
    const Mat3 R = quat_to_rot(bd.orientation);
    f.point = R.transpose() * (position - bd.position);
    f.rotation = R.transpose() * Rf;
  }
  const int idx = static_cast<int>(m_.frames.size());
  m_.frames.push_back(f);
  m_.frame_index[name] = idx;
  return idx;
}

int ModelBuilder::add_revolute(const std::string& name, const std::string& parent,
                               const std::string& child, const Vec3& point, const Vec3& axis) {
  return add_joint(name, JointType::Revolute, parent, child, point, axis, nullptr);
}
int ModelBuilder::add_prismatic(const std::string& name, const std::string& parent,
                                const std::string& child, const Vec3& point, const Vec3& axis) {
  return add_joint(name, JointType::Prismatic, parent, child, point, axis, nullptr);
}
int ModelBuilder::add_cylindrical(const std::string& name, const std::string& parent,
                                  const std::string& child, const Vec3& point, const Vec3& axis) {
  return add_joint(name, JointType::Cylindrical, parent, child, point, axis, nullptr);
}
int ModelBuilder::add_spherical(const std::string& name, const std::string& parent,
                                const std::string& child, const Vec3& point) {
  return add_joint(name, JointType::Spherical, parent, child, point, Vec3::UnitZ(), nullptr);
}
int ModelBuilder::add_fixed(const std::string& name, const std::string& parent,
                            const std::string& child, const Vec3& point) {
  return add_joint(name, JointType::Fixed, parent, child, point, Vec3::UnitZ(), nullptr);
}
int ModelBuilder::add_fixed(const std::string& name, const std::string& parent,
                            const std::string& child, const Vec3* point) {
  if (point) return add_fixed(name, parent, child, *point);
  const int c = m_.find_body(child);
  return add_fixed(name, parent, child, c == kGround ? Vec3::Zero() : m_.bodies[c].position);
}
int ModelBuilder::add_universal(const std::string& name, const std::string& parent,
                                const std::string& child, const Vec3& point, const Vec3& axis1,
                                const Vec3& axis2) {
  return add_joint(name, JointType::Universal, parent, child, point, axis1, &axis2);
}
int ModelBuilder::add_inline(const std::string& name, const std::string& parent,
                             const std::string& child, const Vec3& point, const Vec3& axis) {
  return add_joint(name, JointType::Inline, parent, child, point, axis, nullptr);
}
int ModelBuilder::add_distance(const std::string& name, const std::string& body_a,
                               const Vec3& point_a, const std::string& body_b,
                               const Vec3& point_b) {
  const std::string who = msg("distance joint '", name, "'");
  require_finite(point_a, who + ": point_a");
  require_finite(point_b, who + ": point_b");
  const double len = (point_b - point_a).norm();
  if (!(len > 1e-9))
    throw ModelError(msg(who, ": the points coincide (length ", len,
                         " m); use a spherical joint for a zero-length link"));
  const int idx = add_joint(name, JointType::Distance, body_a, body_b, point_a, Vec3::UnitZ(),
                            nullptr, &point_b);
  m_.joints[idx].length = len;
  return idx;
}
int ModelBuilder::add_free(const std::string& name, const std::string& child, const Vec3* origin) {
  const int c = resolve_body(child, msg("free joint '", name, "'"));
  if (c == kGround) throw ModelError(msg("free joint '", name, "': child must be a body"));
  return add_joint(name, JointType::Free, "ground", child, origin ? *origin : m_.bodies[c].position,
                   Vec3::UnitZ(), nullptr);
}

void ModelBuilder::set_joint_limits(const std::string& joint, double lower, double upper,
                                    double effort, double velocity) {
  auto it = m_.joint_index.find(joint);
  if (it == m_.joint_index.end())
    throw ModelError(msg("set_joint_limits: unknown joint '", joint, "'"));
  const std::string who = msg("joint '", joint, "' limits");
  if (std::isnan(lower) || std::isnan(upper) || std::isnan(effort) || std::isnan(velocity))
    throw ModelError(msg(who, ": NaN"));
  if (lower > upper) throw ModelError(msg(who, ": lower ", lower, " > upper ", upper));
  if (effort < 0 || velocity < 0) throw ModelError(msg(who, ": effort and velocity must be >= 0"));
  Joint& j = m_.joints[it->second];
  j.lower = lower;
  j.upper = upper;
  j.effort = effort;
  j.velocity_limit = velocity;
}

int ModelBuilder::add_drive(const std::string& joint, const Profile& profile, int coord,
                            const std::string& name) {
  auto it = m_.joint_index.find(joint);
  if (it == m_.joint_index.end()) throw ModelError(msg("add_drive: unknown joint '", joint, "'"));
  const Joint& j = m_.joints[it->second];
  const int nq = joint_coords(j.type);
  if (coord < 0 || coord >= nq)
    throw ModelError(msg("add_drive: ", joint_type_name(j.type), " joint '", joint,
                         "' has no coordinate ", coord, " to drive (it has ", nq, ")"));
  const std::string dname =
      name.empty() ? (nq == 1 ? joint : m_.coords[j.coord0 + coord].name) : name;
  for (const Drive& d : m_.drives) {
    if (d.joint == it->second && d.coord == coord)
      throw ModelError(msg("add_drive: coordinate ", coord, " of joint '", joint,
                           "' is already driven by '", d.name, "'"));
    if (d.name == dname) throw ModelError(msg("add_drive: duplicate drive name '", dname, "'"));
  }
  Drive d;
  d.name = dname;
  d.joint = it->second;
  d.coord = coord;
  d.profile = profile;
  const int idx = static_cast<int>(m_.drives.size());
  m_.drives.push_back(d);
  m_.drive_index[dname] = idx;
  return idx;
}

void ModelBuilder::add_body_load(const std::string& body, const Vec3& force, const Vec3& torque,
                                 const Vec3* point_world, const Profile* profile) {
  const int b = resolve_body(body, "add_body_force");
  if (b == kGround) throw ModelError("add_body_force: cannot load 'ground'");
  const std::string who = msg("load on body '", body, "'");
  require_finite(force, who + ": force");
  require_finite(torque, who + ": torque");
  BodyLoad l;
  l.body = b;
  l.force = force;
  l.torque = torque;
  const Body& bd = m_.bodies[b];
  if (point_world) {
    require_finite(*point_world, who + ": point");
    l.point = quat_to_rot(bd.orientation).transpose() * (*point_world - bd.position);
  }
  if (profile) {
    l.has_profile = true;
    l.profile = *profile;
  }
  m_.body_loads.push_back(l);
}

void ModelBuilder::add_spring_damper(const std::string& name, const std::string& body_a,
                                     const Vec3& point_a, const std::string& body_b,
                                     const Vec3& point_b, double stiffness, double damping,
                                     double rest_length) {
  const std::string who = msg("spring-damper '", name, "'");
  const int a = resolve_body(body_a, who);
  const int b = resolve_body(body_b, who);
  if (a == b) throw ModelError(msg(who, ": connects body '", body_a, "' to itself"));
  require_finite(point_a, who + ": point_a");
  require_finite(point_b, who + ": point_b");
  require_finite(stiffness, who + ": stiffness");
  require_finite(damping, who + ": damping");
  require_finite(rest_length, who + ": rest_length");
  if (stiffness < 0 || damping < 0)
    throw ModelError(msg(who, ": stiffness and damping must be >= 0"));
  const double L = (point_b - point_a).norm();
  if (!(L > 1e-12)) throw ModelError(msg(who, ": the two points coincide"));
  SpringDamper s;
  s.name = name;
  s.body_a = a;
  s.body_b = b;
  auto local = [&](int k, const Vec3& p) -> Vec3 {
    if (k == kGround) return p;
    const Body& bd = m_.bodies[k];
    return quat_to_rot(bd.orientation).transpose() * (p - bd.position);
  };
  s.point_a = local(a, point_a);
  s.point_b = local(b, point_b);
  s.stiffness = stiffness;
  s.damping = damping;
  s.rest_length = rest_length < 0 ? L : rest_length;
  m_.springs.push_back(s);
}

const Joint& ModelBuilder::coord_joint(const std::string& who, const std::string& joint,
                                       int coord) const {
  auto it = m_.joint_index.find(joint);
  if (it == m_.joint_index.end()) throw ModelError(msg(who, ": unknown joint '", joint, "'"));
  const Joint& j = m_.joints[it->second];
  if (coord < 0 || coord >= joint_coords(j.type))
    throw ModelError(msg(who, ": ", joint_type_name(j.type), " joint has no coordinate ", coord));
  return j;
}

void ModelBuilder::add_joint_spring_damper(const std::string& joint, double stiffness,
                                           double damping, double rest, int coord) {
  const std::string who = msg("joint spring-damper on '", joint, "'");
  const Joint& j = coord_joint(who, joint, coord);
  require_finite(stiffness, who + ": stiffness");
  require_finite(damping, who + ": damping");
  require_finite(rest, who + ": rest");
  if (stiffness < 0 || damping < 0)
    throw ModelError(msg(who, ": stiffness and damping must be >= 0"));
  if (stiffness == 0.0 && damping == 0.0) return;  // nothing to pay for
  CoordForce cf;
  cf.coord = j.coord0 + coord;
  cf.stiffness = stiffness;
  cf.damping = damping;
  cf.rest = rest;
  m_.coord_forces.push_back(cf);
}

void ModelBuilder::add_joint_friction(const std::string& joint, double viscous, double coulomb,
                                      double smoothing_velocity, int coord) {
  const std::string who = msg("joint friction on '", joint, "'");
  const Joint& j = coord_joint(who, joint, coord);
  require_finite(viscous, who + ": viscous");
  require_finite(coulomb, who + ": coulomb");
  require_finite(smoothing_velocity, who + ": smoothing_velocity");
  if (viscous < 0 || coulomb < 0) throw ModelError(msg(who, ": viscous and coulomb must be >= 0"));
  if (!(smoothing_velocity > 0))
    throw ModelError(msg(who, ": smoothing_velocity must be positive, got ", smoothing_velocity));
  CoordForce cf;
  cf.coord = j.coord0 + coord;
  cf.damping = viscous;
  cf.coulomb = coulomb;
  cf.v_smooth = smoothing_velocity;
  cf.name = who;
  m_.coord_forces.push_back(cf);
}

std::pair<int, int> ModelBuilder::gear_coords(const std::string& who, const std::string& joint_a,
                                              const std::string& joint_b, double r_a,
                                              double r_b) const {
  auto coord_of = [&](const std::string& joint) {
    auto it = m_.joint_index.find(joint);
    if (it == m_.joint_index.end()) throw ModelError(msg(who, ": unknown joint '", joint, "'"));
    const Joint& j = m_.joints[it->second];
    if (j.type != JointType::Revolute)
      throw ModelError(msg(who, ": joint '", joint, "' is ", joint_type_name(j.type),
                           ", a gear needs a revolute joint"));
    return j.coord0;
  };
  const int ca = coord_of(joint_a), cb = coord_of(joint_b);
  if (ca == cb) throw ModelError(msg(who, ": both gears are on joint '", joint_a, "'"));
  for (auto [v, n] : {std::pair{r_a, "r_a"}, std::pair{r_b, "r_b"}}) {
    require_finite(v, who + ": " + n);
    if (!(v > 0)) throw ModelError(msg(who, ": pitch radius ", n, " must be positive, got ", v));
  }
  return {ca, cb};
}

void ModelBuilder::add_gear(const std::string& name, const std::string& joint_a,
                            const std::string& joint_b, double r_a, double r_b) {
  const std::string who = msg("gear '", name, "'");
  for (const GearConstraint& g : m_.gear_constraints)
    if (g.name == name) throw ModelError(msg(who, ": duplicate gear name"));
  const auto [ca, cb] = gear_coords(who, joint_a, joint_b, r_a, r_b);
  GearConstraint g;
  g.name = name;
  g.coord_a = ca;
  g.coord_b = cb;
  g.r_a = r_a;
  g.r_b = r_b;
  m_.gear_constraints.push_back(g);
}

void ModelBuilder::add_coupling(const std::string& name, const std::string& follower,
                                const std::string& leader, double multiplier, double offset) {
  add_coupling_impl(name, follower, leader, multiplier, offset, false);
}

void ModelBuilder::add_coupling_impl(const std::string& name, const std::string& follower,
                                     const std::string& leader, double multiplier, double offset,
                                     bool mixed) {
  const std::string who = msg("coupling '", name, "'");
  if (name.empty()) throw ModelError("coupling: empty name");
  for (const GearConstraint& g : m_.gear_constraints)
    if (g.name == name)
      throw ModelError(msg(who, ": duplicate name (an ideal gear or coupling has it)"));
  auto joint_of = [&](const std::string& joint, const char* role) -> const Joint& {
    auto it = m_.joint_index.find(joint);
    if (it == m_.joint_index.end())
      throw ModelError(msg(who, ": unknown ", role, " joint '", joint, "'"));
    const Joint& j = m_.joints[it->second];
    if (j.type != JointType::Revolute && j.type != JointType::Prismatic)
      throw ModelError(msg(who, ": ", role, " joint '", joint, "' is ", joint_type_name(j.type),
                           joint_coords(j.type) == 0 ? " (no joint coordinate)" : "",
                           "; a coupling needs revolute (continuous) or prismatic joints"));
    return j;
  };
  const Joint& jf = joint_of(follower, "follower");
  const Joint& jl = joint_of(leader, "leader");
  if (&jf == &jl) throw ModelError(msg(who, ": joint '", follower, "' cannot follow itself"));
  if (jf.type != jl.type && !mixed)
    throw ModelError(msg(who, ": follower joint '", follower, "' is ", joint_type_name(jf.type),
                         " but leader joint '", leader, "' is ", joint_type_name(jl.type),
                         "; both must be of the same type (as Pinocchio requires)"));
  if (!std::isfinite(multiplier) || multiplier == 0.0)
    throw ModelError(msg(who, ": multiplier must be finite and nonzero, got ", multiplier));
  require_finite(offset, who + ": offset");
  const int cf = jf.coord0, cl = jl.coord0;
  // the coupling that makes coordinate c follow another, or nullptr
  auto following = [&](int c) -> const GearConstraint* {
    for (const GearConstraint& g : m_.gear_constraints)
      if (g.coupling && g.coord_a == c) return &g;
    return nullptr;
  };
  if (const GearConstraint* g = following(cf))
    throw ModelError(msg(who, ": joint '", follower, "' already follows joint '",
                         m_.joints[m_.coords[g->coord_b].joint].name, "' (coupling '", g->name,
                         "'); a joint can follow only one leader"));
  // up the leader's chain: reaching the follower closes a cycle
  std::string chain = msg("'", follower, "' -> '", leader, "'");
  for (int c = cl; const GearConstraint* g = following(c);) {
    c = g->coord_b;
    const std::string& jn = m_.joints[m_.coords[c].joint].name;
    chain += msg(" -> '", jn, "'");
    if (c == cf) throw ModelError(msg(who, ": the couplings would form a cycle ", chain));
  }
  GearConstraint g;
  g.name = name;
  g.coord_a = cf;
  g.coord_b = cl;
  g.r_a = 1.0;
  g.r_b = -multiplier;
  g.offset = offset;
  g.coupling = true;
  m_.gear_constraints.push_back(g);
}

namespace {

// the joint an actuator drives: known, revolute or prismatic, without an actuator yet
int actuated_joint(const Model& m, const std::string& who, const std::string& joint) {
  auto it = m.joint_index.find(joint);
  if (it == m.joint_index.end()) throw ModelError(msg(who, ": unknown joint"));
  const int ji = it->second;
  const Joint& j = m.joints[ji];
  if (j.type != JointType::Revolute && j.type != JointType::Prismatic)
    throw ModelError(msg(who, ": the joint is ", joint_type_name(j.type),
                         "; an actuator needs a revolute (continuous) or prismatic joint"));
  for (const Actuator& a : m.actuators)
    if (a.joint == ji)
      throw ModelError(msg(who, ": the joint already has an actuator (rotor '",
                           m.joints[a.rotor_joint].name, "')"));
  return ji;
}

// an actuator's numbers and motor, in the order add_actuator takes them
void check_actuator_numbers(const std::string& who, double gear_ratio, double rotor_inertia,
                            double efficiency, double friction_viscous, double friction_coulomb,
                            const MotorSpec* motor, double friction_smoothing) {
  if (!std::isfinite(gear_ratio) || gear_ratio == 0.0)
    throw ModelError(msg(who, ": gear_ratio must be finite and nonzero, got ", gear_ratio));
  if (!std::isfinite(rotor_inertia) || rotor_inertia < 0.0)
    throw ModelError(msg(who, ": rotor_inertia must be finite and >= 0, got ", rotor_inertia));
  if (!std::isfinite(efficiency) || !(efficiency > 0.0 && efficiency <= 1.0))
    throw ModelError(msg(who, ": efficiency must be in (0, 1], got ", efficiency));
  for (auto [v, n] : {std::pair{friction_viscous, "friction_viscous"},
                      std::pair{friction_coulomb, "friction_coulomb"}})
    if (!std::isfinite(v) || v < 0.0)
      throw ModelError(msg(who, ": ", n, " must be finite and >= 0, got ", v));
  if (!std::isfinite(friction_smoothing))
    throw ModelError(msg(who, ": friction_smoothing must be finite, got ", friction_smoothing));
  if (motor) motor->validate(who + ": motor");
}

// the rotor's name taken by no body, joint, coupling or gear
void check_rotor_name_free(const Model& m, const std::string& who, const std::string& rotor) {
  if (m.body_index.count(rotor) || rotor == "ground")
    throw ModelError(msg(who, ": a body named '", rotor, "' exists (the rotor's name)"));
  if (m.joint_index.count(rotor))
    throw ModelError(msg(who, ": a joint named '", rotor, "' exists (the rotor's name)"));
  for (const GearConstraint& g : m.gear_constraints)
    if (g.name == rotor)
      throw ModelError(msg(who, ": a coupling or gear named '", rotor, "' exists (the rotor's)"));
}

// the joint's origin and axis in world at the build pose
std::pair<Vec3, Vec3> joint_axis_in_world(const Model& m, const Joint& j) {
  if (j.parent == kGround) return {j.point_parent, j.frame_parent.col(2)};
  const Body& p = m.bodies[j.parent];
  const Mat3 R = quat_to_rot(p.orientation);
  return {p.position + R * j.point_parent, R * j.frame_parent.col(2)};
}

}  // namespace

void ModelBuilder::add_actuator(const std::string& joint, double gear_ratio, double rotor_inertia,
                                double efficiency, double friction_viscous, double friction_coulomb,
                                const MotorSpec* motor, bool gyroscopic,
                                double friction_smoothing) {
  const std::string who = msg("add_actuator on joint '", joint, "'");
  const int ji = actuated_joint(m_, who, joint);
  const Joint& j = m_.joints[ji];
  check_actuator_numbers(who, gear_ratio, rotor_inertia, efficiency, friction_viscous,
                         friction_coulomb, motor, friction_smoothing);
  // the gear-reduced rotor (on ground) is the joint's reflected inertia N^2 J turning with the
  // joint ("<joint>_armature": the same dynamics as a rotor at N qdot, without a body spinning N
  // times faster for the Cartesian error control to follow); the gyroscopic one is the rotor
  // itself on the joint's parent, turning at N qdot relative to it ("<joint>_rotor")
  const bool reduced = !gyroscopic;
  const std::string rotor = joint + (reduced ? "_armature" : "_rotor");
  const double n_abs = std::abs(gear_ratio);
  check_rotor_name_free(m_, who, rotor);
  const auto [point, axis] = joint_axis_in_world(m_, j);
  const std::string carrier =
      gyroscopic && j.parent != kGround ? m_.bodies[j.parent].name : std::string("ground");
  // thin disc: axial J, transverse J / 2 (the rotor's mass belongs to the link's inertia)
  const double axial = reduced ? gear_ratio * gear_ratio * rotor_inertia : rotor_inertia;
  const Mat3 inertia = 0.5 * axial * (Mat3::Identity() + axis * axis.transpose());
  const double smoothing = friction_smoothing > 0.0 ? friction_smoothing : 1e-3 * n_abs;
  Model saved = m_;  // every step below validated its input; restore on any failure regardless
  try {
    add_body(rotor, 0.0, inertia, point, Vec4(1, 0, 0, 0));
    const int rj = add_revolute(rotor, carrier, rotor, point, axis);
    add_coupling_impl(rotor, rotor, joint, reduced ? 1.0 : gear_ratio, 0.0, true);
    // motor-side friction b omega + c tanh(omega / v_s) at omega = N qdot: on the armature
    // (turning at qdot) as N^2 b and |N| c with the joint-side smoothing v_s / |N|
    if (friction_viscous > 0.0 || friction_coulomb > 0.0) {
      if (reduced)
        add_joint_friction(rotor, gear_ratio * gear_ratio * friction_viscous,
                           n_abs * friction_coulomb, smoothing / n_abs);
      else
        add_joint_friction(rotor, friction_viscous, friction_coulomb, smoothing);
    }
    Actuator a;
    a.joint = ji;
    a.rotor_joint = rj;
    a.gear_ratio = gear_ratio;
    a.rotor_inertia = rotor_inertia;
    a.efficiency = efficiency;
    a.friction_viscous = friction_viscous;
    a.friction_coulomb = friction_coulomb;
    a.friction_smoothing = smoothing;
    a.gyroscopic = gyroscopic;
    if (motor) {
      a.has_motor = true;
      a.motor = *motor;
    }
    m_.actuators.push_back(a);
  } catch (...) {
    m_ = std::move(saved);
    throw;
  }
}

void ModelBuilder::add_gear_pair(const std::string& name, const std::string& joint_a,
                                 const std::string& joint_b, double r_a, double r_b,
                                 double backlash, double stiffness, double exponent,
                                 double hc_damping) {
  const std::string who = msg("gear pair '", name, "'");
  for (const GearPair& g : m_.gears)
    if (g.name == name) throw ModelError(msg(who, ": duplicate gear pair name"));
  const auto [ca, cb] = gear_coords(who, joint_a, joint_b, r_a, r_b);
  require_finite(backlash, who + ": backlash");
  require_finite(stiffness, who + ": stiffness");
  require_finite(exponent, who + ": exponent");
  require_finite(hc_damping, who + ": hc_damping");
  if (backlash < 0) throw ModelError(msg(who, ": backlash must be >= 0, got ", backlash));
  if (!(stiffness > 0)) throw ModelError(msg(who, ": stiffness must be positive"));
  if (!(exponent >= 1.0)) throw ModelError(msg(who, ": exponent must be >= 1, got ", exponent));
  if (hc_damping < 0) throw ModelError(msg(who, ": hc_damping must be >= 0"));
  GearPair g;
  g.name = name;
  g.coord_a = ca;
  g.coord_b = cb;
  g.r_a = r_a;
  g.r_b = r_b;
  g.backlash = backlash;
  g.stiffness = stiffness;
  g.exponent = exponent;
  g.hc_damping = hc_damping;
  m_.gears.push_back(g);
  for (int c : {ca, cb})
    if (std::find(m_.tracked_coords.begin(), m_.tracked_coords.end(), c) == m_.tracked_coords.end())
      m_.tracked_coords.push_back(c);
}

void ModelBuilder::add_motor(const std::string& joint, const Profile& reference, double kp,
                             double kd, double torque_limit, const Profile* feedforward, int coord,
                             double ki) {
  const std::string who = msg("motor on '", joint, "'");
  const Joint& j = coord_joint(who, joint, coord);
  require_finite(kp, who + ": kp");
  require_finite(kd, who + ": kd");
  require_finite(ki, who + ": ki");
  if (kp < 0 || kd < 0 || ki < 0) throw ModelError(msg(who, ": kp, kd and ki must be >= 0"));
  if (!(torque_limit > 0) || std::isnan(torque_limit))
    throw ModelError(msg(who, ": torque_limit must be positive, got ", torque_limit));
  CoordForce cf;
  cf.coord = j.coord0 + coord;
  cf.motor = true;
  cf.reference = reference;
  cf.kp = kp;
  cf.kd = kd;
  cf.torque_limit = torque_limit;
  cf.ki = ki;
  if (ki > 0) cf.aux = m_.n_aux++;
  if (feedforward) {
    cf.has_input = true;
    cf.input = *feedforward;
  }
  cf.name = who;
  m_.coord_forces.push_back(cf);
}

void ModelBuilder::add_joint_torque(const std::string& joint, const Profile& profile, int coord) {
  const std::string who = msg("joint torque on '", joint, "'");
  const Joint& j = coord_joint(who, joint, coord);
  CoordForce cf;
  cf.coord = j.coord0 + coord;
  cf.has_input = true;
  cf.input = profile;
  m_.coord_forces.push_back(cf);
}

}  // namespace armdyn
