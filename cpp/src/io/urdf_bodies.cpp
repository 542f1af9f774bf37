// SPDX-License-Identifier: BSD-3-Clause
// The URDF reader's stages 3 and 4 (urdf_bodies.hpp): the link tree, then the bodies' inertias.
#include "urdf_bodies.hpp"

#include <tinyxml2.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>

#include "armdyn/builder/builder.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/math/quaternion.hpp"
#include "armdyn/poll.hpp"

namespace armdyn::urdf_import {
namespace {

// urdfdom pose (its rotation is the rpy quaternion, R = Rz(yaw) Ry(pitch) Rx(roll))
Frame to_frame(const urdf::Pose& pose) {
  Frame f;
  f.p = Vec3(pose.position.x, pose.position.y, pose.position.z);
  const urdf::Rotation& r = pose.rotation;
  f.R = quat_to_rot(Vec4(r.w, r.x, r.y, r.z).normalized());
  return f;
}

Frame compose(const Frame& a, const Frame& b) {
  Frame c;
  c.p = a.p + a.R * b.p;
  c.R = a.R * b.R;
  return c;
}

bool finite_frame(const Frame& f) { return f.p.allFinite() && f.R.allFinite(); }

// inertia tensor of a URDF <inertial> (about its origin, in its axes)
Mat3 inertia_matrix(const urdf::Inertial& in) {
  Mat3 i;
  i << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
  return i;
}

std::string list_names(const std::vector<std::string>& names, size_t from) {
  std::string s;
  for (size_t k = from; k < names.size(); ++k) s += (k > from ? ", '" : "'") + names[k] + "'";
  return s;
}

// What the file declares in the <inertial> of the links urdfdom reports as massless. urdfdom
// resets an <inertial> it cannot fully read (a NaN in its origin) to mass 0 and zero inertia but
// keeps it, which a massless link must not hide: parsed once, only when such a link exists.
class DeclaredInertials {
 public:
  explicit DeclaredInertials(const std::string& xml) : xml_(xml) {}
  // throws when the file's <inertial> of `link` differs from urdfdom's (mass 0) reading
  void check(const std::string& link, const urdf::Inertial& in) {
    if (!parsed_) parse();
    auto it = declared_.find(link);
    if (it == declared_.end()) return;
    const std::array<double, 7>& d = it->second;
    const std::array<double, 7> got{in.mass, in.ixx, in.ixy, in.ixz, in.iyy, in.iyz, in.izz};
    if (d != got) {
      throw UrdfError(msg("URDF link '", link, "': urdfdom could not read its <inertial> (it ",
                          "reports mass ", in.mass, " kg, the file declares ", d[0], " kg)"));
    }
  }

 private:
  void parse() {
    parsed_ = true;
    tinyxml2::XMLDocument doc;
    if (doc.Parse(xml_.c_str(), xml_.size()) != tinyxml2::XML_SUCCESS) return;
    const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
    if (!robot) return;
    for (auto* e = robot->FirstChildElement("link"); e; e = e->NextSiblingElement("link")) {
      const tinyxml2::XMLElement* in = e->FirstChildElement("inertial");
      if (!in) continue;
      std::array<double, 7> d{};
      const tinyxml2::XMLElement* mass = in->FirstChildElement("mass");
      const tinyxml2::XMLElement* inertia = in->FirstChildElement("inertia");
      if (mass) mass->QueryDoubleAttribute("value", &d[0]);
      int k = 1;
      for (const char* a : {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"}) {
        if (inertia) inertia->QueryDoubleAttribute(a, &d[k]);
        ++k;
      }
      const char* name = e->Attribute("name");
      declared_[name ? std::string(name) : std::string()] = d;
    }
  }
  const std::string& xml_;
  bool parsed_ = false;
  std::map<std::string, std::array<double, 7>> declared_;
};

// the robot's largest link moment: the scale of round-off in its tensors (physical_inertia
// false: CAD exports write point masses as tensors of 1e-20 with either sign)
double largest_link_moment(const LinkTree& tree, const urdf::ModelInterface& model) {
  double robot_moment = 0.0;
  for (const std::string& top : tree.group_order) {
    if (tree.is_ground(top)) continue;
    for (const std::string& name : tree.groups.at(top).links) {
      const urdf::LinkConstSharedPtr link = model.getLink(name);
      if (!link->inertial) continue;
      const Mat3 i_local = inertia_matrix(*link->inertial);
      if (!i_local.allFinite()) continue;  // refused in link_parts
      robot_moment =
          std::max(robot_moment, Eigen::SelfAdjointEigenSolver<Mat3>(i_local).eigenvalues()(2));
    }
  }
  return robot_moment;
}

// a link's mass, centre of mass and inertia about it, in world axes
struct Part {
  double m;
  Vec3 c;
  Mat3 i;
};

// Merges each group: total mass, centre of mass, inertia about it (parallel-axis theorem),
// every link inertia rotated by its inertial rpy and its link frame into world axes first.
// The tensors are checked (physical_inertia: each body's is physically consistent and each
// merged link's positive semidefinite, as add_body would; otherwise each body's -- a lone
// link's, or a merged group's sum -- is positive semidefinite, round-off negatives clamped)
// and every offender is listed at once (refuse_offenders).
// A group without mass (massless links between joints) is a massless body at its top link's
// origin; finalize() checks that every joint motion still carries inertia.
class InertiaMerge {
 public:
  InertiaMerge(const LinkTree& tree, const urdf::ModelInterface& model, const std::string& xml,
               bool physical_inertia)
      : tree_(tree),
        model_(model),
        physical_(physical_inertia),
        declared_(xml),
        robot_moment_(largest_link_moment(tree, model)) {}

