// SPDX-License-Identifier: BSD-3-Clause
// The model bytes (armdyn/io/serialize.hpp): a header, the description element by element, each
// value checked as it is read (counts against the bytes left, indices against the tables read
// before, every invariant the builder establishes), then the derived tables of a draft and, for a
// finalized model, finalize again.
#include "armdyn/io/serialize.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <set>
#include <type_traits>

#include "armdyn/builder/builder.hpp"
#include "armdyn/errors.hpp"
#include "utf8.hpp"

namespace armdyn {

namespace {

constexpr char kMagic[8] = {'A', 'R', 'M', 'D', 'Y', 'N', 'M', '1'};
// Format versions: 3 adds the motor's datasheet fields after the first nine (MotorSpec::fields);
// 4 the independent coordinates the user chose (Model::independent_request, after the warnings);
// this armdyn writes kFormat and reads every version from kOldestFormat (an older one's missing
// fields load as not given).
constexpr std::uint32_t kFormat = 4, kOldestFormat = 2;
/// The motor fields the bytes of format 2 hold: the first nine of MotorSpec::fields().
constexpr std::size_t kMotorFieldsFormat2 = 9;
constexpr std::uint8_t kKindModel = 'M', kKindDraft = 'D';

// Guard: a field added to one of these structs must be stored (or derived on load) too (then
// update the size here; the sizes of this build's ABI: libstdc++ on x86-64).
#if defined(__GLIBCXX__) && defined(__x86_64__) && !defined(_GLIBCXX_DEBUG) && \
    !defined(_GLIBCXX_ASSERTIONS) && !defined(__AVX__)
static_assert(sizeof(Body) == 176, "Body changed: store the new field here, then update its size");
static_assert(sizeof(Joint) == 296,
              "Joint changed: store the new field here, then update its size");
static_assert(sizeof(Drive) == 224,
              "Drive changed: store the new field here, then update its size");
static_assert(sizeof(BodyLoad) == 264,
              "BodyLoad changed: store the new field here, then update its size");
static_assert(sizeof(SpringDamper) == 112,
              "SpringDamper changed: store the new field here, then update its size");
static_assert(sizeof(CoordForce) == 488,
              "CoordForce changed: store the new field here, then update its size");
static_assert(sizeof(GearPair) == 88,
              "GearPair changed: store the new field here, then update its size");
static_assert(sizeof(GearConstraint) == 72,
              "GearConstraint changed: store the new field here, then update its size");
static_assert(sizeof(Actuator) == 232,
              "Actuator changed: store the new field here, then update its size");
static_assert(sizeof(MotorSpec) == 168,
              "MotorSpec changed: store the new field here, then update its size");
static_assert(sizeof(Coord) == 48, "Coord changed: store the new field here, then update its size");
static_assert(sizeof(NamedFrame) == 136,
              "NamedFrame changed: store the new field here, then update its size");
static_assert(sizeof(IndependentCoords) == 112,
              "IndependentCoords changed: store the new field here, then update its size");
static_assert(sizeof(Model) == 1048,
              "Model changed: store the new field here, then update its size");
static_assert(sizeof(Profile) == 176,
              "Profile changed: store the new field here, then update its size");
static_assert(sizeof(FinalizeOptions) == 8,
              "FinalizeOptions changed: store the new field here, then update its size");
#endif

// ------------------------------------------------------------------------------------------
// writing

class Writer {
 public:
  std::string out;
  template <class T>
  void pod(const T& x) {
    static_assert(std::is_trivially_copyable<T>::value, "pod");
    out.append(reinterpret_cast<const char*>(&x), sizeof(T));
  }
  void i(long long x) { pod<std::int64_t>(static_cast<std::int64_t>(x)); }
  void d(double x) { pod(x); }
  void b(bool x) { pod<std::uint8_t>(x ? 1 : 0); }
  void s(const std::string& x) {
    i(static_cast<long long>(x.size()));
    out.append(x);
  }
  /// a fixed-size vector or matrix, column by column (its size is the format's)
  template <class Derived>
  void fixed(const Eigen::MatrixBase<Derived>& m) {
    for (Eigen::Index c = 0; c < m.cols(); ++c)
      for (Eigen::Index r = 0; r < m.rows(); ++r) d(m(r, c));
  }
  void vd(const std::vector<double>& v) {
    i(static_cast<long long>(v.size()));
    for (double x : v) d(x);
  }
  template <class T, class F>
  void list(const std::vector<T>& v, F&& f) {
    i(static_cast<long long>(v.size()));
    for (const auto& x : v) f(x);
  }
};

void put_profile(Writer& w, const Profile& p, const std::string& who) {
  Profile::Raw r;
  try {
    r = p.raw();
  } catch (const ModelError& e) {
    throw ModelError(msg("cannot store the model: ", who, ": ", e.what()));
  }
  w.i(static_cast<int>(r.kind));
  for (double x : r.p) w.d(x);
  w.vd(r.t);
  w.vd(r.y);
}

void put_motor(Writer& w, const MotorSpec& ms) {
  w.s(ms.name);
  for (const auto& [name, field] : MotorSpec::fields()) {
    (void)name;
    w.d(ms.*field);
  }
}

void put_bodies_joints_frames(Writer& w, const Model& m) {
  w.fixed(m.gravity);
  w.list(m.bodies, [&](const Body& x) {
    w.s(x.name);
    w.d(x.mass);
    w.fixed(x.inertia);
    w.fixed(x.position);
    w.fixed(x.orientation);
  });
  w.list(m.joints, [&](const Joint& x) {
    w.s(x.name);
    w.i(static_cast<int>(x.type));
    w.i(x.parent);
    w.i(x.child);
    w.fixed(x.point_parent);
    w.fixed(x.point_child);
    w.fixed(x.frame_parent);
    w.fixed(x.frame_child);
    w.d(x.lower);
    w.d(x.upper);
    w.d(x.effort);
    w.d(x.velocity_limit);
    w.d(x.length);
  });
  w.list(m.frames, [&](const NamedFrame& x) {
    w.s(x.name);
    w.i(x.body);
    w.fixed(x.point);
    w.fixed(x.rotation);
  });
}

void put_drives_loads(Writer& w, const Model& m) {
  w.list(m.drives, [&](const Drive& x) {
    w.s(x.name);
    w.i(x.joint);
    w.i(x.coord);
    put_profile(w, x.profile, "drive '" + x.name + "'");
  });
  w.list(m.body_loads, [&](const BodyLoad& x) {
    w.i(x.body);
    w.fixed(x.force);
    w.fixed(x.torque);
    w.fixed(x.point);
    w.b(x.has_profile);
    put_profile(w, x.profile, "the load on body '" + m.body_name(x.body) + "'");
  });
  w.list(m.springs, [&](const SpringDamper& x) {
    w.s(x.name);
    w.i(x.body_a);
    w.i(x.body_b);
    w.fixed(x.point_a);
    w.fixed(x.point_b);
    w.d(x.stiffness);
    w.d(x.damping);
    w.d(x.rest_length);
  });
}

void put_coord_forces(Writer& w, const Model& m) {
  w.list(m.coord_forces, [&](const CoordForce& x) {
    w.i(x.coord);
    w.d(x.stiffness);
    w.d(x.damping);
    w.d(x.rest);
    w.d(x.coulomb);
    w.d(x.v_smooth);
    w.b(x.has_input);
    const std::string who =
        x.name.empty() && x.coord >= 0 && x.coord < static_cast<int>(m.coords.size())
            ? "coordinate '" + m.coords[x.coord].name + "'"
            : "'" + x.name + "'";
    put_profile(w, x.input, "the torque input of " + who);
    w.b(x.motor);
    put_profile(w, x.reference, "the motor reference of " + who);
    w.d(x.kp);
    w.d(x.kd);
    w.d(x.ki);
    w.d(x.torque_limit);
    w.s(x.name);
  });
}

void put_gears_actuators(Writer& w, const Model& m) {
  w.list(m.gears, [&](const GearPair& x) {
    w.s(x.name);
    w.i(x.coord_a);
    w.i(x.coord_b);
    w.d(x.r_a);
    w.d(x.r_b);
    w.d(x.backlash);
    w.d(x.stiffness);
    w.d(x.exponent);
    w.d(x.hc_damping);
  });
  w.list(m.gear_constraints, [&](const GearConstraint& x) {
    w.s(x.name);
    w.i(x.coord_a);
    w.i(x.coord_b);
    w.d(x.r_a);
    w.d(x.r_b);
    w.d(x.offset);
    w.b(x.coupling);
  });
  w.list(m.actuators, [&](const Actuator& x) {
    w.i(x.joint);
    w.i(x.rotor_joint);
    w.d(x.gear_ratio);
    w.d(x.rotor_inertia);
    w.d(x.efficiency);
    w.d(x.friction_viscous);
    w.d(x.friction_coulomb);
    w.d(x.friction_smoothing);
    w.b(x.gyroscopic);
    w.b(x.has_motor);
    put_motor(w, x.motor);
  });
  w.list(m.warnings, [&](const std::string& x) { w.s(x); });
  w.list(m.independent_request, [&](const std::string& x) { w.s(x); });
}

std::string write(const Model& m, std::uint8_t kind) {
  Writer w;
  w.out.append(kMagic, sizeof(kMagic));
  w.pod<std::uint32_t>(kFormat);
  w.pod<std::uint8_t>(kind);
  put_bodies_joints_frames(w, m);
  put_drives_loads(w, m);
  put_coord_forces(w, m);
  put_gears_actuators(w, m);
  if (kind == kKindModel) {
    w.b(m.force_dense_kkt);
    w.b(m.finalize_options.mass_weighted_assembly);
    w.i(m.finalize_options.max_assembly_iterations);
  }
  return std::move(w.out);
}

// ------------------------------------------------------------------------------------------
// reading: every value checked where it is read, the message naming its field

// well-formed UTF-8 (no overlong forms, surrogates or code points above U+10FFFF)
bool valid_utf8(const std::string& s) { return utf8_error(s) == std::string::npos; }

class Reader {
 public:
  explicit Reader(const std::string& in) : in_(in) {}

