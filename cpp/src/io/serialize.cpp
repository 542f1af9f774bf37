// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/io/serialize.hpp"

#include <cstdint>
#include <cstring>
#include <type_traits>

#include "armdyn/errors.hpp"

namespace armdyn {

namespace {

constexpr char kMagic[8] = {'A', 'R', 'M', 'D', 'Y', 'N', 'M', '1'};
constexpr std::uint32_t kFormat = 1;

// Guard: a field added to one of these structs must be stored too (then update the size here;
// the sizes of this build's ABI: libstdc++ on x86-64).
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
static_assert(sizeof(Actuator) == 168,
              "Actuator changed: store the new field here, then update its size");
static_assert(sizeof(MotorSpec) == 104,
              "MotorSpec changed: store the new field here, then update its size");
static_assert(sizeof(Coord) == 48, "Coord changed: store the new field here, then update its size");
static_assert(sizeof(NamedFrame) == 136,
              "NamedFrame changed: store the new field here, then update its size");
static_assert(sizeof(IndependentCoords) == 112,
              "IndependentCoords changed: store the new field here, then update its size");
static_assert(sizeof(Model) == 1016,
              "Model changed: store the new field here, then update its size");
static_assert(sizeof(Profile) == 176,
              "Profile changed: store the new field here, then update its size");
static_assert(sizeof(FinalizeOptions) == 8,
              "FinalizeOptions changed: store the new field here, then update its size");
#endif

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
  template <class Derived>
  void mat(const Eigen::MatrixBase<Derived>& m) {
    i(m.rows());
    i(m.cols());
    for (Eigen::Index c = 0; c < m.cols(); ++c)
      for (Eigen::Index r = 0; r < m.rows(); ++r) d(m(r, c));
  }
  void vd(const std::vector<double>& v) {
    i(static_cast<long long>(v.size()));
    for (double x : v) d(x);
  }
  void vi(const std::vector<int>& v) {
    i(static_cast<long long>(v.size()));
    for (int x : v) i(x);
  }
  void vs(const std::vector<std::string>& v) {
    i(static_cast<long long>(v.size()));
    for (const auto& x : v) s(x);
  }
  void map(const std::map<std::string, int>& m) {
    i(static_cast<long long>(m.size()));
    for (const auto& [k, v] : m) {
      s(k);
      i(v);
    }
  }
  template <class T, class F>
  void list(const std::vector<T>& v, F&& f) {
    i(static_cast<long long>(v.size()));
    for (const auto& x : v) f(x);
  }
};

[[noreturn]] void corrupt(const char* what) {
  throw ModelError(msg("model data: ", what, " (not model bytes of this armdyn version)"));
}

class Reader {
 public:
  explicit Reader(const std::string& in) : in_(in) {}
  template <class T>
  T pod() {
    if (pos_ + sizeof(T) > in_.size()) corrupt("truncated");
    T x;
    std::memcpy(&x, in_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return x;
  }
  long long i() { return pod<std::int64_t>(); }
  int i32() {
    const long long x = i();
    if (x < INT32_MIN || x > INT32_MAX) corrupt("integer out of range");
    return static_cast<int>(x);
  }
  double d() { return pod<double>(); }
  bool b() {
    const auto x = pod<std::uint8_t>();
    if (x > 1) corrupt("bad flag");
    return x == 1;
  }
  std::size_t count() {
    const long long n = i();
    // every element takes at least one byte: a count beyond the remaining bytes is corrupt
    if (n < 0 || static_cast<unsigned long long>(n) > in_.size() - pos_) corrupt("bad length");
    return static_cast<std::size_t>(n);
  }
  std::string s() {
    const std::size_t n = count();
    std::string x = in_.substr(pos_, n);
    pos_ += n;
    return x;
  }
  template <class M>
  void mat(M& m) {
    const long long r = i(), c = i();
    if (r < 0 || c < 0 || r * c > static_cast<long long>((in_.size() - pos_) / 8))
      corrupt("bad matrix size");
    if (M::RowsAtCompileTime != Eigen::Dynamic && r != M::RowsAtCompileTime) corrupt("bad rows");
    if (M::ColsAtCompileTime != Eigen::Dynamic && c != M::ColsAtCompileTime) corrupt("bad cols");
    m.resize(r, c);
    for (Eigen::Index cc = 0; cc < c; ++cc)
      for (Eigen::Index rr = 0; rr < r; ++rr) m(rr, cc) = d();
  }
  std::vector<double> vd() {
    std::vector<double> v(count());
    for (double& x : v) x = d();
    return v;
  }
  std::vector<int> vi() {
    std::vector<int> v(count());
    for (int& x : v) x = i32();
    return v;
  }
  std::vector<std::string> vs() {
    std::vector<std::string> v(count());
    for (auto& x : v) x = s();
    return v;
  }
  std::map<std::string, int> map() {
    std::map<std::string, int> m;
    const std::size_t n = count();
    for (std::size_t k = 0; k < n; ++k) {
      std::string key = s();
      m[key] = i32();
    }
    return m;
  }
  template <class T, class F>
  std::vector<T> list(F&& f) {
    std::vector<T> v(count());
    for (auto& x : v) f(x);
    return v;
  }
  void magic() {
    for (char c : kMagic)
      if (pod<char>() != c) corrupt("wrong tag");
    if (pod<std::uint32_t>() != kFormat) corrupt("other format version");
  }
  bool done() const { return pos_ == in_.size(); }

 private:
  const std::string& in_;
  std::size_t pos_ = 0;
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
  w.vd(r.m);
  w.s(r.description);
}

Profile get_profile(Reader& rd) {
  Profile::Raw r;
  const int kind = rd.i32();
  if (kind < 0 || kind >= static_cast<int>(Profile::Kind::Callback)) corrupt("bad profile kind");
  r.kind = static_cast<Profile::Kind>(kind);
  for (double& x : r.p) x = rd.d();
  r.t = rd.vd();
  r.y = rd.vd();
  r.m = rd.vd();
  r.description = rd.s();
  return Profile::restore(r);
}

void put_motor(Writer& w, const MotorSpec& ms) {
  w.s(ms.name);
  for (const auto& [name, field] : MotorSpec::fields()) {
    (void)name;
    w.d(ms.*field);
  }
}

void get_motor(Reader& rd, MotorSpec& ms) {
  ms.name = rd.s();
  for (const auto& [name, field] : MotorSpec::fields()) {
    (void)name;
    ms.*field = rd.d();
  }
}

}  // namespace

std::string serialize_model(const Model& m) {
  Writer w;
  w.out.append(kMagic, sizeof(kMagic));
  w.pod<std::uint32_t>(kFormat);
  w.list(m.bodies, [&](const Body& x) {
    w.s(x.name);
    w.d(x.mass);
    w.mat(x.inertia);
    w.mat(x.position);
    w.mat(x.orientation);
  });
  w.list(m.joints, [&](const Joint& x) {
    w.s(x.name);
    w.i(static_cast<int>(x.type));
    w.i(x.parent);
    w.i(x.child);
    w.mat(x.point_parent);
    w.mat(x.point_child);
    w.mat(x.frame_parent);
    w.mat(x.frame_child);
    w.d(x.lower);
    w.d(x.upper);
    w.d(x.effort);
    w.d(x.velocity_limit);
    w.d(x.length);
    w.i(x.row0);
    w.i(x.coord0);
    w.i(x.q0);
    w.i(x.dof0);
  });
  w.list(m.drives, [&](const Drive& x) {
    w.s(x.name);
    w.i(x.joint);
    w.i(x.coord);
    put_profile(w, x.profile, "drive '" + x.name + "'");
    w.i(x.row);
  });
  w.list(m.body_loads, [&](const BodyLoad& x) {
    w.i(x.body);
    w.mat(x.force);
    w.mat(x.torque);
    w.mat(x.point);
    w.b(x.has_profile);
    put_profile(w, x.profile, "the load on body '" + m.body_name(x.body) + "'");
  });
  w.list(m.springs, [&](const SpringDamper& x) {
    w.s(x.name);
    w.i(x.body_a);
    w.i(x.body_b);
    w.mat(x.point_a);
    w.mat(x.point_b);
    w.d(x.stiffness);
    w.d(x.damping);
    w.d(x.rest_length);
  });
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
    w.i(x.aux);
    w.s(x.name);
  });
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
    w.i(x.row);
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
  w.vi(m.tracked_coords);
  w.i(m.n_aux);
  w.list(m.coords, [&](const Coord& x) {
    w.s(x.name);
    w.i(x.joint);
    w.i(x.sub);
    w.b(x.angular);
  });
  w.i(m.n_free);
  w.i(m.nq_joint);
  w.i(m.nv_joint);
  w.vi(m.dof_joint);
  w.vs(m.q_names);
  w.vs(m.dof_names);
  w.list(m.frames, [&](const NamedFrame& x) {
    w.s(x.name);
    w.i(x.body);
    w.mat(x.point);
    w.mat(x.rotation);
  });
  {
    const IndependentCoords& ic = m.independent;
    w.i(ic.n);
    w.i(ic.lead_q);
    w.i(ic.lead_v);
    w.vi(ic.full);
    w.vi(ic.source);
    w.vd(ic.scale);
    w.vd(ic.shift);
  }
  w.mat(m.gravity);
  w.i(m.nb);
  w.i(m.nq);
  w.i(m.nv);
  w.i(m.nc);
  w.i(m.nc_joint);
  w.b(m.is_tree);
  w.b(m.joint_space_ok);
  w.s(m.joint_space_reason);
  w.b(m.coupled_joint_space);
  w.b(m.joint_tree);
  w.vi(m.tree_order);
  w.i(m.rank_joint);
  w.i(m.rank_all);
  w.i(m.mobility);
  w.i(m.mobility_driven);
  w.vs(m.redundant_rows);
  w.vs(m.warnings);
  w.vi(m.aligned_rows);
  w.b(m.redundant);
  w.d(m.length_scale);
  w.b(m.force_dense_kkt);
  w.b(m.finalize_options.mass_weighted_assembly);
  w.i(m.finalize_options.max_assembly_iterations);
  w.mat(m.u0);
  w.mat(m.v0);
  w.map(m.body_index);
  w.map(m.joint_index);
  w.map(m.drive_index);
  w.map(m.frame_index);
  return std::move(w.out);
}