  // the ground group's links are checked, nothing more
  void merge_group(Group& g) {
    const bool ground = tree_.is_ground(g.top);
    const std::vector<Part> parts = link_parts(g, ground);
    if (ground) return;
    sum_parts(parts, g);
    if (g.links.size() > 1) check_merged(g);
  }

  void refuse_offenders(const std::string& where) const {
    if (bad_.empty()) return;
    std::string list;
    for (const std::string& b : bad_) list += (list.empty() ? "" : "; ") + b;
    const std::string links = msg(bad_.size(), bad_.size() == 1 ? " link: " : " links: ");
    throw UrdfError(
        physical_
            ? msg(where, ": inertia not physically consistent on ", links, list,
                  "; load with physical_inertia=False to accept any positive semidefinite tensor")
            : msg(where, ": inertia not positive semidefinite on ", links, list,
                  " (physical_inertia=False clamps only round-off, down to -1e-12 of the "
                  "largest moment, ",
                  robot_moment_, " kg m^2)"));
  }

  std::vector<std::string> notes;  // round-off clamped to zero (physical_inertia false)

 private:
  // the parts of the group's links with an <inertial>, each checked
  std::vector<Part> link_parts(const Group& g, bool ground) {
    const bool merged = g.links.size() > 1;
    std::vector<Part> parts;
    for (const std::string& name : g.links) {
      const urdf::LinkConstSharedPtr link = model_.getLink(name);
      if (!link->inertial) continue;
      const urdf::Inertial& in = *link->inertial;
      const Frame f = compose(tree_.frame.at(name), to_frame(in.origin));
      const Mat3 i_local = inertia_matrix(in);
      if (!std::isfinite(in.mass) || !i_local.allFinite() || !finite_frame(f)) {
        throw UrdfError(msg("URDF link '", name, "': non-finite inertial data"));
      }
      if (in.mass < 0) throw UrdfError(msg("URDF link '", name, "': negative mass ", in.mass));
      if (ground) continue;
      if (in.mass == 0.0) declared_.check(name, in);
      add_part(name, in.mass, f, i_local, merged, &parts);
    }
    return parts;
  }

  // the link's part, or its name among the offenders when its tensor fails its check
  void add_part(const std::string& name, double mass, const Frame& f, const Mat3& i_local,
                bool merged, std::vector<Part>* parts) {
    if (physical_) {
      // a link merged with others may be a point mass, but its inertia must still be positive
      // semi-definite; the triangle inequality is the body's (checked below, as add_body does)
      // (a lone link's tensor is its body's: checked here, in its own axes)
      const InertiaCheck ic = check_inertia(i_local, true);
      const Vec3& p = ic.moments;
      if (merged ? p[0] < -1e-12 * std::max(1.0, i_local.trace()) : !ic.problem.empty()) {
        bad_.push_back(msg("'", name, "' (principal moments ", p[0], ", ", p[1], ", ", p[2],
                           " kg m^2: ", merged ? "is not positive semidefinite" : ic.problem, ")"));
        return;
      }
      parts->push_back({mass, f.p, f.R * i_local * f.R.transpose()});
      return;
    }
    if (merged) {
      // a link merged into a body is no rigid body of its own: only the body's tensor, its
      // links' sum, must be positive semidefinite (checked below); tiago's antenna links
      // (-3.5e-8 kg m^2) on its 28 kg base
      parts->push_back({mass, f.p, f.R * i_local * f.R.transpose()});
      return;
    }
    const InertiaCheck ic = check_inertia(i_local, false, robot_moment_);
    if (!ic.problem.empty()) {
      const Vec3& p = ic.moments;
      bad_.push_back(msg("'", name, "' (principal moments ", p[0], ", ", p[1], ", ", p[2],
                         " kg m^2: ", ic.problem, ")"));
      return;
    }
    if (ic.warn) {
      notes.push_back(msg("URDF link '", name, "': negative principal moment ", ic.smallest,
                          " kg m^2 (round-off) clamped to zero"));
    }
    parts->push_back({mass, f.p, f.R * ic.tensor * f.R.transpose()});
  }