  /// the element being read, for messages ("joints[3] 'elbow'")
  void at(std::string where) { where_ = std::move(where); }
  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    const std::string place = where_.empty() ? field : where_ + (field.empty() ? "" : ".") + field;
    throw ModelError(msg("model data: ", place, ": ", what,
                         " (not model bytes of this armdyn version, or altered)"));
  }

  template <class T>
  T pod(const char* field) {
    if (sizeof(T) > in_.size() - pos_) fail(field, "truncated");
    T x;
    std::memcpy(&x, in_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return x;
  }
  long long i(const char* field) { return pod<std::int64_t>(field); }
  /// an index in [lo, hi)
  int index(const char* field, int lo, int hi, const char* of) {
    const long long x = i(field);
    if (x < lo || x >= hi)
      fail(field, msg("index ", x, " out of range [", lo, ", ", hi, ") of ", of));
    return static_cast<int>(x);
  }
  double d(const char* field) { return pod<double>(field); }
  double finite(const char* field) {
    const double x = d(field);
    if (!std::isfinite(x)) fail(field, msg("must be finite, got ", x));
    return x;
  }
  /// finite and >= lo (strictly above lo when `strict`)
  double at_least(const char* field, double lo, bool strict = false) {
    const double x = finite(field);
    if (strict ? !(x > lo) : !(x >= lo))
      fail(field, msg("must be ", strict ? "> " : ">= ", lo, ", got ", x));
    return x;
  }
  bool b(const char* field) {
    const auto x = pod<std::uint8_t>(field);
    if (x > 1) fail(field, msg("a flag must be 0 or 1, got ", static_cast<int>(x)));
    return x == 1;
  }
  /// a count of elements of at least `min_bytes` bytes each, checked against the bytes left
  /// before anything is allocated
  std::size_t count(const char* field, std::size_t min_bytes) {
    const long long n = i(field);
    if (n < 0 || static_cast<unsigned long long>(n) > (in_.size() - pos_) / min_bytes)
      fail(field, msg("count ", n, " exceeds the ", in_.size() - pos_, " bytes left"));
    return static_cast<std::size_t>(n);
  }
  /// a string: valid UTF-8, as every name and note from Python is
  std::string s(const char* field) {
    const std::size_t n = count(field, 1);
    std::string x = in_.substr(pos_, n);
    pos_ += n;
    if (!valid_utf8(x)) fail(field, "text is not valid UTF-8");
    return x;
  }
  template <class M>
  void fixed(M& m, const char* field) {
    for (Eigen::Index c = 0; c < m.cols(); ++c)
      for (Eigen::Index r = 0; r < m.rows(); ++r) m(r, c) = finite(field);
  }
  std::vector<double> vd(const char* field) {
    std::vector<double> v(count(field, sizeof(double)));
    for (double& x : v) x = d(field);
    return v;
  }
  bool done() const { return pos_ == in_.size(); }
  /// the format version of the bytes (read_header)
  std::uint32_t format = kFormat;

 private:
  const std::string& in_;
  std::size_t pos_ = 0;
  std::string where_;
};

std::uint8_t read_header(Reader& r) {
  for (char c : kMagic)
    if (r.pod<char>("tag") != c) r.fail("tag", "wrong tag");
  const auto format = r.pod<std::uint32_t>("format");
  if (format < kOldestFormat || format > kFormat)
    r.fail("format", msg("format version ", format, ", this armdyn reads versions ", kOldestFormat,
                         " to ", kFormat,
                         " (bytes of another armdyn version: store the model's source -- its "
                         "builder script or URDF -- rather than its bytes)"));
  const auto kind = r.pod<std::uint8_t>("kind");
  if (kind != kKindModel && kind != kKindDraft) r.fail("kind", msg("unknown kind ", int(kind)));
  r.format = format;
  return kind;
}

// a rotation matrix to round-off (orthonormal, determinant +1)
void check_rotation(Reader& r, const Mat3& R, const char* field) {
  const double err = (R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff();
  if (!(err <= 1e-9) || !(R.determinant() > 0.0))
    r.fail(field,
           msg("not a rotation matrix (|R^T R - I| = ", err, ", det ", R.determinant(), ")"));
}

// a name, non-empty and new to `seen` (when given)
std::string read_name(Reader& r, std::map<std::string, int>* seen, int idx, bool allow_empty) {
  std::string name = r.s("name");
  if (name.empty() && !allow_empty) r.fail("name", "empty");
  if (seen && !seen->emplace(name, idx).second) r.fail("name", msg("duplicate name '", name, "'"));
  return name;
}

Profile read_profile(Reader& r, const char* field) {
  Profile::Raw raw;
  const long long kind = r.i(field);
  if (kind < 0 || kind >= static_cast<long long>(Profile::Kind::Callback))
    r.fail(field, msg("unknown profile kind ", kind));
  raw.kind = static_cast<Profile::Kind>(kind);
  for (double& x : raw.p) x = r.d(field);
  raw.t = r.vd(field);
  raw.y = r.vd(field);
  try {
    return Profile::restore(raw);
  } catch (const ModelError& e) {
    r.fail(field, e.what());
  }
}

void read_body(Reader& r, Model& m, int k) {
  Body& x = m.bodies[k];
  r.at(msg("bodies[", k, "]"));
  x.name = read_name(r, &m.body_index, k, false);
  r.at(msg("bodies[", k, "] '", x.name, "'"));
  if (x.name == "ground") r.fail("name", "'ground' is reserved");
  x.mass = r.at_least("mass", 0.0);
  r.fixed(x.inertia, "inertia");
  r.fixed(x.position, "position");
  r.fixed(x.orientation, "orientation");
  const double scale = x.inertia.cwiseAbs().maxCoeff();
  if ((x.inertia - x.inertia.transpose()).cwiseAbs().maxCoeff() > 1e-9 * std::max(scale, 1e-300))
    r.fail("inertia", "not symmetric");
  const InertiaCheck ic = check_inertia(0.5 * (x.inertia + x.inertia.transpose()), false);
  if (!ic.problem.empty()) r.fail("inertia", ic.problem);
  if (!(std::abs(x.orientation.norm() - 1.0) <= 1e-9))
    r.fail("orientation", msg("not a unit quaternion (norm ", x.orientation.norm(), ")"));
}

// the joint's derived fields: rows, coordinates (as ModelBuilder::add_joint makes them)
void derive_joint(Model& m, int k) {
  Joint& j = m.joints[k];
  j.row0 = m.nc_joint;
  const int nq = joint_coords(j.type);
  j.coord0 = nq ? static_cast<int>(m.coords.size()) : -1;
  for (int s = 0; s < nq; ++s) {
    Coord c;
    c.joint = k;
    c.sub = s;
    c.angular = j.type != JointType::Prismatic && s == 0;
    c.name = nq == 1 ? j.name : j.name + (s == 0 ? ":angle" : ":displacement");
    m.coords.push_back(c);
  }
  m.nc_joint += joint_rows(j.type);
}

void read_joint(Reader& r, Model& m, int k) {
  Joint& x = m.joints[k];
  r.at(msg("joints[", k, "]"));
  x.name = read_name(r, &m.joint_index, k, false);
  r.at(msg("joints[", k, "] '", x.name, "'"));
  x.type = static_cast<JointType>(
      r.index("type", 0, static_cast<int>(JointType::Distance) + 1, "the joint types"));
  const int nb = static_cast<int>(m.bodies.size());
  x.parent = r.index("parent", kGround, nb, "the bodies (-1 ground)");
  x.child = r.index("child", kGround, nb, "the bodies (-1 ground)");
  if (x.parent == x.child) r.fail("child", "the joint links a body to itself");
  if (x.type == JointType::Free && (x.parent != kGround || x.child == kGround))
    r.fail("parent", "a free joint goes from ground to a body");
  r.fixed(x.point_parent, "point_parent");
  r.fixed(x.point_child, "point_child");
  r.fixed(x.frame_parent, "frame_parent");
  r.fixed(x.frame_child, "frame_child");
  check_rotation(r, x.frame_parent, "frame_parent");
  check_rotation(r, x.frame_child, "frame_child");
  x.lower = r.d("lower");
  x.upper = r.d("upper");
  if (std::isnan(x.lower) || std::isnan(x.upper) || !(x.lower <= x.upper))
    r.fail("lower", msg("limits [", x.lower, ", ", x.upper, "] are not an interval"));
  x.effort = r.d("effort");
  x.velocity_limit = r.d("velocity_limit");
  if (!(x.effort >= 0.0) || !(x.velocity_limit >= 0.0))
    r.fail("effort", "effort and velocity limits must be >= 0");
  x.length = r.d("length");
  if (x.type == JointType::Distance ? !(std::isfinite(x.length) && x.length > 1e-9)
                                    : x.length != 0.0)
    r.fail("length",
           msg("invalid length ", x.length, " for a ", joint_type_name(x.type), " joint"));
  derive_joint(m, k);
}

void read_frame(Reader& r, Model& m, int k) {
  NamedFrame& x = m.frames[k];
  r.at(msg("frames[", k, "]"));
  x.name = read_name(r, &m.frame_index, k, false);
  r.at(msg("frames[", k, "] '", x.name, "'"));
  x.body = r.index("body", kGround, static_cast<int>(m.bodies.size()), "the bodies (-1 ground)");
  r.fixed(x.point, "point");
  r.fixed(x.rotation, "rotation");
  check_rotation(r, x.rotation, "rotation");
}

void read_bodies_joints_frames(Reader& r, Model& m) {
  r.fixed(m.gravity, "gravity");
  m.bodies.resize(r.count("bodies", 8));
  for (int k = 0; k < static_cast<int>(m.bodies.size()); ++k) read_body(r, m, k);
  r.at("");
  m.joints.resize(r.count("joints", 8));
  for (int k = 0; k < static_cast<int>(m.joints.size()); ++k) read_joint(r, m, k);
  r.at("");
  m.frames.resize(r.count("frames", 8));
  for (int k = 0; k < static_cast<int>(m.frames.size()); ++k) read_frame(r, m, k);
  r.at("");
}

void read_drive(Reader& r, Model& m, int k, std::set<std::pair<int, int>>& driven) {
  Drive& x = m.drives[k];
  r.at(msg("drives[", k, "]"));
  x.name = read_name(r, &m.drive_index, k, false);
  r.at(msg("drives[", k, "] '", x.name, "'"));
  x.joint = r.index("joint", 0, static_cast<int>(m.joints.size()), "the joints");
  const JointType type = m.joints[x.joint].type;
  x.coord = r.index("coord", 0, joint_coords(type), "the joint's coordinates");
  if (!driven.emplace(x.joint, x.coord).second) r.fail("coord", "the coordinate is driven twice");
  x.profile = read_profile(r, "profile");
}

void read_load(Reader& r, Model& m, int k) {
  BodyLoad& x = m.body_loads[k];
  r.at(msg("body_loads[", k, "]"));
  x.body = r.index("body", 0, static_cast<int>(m.bodies.size()), "the bodies");
  r.fixed(x.force, "force");
  r.fixed(x.torque, "torque");
  r.fixed(x.point, "point");
  x.has_profile = r.b("has_profile");
  x.profile = read_profile(r, "profile");
}

void read_spring(Reader& r, Model& m, int k) {
  SpringDamper& x = m.springs[k];
  r.at(msg("springs[", k, "]"));
  x.name = read_name(r, nullptr, k, true);
  r.at(msg("springs[", k, "] '", x.name, "'"));
  const int nb = static_cast<int>(m.bodies.size());
  x.body_a = r.index("body_a", kGround, nb, "the bodies (-1 ground)");
  x.body_b = r.index("body_b", kGround, nb, "the bodies (-1 ground)");
  if (x.body_a == x.body_b) r.fail("body_b", "the spring connects a body to itself");
  r.fixed(x.point_a, "point_a");
  r.fixed(x.point_b, "point_b");
  x.stiffness = r.at_least("stiffness", 0.0);
  x.damping = r.at_least("damping", 0.0);
  x.rest_length = r.at_least("rest_length", 0.0);
}

void read_drives_loads(Reader& r, Model& m) {
  std::set<std::pair<int, int>> driven;
  m.drives.resize(r.count("drives", 8));
  for (int k = 0; k < static_cast<int>(m.drives.size()); ++k) read_drive(r, m, k, driven);
  r.at("");
  m.body_loads.resize(r.count("body_loads", 8));
  for (int k = 0; k < static_cast<int>(m.body_loads.size()); ++k) read_load(r, m, k);
  r.at("");
  m.springs.resize(r.count("springs", 8));
  for (int k = 0; k < static_cast<int>(m.springs.size()); ++k) read_spring(r, m, k);
  r.at("");
}

void read_coord_force(Reader& r, Model& m, int k) {
  CoordForce& x = m.coord_forces[k];
  r.at(msg("coord_forces[", k, "]"));
  x.coord = r.index("coord", 0, static_cast<int>(m.coords.size()), "the joint coordinates");
  x.stiffness = r.at_least("stiffness", 0.0);
  x.damping = r.at_least("damping", 0.0);
  x.rest = r.finite("rest");
  x.coulomb = r.at_least("coulomb", 0.0);
  x.v_smooth = r.at_least("v_smooth", 0.0, true);
  x.has_input = r.b("has_input");
  x.input = read_profile(r, "input");
  x.motor = r.b("motor");
  x.reference = read_profile(r, "reference");
  x.kp = r.at_least("kp", 0.0);
  x.kd = r.at_least("kd", 0.0);
  x.ki = r.at_least("ki", 0.0);
  if (!x.motor && (x.kp != 0.0 || x.kd != 0.0 || x.ki != 0.0))
    r.fail("kp", "gains of an element that is not a motor");
  x.torque_limit = r.d("torque_limit");
  if (!(x.torque_limit > 0.0)) r.fail("torque_limit", msg("must be > 0, got ", x.torque_limit));
  x.name = r.s("name");
  // the integral state of a PI motor (ModelBuilder::add_motor)
  x.aux = x.motor && x.ki > 0.0 ? m.n_aux++ : -1;
}

// the coordinate `c` of a revolute joint (gears), or of a revolute or prismatic one (couplings)
void check_gear_coord(Reader& r, const Model& m, int c, bool prismatic_ok, const char* field) {
  const JointType t = m.joints[m.coords[c].joint].type;
  if (!(t == JointType::Revolute || (prismatic_ok && t == JointType::Prismatic)))
    r.fail(field, msg("coordinate ", c, " is of a ", joint_type_name(t), " joint"));
}

void read_gear(Reader& r, Model& m, int k, std::set<std::string>& names) {
  GearPair& x = m.gears[k];
  r.at(msg("gears[", k, "]"));
  x.name = read_name(r, nullptr, k, true);
  r.at(msg("gears[", k, "] '", x.name, "'"));
  if (!names.insert(x.name).second) r.fail("name", "duplicate name");
  const int nc = static_cast<int>(m.coords.size());
  x.coord_a = r.index("coord_a", 0, nc, "the joint coordinates");
  x.coord_b = r.index("coord_b", 0, nc, "the joint coordinates");
  check_gear_coord(r, m, x.coord_a, false, "coord_a");
  check_gear_coord(r, m, x.coord_b, false, "coord_b");
  if (x.coord_a == x.coord_b) r.fail("coord_b", "both gears on one joint");
  x.r_a = r.at_least("r_a", 0.0, true);
  x.r_b = r.at_least("r_b", 0.0, true);
  x.backlash = r.at_least("backlash", 0.0);
  x.stiffness = r.at_least("stiffness", 0.0, true);
  x.exponent = r.at_least("exponent", 1.0);
  x.hc_damping = r.at_least("hc_damping", 0.0);
  for (int c : {x.coord_a, x.coord_b})
    if (std::find(m.tracked_coords.begin(), m.tracked_coords.end(), c) == m.tracked_coords.end())
      m.tracked_coords.push_back(c);
}

void read_gear_constraint(Reader& r, Model& m, int k, std::set<std::string>& names,
                          std::vector<int>& follows) {
  GearConstraint& x = m.gear_constraints[k];
  r.at(msg("gear_constraints[", k, "]"));
  x.name = read_name(r, nullptr, k, true);
  r.at(msg("gear_constraints[", k, "] '", x.name, "'"));
  if (!names.insert(x.name).second) r.fail("name", "duplicate name");
  const int nc = static_cast<int>(m.coords.size());
  x.coord_a = r.index("coord_a", 0, nc, "the joint coordinates");
  x.coord_b = r.index("coord_b", 0, nc, "the joint coordinates");
  x.r_a = r.finite("r_a");
  x.r_b = r.finite("r_b");
  x.offset = r.finite("offset");
  x.coupling = r.b("coupling");
  if (x.coord_a == x.coord_b) r.fail("coord_b", "couples a coordinate to itself");
  check_gear_coord(r, m, x.coord_a, x.coupling, "coord_a");
  check_gear_coord(r, m, x.coord_b, x.coupling, "coord_b");
  if (!x.coupling) {
    if (!(x.r_a > 0.0) || !(x.r_b > 0.0)) r.fail("r_a", "pitch radii must be > 0");
    if (x.offset != 0.0) r.fail("offset", "an ideal gear has no offset");
    return;
  }
  if (x.name.empty()) r.fail("name", "empty");
  if (x.r_a != 1.0 || x.r_b == 0.0)
    r.fail("r_b", "a coupling has r_a = 1 and r_b = -multiplier != 0");
  if (follows[x.coord_a] >= 0) r.fail("coord_a", "the follower follows two leaders");
  follows[x.coord_a] = x.coord_b;
}

// couplings form chains, never a cycle (each coordinate follows at most one other)
void check_chains(Reader& r, const std::vector<int>& follows) {
  std::vector<char> state(follows.size(), 0);  // 0 unseen, 1 on the current walk, 2 done
  for (std::size_t c0 = 0; c0 < follows.size(); ++c0) {
    int c = static_cast<int>(c0);
    while (c >= 0 && state[c] == 0) {
      state[c] = 1;
      c = follows[c];
    }
    if (c >= 0 && state[c] == 1) r.fail("coord_b", "the couplings form a cycle");
    for (c = static_cast<int>(c0); c >= 0 && state[c] == 1; c = follows[c]) state[c] = 2;
  }
}

void read_actuator(Reader& r, Model& m, int k, const std::vector<int>& follows,
                   std::vector<char>& actuated) {
  Actuator& x = m.actuators[k];
  r.at(msg("actuators[", k, "]"));
  const int nj = static_cast<int>(m.joints.size());
  x.joint = r.index("joint", 0, nj, "the joints");
  x.rotor_joint = r.index("rotor_joint", 0, nj, "the joints");
  const Joint& j = m.joints[x.joint];
  const Joint& rj = m.joints[x.rotor_joint];
  r.at(msg("actuators[", k, "] on '", j.name, "'"));
  if (j.type != JointType::Revolute && j.type != JointType::Prismatic)
    r.fail("joint", "not a revolute or prismatic joint");
  if (actuated[x.joint]) r.fail("joint", "a second actuator on the joint");
  actuated[x.joint] = 1;
  x.gear_ratio = r.finite("gear_ratio");
  if (x.gear_ratio == 0.0) r.fail("gear_ratio", "must be nonzero");
  x.rotor_inertia = r.at_least("rotor_inertia", 0.0);
  x.efficiency = r.at_least("efficiency", 0.0, true);
  if (!(x.efficiency <= 1.0)) r.fail("efficiency", msg("must be in (0, 1], got ", x.efficiency));
  x.friction_viscous = r.at_least("friction_viscous", 0.0);
  x.friction_coulomb = r.at_least("friction_coulomb", 0.0);
  x.friction_smoothing = r.at_least("friction_smoothing", 0.0, true);
  x.gyroscopic = r.b("gyroscopic");
  x.has_motor = r.b("has_motor");
  x.motor.name = r.s("motor.name");
  const std::size_t stored =
      r.format >= 3 ? MotorSpec::kNumFields : kMotorFieldsFormat2;  // the rest: not given
  for (std::size_t f = 0; f < stored; ++f)
    x.motor.*MotorSpec::fields()[f].second = r.d(MotorSpec::fields()[f].first);
  try {
    x.motor.validate("motor");
  } catch (const ModelError& e) {
    r.fail("motor", e.what());
  }
  // the rotor: its revolute joint, named after the joint, following it by a coupling
  if (rj.type != JointType::Revolute ||
      rj.name != j.name + (x.gyroscopic ? "_rotor" : "_armature") || follows[rj.coord0] != j.coord0)
    r.fail("rotor_joint", msg("joint '", rj.name, "' is not the rotor of joint '", j.name, "'"));
}

void read_gears_actuators(Reader& r, Model& m) {
  std::set<std::string> names;
  m.gears.resize(r.count("gears", 8));
  for (int k = 0; k < static_cast<int>(m.gears.size()); ++k) read_gear(r, m, k, names);
  r.at("");
  names.clear();
  std::vector<int> follows(m.coords.size(), -1);
  m.gear_constraints.resize(r.count("gear_constraints", 8));
  for (int k = 0; k < static_cast<int>(m.gear_constraints.size()); ++k)
    read_gear_constraint(r, m, k, names, follows);
  r.at("gear_constraints");
  check_chains(r, follows);
  r.at("");
  std::vector<char> actuated(m.joints.size(), 0), rotor(m.joints.size(), 0);
  m.actuators.resize(r.count("actuators", 8));
  for (int k = 0; k < static_cast<int>(m.actuators.size()); ++k) {
    read_actuator(r, m, k, follows, actuated);
    rotor[m.actuators[k].rotor_joint] = 1;
  }
  // a coupling between joints of different types is an actuator's rotor following its joint
  for (std::size_t k = 0; k < m.gear_constraints.size(); ++k) {
    const GearConstraint& g = m.gear_constraints[k];
    const int ja = m.coords[g.coord_a].joint, jb = m.coords[g.coord_b].joint;
    if (g.coupling && m.joints[ja].type != m.joints[jb].type && !rotor[ja]) {
      r.at(msg("gear_constraints[", k, "] '", g.name, "'"));
      r.fail("coord_b", "couples joints of different types");
    }
  }
  r.at("");
  const std::size_t nw = r.count("warnings", 8);
  for (std::size_t k = 0; k < nw; ++k) m.warnings.push_back(r.s("warnings"));
  if (r.format >= 4) {
    const std::size_t ni = r.count("independent_request", 8);
    for (std::size_t k = 0; k < ni; ++k)
      m.independent_request.push_back(r.s("independent_request"));
  }
}

/// The checked description (a draft, its derived tables made as the builder makes them).
Model read_description(Reader& r) {
  Model m;
  read_bodies_joints_frames(r, m);
  read_drives_loads(r, m);
  m.coord_forces.resize(r.count("coord_forces", 8));
  for (int k = 0; k < static_cast<int>(m.coord_forces.size()); ++k) read_coord_force(r, m, k);
  r.at("");
  read_gears_actuators(r, m);
  return m;
}

/// Finalize the description again (the builder's path); the notes and the KKT path as stored.
Model refinalize(Reader& r, Model draft, bool dense, const FinalizeOptions& options) {
  std::vector<std::string> warnings = std::move(draft.warnings);
  draft.warnings.clear();
  std::shared_ptr<Model> fin;
  try {
    fin = detail::finalize_draft(draft, options);
  } catch (const ModelError& e) {
    r.fail("description", msg("does not finalize: ", e.what()));
  } catch (const SolverError& e) {
    r.fail("description", msg("does not finalize: ", e.what()));
  }
  // what finalize assembled must be finite (a description of extreme but finite values can
  // overflow there)
  if (!fin->u0.allFinite() || !fin->v0.allFinite())
    r.fail("description", "its assembled state is not finite (values too large)");
  Model m = *fin;  // a copy: its derived caches empty
  m.warnings = std::move(warnings);
  m.force_dense_kkt = dense;
  return m;
}

}  // namespace

std::string serialize_model(const Model& m) { return write(m, kKindModel); }

std::string serialize_draft(const Model& draft) { return write(draft, kKindDraft); }

Model deserialize_model(const std::string& bytes) {
  Reader r(bytes);
  if (read_header(r) != kKindModel) r.fail("kind", "a builder's draft, not a model");
  Model draft = read_description(r);
  const bool dense = r.b("force_dense_kkt");
  FinalizeOptions options;
  options.mass_weighted_assembly = r.b("mass_weighted_assembly");
  const long long iters = r.i("max_assembly_iterations");
  if (iters < 1 || iters > 1000000)
    r.fail("max_assembly_iterations", msg("must be in [1, 1000000], got ", iters));
  options.max_assembly_iterations = static_cast<int>(iters);
  if (!r.done()) r.fail("", "trailing bytes");
  return refinalize(r, std::move(draft), dense, options);
}

Model deserialize_draft(const std::string& bytes) {
  Reader r(bytes);
  if (read_header(r) != kKindDraft) r.fail("kind", "a model, not a builder's draft");
  Model draft = read_description(r);
  if (!r.done()) r.fail("", "trailing bytes");
  return draft;
}

}  // namespace armdyn
