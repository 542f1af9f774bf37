// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/model/builder.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <deque>
#include <numeric>

#include "armdyn/algorithm/kinematics.hpp"
#include "armdyn/algorithm/projection.hpp"
#include "armdyn/analysis/joint_space.hpp"
#include "armdyn/data.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/math/quaternion.hpp"
#include "armdyn/solver/block_sparse.hpp"

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

}  // namespace

ModelBuilder::ModelBuilder(const Vec3& gravity) {
  require_finite(gravity, "gravity");
  m_.gravity = gravity;
}

int ModelBuilder::add_body(const std::string& name, double mass, const Mat3& inertia,
                           const Vec3& position, const Vec4& orientation) {
  const std::string who = msg("body '", name, "'");
  if (name.empty()) throw ModelError("body name must not be empty");
  if (name == "ground") throw ModelError("body name 'ground' is reserved");
  if (m_.body_index.count(name)) throw ModelError(msg(who, ": duplicate body name"));
  require_finite(mass, who + ": mass");
  if (!(mass > 0.0)) throw ModelError(msg(who, ": mass must be positive, got ", mass));
  require_finite(inertia, who + ": inertia");
  const double scale = inertia.cwiseAbs().maxCoeff();
  if ((inertia - inertia.transpose()).cwiseAbs().maxCoeff() > 1e-9 * std::max(scale, 1e-300))
    throw ModelError(msg(who, ": inertia is not symmetric"));
  Eigen::SelfAdjointEigenSolver<Mat3> es(0.5 * (inertia + inertia.transpose()));
  const Vec3 p = es.eigenvalues();  // ascending
  if (!(p[0] > 0.0))
    throw ModelError(msg(who, ": inertia is not positive definite (principal moments ", p[0], ", ",
                         p[1], ", ", p[2], ")"));
  if (p[0] + p[1] < p[2] * (1.0 - 1e-9))
    throw ModelError(msg(who, ": inertia violates the triangle inequality (principal moments ",
                         p[0], " + ", p[1], " < ", p[2], ")"));
  require_finite(position, who + ": position");
  require_finite(orientation, who + ": orientation");
  if (std::abs(orientation.norm() - 1.0) > 1e-6)
    throw ModelError(msg(who,
                         ": orientation must be a unit quaternion [e0, e1, e2, e3] "
                         "(scalar first), got norm ",
                         orientation.norm()));
  Body b;
  b.name = name;
  b.mass = mass;
  b.inertia = 0.5 * (inertia + inertia.transpose());
  b.position = position;
  b.orientation = orientation.normalized();
  const int idx = static_cast<int>(m_.bodies.size());
  m_.bodies.push_back(b);
  m_.body_index[name] = idx;
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
int ModelBuilder::add_free(const std::string& name, const std::string& child) {
  const int c = resolve_body(child, msg("free joint '", name, "'"));
  if (c == kGround) throw ModelError(msg("free joint '", name, "': child must be a body"));
  return add_joint(name, JointType::Free, "ground", child, m_.bodies[c].position, Vec3::UnitZ(),
                   nullptr);
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

namespace {

std::shared_ptr<Model> finalize_draft(const Model& draft, const FinalizeOptions& options) {
  auto mp = std::make_shared<Model>(draft);
  Model& m = *mp;
  if (m.bodies.empty()) throw ModelError("finalize: the model has no bodies");
  m.nb = static_cast<int>(m.bodies.size());
  m.nq = 7 * m.nb;
  m.nv = 6 * m.nb;
  // ideal gear rows follow the joint rows; drives come last
  for (GearConstraint& g : m.gear_constraints) g.row = m.nc_joint++;
  for (size_t k = 0; k < m.drives.size(); ++k) m.drives[k].row = m.nc_joint + static_cast<int>(k);
  m.nc = m.nc_joint + static_cast<int>(m.drives.size());

  // connectivity: every body must reach ground through joints (node nb = ground)
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
  if (!loose.empty()) {
    std::string names;
    for (size_t k = 0; k < loose.size() && k < 8; ++k) names += (k ? ", '" : "'") + loose[k] + "'";
    if (loose.size() > 8) names += ", ...";
    throw ModelError(msg("finalize: bodies not connected to ground: ", names,
                         " (add a joint, or add_free for a free-floating body)"));
  }

  // topology: a tree has exactly nb joints; order joints parent-before-child from ground
  m.is_tree = static_cast<int>(m.joints.size()) == m.nb;
  m.joint_space_ok = false;
  m.joint_tree = false;
  if (m.is_tree) {
    std::vector<char> seen(m.nb + 1, 0);
    seen[m.nb] = 1;
    std::deque<int> queue{m.nb};
    std::vector<char> used(m.joints.size(), 0);
    bool ok = true;
    while (!queue.empty()) {
      const int n = queue.front();
      queue.pop_front();
      for (size_t ji = 0; ji < m.joints.size(); ++ji) {
        if (used[ji]) continue;
        const Joint& j = m.joints[ji];
        const int p = node(j.parent), c = node(j.child);
        if (p != n && c != n) continue;
        used[ji] = 1;
        const int other = p == n ? c : p;
        if (p != n && ok) {
          ok = false;
          m.joint_space_reason = msg("joint '", j.name, "' points from child to parent");
        }
        seen[other] = 1;
        queue.push_back(other);
        m.tree_order.push_back(static_cast<int>(ji));
      }
    }
    for (const Joint& j : m.joints) {
      if (j.type == JointType::Spherical || j.type == JointType::Universal ||
          j.type == JointType::Free || j.type == JointType::Inline ||
          j.type == JointType::Distance) {
        if (ok)
          m.joint_space_reason =
              msg(joint_type_name(j.type), " joint '", j.name, "' has no joint coordinates");
        ok = false;
      }
    }
    m.joint_tree = ok;
    if (ok && !m.gear_constraints.empty()) {
      ok = false;
      m.joint_space_reason =
          msg("ideal gear '", m.gear_constraints[0].name, "' couples joint coordinates");
    }
    m.joint_space_ok = ok;
  } else {
    m.joint_space_reason = "the model has closed loops";
  }

  // characteristic length for tolerances
  double ls = 0.0;
  for (const Joint& j : m.joints) {
    if (j.parent != kGround) ls = std::max(ls, j.point_parent.norm());
    if (j.child != kGround) ls = std::max(ls, j.point_child.norm());
  }
  m.length_scale = std::max(ls, 1e-3);

  // KKT solver plans (block order and fill), fixed here for the model's lifetime
  m.kkt_all = plan_kkt(m, m.nc);
  if (m.nc_joint != m.nc) m.kkt_joint = plan_kkt(m, m.nc_joint);

  // assembly: project the given poses onto f(u, 0) = 0, then rest velocities onto zeta v = rhs
  m.u0 = VecX(m.nq);
  for (int i = 0; i < m.nb; ++i) {
    m.u0.segment<3>(7 * i) = m.bodies[i].position;
    m.u0.segment<4>(7 * i + 3) = m.bodies[i].orientation;
  }
  m.v0 = VecX::Zero(m.nv);
  // a driven joint-space tree starts from the forward kinematics of the drives' initial values:
  // Newton from the build pose could otherwise land on a flipped branch of the joint rows
  if (m.joint_space_ok && !m.drives.empty()) {
    VecX q, qd;
    joint_coordinates(m, m.u0, m.v0, q, qd);
    for (const Drive& d : m.drives) q[m.joints[d.joint].coord0 + d.coord] = d.profile.eval(0.0).y;
    if (q.allFinite()) {
      VecX u, v;
      state_from_joints(m, q, VecX::Zero(q.size()), u, v);
      m.u0 = u;
    }
  }
  const Metric metric = options.mass_weighted_assembly ? Metric::Mass : Metric::Identity;
  {
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

  // rank analysis at the assembled configuration: mobility and redundant rows by name
  {
    std::vector<BodyKin> kin;
    body_kinematics(m, m.u0.data(), nullptr, kin);
    ConstraintEval ce;
    ce.init(m);
    eval_constraints(m, kin, 0.0, false, ce);
    MatX z;
    auto analyse = [&](int nrows, std::vector<std::string>* names) {
      if (nrows == 0) return 0;
      if (z.size() == 0) z = dense_zeta(m, ce);
      Eigen::ColPivHouseholderQR<MatX> qr(z.topRows(nrows).transpose());
      qr.setThreshold(1e-10);
      const int r = static_cast<int>(qr.rank());
      if (names)
        for (int k = r; k < nrows; ++k)
          names->push_back(m.row_name(qr.colsPermutation().indices()[k]));
      return r;
    };
    // fast path: when the block-sparse Cholesky of zeta zeta^T succeeds on all rows, every row
    // is independent (its pivots pass the same relative test the solver uses) and the dense
    // QR below -- cubic in the rows -- is not needed
    bool full_rank = false;
    if (m.kkt_all.path != "dense" && m.nc > 0) {
      BlockSparseSchur sp(m, m.kkt_all);
      full_rank = sp.factor(ce, nullptr);
    }
    std::vector<std::string> all;
    if (full_rank) {
      m.rank_joint = m.nc_joint;
      m.rank_all = m.nc;
    } else {
      m.rank_joint = analyse(m.nc_joint, &m.redundant_rows);
      m.rank_all = analyse(m.nc, &all);
    }
    for (const auto& n : all)
      if (std::find(m.redundant_rows.begin(), m.redundant_rows.end(), n) ==
              m.redundant_rows.end() &&
          n.rfind("drive", 0) == 0)
        m.redundant_rows.push_back(n);
    m.mobility = m.nv - m.rank_joint;
    m.mobility_driven = m.nv - m.rank_all;
    m.redundant = m.rank_joint < m.nc_joint || m.rank_all < m.nc;
  }
  if (m.redundant) {
    // redundant rows: the dense pivoted factorisation (minimum-norm multipliers) throughout
    for (KktPlan* p : {&m.kkt_all, &m.kkt_joint}) {
      p->path = "dense";
      p->description = "dense Schur complement, pivoted Cholesky (minimum-norm multipliers)";
    }
    Data d(m);
    project(m, d, 0.0, m.u0.data(), m.v0.data(), metric);
  }
  return mp;
}

// Composite bodies of the fixed joints (Model::welded), from the assembled state of m. Leaves m
// without a welded model when nothing merges or when merging would change the model's meaning
// (a loop of fixed joints, a moving joint or a spring inside one composite, or no body left).
void attach_welded(Model& m, const Model& draft, const FinalizeOptions& options) {
  const int nb = m.nb;
  const int ground = nb;  // union-find node of ground
  std::vector<int> uf(nb + 1);
  std::iota(uf.begin(), uf.end(), 0);
  auto find = [&](int x) {
    while (uf[x] != x) x = uf[x] = uf[uf[x]];
    return x;
  };
  auto node = [&](int b) { return b == kGround ? ground : b; };
  const int nj = static_cast<int>(m.joints.size());
  std::vector<char> merged(nj, 0);
  int n_merged = 0;
  for (int j = 0; j < nj; ++j) {
    const Joint& jt = m.joints[j];
    if (jt.type != JointType::Fixed) continue;
    int a = find(node(jt.parent)), c = find(node(jt.child));
    if (a == c) return;  // a loop of fixed joints
    if (c == ground) std::swap(a, c);
    uf[c] = a;  // ground stays its group's representative
    merged[j] = 1;
    ++n_merged;
  }
  if (n_merged == 0) return;
  // composites: one per group without ground, rooted at its first body
  std::vector<int> comp(nb, kGround), comp_of(nb + 1, -2);
  std::vector<int> roots;
  for (int b = 0; b < nb; ++b) {
    const int r = find(b);
    if (r == ground) continue;
    if (comp_of[r] == -2) {
      comp_of[r] = static_cast<int>(roots.size());
      roots.push_back(b);
    }
    comp[b] = comp_of[r];
  }
  const int nc = static_cast<int>(roots.size());
  if (nc == 0) return;  // everything is welded to ground
  // composite frames at the assembled state: the root's axes, origin at the centre of mass
  auto pos = [&](int b) { return Vec3(m.u0.segment<3>(7 * b)); };
  auto rot = [&](int b) { return quat_to_rot(m.u0.segment<4>(7 * b + 3)); };
  std::vector<double> mass(nc, 0.0);
  std::vector<Vec3> com(nc, Vec3::Zero());
  for (int b = 0; b < nb; ++b)
    if (comp[b] >= 0) {
      mass[comp[b]] += m.bodies[b].mass;
      com[comp[b]] += m.bodies[b].mass * pos(b);
    }
  for (int c = 0; c < nc; ++c) com[c] /= mass[c];
  std::vector<Model::Weld> weld(nb);
  std::vector<Mat3> inertia(nc, Mat3::Zero());
  for (int b = 0; b < nb; ++b) {
    Model::Weld& w = weld[b];
    w.composite = comp[b];
    if (comp[b] == kGround) {  // ground's frame is the world
      w.offset = pos(b);
      w.rotation = rot(b);
      continue;
    }
    const Mat3 Rc = rot(roots[comp[b]]);
    w.offset = Rc.transpose() * (pos(b) - com[comp[b]]);
    w.rotation = Rc.transpose() * rot(b);
    const Vec3& o = w.offset;
    inertia[comp[b]] += w.rotation * m.bodies[b].inertia * w.rotation.transpose() +
                        m.bodies[b].mass * (o.squaredNorm() * Mat3::Identity() - o * o.transpose());
  }
  // the merged draft
  Model d;
  d.gravity = draft.gravity;
  for (int c = 0; c < nc; ++c) {
    Body bd;
    int members = 0;
    for (int b = 0; b < nb; ++b) members += comp[b] == c;
    bd.name = m.bodies[roots[c]].name;
    if (members > 1) bd.name += msg(" (+", members - 1, " welded)");
    bd.mass = mass[c];
    bd.inertia = 0.5 * (inertia[c] + inertia[c].transpose());
    bd.position = com[c];
    bd.orientation = m.u0.segment<4>(7 * roots[c] + 3);
    d.body_index[bd.name] = c;
    d.bodies.push_back(bd);
  }
  std::vector<int> weld_joint(nj, -1);
  auto place = [&](int b, Vec3& point, Mat3& frame) {
    if (b == kGround) return kGround;
    const Model::Weld& w = weld[b];
    point = w.offset + w.rotation * point;
    frame = w.rotation * frame;
    return w.composite;
  };
  for (int j = 0; j < nj; ++j) {
    if (merged[j]) continue;
    Joint jt = draft.joints[j];
    jt.parent = place(jt.parent, jt.point_parent, jt.frame_parent);
    jt.child = place(jt.child, jt.point_child, jt.frame_child);
    if (jt.parent == jt.child) return;  // a moving joint inside one composite
    jt.row0 = d.nc_joint;
    d.nc_joint += joint_rows(jt.type);
    weld_joint[j] = static_cast<int>(d.joints.size());
    d.joint_index[jt.name] = weld_joint[j];
    d.joints.push_back(jt);
  }
  d.coords = draft.coords;
  for (Coord& c : d.coords) c.joint = weld_joint[c.joint];
  d.drives = draft.drives;
  for (Drive& dr : d.drives) dr.joint = weld_joint[dr.joint];
  d.drive_index = draft.drive_index;
  for (BodyLoad l : draft.body_loads) {
    if (comp[l.body] == kGround) continue;  // acts on ground
    l.point = weld[l.body].offset + weld[l.body].rotation * l.point;
    l.body = comp[l.body];
    d.body_loads.push_back(l);
  }
  for (SpringDamper sd : draft.springs) {
    Mat3 unused = Mat3::Identity();
    sd.body_a = place(sd.body_a, sd.point_a, unused);
    sd.body_b = place(sd.body_b, sd.point_b, unused);
    if (sd.body_a == sd.body_b) return;  // a spring inside one composite
    d.springs.push_back(sd);
  }
  d.coord_forces = draft.coord_forces;
  d.gears = draft.gears;
  d.gear_constraints = draft.gear_constraints;
  d.tracked_coords = draft.tracked_coords;
  d.n_aux = draft.n_aux;
  std::shared_ptr<Model> w;
  try {
    w = finalize_draft(d, options);
  } catch (const std::exception&) {
    return;  // keep the model unmerged rather than fail a valid model
  }
  // the merged joints, far bodies first: breadth-first from each composite's root (and ground)
  std::vector<std::vector<std::pair<int, int>>> adj(nb + 1);  // node -> (joint, other node)
  for (int j = 0; j < nj; ++j)
    if (merged[j]) {
      const int p = node(m.joints[j].parent), c = node(m.joints[j].child);
      adj[p].push_back({j, c});
      adj[c].push_back({j, p});
    }
  std::vector<char> seen(nb + 1, 0);
  std::vector<std::pair<int, int>> order;
  std::deque<int> queue{ground};
  for (int r : roots) queue.push_back(r);
  for (int n : queue) seen[n] = 1;
  while (!queue.empty()) {
    const int n = queue.front();
    queue.pop_front();
    for (const auto& [j, o] : adj[n]) {
      if (seen[o]) continue;
      seen[o] = 1;
      order.push_back({j, o});
      queue.push_back(o);
    }
  }
  std::reverse(order.begin(), order.end());
  m.welded = w;
  m.weld = weld;
  m.weld_joint = weld_joint;
  m.weld_sweep = order;
  m.weld_root = roots;
}

}  // namespace

ModelPtr ModelBuilder::finalize(const FinalizeOptions& options) const {
  std::shared_ptr<Model> m = finalize_draft(m_, options);
  attach_welded(*m, m_, options);
  return m;
}

}  // namespace armdyn
