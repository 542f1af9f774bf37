// SPDX-License-Identifier: BSD-3-Clause
// URDF loader (documented element by element in docs/urdf.md). Passes over the input:
//  0. the source: a string starting with '<' is XML, anything else a path, which must name a
//     regular file (stat before open: a FIFO or a device is refused, never read) of at most
//     kUrdfMaxBytes; then a linear pre-scan of the raw text refuses NUL bytes and elements with
//     more than kUrdfMaxAttributes attributes (tinyxml2 is quadratic in them);
//  1. tinyxml2: names valid UTF-8; every numeric attribute (origins, axes, inertials, limits,
//     dynamics, mimic, safety_controller, calibration, visual/collision geometry, colours)
//     parsed completely as a finite double before urdfdom sees it (urdfdom zeroes nan, inf and
//     1e400 silently); the document order of <joint> elements (urdfdom keeps joints in a
//     std::map sorted by name), joint types and the tree structure, with error messages that
//     name the culprit and quote short, escaped excerpts only;
//  2. urdfdom (urdf::parseURDF): the full parse of poses, axes, limits and inertials.
// Every loop over the links and joints is a poll point (Ctrl-C; the two parses are not).
// Then every group of links joined by fixed joints is merged into one body, bodies are added
// parent-before-child, and the moving joints are added in document order with their <limit>
// and their <dynamics> (damping: viscous friction; friction: Coulomb friction smoothed with
// kUrdfCoulombSmoothing). With a fixed base and no moving joint the builder has no bodies: a
// zero-DOF model. Then (mimic = true) each <mimic> becomes a coupling (add_coupling).
//
// Ignored (numbers checked, nothing imported): <visual>, <collision>, <material>,
// <transmission>, <gazebo>, <safety_controller>, <calibration>; <mimic> with mimic = false.
//
// urdfdom reports its own parse errors through console_bridge. When the build defines
// ARMDYN_HAVE_CONSOLE_BRIDGE (and links console_bridge::console_bridge) those messages are
// captured into the UrdfError; otherwise they only reach stderr.
#include "armdyn/io/urdf.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <tinyxml2.h>
#include <unistd.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <initializer_list>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "armdyn/errors.hpp"
#include "armdyn/math/quaternion.hpp"
#include "armdyn/poll.hpp"
#include "utf8.hpp"

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
  // a UTF-8 byte order mark may precede the XML (tinyxml2 skips it)
  const size_t from = s.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
  for (size_t i = from; i < s.size(); ++i) {
    const char c = s[i];
    if (std::isspace(static_cast<unsigned char>(c))) continue;
    return c == '<';
  }
  return false;
}

// s with its control characters and invalid UTF-8 bytes escaped as \xNN, cut to at most about
// `max_chars` characters (an ellipsis marks the cut): always valid UTF-8, always short
std::string excerpt(const std::string_view s, size_t max_chars = 40) {
  std::string out;
  size_t shown = 0;
  for (size_t i = 0; i < s.size();) {
    if (shown >= max_chars) {
      out += "...";
      break;
    }
    const size_t n = utf8_sequence(s, i);
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (n == 0 || (n == 1 && (c < 0x20 || c == 0x7F))) {
      static const char* hex = "0123456789abcdef";
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
      i += 1;
    } else {
      out.append(s.data() + i, n);
      i += n;
    }
    ++shown;
  }
  return out;
}

// a name as quoted in messages: escaped and at most 80 characters
std::string nm(const std::string& name) { return excerpt(name, 80); }

// a path as quoted in messages: its head and its tail when it is long
std::string shown_path(const std::string& path) {
  if (path.size() <= 120) return excerpt(path, 120);
  return excerpt(path.substr(0, 40), 40) + "..." + excerpt(path.substr(path.size() - 60), 60);
}

