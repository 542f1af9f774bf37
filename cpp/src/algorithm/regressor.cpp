// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/regressor.hpp"

#include <cmath>

#include "armdyn/errors.hpp"
#include "armdyn/kernels/joint_space.hpp"

namespace armdyn {

// (a named namespace: the algorithm sources share one unity translation unit)
namespace regressor_detail {

// a spatial inertia about o in world axes: mass, first moment m (c - o), inertia about o
struct SpatialInertia {
  double m = 0.0;
  Vec3 h = Vec3::Zero();
  Mat3 I = Mat3::Zero();
};

// the Newton-Euler wrench (about o, world axes, torque first) of a body of spatial inertia Y with
// spatial velocity V = (w, v_o) and acceleration A = (alpha, a_o) offset by gravity
Vec6 wrench(const SpatialInertia& Y, const Vec6& V, const Vec6& A) {
  auto times = [&Y](const Vec6& x) {
    Vec6 r;
    r.head<3>().noalias() = Y.I * x.head<3>();
    r.head<3>() += Y.h.cross(x.tail<3>());
    r.tail<3>() = Y.m * x.tail<3>() - Y.h.cross(x.head<3>());
    return r;
  };
  const Vec6 hm = times(V);
  Vec6 f = times(A);
  f.head<3>() += V.head<3>().cross(hm.head<3>()) + V.tail<3>().cross(hm.tail<3>());
  f.tail<3>() += V.head<3>().cross(hm.tail<3>());
  return f;
}

// the 10 unit spatial inertias (about o, world axes) of a parameter frame with origin r (from o)
// and axes R (frame -> world), in ParameterLayout's order
std::array<SpatialInertia, 10> unit_inertias(const Vec3& r, const Mat3& R) {
  std::array<SpatialInertia, 10> Y;
  Y[0].m = 1.0;
  Y[0].h = r;
  Y[0].I = r.squaredNorm() * Mat3::Identity() - r * r.transpose();
  for (int a = 0; a < 3; ++a) {
    const Vec3 e = R.col(a);
    Y[1 + a].h = e;
    Y[1 + a].I = 2.0 * r.dot(e) * Mat3::Identity() - r * e.transpose() - e * r.transpose();
  }
  // Ixx, Ixy, Iyy, Ixz, Iyz, Izz
  constexpr int rows[6] = {0, 0, 1, 0, 1, 2}, cols[6] = {0, 1, 1, 2, 2, 2};
  for (int k = 0; k < 6; ++k) {
    const Vec3 u = R.col(rows[k]), v = R.col(cols[k]);
    Y[4 + k].I =
        rows[k] == cols[k] ? Mat3(u * u.transpose()) : Mat3(u * v.transpose() + v * u.transpose());
  }
  return Y;
}

Vec3 about_point(const Model& m, const Data& d) {
  if (m.n_free == 0) return Vec3::Zero();
  for (int ji : m.tree_order)
    if (m.joints[ji].type == JointType::Free) return d.kin[m.joints[ji].child].x;
  return Vec3::Zero();
}

// degree of freedom k of joint j: its world motion about o
Vec6 dof_motion(const Joint& j, int k, const BodyKin& child, const Vec3& point, const Vec3& axis,
                const Vec3& o) {
  Vec6 s;
  const Vec3 p = point - o;
  if (j.type == JointType::Free) {
    const Vec3 e = free_frame(j, child).col(k % 3);
    if (k < 3)
      s << Vec3::Zero(), e;
    else
      s << e, p.cross(e);
    return s;
  }
  if (j.type == JointType::Prismatic || k == 1)
    s << Vec3::Zero(), axis;
  else
    s << axis, p.cross(axis);
  return s;
}

// the independent coordinate of joint coordinate c and its scale (q_c = s q_k + shift)
std::pair<int, double> source_of(const Model& m, int c) {
  return {m.independent.source[c], m.independent.scale[c]};
}

void refuse_non_parameters(const Model& m, const char* fn) {
  if (!m.body_loads.empty())
    throw ModelError(msg(fn, ": the model has body loads, which are not dynamic parameters"));
  if (!m.springs.empty())
    throw ModelError(msg(fn, ": spring-damper '", m.springs[0].name,
                         "' is not a dynamic parameter (remove it for identification)"));
  if (!m.gears.empty())
    throw ModelError(msg(fn, ": gear pair '", m.gears[0].name, "' is not a dynamic parameter"));
  for (const CoordForce& cf : m.coord_forces) {
    const char* what = cf.stiffness != 0.0 ? "a spring"
                       : cf.has_input      ? "a torque input"
                       : cf.motor          ? "a PD motor"
                                           : nullptr;
    if (what)
      throw ModelError(msg(fn, ": joint coordinate '", m.coords[cf.coord].name, "' has ", what,
                           ", which is not a dynamic parameter (only friction is)"));
  }
}

int actuated_coord(const Model& m, int joint) {
  for (int c = 0; c < static_cast<int>(m.coords.size()); ++c)
    if (m.coords[c].joint == joint && m.coords[c].sub == 0) return c;
  return -1;
}

}  // namespace regressor_detail

using namespace regressor_detail;

ParameterLayout dynamic_parameter_layout(const Model& m) {
  constexpr const char* fn = "dynamic_parameter_layout";
  require_joint_space(m, fn, true);
  refuse_non_parameters(m, fn);
  ParameterLayout L;
  std::vector<bool> rotor(static_cast<size_t>(m.nb), false);
  for (const Actuator& a : m.actuators) rotor[m.joints[a.rotor_joint].child] = true;
  for (int b = 0; b < m.nb; ++b) {
    if (rotor[b]) continue;
    L.bodies.push_back(b);
    Vec3 p = Vec3::Zero();
    Mat3 R = Mat3::Identity();
    std::string name;
    for (const NamedFrame& f : m.frames)
      if (f.body == b && f.name == m.bodies[b].name) {
        p = f.point;
        R = f.rotation;
        name = f.name;
        break;
      }
    L.frame_point.push_back(p);
    L.frame_rotation.push_back(R);
    L.frame_name.push_back(name);
  }
  const int nc = m.independent.n;
  L.coulomb.assign(nc, {});
  L.viscous.assign(nc, 0.0);
  L.actuators.assign(nc, {});
  for (const CoordForce& cf : m.coord_forces) {
    const auto [k, s] = source_of(m, cf.coord);
    L.viscous[k] += s * s * cf.damping;
    if (cf.coulomb != 0.0)
      L.coulomb[k].emplace_back(std::abs(s) * cf.coulomb, cf.v_smooth / std::abs(s));
  }
  for (int a = 0; a < static_cast<int>(m.actuators.size()); ++a) {
    const int c = actuated_coord(m, m.actuators[a].joint);
    if (c < 0) throw ModelError(msg(fn, ": actuator ", a, " acts on no joint coordinate"));
    L.actuators[source_of(m, c).first].push_back(a);
  }
  for (int k = 0; k < nc; ++k) {
    int gyro = 0;
    for (int a : L.actuators[k]) gyro += m.actuators[a].gyroscopic ? 1 : 0;
    if (gyro != 0 && gyro != static_cast<int>(L.actuators[k].size()))
      throw ModelError(msg(fn, ": joint coordinate '", m.coords[m.independent.full[k]].name,
                           "' has both a gyroscopic and a gear-reduced actuator"));
  }
  L.n_params = L.coord_offset(nc);
  return L;
}

std::vector<std::string> dynamic_parameter_names(const Model& m) {
  const ParameterLayout L = dynamic_parameter_layout(m);
  static const char* body[10] = {"m",   "mcx", "mcy", "mcz", "Ixx",
                                 "Ixy", "Iyy", "Ixz", "Iyz", "Izz"};
  static const char* coord[4] = {"fv", "fc", "offset", "Ia"};
  std::vector<std::string> names;
  for (int b : L.bodies)
    for (const char* s : body) names.push_back(m.bodies[b].name + "." + s);
  for (int k = 0; k < m.independent.n; ++k)
    for (const char* s : coord) names.push_back(m.coords[m.independent.full[k]].name + "." + s);
  return names;
}

VecX dynamic_parameters(const Model& m) {
  const ParameterLayout L = dynamic_parameter_layout(m);
  VecX pi = VecX::Zero(L.n_params);
  for (int i = 0; i < static_cast<int>(L.bodies.size()); ++i) {
    const Body& b = m.bodies[L.bodies[i]];
    const Mat3& R = L.frame_rotation[i];
    const Vec3 dc = -L.frame_point[i];  // the centre of mass from the frame origin, body axes
    const Mat3 Ib =
        b.inertia + b.mass * (dc.squaredNorm() * Mat3::Identity() - dc * dc.transpose());
    const Mat3 I = R.transpose() * Ib * R;
    const Vec3 h = b.mass * (R.transpose() * dc);
    pi.segment<10>(L.body_offset(i)) << b.mass, h, I(0, 0), I(0, 1), I(1, 1), I(0, 2), I(1, 2),
        I(2, 2);
  }
  for (int k = 0; k < m.independent.n; ++k) {
    const int o = L.coord_offset(k);
    pi[o] = L.viscous[k];
    for (const auto& [c, v] : L.coulomb[k]) pi[o + 1] += c;
    for (int a : L.actuators[k]) {
      const Actuator& act = m.actuators[a];
      pi[o + 3] += act.gear_ratio * act.gear_ratio * act.rotor_inertia;
    }
  }
  return pi;
}

namespace regressor_detail {

// the columns of body b's parameters (unit inertias Y) into the full rows of its ancestors' dofs
void add_body_columns(const Model& m, const Data& d, int b, const std::array<SpatialInertia, 10>& Y,
                      const Vec6& V, const Vec6& A, const Vec3& o,
                      const Eigen::Matrix<double, 10, 1>& w, int col, bool combine, MatX& Yf) {
  Eigen::Matrix<double, 6, 10> F;
  for (int k = 0; k < 10; ++k) F.col(k) = wrench(Y[k], V, A);
  for (int ja = d.joint_of_body[b]; ja >= 0;) {
    const Joint& j = m.joints[ja];
    for (int k = 0; k < joint_dofs(j.type); ++k) {
      const int r = j.dof0 + k;
      const Vec6 S = dof_motion(j, k, d.kin[j.child], d.rne.point[ja], d.rne.axis[ja], o);
      const Eigen::Matrix<double, 1, 10> row = S.transpose() * F;
      if (combine)
        Yf(r, col) += row.dot(w);
      else
        Yf.block<1, 10>(r, col) += row;
    }
    ja = j.parent == kGround ? -1 : d.joint_of_body[j.parent];
  }
}

// a gyroscopic rotor's inertia per unit reflected inertia N^2 J (thin disc about its joint's
// axis: axial 1/N^2, transverse 1/(2 N^2)), as weights of the 10 body parameters (body frame)
Eigen::Matrix<double, 10, 1> rotor_weights(const Model& m, const Actuator& a) {
  const Vec3 ax = m.joints[a.rotor_joint].frame_child.col(2);
  const Mat3 S = (0.5 * (Mat3::Identity() + ax * ax.transpose())) / (a.gear_ratio * a.gear_ratio);
  Eigen::Matrix<double, 10, 1> w = Eigen::Matrix<double, 10, 1>::Zero();
  w.tail<6>() << S(0, 0), S(0, 1), S(1, 1), S(0, 2), S(1, 2), S(2, 2);
  return w;
}

}  // namespace regressor_detail

void joint_torque_regressor(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                            Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> qdd, MatX& Y) {
  constexpr const char* fn = "joint_torque_regressor";
  require_joint_space(m, fn, true);
  check_data(m, d, fn);
  check_joint_vector(q, d.niq, fn, "q");
  check_joint_vector(qd, d.ni, fn, "qd");
  check_joint_vector(qdd, d.ni, fn, "qdd");
  check_base_quaternions(m, q, fn);
  const ParameterLayout L = dynamic_parameter_layout(m);
  const bool coupled = d.ni != d.n;
  VecX qf(d.niq), qdf(d.n), qddf(d.n);
  if (coupled) {
    qf.resize(m.nq_joint);
    m.independent.expand_q(q.data(), qf.data());
    m.independent.expand_v(qd.data(), qdf.data());
    m.independent.expand_v(qdd.data(), qddf.data());
  } else {
    qf = q;
    qdf = qd;
    qddf = qdd;
  }
  joint_space_kinematics(m, qf, qdf, d.kin, d.rne);
  rne_forward(m, d.kin, qdf, qddf, d.rne);
  const Vec3 o = about_point(m, d);
  MatX Yf = MatX::Zero(d.n, L.n_params);
  auto motion = [&](int b, Vec6& V, Vec6& A) {
    const BodyKin& k = d.kin[b];
    const Vec3 c = k.x - o;
    const Vec3& alpha = d.rne.alpha[b];
    V << k.W, k.xd - k.W.cross(c);
    A << alpha, d.rne.acc[b] - alpha.cross(c) - k.W.cross(k.xd) - m.gravity;
  };
  const Eigen::Matrix<double, 10, 1> none = Eigen::Matrix<double, 10, 1>::Zero();
  for (int i = 0; i < static_cast<int>(L.bodies.size()); ++i) {
    const int b = L.bodies[i];
    const BodyKin& k = d.kin[b];
    Vec6 V, A;
    motion(b, V, A);
    const Vec3 r = k.x + k.R * L.frame_point[i] - o;
    add_body_columns(m, d, b, unit_inertias(r, k.R * L.frame_rotation[i]), V, A, o, none,
                     L.body_offset(i), false, Yf);
  }
  const int lead = m.independent.lead_v;
  for (int kc = 0; kc < m.independent.n; ++kc)
    for (int a : L.actuators[kc]) {
      const Actuator& act = m.actuators[a];
      if (!act.gyroscopic) continue;
      const int b = m.joints[act.rotor_joint].child;
      Vec6 V, A;
      motion(b, V, A);
      add_body_columns(m, d, b, unit_inertias(d.kin[b].x - o, d.kin[b].R), V, A, o,
                       rotor_weights(m, act), L.coord_offset(kc) + 3, true, Yf);
    }
  if (coupled) {
    Y.resize(d.ni, L.n_params);
    for (int c = 0; c < L.n_params; ++c) m.independent.reduce(Yf.col(c).data(), Y.col(c).data());
  } else {
    Y = Yf;
  }
  for (int kc = 0; kc < m.independent.n; ++kc) {
    const int r = lead + kc, o0 = L.coord_offset(kc);
    const double v = qd[r];
    Y(r, o0) = v;
    double sum = 0.0, col = 0.0;
    for (const auto& [c, vs] : L.coulomb[kc]) {
      sum += c;
      col += c * std::tanh(v / vs);
    }
    Y(r, o0 + 1) = sum > 0.0 ? col / sum : std::tanh(v / kRegressorCoulombSmoothing);
    Y(r, o0 + 2) = 1.0;
    bool gyro = false;
    for (int a : L.actuators[kc]) gyro = gyro || m.actuators[a].gyroscopic;
    if (!gyro) Y(r, o0 + 3) = qdd[r];
  }
}

}  // namespace armdyn
