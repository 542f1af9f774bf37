// SPDX-License-Identifier: BSD-3-Clause
// URDF loader (documented element by element in docs/urdf.md). urdf_builder is a list of stages:
//  0. the text (urdf_source.cpp): read_source -- a string starting with '<' is XML, anything
//     else a path, which must name a regular file (stat before open: a FIFO or a device is
//     refused, never read) of at most kUrdfMaxBytes; then prescan, a linear pass over the raw
//     text that refuses NUL bytes and elements with more than kUrdfMaxAttributes attributes
//     (tinyxml2 is quadratic in them);
//  1. the first pass with tinyxml2 (urdf_scan.cpp): scan_document -- names valid UTF-8; every
//     numeric attribute (origins, axes, inertials, limits, dynamics, mimic, safety_controller,
//     calibration, visual/collision geometry, colours) parsed completely as a finite double
//     before urdfdom sees it (urdfdom zeroes nan, inf and 1e400 silently); the document order
//     of <joint> elements (urdfdom keeps joints in a std::map sorted by name), joint types and
//     the tree structure, with error messages that name the culprit and quote short, escaped
//     excerpts only;
//  2. urdfdom (here): parse_urdfdom (urdf::parseURDF), the full parse of poses, axes, limits and
//     inertials; check_inertials_read: no <inertial> urdfdom dropped;
//  3. the link tree (urdf_bodies.cpp): link_tree -- each link frame at q = 0, and every group of
//     links joined by fixed joints, to be merged into one body;
//  4. the bodies' inertias (urdf_bodies.cpp): merge_inertias -- each group's mass, centre of
//     mass and inertia, every offending tensor listed at once;
//  5. the assembly (here, class Assembly): the floating base, the bodies parent-before-child,
//     the moving joints in document order with their <limit> and their <dynamics> (damping:
//     viscous friction; friction: Coulomb friction smoothed with kUrdfCoulombSmoothing), then
//     (mimic = true) each <mimic> as a coupling (add_coupling), then every link as a frame.
//     With a fixed base and no moving joint the builder has no bodies: a zero-DOF model.
// Every loop over the links and joints is a poll point (Ctrl-C; the two parses are not).
//
// Ignored (numbers checked, nothing imported): <visual>, <collision>, <material>,
// <transmission>, <gazebo>, <safety_controller>, <calibration>; <mimic> with mimic = false.
//
// urdfdom reports its own parse errors through console_bridge. When the build defines
// ARMDYN_HAVE_CONSOLE_BRIDGE (and links console_bridge::console_bridge) those messages are
// captured into the UrdfError; otherwise they only reach stderr.
#include "armdyn/io/urdf.hpp"

#include <urdf_parser/urdf_parser.h>

#include <cmath>
#include <exception>
#include <set>
#include <string>
#include <vector>

#include "armdyn/errors.hpp"
#include "armdyn/math/quaternion.hpp"
#include "armdyn/poll.hpp"
#include "urdf_bodies.hpp"
#include "urdf_scan.hpp"
#include "urdf_source.hpp"

#ifdef ARMDYN_HAVE_CONSOLE_BRIDGE
#include <console_bridge/console.h>

#include <mutex>
#endif

namespace armdyn {
namespace urdf_import {
namespace {

// same "unbounded" value as the Joint defaults
constexpr double kUnbounded = 1e300;

// infinite URDF limits map to the "unbounded" Joint defaults
double clamp_limit(double v) {
  if (std::isnan(v)) return v;
  if (v > kUnbounded) return kUnbounded;
  if (v < -kUnbounded) return -kUnbounded;
  return v;
}

#ifdef ARMDYN_HAVE_CONSOLE_BRIDGE
// collects urdfdom's warnings and errors while it parses
class LogCapture : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level < console_bridge::CONSOLE_BRIDGE_LOG_WARN) return;
    if (!text_.empty()) text_ += "; ";
    text_ += text;
  }
  std::string text_;
};
#endif

// second pass: urdfdom
urdf::ModelInterfaceSharedPtr parse_urdfdom(const std::string& xml, const std::string& where) {
  urdf::ModelInterfaceSharedPtr model;
  std::string reason;
#ifdef ARMDYN_HAVE_CONSOLE_BRIDGE
  // console_bridge's handler is global: serialise, and restore it even on exceptions
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  LogCapture capture;
  struct Restore {
    ~Restore() { console_bridge::restorePreviousOutputHandler(); }
  };
  console_bridge::useOutputHandler(&capture);
  Restore restore;
#endif
  try {
    model = urdf::parseURDF(xml);
  } catch (const std::exception& e) {
    reason = e.what();
  }
#ifdef ARMDYN_HAVE_CONSOLE_BRIDGE
  if (reason.empty()) reason = capture.text_;
#endif
  if (!model) {
    // urdfdom's log may quote the input: a short excerpt only
    throw UrdfError(msg(
        where, ": urdfdom could not parse the URDF",
        reason.empty() ? std::string(" (see its log on stderr)") : ": " + excerpt(reason, 400)));
  }
  if (!model->getRoot()) throw UrdfError(msg(where, ": urdfdom found no root link"));
  return model;
}

