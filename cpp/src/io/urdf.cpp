// SPDX-License-Identifier: BSD-3-Clause
// URDF loader. Two passes over the XML:
//  1. tinyxml2: the document order of <joint> elements (urdfdom keeps joints in a std::map sorted
//     by name), joint types and the tree structure, with error messages that name the culprit;
//  2. urdfdom (urdf::parseURDF): the full parse of poses, axes, limits and inertials.
// Then every group of links joined by fixed joints is merged into one body, bodies are added
// parent-before-child, and the moving joints are added in document order.
//
// Ignored silently: <visual>, <collision>, <material>, <transmission>, <gazebo>, <mimic>,
// <safety_controller>, <calibration>, and joint <dynamics> (damping/friction are not imported;
// add them with add_joint_spring_damper / add_joint_friction on the returned builder).
//
// urdfdom reports its own parse errors through console_bridge. When the build defines
// ARMDYN_HAVE_CONSOLE_BRIDGE (and links console_bridge::console_bridge) those messages are
// captured into the UrdfError; otherwise they only reach stderr.
#include "armdyn/io/urdf.hpp"

#include <tinyxml2.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "armdyn/errors.hpp"
#include "armdyn/math/quaternion.hpp"

#ifdef ARMDYN_HAVE_CONSOLE_BRIDGE
#include <console_bridge/console.h>

#include <mutex>
#endif

namespace armdyn {
namespace {

// same "unbounded" value as the Joint defaults
constexpr double kUnbounded = 1e300;

// a rigid frame: origin and rotation (frame -> world)
struct Frame {
  Vec3 p = Vec3::Zero();
  Mat3 R = Mat3::Identity();
};

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

// infinite URDF limits map to the "unbounded" Joint defaults
double clamp_limit(double v) {
  if (std::isnan(v)) return v;
  if (v > kUnbounded) return kUnbounded;
  if (v < -kUnbounded) return -kUnbounded;
  return v;
}

// one <joint> element as written in the document
struct JointDecl {
  std::string name, type, parent, child;
};

bool looks_like_xml(const std::string& s) {
  for (char c : s) {
    if (std::isspace(static_cast<unsigned char>(c))) continue;
    return c == '<';
  }
  return false;
}

// the XML text, and a description of where it came from for error messages
std::string read_source(const std::string& path_or_xml, std::string* where) {
  if (looks_like_xml(path_or_xml)) {
    *where = "URDF string";
    return path_or_xml;
  }
  *where = msg("URDF file '", path_or_xml, "'");
  std::error_code ec;
  if (path_or_xml.empty() || !std::filesystem::exists(path_or_xml, ec)) {
    throw UrdfError(msg("URDF file '", path_or_xml, "' not found"));
  }
  if (std::filesystem::is_directory(path_or_xml, ec)) {
    throw UrdfError(msg("URDF file '", path_or_xml, "' is a directory"));
  }
  std::ifstream in(path_or_xml, std::ios::in | std::ios::binary);
  if (!in) throw UrdfError(msg("URDF file '", path_or_xml, "' cannot be opened"));
  std::ostringstream os;
  os << in.rdbuf();
  if (in.bad()) throw UrdfError(msg("URDF file '", path_or_xml, "' cannot be read"));
  return os.str();
}

std::string attribute(const tinyxml2::XMLElement* e, const char* name) {
  const char* v = e ? e->Attribute(name) : nullptr;
  return v ? std::string(v) : std::string();
}

// an <inertial> number urdfdom needs: without it urdfdom logs an error and keeps a partly filled
// (or no) inertial, which must not pass for a massless link
void check_number(const tinyxml2::XMLElement* e, const char* element, const char* name,
                  const std::string& link) {
  double v = 0.0;
  if (!e) throw UrdfError(msg("URDF link '", link, "': <inertial> without <", element, ">"));
  if (e->QueryDoubleAttribute(name, &v) != tinyxml2::XML_SUCCESS) {
    throw UrdfError(msg("URDF link '", link, "': <", element, "> needs a number in '", name,
                        "', got '", attribute(e, name), "'"));
  }
}

// what the first pass keeps
struct Document {
  std::vector<JointDecl> joints;   // in document order
  std::set<std::string> inertial;  // links with an <inertial> element
};

// first pass: XML well-formedness, link names, and the <joint> elements in document order with
// their types and the tree structure checked
Document scan_document(const std::string& xml, const std::string& where) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS) {
    throw UrdfError(msg(where, ": malformed XML: ", doc.ErrorStr()));
  }
  const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  if (!robot) throw UrdfError(msg(where, ": no <robot> root element"));