const char* file_kind(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

std::string too_large(const std::string& what, uint64_t bytes) {
  return msg(what, " is ", bytes, " bytes, more than the limit of ", kUrdfMaxBytes, " bytes (",
             kUrdfMaxBytes >> 20, " MiB)");
}

// the XML text, and a description of where it came from for error messages. A path must name a
// regular file (checked with stat before it is opened, so that a FIFO or a device never blocks
// or streams) of at most kUrdfMaxBytes.
std::string read_source(const std::string& path_or_xml, std::string* where) {
  if (looks_like_xml(path_or_xml)) {
    *where = "URDF string";
    if (path_or_xml.size() > kUrdfMaxBytes)
      throw UrdfError(too_large("URDF string", path_or_xml.size()));
    return path_or_xml;
  }
  const std::string& path = path_or_xml;
  if (path.find_first_not_of(" \t\r\n") == std::string::npos) {
    throw UrdfError("URDF source is empty: expected a file path or URDF XML (starting with '<')");
  }
  if (path.size() > 4096 || path.find('\0') != std::string::npos ||
      path.find('\n') != std::string::npos) {
    throw UrdfError(msg("URDF source is neither XML (it does not start with '<') nor a file path (",
                        path.size(), " bytes): '", excerpt(path), "'"));
  }
  const std::string shown = shown_path(path);
  *where = msg("URDF file '", shown, "'");
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) {
    const int err = errno;
    if (err == ENOENT || err == ENOTDIR) {
      // text with spaces is more likely XML gone wrong than a path
      const bool text = path.find_first_of(" \t") != std::string::npos;
      throw UrdfError(msg("URDF file '", shown, "' not found",
                          text ? " (a URDF string must start with '<')" : ""));
    }
    throw UrdfError(msg("URDF file '", shown, "' cannot be accessed: ", std::strerror(err)));
  }
  if (!S_ISREG(st.st_mode)) {
    throw UrdfError(
        msg("URDF file '", shown, "' is ", file_kind(st.st_mode), ", not a regular file"));
  }
  if (static_cast<uint64_t>(st.st_size) > kUrdfMaxBytes) {
    throw UrdfError(too_large(msg("URDF file '", shown, "'"), static_cast<uint64_t>(st.st_size)));
  }
  // O_NONBLOCK: should the path have been replaced by a FIFO since the stat, open does not wait
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    throw UrdfError(msg("URDF file '", shown, "' cannot be opened: ", std::strerror(errno)));
  }
  struct Close {
    int fd;
    ~Close() { ::close(fd); }
  } close_fd{fd};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    throw UrdfError(msg("URDF file '", shown, "' is not a regular file"));
  }
  std::string text;
  text.reserve(static_cast<size_t>(st.st_size));
  char buf[65536];
  for (;;) {
    const ssize_t r = ::read(fd, buf, sizeof buf);
    if (r < 0) {
      if (errno == EINTR) continue;
      throw UrdfError(msg("URDF file '", shown, "' cannot be read: ", std::strerror(errno)));
    }
    if (r == 0) break;
    text.append(buf, static_cast<size_t>(r));
    if (text.size() > kUrdfMaxBytes)
      throw UrdfError(too_large(msg("URDF file '", shown, "'"), text.size()));
  }
  return text;
}