// the joint's unit axis in world axes (the joint frame jf is the child link frame at q = 0)
Vec3 joint_axis(const std::string& name, const urdf::Joint& j, const Frame& jf) {
  const Vec3 axis_local(j.axis.x, j.axis.y, j.axis.z);
  if (!axis_local.allFinite()) throw UrdfError(msg("URDF joint '", name, "': non-finite axis"));
  if (axis_local.norm() < 1e-12) {
    throw UrdfError(msg("URDF joint '", name, "': axis has zero length"));
  }
  return jf.R * axis_local.normalized();
}

// <limit>: continuous joints keep unbounded positions; effort/velocity are informative
void set_limits(ModelBuilder& builder, const std::string& name, const urdf::Joint& j) {
  const urdf::JointLimits& lim = *j.limits;
  const bool continuous = j.type == urdf::Joint::CONTINUOUS;
  builder.set_joint_limits(name, continuous ? -kUnbounded : clamp_limit(lim.lower),
                           continuous ? kUnbounded : clamp_limit(lim.upper),
                           clamp_limit(lim.effort), clamp_limit(lim.velocity));
}

// <dynamics>: viscous damping and Coulomb friction on the joint coordinate
void add_friction(ModelBuilder& builder, const std::string& name, const urdf::JointDynamics& dyn) {
  const double damping = dyn.damping, friction = dyn.friction;
  if (damping < 0 || friction < 0) {
    throw UrdfError(msg("URDF joint '", name,
                        "': <dynamics> damping and friction must be >= 0, got damping ", damping,
                        " and friction ", friction));
  }
  if (damping > 0 || friction > 0) {
    builder.add_joint_friction(name, damping, friction, kUrdfCoulombSmoothing);
  }
}

// <mimic joint= multiplier= offset=>: q_joint = multiplier q_mimicked + offset, a coupling
// named after the mimicking joint (a fixed joint's mimic has nothing to couple: ignored)
void add_mimic_couplings(ModelBuilder& builder, const std::vector<JointDecl>& decls,
                         const urdf::ModelInterface& urdf_model) {
  for (const JointDecl& d : decls) {
    if (d.type == "fixed") continue;
    const urdf::JointConstSharedPtr j = urdf_model.getJoint(d.name);
    if (!j || !j->mimic) continue;
    const std::string& leader = j->mimic->joint_name;
    const urdf::JointConstSharedPtr lj = urdf_model.getJoint(leader);
    if (!lj)
      throw UrdfError(msg("URDF joint '", d.name, "': <mimic> names unknown joint '", leader, "'"));
    if (lj->type == urdf::Joint::FIXED)
      throw UrdfError(msg("URDF joint '", d.name, "': <mimic> names fixed joint '", leader,
                          "', which has no coordinate to follow"));
    try {
      builder.add_coupling(d.name, d.name, leader, j->mimic->multiplier, j->mimic->offset);
    } catch (const UrdfError&) {
      throw;
    } catch (const ModelError& e) {
      throw UrdfError(msg("URDF joint '", d.name, "' <mimic joint='", leader, "'>: ", e.what()));
    }
  }
}

// The builder's bodies, joints and frames from the link tree. A ModelError of the builder
// becomes a UrdfError naming the link or joint.
class Assembly {
 public:
  Assembly(ModelBuilder& builder, const LinkTree& tree, const urdf::ModelInterface& model)
      : builder_(builder), tree_(tree), model_(model) {}

  // floating base: the root body first, declared free
  void add_floating_base() {
    const std::string& root = tree_.root;
    ensure_body(root);
    std::string free_name = "root_free";
    while (model_.getJoint(free_name)) free_name += "_";
    try {
      // the floating base's frame is the root link's frame (q: its pose, qd: its velocity)
      const Vec3 origin = tree_.frame.at(root).p;
      builder_.add_free(free_name, root, &origin);
    } catch (const UrdfError&) {
      throw;
    } catch (const ModelError& e) {
      throw UrdfError(msg("URDF link '", root, "': ", e.what()));
    }
  }

  // all bodies first, in the order the moving joints first need them (ancestors first)
  void add_bodies(const std::vector<JointDecl>& decls) {
    for (const JointDecl& d : decls) {
      if (d.type != "fixed") ensure_body(tree_.top_of.at(d.child));
    }
  }