  // the group's mass, centre of mass and inertia about it in its top link's axes
  void sum_parts(const std::vector<Part>& parts, Group& g) const {
    for (const Part& p : parts) {
      g.mass += p.m;
      g.com += p.m * p.c;
    }
    g.com = g.mass > 0 ? Vec3(g.com / g.mass) : tree_.frame.at(g.top).p;
    Mat3 i_world = Mat3::Zero();
    for (const Part& p : parts) {
      const Vec3 d = p.c - g.com;
      i_world += p.i + p.m * (d.squaredNorm() * Mat3::Identity() - d * d.transpose());
    }
    const Mat3& r_top = tree_.frame.at(g.top).R;
    const Mat3 i_body = r_top.transpose() * i_world * r_top;
    g.inertia = 0.5 * (i_body + i_body.transpose());
  }

  // the body's tensor, as add_body checks it: its links' sum (round-off clamped without
  // physical_inertia)
  void check_merged(Group& g) {
    const InertiaCheck ic = check_inertia(g.inertia, physical_, robot_moment_);
    const std::string also = merged_with(g);
    if (!ic.problem.empty()) {
      const Vec3& p = ic.moments;
      bad_.push_back(msg("'", g.top, "'", also, " (principal moments ", p[0], ", ", p[1], ", ",
                         p[2], " kg m^2: ", ic.problem, ")"));
    } else if (!physical_) {
      if (ic.warn)
        notes.push_back(msg("URDF link '", g.top, "'", also, ": negative principal moment ",
                            ic.smallest, " kg m^2 (round-off) clamped to zero"));
      g.inertia = ic.tensor;
    }
  }

  const LinkTree& tree_;
  const urdf::ModelInterface& model_;
  const bool physical_;
  DeclaredInertials declared_;
  const double robot_moment_;
  std::vector<std::string> bad_;  // "'link' (principal moments a, b, c kg m^2: why)"
};

}  // namespace

std::string merged_with(const Group& g) {
  return g.links.size() > 1 ? msg(" (merged with ", list_names(g.links, 1), ")") : "";
}

void check_inertials_read(const Document& document, const urdf::ModelInterface& model) {
  for (const std::string& name : document.inertial) {
    const urdf::LinkConstSharedPtr link = model.getLink(name);
    if (!link || !link->inertial) {
      throw UrdfError(msg("URDF link '", name, "': urdfdom could not read its <inertial>"));
    }
  }
}

LinkTree link_tree(const urdf::ModelInterface& model, bool fixed_base) {
  LinkTree t;
  const urdf::LinkConstSharedPtr root = model.getRoot();
  t.root = root->name;
  t.fixed_base = fixed_base;
  t.frame[t.root] = Frame();
  t.top_of[t.root] = t.root;
  std::vector<urdf::LinkConstSharedPtr> todo{root};
  while (!todo.empty()) {
    poll_point();
    const urdf::LinkConstSharedPtr link = todo.back();
    todo.pop_back();
    const std::string& top = t.top_of.at(link->name);
    if (top == link->name) {
      t.groups[top].top = top;
      t.group_order.push_back(top);
    }
    t.groups[top].links.push_back(link->name);
    for (const urdf::JointSharedPtr& j : link->child_joints) {
      const std::string& c = j->child_link_name;
      if (t.frame.count(c)) throw UrdfError(msg("URDF link '", c, "' is reached twice"));
      const Frame f =
          compose(t.frame.at(link->name), to_frame(j->parent_to_joint_origin_transform));
      if (!finite_frame(f)) throw UrdfError(msg("URDF joint '", j->name, "': non-finite origin"));
      t.frame[c] = f;
      t.top_of[c] = j->type == urdf::Joint::FIXED ? top : c;
      const urdf::LinkConstSharedPtr child = model.getLink(c);
      if (!child) throw UrdfError(msg("URDF joint '", j->name, "': child link '", c, "' missing"));
      todo.push_back(child);
    }
  }
  for (const auto& kv : model.links_) {
    if (!t.frame.count(kv.first)) {
      throw UrdfError(msg("URDF link '", kv.first, "' is not connected to the root link '", t.root,
                          "' (the joints form a cycle)"));
    }
  }
  return t;
}

std::vector<std::string> merge_inertias(LinkTree& tree, const urdf::ModelInterface& model,
                                        const std::string& xml, const std::string& where,
                                        bool physical_inertia) {
  InertiaMerge merge(tree, model, xml, physical_inertia);
  for (const std::string& top : tree.group_order) {
    poll_point();
    merge.merge_group(tree.groups.at(top));
  }
  merge.refuse_offenders(where);
  return std::move(merge.notes);
}

}  // namespace armdyn::urdf_import
