// SPDX-License-Identifier: BSD-3-Clause
// The URDF reader's stage 1 (urdf_scan.hpp): the first pass over the XML with tinyxml2, as a
// list of stages -- parse the <robot>, check the materials' numbers, scan the links, scan the
// joints, find the one root.
#include "urdf_scan.hpp"

#include <tinyxml2.h>

#include <charconv>
#include <cmath>
#include <initializer_list>
#include <map>
#include <string_view>

#include "armdyn/errors.hpp"
#include "armdyn/poll.hpp"
#include "urdf_source.hpp"
#include "utf8.hpp"

namespace armdyn::urdf_import {
namespace {

std::string attribute(const tinyxml2::XMLElement* e, const char* name) {
  const char* v = e ? e->Attribute(name) : nullptr;
  return v ? std::string(v) : std::string();
}

// every name-like attribute (name, link, joint) of every element must be valid UTF-8: names
// reach body_names, summary() and every message
void check_names_utf8(const tinyxml2::XMLElement* e, const std::string& where) {
  for (; e; e = e->NextSiblingElement()) {
    for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a; a = a->Next()) {
      const std::string key = a->Name();
      if (key != "name" && key != "link" && key != "joint") continue;
      const std::string value = a->Value();
      const size_t bad = utf8_error(value);
      if (bad != std::string::npos) {
        throw UrdfError(msg(where, ": <", excerpt(e->Name()), "> on line ", e->GetLineNum(),
                            ": attribute '", key, "' is not valid UTF-8 (byte offset ", bad, "): '",
                            excerpt(value), "'"));
      }
    }
    check_names_utf8(e->FirstChildElement(), where);
  }
}

// one number, parsed completely: empty reason when it is a finite double
std::string number_problem(std::string_view s, double* value) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  if (s.empty()) return "is empty";
  double v = 0.0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec == std::errc::invalid_argument) return "is not a number";
  if (r.ec == std::errc::result_out_of_range) return "is out of the range of a double";
  if (r.ptr != s.data() + s.size()) return "has trailing characters after the number";
  if (!std::isfinite(v)) return "is not finite";
  if (value) *value = v;
  return "";
}

// The attribute `attr` of element `e` (when present) holds `count` whitespace-separated finite
// numbers. owner: "link 'x'" or "joint 'y'"; path: the elements from the owner down, "<origin>".
void check_numbers(const tinyxml2::XMLElement* e, const std::string& owner, const std::string& path,
                   const char* attr, int count) {
  const char* raw = e->Attribute(attr);
  if (!raw) return;
  const std::string_view value(raw);
  auto fail = [&](const std::string& what) {
    throw UrdfError(msg("URDF ", owner, ": ", path, " attribute '", attr, "' ", what, ": \"",
                        excerpt(value), "\" (line ", e->GetLineNum(), ")"));
  };
  std::vector<std::string_view> parts;
  size_t i = 0;
  const char* space = " \t\r\n";
  while (i < value.size()) {
    const size_t a = value.find_first_not_of(space, i);
    if (a == std::string_view::npos) break;
    size_t b = value.find_first_of(space, a);
    if (b == std::string_view::npos) b = value.size();
    parts.push_back(value.substr(a, b - a));
    i = b;
  }
  if (static_cast<int>(parts.size()) != count) {
    if (count == 1 && parts.empty()) fail("is empty");
    if (count == 1) fail(msg("needs one number, got ", parts.size(), " values"));
    fail(msg("needs ", count, " numbers, got ", parts.size()));
  }
  for (size_t k = 0; k < parts.size(); ++k) {
    const std::string why = number_problem(parts[k], nullptr);
    if (!why.empty()) {
      fail(count == 1
               ? why
               : msg("component ", k + 1, " of ", count, " (\"", excerpt(parts[k]), "\") ", why));
    }
  }
}

// every numeric attribute of the children named `child` of `parent`
struct NumberSpec {
  const char* attr;
  int count;
};
void check_children(const tinyxml2::XMLElement* parent, const char* child, const std::string& owner,
                    const std::string& path, std::initializer_list<NumberSpec> specs) {
  for (auto* e = parent->FirstChildElement(child); e; e = e->NextSiblingElement(child)) {
    for (const NumberSpec& s : specs)
      check_numbers(e, owner, path + "<" + child + ">", s.attr, s.count);
  }
}

// visual and collision: origins, geometry sizes, material colours (armdyn ignores them, urdfdom
// reads them)
void check_shape_numbers(const tinyxml2::XMLElement* link, const std::string& owner) {
  for (const char* kind : {"visual", "collision"}) {
    for (auto* v = link->FirstChildElement(kind); v; v = v->NextSiblingElement(kind)) {
      const std::string path = msg("<", kind, ">");
      check_children(v, "origin", owner, path, {{"xyz", 3}, {"rpy", 3}});
      for (auto* g = v->FirstChildElement("geometry"); g; g = g->NextSiblingElement("geometry")) {
        const std::string gp = path + "<geometry>";
        check_children(g, "box", owner, gp, {{"size", 3}});
        check_children(g, "cylinder", owner, gp, {{"radius", 1}, {"length", 1}});
        check_children(g, "capsule", owner, gp, {{"radius", 1}, {"length", 1}});
        check_children(g, "sphere", owner, gp, {{"radius", 1}});
        check_children(g, "mesh", owner, gp, {{"scale", 3}});
      }
      for (auto* mt = v->FirstChildElement("material"); mt;
           mt = mt->NextSiblingElement("material")) {
        check_children(mt, "color", owner, path + "<material>", {{"rgba", 4}});
      }
    }
  }
}