// Linear pre-scan of the raw text before tinyxml2 (whose duplicate-attribute check is quadratic
// in the attributes of one element): refuses an element with more than kUrdfMaxAttributes
// attributes, and NUL bytes (urdfdom would read the text only up to the first).
void prescan(const std::string& xml, const std::string& where) {
  if (const size_t z = xml.find('\0'); z != std::string::npos) {
    throw UrdfError(msg(where, ": contains a NUL byte at byte offset ", z));
  }
  const size_t n = xml.size();
  size_t i = 0;
  long line = 1;
  // skip to just past `end`, counting lines
  auto skip_past = [&](const char* end) {
    const size_t e = xml.find(end, i);
    const size_t stop = e == std::string::npos ? n : e + std::strlen(end);
    line +=
        std::count(xml.begin() + static_cast<long>(i), xml.begin() + static_cast<long>(stop), '\n');
    i = stop;
  };
  while (i < n) {
    const char c = xml[i];
    if (c == '\n') ++line;
    if (c != '<') {
      ++i;
      continue;
    }
    if (xml.compare(i, 4, "<!--") == 0) {
      skip_past("-->");
      continue;
    }
    if (xml.compare(i, 9, "<![CDATA[") == 0) {
      skip_past("]]>");
      continue;
    }
    if (xml.compare(i, 2, "<?") == 0) {
      skip_past("?>");
      continue;
    }
    if (xml.compare(i, 2, "<!") == 0 || xml.compare(i, 2, "</") == 0) {
      skip_past(">");
      continue;
    }
    // a start tag: count the '=' outside quoted values up to its '>'
    const long tag_line = line;
    const size_t name0 = ++i;
    while (i < n && !std::isspace(static_cast<unsigned char>(xml[i])) && xml[i] != '>' &&
           xml[i] != '/')
      ++i;
    const std::string name = xml.substr(name0, i - name0);
    long attributes = 0;
    char quote = 0;
    for (; i < n; ++i) {
      const char t = xml[i];
      if (t == '\n') ++line;
      if (quote) {
        if (t == quote) quote = 0;
      } else if (t == '"' || t == '\'') {
        quote = t;
      } else if (t == '=') {
        ++attributes;
      } else if (t == '>') {
        ++i;
        break;
      }
    }
    if (attributes > kUrdfMaxAttributes) {
      throw UrdfError(msg(where, ": element <", excerpt(name), "> on line ", tag_line, " has ",
                          attributes, " attributes, more than the limit of ", kUrdfMaxAttributes));
    }
  }
}

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

// what the first pass keeps
struct Document {
  std::vector<JointDecl> joints;   // in document order
  std::set<std::string> inertial;  // links with an <inertial> element
};

// first pass: XML well-formedness, link names, and the <joint> elements in document order with
// their types and the tree structure checked
Document scan_document(const std::string& xml, const std::string& where) {
  prescan(xml, where);
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS) {
    throw UrdfError(msg(where, ": malformed XML: ", excerpt(doc.ErrorStr(), 200)));
  }
  const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  if (!robot) throw UrdfError(msg(where, ": no <robot> root element"));
  check_names_utf8(doc.FirstChildElement(), where);
  for (auto* mt = robot->FirstChildElement("material"); mt;
       mt = mt->NextSiblingElement("material")) {
    check_children(mt, "color", msg("material '", nm(attribute(mt, "name")), "'"), "",
                   {{"rgba", 4}});
  }

  // links: named and unique; an <inertial> needs <mass> and <inertia> (urdfdom would drop it)
  Document out;
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
      out.inertial.insert(name);
    }
  }
  if (links.empty()) throw UrdfError(msg(where, ": no <link> elements"));

  // joints, only the direct children of <robot> (a <transmission> also holds <joint> elements)
  std::vector<JointDecl>& joints = out.joints;
  std::set<std::string> joint_names;
  std::map<std::string, std::string> parent_joint;  // child link -> joint
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

    // supported types: revolute, continuous, prismatic, fixed
    if (d.type == "floating" || d.type == "planar") {
      throw UrdfError(msg("URDF joint '", nm(d.name), "': unsupported joint type '", nm(d.type),
                          "' (supported: revolute, continuous, prismatic, fixed)"));
    }
    if (d.type != "revolute" && d.type != "continuous" && d.type != "prismatic" &&
        d.type != "fixed") {
      throw UrdfError(msg("URDF joint '", nm(d.name), "': unknown joint type '", nm(d.type),
                          "' (supported: revolute, continuous, prismatic, fixed)"));
    }

    // parent and child: present, defined, distinct, one parent joint per link
    if (d.parent.empty())
      throw UrdfError(msg("URDF joint '", nm(d.name), "': no <parent link=...>"));
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
    auto [it, fresh] = parent_joint.emplace(d.child, d.name);
    if (!fresh) {
      throw UrdfError(msg("URDF link '", nm(d.child), "' is the child of two joints, '",
                          nm(it->second), "' and '", nm(d.name), "'"));
    }

    // the URDF spec requires <limit> on revolute and prismatic joints (urdfdom enforces it)
    if ((d.type == "revolute" || d.type == "prismatic") && !e->FirstChildElement("limit")) {
      throw UrdfError(
          msg("URDF joint '", nm(d.name), "': a ", nm(d.type), " joint needs a <limit>"));
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
    for (size_t k = 0; k < roots.size() && k < 8; ++k) {
      names += (k ? ", '" : "'") + nm(roots[k]) + "'";
    }
    if (roots.size() > 8) names += msg(", ... (", roots.size(), " in all)");
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
    // urdfdom's log may quote the input: a short excerpt only
    throw UrdfError(msg(
        where, ": urdfdom could not parse the URDF",
        reason.empty() ? std::string(" (see its log on stderr)") : ": " + excerpt(reason, 400)));
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

}  // namespace