  // links: named and unique; an <inertial> needs <mass> and <inertia> (urdfdom would drop it)
  Document out;
  std::set<std::string> links;
  for (auto* e = robot->FirstChildElement("link"); e; e = e->NextSiblingElement("link")) {
    const std::string name = attribute(e, "name");
    if (name.empty()) {
      throw UrdfError(msg(where, ": <link> without a name (line ", e->GetLineNum(), ")"));
    }
    if (!links.insert(name).second) throw UrdfError(msg("URDF link '", name, "' is defined twice"));
    if (const tinyxml2::XMLElement* in = e->FirstChildElement("inertial")) {
      check_number(in->FirstChildElement("mass"), "mass", "value", name);
      for (const char* a : {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"}) {
        check_number(in->FirstChildElement("inertia"), "inertia", a, name);
      }
      out.inertial.insert(name);
    }
  }
  if (links.empty()) throw UrdfError(msg(where, ": no <link> elements"));

  // joints, only the direct children of <robot> (a <transmission> also holds <joint> elements)
  std::vector<JointDecl>& joints = out.joints;
  std::set<std::string> joint_names;
  std::map<std::string, std::string> parent_joint;  // child link -> joint
  for (auto* e = robot->FirstChildElement("joint"); e; e = e->NextSiblingElement("joint")) {
    JointDecl d;
    d.name = attribute(e, "name");
    d.type = attribute(e, "type");
    d.parent = attribute(e->FirstChildElement("parent"), "link");
    d.child = attribute(e->FirstChildElement("child"), "link");
    if (d.name.empty()) {
      throw UrdfError(msg(where, ": <joint> without a name (line ", e->GetLineNum(), ")"));
    }
    if (!joint_names.insert(d.name).second) {
      throw UrdfError(msg("URDF joint '", d.name, "' is defined twice"));
    }

    // supported types: revolute, continuous, prismatic, fixed
    if (d.type == "floating" || d.type == "planar") {
      throw UrdfError(msg("URDF joint '", d.name, "': unsupported joint type '", d.type,
                          "' (supported: revolute, continuous, prismatic, fixed)"));
    }
    if (d.type != "revolute" && d.type != "continuous" && d.type != "prismatic" &&
        d.type != "fixed") {
      throw UrdfError(msg("URDF joint '", d.name, "': unknown joint type '", d.type,
                          "' (supported: revolute, continuous, prismatic, fixed)"));
    }

    // parent and child: present, defined, distinct, one parent joint per link
    if (d.parent.empty()) throw UrdfError(msg("URDF joint '", d.name, "': no <parent link=...>"));
    if (d.child.empty()) throw UrdfError(msg("URDF joint '", d.name, "': no <child link=...>"));
    if (!links.count(d.parent)) {
      throw UrdfError(
          msg("URDF joint '", d.name, "': parent link '", d.parent, "' is not defined"));
    }
    if (!links.count(d.child)) {
      throw UrdfError(msg("URDF joint '", d.name, "': child link '", d.child, "' is not defined"));
    }
    if (d.parent == d.child) {
      throw UrdfError(msg("URDF joint '", d.name, "' connects link '", d.parent, "' to itself"));
    }
    auto [it, fresh] = parent_joint.emplace(d.child, d.name);
    if (!fresh) {
      throw UrdfError(msg("URDF link '", d.child, "' is the child of two joints, '", it->second,
                          "' and '", d.name, "'"));
    }

    // the URDF spec requires <limit> on revolute and prismatic joints (urdfdom enforces it)
    if ((d.type == "revolute" || d.type == "prismatic") && !e->FirstChildElement("limit")) {
      throw UrdfError(msg("URDF joint '", d.name, "': a ", d.type, " joint needs a <limit>"));
    }
    joints.push_back(d);
  }

  // exactly one root: the one link that is nobody's child
  std::vector<std::string> roots;
  for (const std::string& l : links) {
    if (!parent_joint.count(l)) roots.push_back(l);
  }
  if (roots.empty()) {
    throw UrdfError(msg(where, ": no root link (every link is a joint's child: a cycle)"));
  }
  if (roots.size() > 1) {
    std::string names;
    for (const std::string& r : roots) names += (names.empty() ? "'" : ", '") + r + "'";
    throw UrdfError(msg(where, ": several root links (", names,
                        "); a URDF must be one tree, connect them with joints"));
  }
  return out;
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
    throw UrdfError(msg(where, ": urdfdom could not parse the URDF",
                        reason.empty() ? std::string(" (see its log on stderr)") : ": " + reason));
  }
  if (!model->getRoot()) throw UrdfError(msg(where, ": urdfdom found no root link"));
  return model;
}