// every numeric attribute urdfdom reads, before it reads them (it turns nan, inf and 1e400 into
// zeros silently)
void check_link_numbers(const tinyxml2::XMLElement* link, const std::string& name) {
  const std::string owner = msg("link '", nm(name), "'");
  for (auto* in = link->FirstChildElement("inertial"); in;
       in = in->NextSiblingElement("inertial")) {
    check_children(in, "origin", owner, "<inertial>", {{"xyz", 3}, {"rpy", 3}});
    check_children(in, "mass", owner, "<inertial>", {{"value", 1}});
    check_children(in, "inertia", owner, "<inertial>",
                   {{"ixx", 1}, {"ixy", 1}, {"ixz", 1}, {"iyy", 1}, {"iyz", 1}, {"izz", 1}});
  }
  check_shape_numbers(link, owner);
}

void check_joint_numbers(const tinyxml2::XMLElement* joint, const std::string& name) {
  const std::string owner = msg("joint '", nm(name), "'");
  check_children(joint, "origin", owner, "", {{"xyz", 3}, {"rpy", 3}});
  check_children(joint, "axis", owner, "", {{"xyz", 3}});
  check_children(joint, "limit", owner, "",
                 {{"lower", 1}, {"upper", 1}, {"effort", 1}, {"velocity", 1}});
  check_children(joint, "dynamics", owner, "", {{"damping", 1}, {"friction", 1}});
  check_children(joint, "mimic", owner, "", {{"multiplier", 1}, {"offset", 1}});
  check_children(
      joint, "safety_controller", owner, "",
      {{"soft_lower_limit", 1}, {"soft_upper_limit", 1}, {"k_position", 1}, {"k_velocity", 1}});
  check_children(joint, "calibration", owner, "",
                 {{"rising", 1}, {"falling", 1}, {"reference_position", 1}});
}

// an <inertial> number urdfdom needs: without it urdfdom logs an error and keeps a partly filled
// (or no) inertial, which must not pass for a massless link
void check_number(const tinyxml2::XMLElement* e, const char* element, const char* name,
                  const std::string& link) {
  double v = 0.0;
  if (!e) throw UrdfError(msg("URDF link '", nm(link), "': <inertial> without <", element, ">"));
  if (e->QueryDoubleAttribute(name, &v) != tinyxml2::XML_SUCCESS) {
    throw UrdfError(msg("URDF link '", nm(link), "': <", element, "> needs a number in '", name,
                        "', got '", excerpt(attribute(e, name)), "'"));
  }
}

// the <robot> element of a well-formed document whose names are valid UTF-8
const tinyxml2::XMLElement* parse_robot(tinyxml2::XMLDocument& doc, const std::string& xml,
                                        const std::string& where) {
  if (doc.Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS) {
    throw UrdfError(msg(where, ": malformed XML: ", excerpt(doc.ErrorStr(), 200)));
  }
  const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  if (!robot) throw UrdfError(msg(where, ": no <robot> root element"));
  check_names_utf8(doc.FirstChildElement(), where);
  return robot;
}

// the colours of the top-level <material> elements
void check_material_numbers(const tinyxml2::XMLElement* robot) {
  for (auto* mt = robot->FirstChildElement("material"); mt;
       mt = mt->NextSiblingElement("material")) {
    check_children(mt, "color", msg("material '", nm(attribute(mt, "name")), "'"), "",
                   {{"rgba", 4}});
  }
}