  // then the moving joints in document order (this order defines the joint-space arrays)
  void add_moving_joints(const std::vector<JointDecl>& decls) {
    for (const JointDecl& d : decls) {
      if (d.type == "fixed") continue;
      poll_point();
      add_joint(d);
    }
  }

  // every link stays a named frame (its link frame, not its centre of mass) on the body it was
  // merged into, or on ground: depth-first from the root (children in urdfdom's order)
  void add_link_frames() {
    std::vector<urdf::LinkConstSharedPtr> pending{model_.getRoot()};
    while (!pending.empty()) {
      poll_point();
      const urdf::LinkConstSharedPtr link = pending.back();
      pending.pop_back();
      const Frame& f = tree_.frame.at(link->name);
      try {
        builder_.add_frame(link->name, tree_.body_of(link->name), f.p, rot_to_quat(f.R));
      } catch (const UrdfError&) {
        throw;
      } catch (const ModelError& e) {
        throw UrdfError(msg("URDF link '", link->name, "': ", e.what()));
      }
      for (auto it = link->child_joints.rbegin(); it != link->child_joints.rend(); ++it)
        pending.push_back(model_.getLink((*it)->child_link_name));
    }
  }

 private:
  void add_group_body(const std::string& top) {
    const Group& g = tree_.groups.at(top);
    try {
      builder_.add_body(top, g.mass, g.inertia, g.com, rot_to_quat(tree_.frame.at(top).R));
    } catch (const UrdfError&) {
      throw;
    } catch (const ModelError& e) {
      throw UrdfError(msg("URDF link '", top, "'", merged_with(g), ": ", e.what()));
    }
    added_.insert(top);
  }

  // the body of a group, after the bodies of all its ancestors (parent before child)
  void ensure_body(const std::string& top) {
    std::vector<std::string> chain;
    for (std::string t = top; !tree_.is_ground(t) && !added_.count(t);) {
      chain.push_back(t);
      if (t == tree_.root) break;
      t = tree_.top_of.at(model_.getLink(t)->parent_joint->parent_link_name);
    }
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) add_group_body(*it);
  }

  void add_joint(const JointDecl& d) {
    const urdf::JointConstSharedPtr j = model_.getJoint(d.name);
    if (!j) throw UrdfError(msg("URDF joint '", d.name, "': not found by urdfdom"));
    const Frame& jf = tree_.frame.at(j->child_link_name);
    const Vec3 axis = joint_axis(d.name, *j, jf);
    const std::string parent = tree_.body_of(j->parent_link_name);
    const std::string child = tree_.body_of(j->child_link_name);
    try {
      if (j->type == urdf::Joint::PRISMATIC) {
        builder_.add_prismatic(d.name, parent, child, jf.p, axis);
      } else {
        builder_.add_revolute(d.name, parent, child, jf.p, axis);
      }
      if (j->limits) set_limits(builder_, d.name, *j);
      if (j->dynamics) add_friction(builder_, d.name, *j->dynamics);
    } catch (const UrdfError&) {
      throw;
    } catch (const ModelError& e) {
      throw UrdfError(msg("URDF joint '", d.name, "': ", e.what()));
    }
  }

  ModelBuilder& builder_;
  const LinkTree& tree_;
  const urdf::ModelInterface& model_;
  std::set<std::string> added_;  // groups whose body exists
};

}  // namespace
}  // namespace urdf_import

ModelBuilder urdf_builder(const std::string& path_or_xml, bool fixed_base, const Vec3& gravity,
                          bool physical_inertia, bool mimic) {
  namespace ui = urdf_import;
  std::string where;  // the source, as messages name it
  const std::string xml = ui::read_source(path_or_xml, &where);
  ui::prescan(xml, where);
  const ui::Document document = ui::scan_document(xml, where);
  const urdf::ModelInterfaceSharedPtr model = ui::parse_urdfdom(xml, where);
  ui::check_inertials_read(document, *model);
  ui::LinkTree tree = ui::link_tree(*model, fixed_base);
  const std::vector<std::string> notes =
      ui::merge_inertias(tree, *model, xml, where, physical_inertia);

  ModelBuilder builder(gravity, physical_inertia);
  for (const std::string& note : notes) builder.add_warning(note);
  ui::Assembly assembly(builder, tree, *model);
  if (!fixed_base) assembly.add_floating_base();
  assembly.add_bodies(document.joints);
  assembly.add_moving_joints(document.joints);
  if (mimic) ui::add_mimic_couplings(builder, document.joints, *model);
  assembly.add_link_frames();
  return builder;
}

}  // namespace armdyn