ModelBuilder urdf_builder(const std::string& path_or_xml, bool fixed_base, const Vec3& gravity,
                          bool physical_inertia, bool mimic) {
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
    poll_point();
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
  // merged link's positive semidefinite, as add_body would; otherwise each body's -- a lone
  // link's, or a merged group's sum -- is positive semidefinite, round-off negatives clamped)
  // and every offender is listed at once.
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
    poll_point();
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
      if (merged) {
        // a link merged into a body is no rigid body of its own: only the body's tensor, its
        // links' sum, must be positive semidefinite (checked below); tiago's antenna links
        // (-3.5e-8 kg m^2) on its 28 kg base
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
    if (merged) {
      // the body's tensor, as add_body checks it: its links' sum (round-off clamped without
      // physical_inertia)
      const InertiaCheck ic = check_inertia(g.inertia, physical_inertia, robot_moment);
      const std::string also = msg(" (merged with ", list_names(g.links, 1), ")");
      if (!ic.problem.empty()) {
        const Vec3& p = ic.moments;
        bad_inertia.push_back(msg("'", top, "'", also, " (principal moments ", p[0], ", ", p[1],
                                  ", ", p[2], " kg m^2: ", ic.problem, ")"));
      } else if (!physical_inertia) {
        if (ic.warn)
          clamp_notes.push_back(msg("URDF link '", top, "'", also, ": negative principal moment ",
                                    ic.smallest, " kg m^2 (round-off) clamped to zero"));
        g.inertia = ic.tensor;
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
      // the floating base's frame is the root link's frame (q: its pose, qd: its velocity)
      const Vec3 origin = frame.at(root_name).p;
      builder.add_free(free_name, root_name, &origin);
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
    poll_point();
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
      // <dynamics>: viscous damping and Coulomb friction on the joint coordinate
      if (j->dynamics) {
        const double damping = j->dynamics->damping, friction = j->dynamics->friction;
        if (damping < 0 || friction < 0) {
          throw UrdfError(msg("URDF joint '", d.name,
                              "': <dynamics> damping and friction must be >= 0, got damping ",
                              damping, " and friction ", friction));
        }
        if (damping > 0 || friction > 0) {
          builder.add_joint_friction(d.name, damping, friction, kUrdfCoulombSmoothing);
        }
      }
    } catch (const UrdfError&) {
      throw;
    } catch (const ModelError& e) {
      throw UrdfError(msg("URDF joint '", d.name, "': ", e.what()));
    }
  }

  if (mimic) add_mimic_couplings(builder, decls, *urdf_model);

  // every link stays a named frame (its link frame, not its centre of mass) on the body it was
  // merged into, or on ground: depth-first from the root (children in urdfdom's order)
  std::vector<urdf::LinkConstSharedPtr> pending{root};
  while (!pending.empty()) {
    poll_point();
    const urdf::LinkConstSharedPtr link = pending.back();
    pending.pop_back();
    const Frame& f = frame.at(link->name);
    try {
      builder.add_frame(link->name, body_of(link->name), f.p, rot_to_quat(f.R));
    } catch (const UrdfError&) {
      throw;
    } catch (const ModelError& e) {
      throw UrdfError(msg("URDF link '", link->name, "': ", e.what()));
    }
    for (auto it = link->child_joints.rbegin(); it != link->child_joints.rend(); ++it)
      pending.push_back(urdf_model->getLink((*it)->child_link_name));
  }
  return builder;
}

}  // namespace armdyn