// links: named and unique, their numbers checked; an <inertial> needs <mass> and <inertia>
// (urdfdom would drop it). The link names; the links with an <inertial> into *inertial.
std::set<std::string> scan_links(const tinyxml2::XMLElement* robot, const std::string& where,
                                 std::set<std::string>* inertial) {
  std::set<std::string> links;
  for (auto* e = robot->FirstChildElement("link"); e; e = e->NextSiblingElement("link")) {
    poll_point();
    const std::string name = attribute(e, "name");
    if (name.empty()) {
      throw UrdfError(msg(where, ": <link> without a name (line ", e->GetLineNum(), ")"));
    }
    if (!links.insert(name).second) {
      throw UrdfError(msg("URDF link '", nm(name), "' is defined twice"));
    }
    check_link_numbers(e, name);
    if (const tinyxml2::XMLElement* in = e->FirstChildElement("inertial")) {
      check_number(in->FirstChildElement("mass"), "mass", "value", name);
      for (const char* a : {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"}) {
        check_number(in->FirstChildElement("inertia"), "inertia", a, name);
      }
      inertial->insert(name);
    }
  }
  if (links.empty()) throw UrdfError(msg(where, ": no <link> elements"));
  return links;
}

// supported types: revolute, continuous, prismatic, fixed
void check_joint_type(const JointDecl& d) {
  if (d.type == "floating" || d.type == "planar") {
    throw UrdfError(msg("URDF joint '", nm(d.name), "': unsupported joint type '", nm(d.type),
                        "' (supported: revolute, continuous, prismatic, fixed)"));
  }
  if (d.type != "revolute" && d.type != "continuous" && d.type != "prismatic" &&
      d.type != "fixed") {
    throw UrdfError(msg("URDF joint '", nm(d.name), "': unknown joint type '", nm(d.type),
                        "' (supported: revolute, continuous, prismatic, fixed)"));
  }
}

// parent and child: present, defined, distinct, one parent joint per link (recorded in
// *parent_joint: child link -> joint)
void check_joint_links(const JointDecl& d, const std::set<std::string>& links,
                       std::map<std::string, std::string>* parent_joint) {
  if (d.parent.empty()) throw UrdfError(msg("URDF joint '", nm(d.name), "': no <parent link=...>"));
  if (d.child.empty()) throw UrdfError(msg("URDF joint '", nm(d.name), "': no <child link=...>"));
  if (!links.count(d.parent)) {
    throw UrdfError(
        msg("URDF joint '", nm(d.name), "': parent link '", nm(d.parent), "' is not defined"));
  }
  if (!links.count(d.child)) {
    throw UrdfError(
        msg("URDF joint '", nm(d.name), "': child link '", nm(d.child), "' is not defined"));
  }
  if (d.parent == d.child) {
    throw UrdfError(
        msg("URDF joint '", nm(d.name), "' connects link '", nm(d.parent), "' to itself"));
  }
  auto [it, fresh] = parent_joint->emplace(d.child, d.name);
  if (!fresh) {
    throw UrdfError(msg("URDF link '", nm(d.child), "' is the child of two joints, '",
                        nm(it->second), "' and '", nm(d.name), "'"));
  }
}

// joints, only the direct children of <robot> (a <transmission> also holds <joint> elements), in
// document order: named and unique, their numbers, type and links checked, and the <limit> the
// URDF spec requires on revolute and prismatic joints (urdfdom enforces it)
std::vector<JointDecl> scan_joints(const tinyxml2::XMLElement* robot,
                                   const std::set<std::string>& links, const std::string& where,
                                   std::map<std::string, std::string>* parent_joint) {
  std::vector<JointDecl> joints;
  std::set<std::string> joint_names;
  for (auto* e = robot->FirstChildElement("joint"); e; e = e->NextSiblingElement("joint")) {
    poll_point();
    JointDecl d;
    d.name = attribute(e, "name");
    d.type = attribute(e, "type");
    d.parent = attribute(e->FirstChildElement("parent"), "link");
    d.child = attribute(e->FirstChildElement("child"), "link");
    if (d.name.empty()) {
      throw UrdfError(msg(where, ": <joint> without a name (line ", e->GetLineNum(), ")"));
    }
    if (!joint_names.insert(d.name).second) {
      throw UrdfError(msg("URDF joint '", nm(d.name), "' is defined twice"));
    }
    check_joint_numbers(e, d.name);
    check_joint_type(d);
    check_joint_links(d, links, parent_joint);
    if ((d.type == "revolute" || d.type == "prismatic") && !e->FirstChildElement("limit")) {
      throw UrdfError(
          msg("URDF joint '", nm(d.name), "': a ", nm(d.type), " joint needs a <limit>"));
    }
    joints.push_back(d);
  }
  return joints;
}

// exactly one root: the one link that is nobody's child
void check_one_root(const std::set<std::string>& links,
                    const std::map<std::string, std::string>& parent_joint,
                    const std::string& where) {
  std::vector<std::string> roots;
  for (const std::string& l : links) {
    if (!parent_joint.count(l)) roots.push_back(l);
  }
  if (roots.empty()) {
    throw UrdfError(msg(where, ": no root link (every link is a joint's child: a cycle)"));
  }
  if (roots.size() > 1) {
    std::string names;
    for (size_t k = 0; k < roots.size() && k < 8; ++k) {
      names += (k ? ", '" : "'") + nm(roots[k]) + "'";
    }
    if (roots.size() > 8) names += msg(", ... (", roots.size(), " in all)");
    throw UrdfError(msg(where, ": several root links (", names,
                        "); a URDF must be one tree, connect them with joints"));
  }
}

}  // namespace

Document scan_document(const std::string& xml, const std::string& where) {
  tinyxml2::XMLDocument doc;
  const tinyxml2::XMLElement* robot = parse_robot(doc, xml, where);
  check_material_numbers(robot);
  Document out;
  const std::set<std::string> links = scan_links(robot, where, &out.inertial);
  std::map<std::string, std::string> parent_joint;  // child link -> joint
  out.joints = scan_joints(robot, links, where, &parent_joint);
  check_one_root(links, parent_joint, where);
  return out;
}

}  // namespace armdyn::urdf_import