// inertia tensor of a URDF <inertial> (about its origin, in its axes)
Mat3 inertia_matrix(const urdf::Inertial& in) {
  Mat3 i;
  i << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
  return i;
}

// a group of links welded by fixed joints: one body
struct Group {
  std::string top;                 // its first (top) link: names the body, gives its frame
  std::vector<std::string> links;  // top first
  double mass = 0.0;
  Vec3 com = Vec3::Zero();      // world
  Mat3 inertia = Mat3::Zero();  // about com, in the top link's axes
};

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
      declared_[attribute(e, "name")] = d;
    }
  }
  const std::string& xml_;
  bool parsed_ = false;
  std::map<std::string, std::array<double, 7>> declared_;
};

}  // namespace

ModelBuilder urdf_builder(const std::string& path_or_xml, bool fixed_base, const Vec3& gravity,
                          bool physical_inertia) {
  std::string where;
  const std::string xml = read_source(path_or_xml, &where);
  const Document document = scan_document(xml, where);
  const std::vector<JointDecl>& decls = document.joints;
  const urdf::ModelInterfaceSharedPtr urdf_model = parse_urdfdom(xml, where);
  const urdf::LinkConstSharedPtr root = urdf_model->getRoot();
  const std::string root_name = root->name;

  // urdfdom logs an <inertial> it cannot read and drops it: never take that as "massless"
  for (const std::string& name : document.inertial) {
    const urdf::LinkConstSharedPtr link = urdf_model->getLink(name);
    if (!link || !link->inertial) {
      throw UrdfError(msg("URDF link '", name, "': urdfdom could not read its <inertial>"));
    }
  }

  // world pose of every link frame at q = 0 and the top link of its fixed group, from the root;
  // a child link frame is its joint frame (parent link frame composed with the joint origin)
  std::map<std::string, Frame> frame;
  std::map<std::string, std::string> top_of;
  std::map<std::string, Group> groups;
  std::vector<std::string> group_order;  // tops in depth-first order from the root
  frame[root_name] = Frame();
  top_of[root_name] = root_name;
  std::vector<urdf::LinkConstSharedPtr> todo{root};
  while (!todo.empty()) {
    const urdf::LinkConstSharedPtr link = todo.back();
    todo.pop_back();
    const std::string& top = top_of.at(link->name);
    if (top == link->name) {
      groups[top].top = top;
      group_order.push_back(top);
    }
    groups[top].links.push_back(link->name);
    for (const urdf::JointSharedPtr& j : link->child_joints) {
      const std::string& c = j->child_link_name;
      if (frame.count(c)) throw UrdfError(msg("URDF link '", c, "' is reached twice"));
      const Frame f = compose(frame.at(link->name), to_frame(j->parent_to_joint_origin_transform));
      if (!finite_frame(f)) throw UrdfError(msg("URDF joint '", j->name, "': non-finite origin"));
      frame[c] = f;
      top_of[c] = j->type == urdf::Joint::FIXED ? top : c;
      const urdf::LinkConstSharedPtr child = urdf_model->getLink(c);
      if (!child) throw UrdfError(msg("URDF joint '", j->name, "': child link '", c, "' missing"));
      todo.push_back(child);
    }
  }
  for (const auto& kv : urdf_model->links_) {
    if (!frame.count(kv.first)) {
      throw UrdfError(msg("URDF link '", kv.first, "' is not connected to the root link '",
                          root_name, "' (the joints form a cycle)"));
    }
  }

  // the ground group (fixed base) needs no mass; every other group becomes a body with mass
  auto is_ground = [&](const std::string& top) { return fixed_base && top == root_name; };
  auto body_of = [&](const std::string& link) {
    const std::string& top = top_of.at(link);
    return is_ground(top) ? std::string("ground") : top;
  };

  // merge each group: total mass, centre of mass, inertia about it (parallel-axis theorem),
  // every link inertia rotated by its inertial rpy and its link frame into world axes first.
  // The tensors are checked (physical_inertia: each body's is physically consistent and each
  // merged link's positive semidefinite, as add_body would; otherwise each link's is positive
  // semidefinite, round-off negatives clamped) and every offender is listed at once.
  // A group without mass (massless links between joints) is a massless body at its top link's
  // origin; finalize() checks that every joint motion still carries inertia.
  std::vector<std::string> bad_inertia;  // "'link' (principal moments a, b, c kg m^2: why)"
  std::vector<std::string> clamp_notes;
  DeclaredInertials declared(xml);
  // the robot's largest link moment: the scale of round-off in its tensors (physical_inertia
  // false: CAD exports write point masses as tensors of 1e-20 with either sign)
  double robot_moment = 0.0;
  for (const std::string& top : group_order) {
    if (is_ground(top)) continue;
    for (const std::string& name : groups.at(top).links) {
      const urdf::LinkConstSharedPtr link = urdf_model->getLink(name);
      if (!link->inertial) continue;
      const Mat3 i_local = inertia_matrix(*link->inertial);
      if (!i_local.allFinite()) continue;  // refused below
      robot_moment =
          std::max(robot_moment, Eigen::SelfAdjointEigenSolver<Mat3>(i_local).eigenvalues()(2));
    }
  }
  for (const std::string& top : group_order) {
    Group& g = groups.at(top);
    const bool merged = g.links.size() > 1;
    struct Part {
      double m;
      Vec3 c;
      Mat3 i;
    };
    std::vector<Part> parts;
    for (const std::string& name : g.links) {
      const urdf::LinkConstSharedPtr link = urdf_model->getLink(name);
      if (!link->inertial) continue;
      const urdf::Inertial& in = *link->inertial;
      const Frame f = compose(frame.at(name), to_frame(in.origin));
      const Mat3 i_local = inertia_matrix(in);
      if (!std::isfinite(in.mass) || !i_local.allFinite() || !finite_frame(f)) {
        throw UrdfError(msg("URDF link '", name, "': non-finite inertial data"));
      }
      if (in.mass < 0) throw UrdfError(msg("URDF link '", name, "': negative mass ", in.mass));
      if (is_ground(top)) continue;
      if (in.mass == 0.0) declared.check(name, in);
      if (physical_inertia) {
        // a link merged with others may be a point mass, but its inertia must still be positive
        // semi-definite; the triangle inequality is the body's (checked below, as add_body does)
        // (a lone link's tensor is its body's: checked here, in its own axes)
        const InertiaCheck ic = check_inertia(i_local, true);
        const Vec3& p = ic.moments;
        if (merged ? p[0] < -1e-12 * std::max(1.0, i_local.trace()) : !ic.problem.empty()) {
          bad_inertia.push_back(
              msg("'", name, "' (principal moments ", p[0], ", ", p[1], ", ", p[2],
                  " kg m^2: ", merged ? "is not positive semidefinite" : ic.problem, ")"));
          continue;
        }
        parts.push_back({in.mass, f.p, f.R * i_local * f.R.transpose()});
        continue;
      }
      const InertiaCheck ic = check_inertia(i_local, false, robot_moment);
      if (!ic.problem.empty()) {
        const Vec3& p = ic.moments;
        bad_inertia.push_back(msg("'", name, "' (principal moments ", p[0], ", ", p[1], ", ", p[2],
                                  " kg m^2: ", ic.problem, ")"));
        continue;
      }
      if (ic.warn) {
        clamp_notes.push_back(msg("URDF link '", name, "': negative principal moment ", ic.smallest,
                                  " kg m^2 (round-off) clamped to zero"));
      }
      parts.push_back({in.mass, f.p, f.R * ic.tensor * f.R.transpose()});
    }
    if (is_ground(top)) continue;

    for (const Part& p : parts) {
      g.mass += p.m;
      g.com += p.m * p.c;
    }
    g.com = g.mass > 0 ? Vec3(g.com / g.mass) : frame.at(top).p;
    Mat3 i_world = Mat3::Zero();
    for (const Part& p : parts) {
      const Vec3 d = p.c - g.com;
      i_world += p.i + p.m * (d.squaredNorm() * Mat3::Identity() - d * d.transpose());
    }
    const Mat3& r_top = frame.at(top).R;
    const Mat3 i_body = r_top.transpose() * i_world * r_top;
    g.inertia = 0.5 * (i_body + i_body.transpose());
    if (physical_inertia && merged) {
      // the body's tensor, as add_body checks it: its links' sum
      const InertiaCheck ic = check_inertia(g.inertia, true);
      if (!ic.problem.empty()) {
        const Vec3& p = ic.moments;
        const std::string also = msg(" (merged with ", list_names(g.links, 1), ")");
        bad_inertia.push_back(msg("'", top, "'", also, " (principal moments ", p[0], ", ", p[1],
                                  ", ", p[2], " kg m^2: ", ic.problem, ")"));
      }
    }
  }
  if (!bad_inertia.empty()) {
    std::string list;
    for (const std::string& b : bad_inertia) list += (list.empty() ? "" : "; ") + b;
    const std::string links =
        msg(bad_inertia.size(), bad_inertia.size() == 1 ? " link: " : " links: ");
    throw UrdfError(
        physical_inertia
            ? msg(where, ": inertia not physically consistent on ", links, list,
                  "; load with physical_inertia=False to accept any positive semidefinite tensor")
            : msg(where, ": inertia not positive semidefinite on ", links, list,
                  " (physical_inertia=False clamps only round-off, down to -1e-12 of the "
                  "largest moment, ",
                  robot_moment, " kg m^2)"));
  }

  ModelBuilder builder(gravity, physical_inertia);
  for (const std::string& note : clamp_notes) builder.add_warning(note);
  std::set<std::string> added;  // groups whose body exists
  auto add_group_body = [&](const std::string& top) {
    const Group& g = groups.at(top);
    try {
      builder.add_body(top, g.mass, g.inertia, g.com, rot_to_quat(frame.at(top).R));
    } catch (const UrdfError&) {
      throw;
    } catch (const ModelError& e) {
      const std::string also =
          g.links.size() > 1 ? msg(" (merged with ", list_names(g.links, 1), ")") : "";
      throw UrdfError(msg("URDF link '", top, "'", also, ": ", e.what()));
    }
    added.insert(top);
  };
  // the body of a group, after the bodies of all its ancestors (parent before child)
  auto ensure_body = [&](const std::string& top) {
    std::vector<std::string> chain;
    for (std::string t = top; !is_ground(t) && !added.count(t);) {
      chain.push_back(t);
      if (t == root_name) break;
      t = top_of.at(urdf_model->getLink(t)->parent_joint->parent_link_name);
    }
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) add_group_body(*it);
  };

  // floating base: the root body first, declared free
  if (!fixed_base) {
    ensure_body(root_name);
    std::string free_name = "root_free";
    while (urdf_model->getJoint(free_name)) free_name += "_";
    try {
      builder.add_free(free_name, root_name);
    } catch (const UrdfError&) {
      throw;
    } catch (const ModelError& e) {
      throw UrdfError(msg("URDF link '", root_name, "': ", e.what()));
    }
  }

  // all bodies first, in the order the moving joints first need them (ancestors first)
  for (const JointDecl& d : decls) {
    if (d.type != "fixed") ensure_body(top_of.at(d.child));
  }

  // then the moving joints in document order (this order defines the joint-space arrays)
  for (const JointDecl& d : decls) {
    if (d.type == "fixed") continue;
    const urdf::JointConstSharedPtr j = urdf_model->getJoint(d.name);
    if (!j) throw UrdfError(msg("URDF joint '", d.name, "': not found by urdfdom"));
    // the joint frame is the child link frame at q = 0
    const Frame& jf = frame.at(j->child_link_name);
    const Vec3 axis_local(j->axis.x, j->axis.y, j->axis.z);
    if (!axis_local.allFinite()) throw UrdfError(msg("URDF joint '", d.name, "': non-finite axis"));
    if (axis_local.norm() < 1e-12) {
      throw UrdfError(msg("URDF joint '", d.name, "': axis has zero length"));
    }
    const Vec3 axis = jf.R * axis_local.normalized();
    const std::string parent = body_of(j->parent_link_name);
    const std::string child = body_of(j->child_link_name);
    try {
      if (j->type == urdf::Joint::PRISMATIC) {
        builder.add_prismatic(d.name, parent, child, jf.p, axis);
      } else {
        builder.add_revolute(d.name, parent, child, jf.p, axis);
      }
      // continuous joints keep unbounded positions; effort/velocity are informative
      if (j->limits) {
        const urdf::JointLimits& lim = *j->limits;
        const bool continuous = j->type == urdf::Joint::CONTINUOUS;
        builder.set_joint_limits(d.name, continuous ? -kUnbounded : clamp_limit(lim.lower),
                                 continuous ? kUnbounded : clamp_limit(lim.upper),
                                 clamp_limit(lim.effort), clamp_limit(lim.velocity));
      }
    } catch (const UrdfError&) {
      throw;
    } catch (const ModelError& e) {
      throw UrdfError(msg("URDF joint '", d.name, "': ", e.what()));
    }
  }
  return builder;
}

}  // namespace armdyn