Model deserialize_model(const std::string& bytes) {
  Reader r(bytes);
  r.magic();
  Model m;
  m.bodies = r.list<Body>([&](Body& x) {
    x.name = r.s();
    x.mass = r.d();
    r.mat(x.inertia);
    r.mat(x.position);
    r.mat(x.orientation);
  });
  m.joints = r.list<Joint>([&](Joint& x) {
    x.name = r.s();
    const int type = r.i32();
    if (type < 0 || type > static_cast<int>(JointType::Distance)) corrupt("bad joint type");
    x.type = static_cast<JointType>(type);
    x.parent = r.i32();
    x.child = r.i32();
    r.mat(x.point_parent);
    r.mat(x.point_child);
    r.mat(x.frame_parent);
    r.mat(x.frame_child);
    x.lower = r.d();
    x.upper = r.d();
    x.effort = r.d();
    x.velocity_limit = r.d();
    x.length = r.d();
    x.row0 = r.i32();
    x.coord0 = r.i32();
    x.q0 = r.i32();
    x.dof0 = r.i32();
  });
  m.drives = r.list<Drive>([&](Drive& x) {
    x.name = r.s();
    x.joint = r.i32();
    x.coord = r.i32();
    x.profile = get_profile(r);
    x.row = r.i32();
  });
  m.body_loads = r.list<BodyLoad>([&](BodyLoad& x) {
    x.body = r.i32();
    r.mat(x.force);
    r.mat(x.torque);
    r.mat(x.point);
    x.has_profile = r.b();
    x.profile = get_profile(r);
  });
  m.springs = r.list<SpringDamper>([&](SpringDamper& x) {
    x.name = r.s();
    x.body_a = r.i32();
    x.body_b = r.i32();
    r.mat(x.point_a);
    r.mat(x.point_b);
    x.stiffness = r.d();
    x.damping = r.d();
    x.rest_length = r.d();
  });
  m.coord_forces = r.list<CoordForce>([&](CoordForce& x) {
    x.coord = r.i32();
    x.stiffness = r.d();
    x.damping = r.d();
    x.rest = r.d();
    x.coulomb = r.d();
    x.v_smooth = r.d();
    x.has_input = r.b();
    x.input = get_profile(r);
    x.motor = r.b();
    x.reference = get_profile(r);
    x.kp = r.d();
    x.kd = r.d();
    x.ki = r.d();
    x.torque_limit = r.d();
    x.aux = r.i32();
    x.name = r.s();
  });
  m.gears = r.list<GearPair>([&](GearPair& x) {
    x.name = r.s();
    x.coord_a = r.i32();
    x.coord_b = r.i32();
    x.r_a = r.d();
    x.r_b = r.d();
    x.backlash = r.d();
    x.stiffness = r.d();
    x.exponent = r.d();
    x.hc_damping = r.d();
  });
  m.gear_constraints = r.list<GearConstraint>([&](GearConstraint& x) {
    x.name = r.s();
    x.coord_a = r.i32();
    x.coord_b = r.i32();
    x.r_a = r.d();
    x.r_b = r.d();
    x.offset = r.d();
    x.coupling = r.b();
    x.row = r.i32();
  });
  m.actuators = r.list<Actuator>([&](Actuator& x) {
    x.joint = r.i32();
    x.rotor_joint = r.i32();
    x.gear_ratio = r.d();
    x.rotor_inertia = r.d();
    x.efficiency = r.d();
    x.friction_viscous = r.d();
    x.friction_coulomb = r.d();
    x.friction_smoothing = r.d();
    x.gyroscopic = r.b();
    x.has_motor = r.b();
    get_motor(r, x.motor);
  });
  m.tracked_coords = r.vi();
  m.n_aux = r.i32();
  m.coords = r.list<Coord>([&](Coord& x) {
    x.name = r.s();
    x.joint = r.i32();
    x.sub = r.i32();
    x.angular = r.b();
  });
  m.n_free = r.i32();
  m.nq_joint = r.i32();
  m.nv_joint = r.i32();
  m.dof_joint = r.vi();
  m.q_names = r.vs();
  m.dof_names = r.vs();
  m.frames = r.list<NamedFrame>([&](NamedFrame& x) {
    x.name = r.s();
    x.body = r.i32();
    r.mat(x.point);
    r.mat(x.rotation);
  });
  {
    IndependentCoords& ic = m.independent;
    ic.n = r.i32();
    ic.lead_q = r.i32();
    ic.lead_v = r.i32();
    ic.full = r.vi();
    ic.source = r.vi();
    ic.scale = r.vd();
    ic.shift = r.vd();
  }
  r.mat(m.gravity);
  m.nb = r.i32();
  m.nq = r.i32();
  m.nv = r.i32();
  m.nc = r.i32();
  m.nc_joint = r.i32();
  m.is_tree = r.b();
  m.joint_space_ok = r.b();
  m.joint_space_reason = r.s();
  m.coupled_joint_space = r.b();
  m.joint_tree = r.b();
  m.tree_order = r.vi();
  m.rank_joint = r.i32();
  m.rank_all = r.i32();
  m.mobility = r.i32();
  m.mobility_driven = r.i32();
  m.redundant_rows = r.vs();
  m.warnings = r.vs();
  m.aligned_rows = r.vi();
  m.redundant = r.b();
  m.length_scale = r.d();
  m.force_dense_kkt = r.b();
  m.finalize_options.mass_weighted_assembly = r.b();
  m.finalize_options.max_assembly_iterations = r.i32();
  r.mat(m.u0);
  r.mat(m.v0);
  m.body_index = r.map();
  m.joint_index = r.map();
  m.drive_index = r.map();
  m.frame_index = r.map();
  if (!r.done()) corrupt("trailing bytes");
  // the sizes the solver indexes by must agree with the stored tables
  // (a builder's draft has its sizes still zero)
  if ((m.nb != 0 && m.nb != static_cast<int>(m.bodies.size())) || m.nq != 7 * m.nb ||
      m.nv != 6 * m.nb || (m.u0.size() != 0 && m.u0.size() != m.nq) ||
      (m.v0.size() != 0 && m.v0.size() != m.nv))
    corrupt("inconsistent sizes");
  return m;
}

}  // namespace armdyn
