// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/regressor.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "armdyn/errors.hpp"
#include "armdyn/kernels/joint_space.hpp"
#include "armdyn/math/quaternion.hpp"

namespace armdyn {

// (a named namespace: the algorithm sources share one unity translation unit)
namespace regressor_detail {

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

// the bodies with parameters and their parameter frames
void layout_bodies(const Model& m, ParameterLayout& L) {
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

// the coordinates' friction, actuators and rows
void layout_coordinates(const Model& m, ParameterLayout& L, const char* fn) {
  const int nc = m.independent.n;
  L.coulomb.assign(nc, {});
  L.viscous.assign(nc, 0.0);
  L.actuators.assign(nc, {});
  L.gyroscopic.assign(nc, 0);
  L.coulomb_sum.assign(nc, 0.0);
  for (const CoordForce& cf : m.coord_forces) {
    const auto [k, s] = source_of(m, cf.coord);
    L.viscous[k] += s * s * cf.damping;
    if (cf.coulomb != 0.0) {
      L.coulomb[k].emplace_back(std::abs(s) * cf.coulomb, cf.v_smooth / std::abs(s));
      L.coulomb_sum[k] += std::abs(s) * cf.coulomb;
    }
  }
  for (int a = 0; a < static_cast<int>(m.actuators.size()); ++a) {
    const int c = actuated_coord(m, m.actuators[a].joint);
    if (c < 0) throw ModelError(msg(fn, ": actuator ", a, " acts on no joint coordinate"));
    const auto [k, scale] = source_of(m, c);
    L.actuators[k].push_back(a);
    const Actuator& act = m.actuators[a];
    L.reflection.push_back(act.gear_ratio * act.gear_ratio *
                           (act.gyroscopic ? 1.0 : scale * scale));
  }
  for (int k = 0; k < nc; ++k) {
    int gyro = 0;
    for (int a : L.actuators[k]) gyro += m.actuators[a].gyroscopic ? 1 : 0;
    if (gyro != 0 && gyro != static_cast<int>(L.actuators[k].size()))
      throw ModelError(msg(fn, ": joint coordinate '", m.coords[m.independent.full[k]].name,
                           "' has both a gyroscopic and a gear-reduced actuator"));
    L.gyroscopic[k] = gyro != 0;
  }
  // the full degrees of freedom's rows of G^T (IndependentCoords::reduce)
  const int lead = m.independent.lead_v, nfull = m.nv_joint;
  L.dof_row.assign(nfull, 0);
  L.dof_scale.assign(nfull, 1.0);
  for (int r = 0; r < nfull; ++r) {
    L.dof_row[r] = r;
    if (r >= lead && !m.independent.source.empty()) {
      L.dof_row[r] = lead + m.independent.source[r - lead];
      L.dof_scale[r] = m.independent.scale[r - lead];
    }
  }
}

}  // namespace regressor_detail

ParameterLayout dynamic_parameter_layout(const Model& m) {
  constexpr const char* fn = "dynamic_parameter_layout";
  require_joint_space(m, fn, true);
  regressor_detail::refuse_non_parameters(m, fn);
  ParameterLayout L;
  regressor_detail::layout_bodies(m, L);
  regressor_detail::layout_coordinates(m, L, fn);
  L.n_params = L.coord_offset(m.independent.n);
  for (int k = 0; k < m.independent.n; ++k)
    for (int a : L.actuators[k]) {
      const Actuator& act = m.actuators[a];
      if (!act.gyroscopic) continue;
      ParameterLayout::Rotor r;
      r.body = m.joints[act.rotor_joint].child;
      r.column = L.coord_offset(k) + 3;
      r.weights = regressor_detail::rotor_weights(m, act);
      L.rotors.push_back(r);
    }
  return L;
}

const ParameterLayout& cached_parameter_layout(const Model& m) {
  return m.derived.get<ParameterLayout>([&] { return dynamic_parameter_layout(m); });
}

std::vector<std::string> dynamic_parameter_names(const Model& m) {
  const ParameterLayout& L = cached_parameter_layout(m);
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
  const ParameterLayout& L = cached_parameter_layout(m);
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
    pi[o + 1] = L.coulomb_sum[k];
    for (int a : L.actuators[k]) {
      const Actuator& act = m.actuators[a];
      pi[o + 3] += L.reflection[a] * act.rotor_inertia;
    }
  }
  return pi;
}

namespace regressor_detail {

using Row10 = Eigen::Matrix<double, 1, 10>;
using Weights = Eigen::Matrix<double, 10, 1>;

// the unit inertias' order (Ixx, Ixy, Iyy, Ixz, Iyz, Izz): the entries (a, b) of each
constexpr int kInertiaRow[6] = {0, 0, 1, 0, 1, 2}, kInertiaCol[6] = {0, 1, 1, 2, 2, 2};

// a parameter frame's pose (world) and velocity (its own axes): the energy regressor's
struct FrameMotion {
  Mat3 R;     // frame -> world
  Vec3 p;     // origin (world)
  Vec3 w, v;  // angular velocity, the origin's velocity (frame axes)
};

// body b's frame at point (body frame, from the centre of mass) with axes rot (frame -> body)
void frame_motion(const Data& d, int b, const Vec3& point, const Mat3& rot, FrameMotion& f) {
  const BodyKin& k = d.kin[b];
  f.R.noalias() = k.R * rot;
  const Vec3 r = k.R * point;
  f.p = k.x + r;
  f.w.noalias() = f.R.transpose() * k.W;
  f.v.noalias() = f.R.transpose() * (k.xd + k.W.cross(r));
}

// A body's Newton-Euler wrench per unit parameter (Atkeson, An, Hollerbach 1986): with mass m,
// first moment h and inertia I about its parameter frame's origin p, the force is
// f = m a + al x h + W x (W x h) and the moment about p n = h x a + I al + W x (I W) (a the
// acceleration of p less gravity, al and W the angular acceleration and velocity). The 6 x 10
// block F of these per parameter is kept in factors: its mass column is (0, a); its first-moment
// columns (h = R e_k) give a degree of freedom of motion S = (sw, sv) about p (world axes) the
// row R^T (a x sw + sv x al + W (W . sv) - |W|^2 sv); its inertia columns (f = 0) the row
// (R^T sw)^T N, N the moments U al + W x (U W) of the unit inertias U in the frame's axes.
struct BodyTerms {
  Mat3 R;                         // frame -> world
  Vec3 p, a, al, W;               // world
  double W2 = 0.0;                // |W|^2
  Vec3 w_f, al_f, a_f;            // W, al and a in the frame's axes
  Eigen::Matrix<double, 3, 6> N;  // frame axes
};

void body_terms(const Model& m, const Data& d, int b, const Vec3& point, const Mat3& rot,
                BodyTerms& t) {
  const BodyKin& k = d.kin[b];
  t.R.noalias() = k.R * rot;
  const Vec3 r = k.R * point;
  t.p = k.x + r;
  t.W = k.W;
  t.W2 = k.W.squaredNorm();
  t.al = d.rne.alpha[b];
  t.a = d.rne.acc[b] + t.al.cross(r) + k.W.cross(k.W.cross(r)) - m.gravity;
  t.w_f.noalias() = t.R.transpose() * k.W;
  t.al_f.noalias() = t.R.transpose() * t.al;
  t.a_f.noalias() = t.R.transpose() * t.a;
  const Vec3 &w = t.w_f, &al = t.al_f;
  const double xx = w[0] * w[0], yy = w[1] * w[1], zz = w[2] * w[2];
  const double xy = w[0] * w[1], xz = w[0] * w[2], yz = w[1] * w[2];
  // U al + w x (U w) for Ixx, Ixy, Iyy, Ixz, Iyz, Izz
  t.N << al[0], al[1] - xz, -yz, al[2] + xy, yy - zz, yz,  //
      xz, al[0] + yz, al[1], zz - xx, al[2] - xy, -xz,     //
      -xy, xx - yy, xy, al[0] - yz, al[1] + xz, al[2];
}

// the row S^T F of body terms t for the motion S = (sw, sv) about t.p (world axes)
// (inlined: called once per degree of freedom and body, the recursion's inner loop)
template <bool Turns>
EIGEN_STRONG_INLINE Row10 unit_row(const BodyTerms& t, const Vec3& sw, const Vec3& sv) {
  Row10 row;
  row[0] = t.a.dot(sv);
  Vec3 u = sv.cross(t.al) + t.W.dot(sv) * t.W - t.W2 * sv;
  if constexpr (Turns) {
    u += t.a.cross(sw);
    Eigen::Matrix<double, 3, 2> us;
    us << u, sw;
    const Eigen::Matrix<double, 3, 2> ul = t.R.transpose() * us;
    row.segment<3>(1) = ul.col(0).transpose();
    row.tail<6>().noalias() = ul.col(1).transpose() * t.N;
  } else {
    row.segment<3>(1).noalias() = (t.R.transpose() * u).transpose();
    row.tail<6>().setZero();
  }
  return row;
}

// the output: row-major (rs = n_params, cs = 1) or a column-major matrix (rs = 1, cs = rows)
struct Out {
  double* data;
  long rs, cs;
  double& at(int row, int col) const { return data[row * rs + col * cs]; }
};

// The six rows of a free joint (base frame B, origin P) at once: its translations' (sv = B_k,
// sw = 0) and rotations' (sw = B_k, sv = B_k x (p - P)) rows of unit_row, in the frame's axes
// with Bl = R^T B: the mass column B^T a and B^T ((p - P) x a); the first moments' Fh^T Bl and
// ([a]x - Fh^T [r]x) Bl (Fh^T v = v x al + w (w . v) - |w|^2 v); the inertias' Bl^T N.
EIGEN_ALWAYS_INLINE void free_rows(const BodyTerms& t, const Mat3& B, const Vec3& P,
                                   Eigen::Matrix<double, 6, 10>& F) {
  const Mat3 Bl = t.R.transpose() * B;
  const Vec3 rl = t.R.transpose() * (t.p - P);
  Mat3 FhT = t.w_f * t.w_f.transpose() - skew(t.al_f);  // Fh^T = -[al]x + w w^T - |w|^2 1
  FhT.diagonal().array() -= t.W2;
  F.block<3, 1>(0, 0).noalias() = Bl.transpose() * t.a_f;
  F.block<3, 1>(3, 0).noalias() = Bl.transpose() * rl.cross(t.a_f);
  F.block<3, 3>(0, 1).noalias() = (FhT * Bl).transpose();
  const Mat3 K = skew(t.a_f) - FhT * skew(rl);
  F.block<3, 3>(3, 1).noalias() = (K * Bl).transpose();
  F.block<3, 6>(0, 4).setZero();
  F.block<3, 6>(3, 4).noalias() = Bl.transpose() * t.N;
}

// Adds the rows of the degrees of freedom on body b's path to the root: row(dof, sw, sv, turns)
// gives each one's entries for its motion (sw, sv) about t.p in world axes, free(dof0, B, P) a
// free joint's six (free_rows).
template <class RowFn, class FreeFn>
EIGEN_STRONG_INLINE void path_rows(const Model& m, const Data& d, int b, const Vec3& p, RowFn&& row,
                                   FreeFn&& free) {
  for (int ja = d.joint_of_body[b]; ja >= 0;) {
    const Joint& j = m.joints[ja];
    const Vec3& P = d.rne.point[ja];
    const Vec3& z = d.rne.axis[ja];
    switch (j.type) {
      case JointType::Revolute:
        row(j.dof0, z, z.cross(p - P), std::true_type{});
        break;
      case JointType::Prismatic:
        row(j.dof0, Vec3::Zero(), z, std::false_type{});
        break;
      case JointType::Cylindrical:
        row(j.dof0, z, z.cross(p - P), std::true_type{});
        row(j.dof0 + 1, Vec3::Zero(), z, std::false_type{});
        break;
      case JointType::Free:
        free(j.dof0, free_frame(j, d.kin[j.child]), P);
        break;
      default:
        break;
    }
    ja = j.parent == kGround ? -1 : d.joint_of_body[j.parent];
  }
}

// the checks of inverse_dynamics (its sizes, values, quaternions; qdd when given), and the
// layout (the model's cached one, its pointer kept in the Data)
const ParameterLayout& checked_layout(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                                      Eigen::Ref<const VecX> qd, const Eigen::Ref<const VecX>* qdd,
                                      const char* fn) {
  require_joint_space(m, fn, true);
  check_data(m, d, fn);
  check_joint_vector(q, d.niq, fn, "q");
  check_joint_vector(qd, d.ni, fn, "qd");
  if (qdd) check_joint_vector(*qdd, d.ni, fn, "qdd");
  check_base_quaternions(m, q, fn);
  if (!d.parameter_layout) d.parameter_layout = &cached_parameter_layout(m);
  return *d.parameter_layout;
}

// the model's full coordinates (a coupled model's expanded into the Data's buffers) and its
// kinematics at them; with qdd also the forward Newton-Euler sweep
void load_state(const Model& m, Data& d, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                const Eigen::Ref<const VecX>* qdd) {
  if (d.ni == d.n) {
    joint_space_kinematics(m, q, qd, d.kin, d.rne);
    if (qdd) rne_forward(m, d.kin, qd, *qdd, d.rne);
    return;
  }
  Data::Coupled& c = d.coupled;
  m.independent.expand_q(q.data(), c.q.data());
  m.independent.expand_v(qd.data(), c.qd.data());
  joint_space_kinematics(m, c.q, c.qd, d.kin, d.rne);
  if (qdd) {
    m.independent.expand_v(qdd->data(), c.qdd.data());
    rne_forward(m, d.kin, c.qd, c.qdd, d.rne);
  }
}

// the rigid bodies' and gyroscopic rotors' columns: for each, its terms, then one row block per
// degree of freedom on its path to the root (into the row G^T reduces it to)
void body_columns(const Model& m, const Data& d, const ParameterLayout& L, const Out& out) {
  BodyTerms t;
  Eigen::Matrix<double, 6, 10> F;
  for (int i = 0; i < static_cast<int>(L.bodies.size()); ++i) {
    const int b = L.bodies[i], col = L.body_offset(i);
    body_terms(m, d, b, L.frame_point[i], L.frame_rotation[i], t);
    auto write = [&](int dof, const auto& row) {
      const double s = L.dof_scale[dof];
      double* o = &out.at(L.dof_row[dof], col);
      if (out.cs == 1)
        Eigen::Map<Row10>(o) += s * row;
      else
        for (int k = 0; k < 10; ++k) o[k * out.cs] += s * row[k];
    };
    path_rows(
        m, d, b, t.p,
        [&](int dof, const Vec3& sw, const Vec3& sv, auto turns) {
          write(dof, unit_row<decltype(turns)::value>(t, sw, sv));
        },
        [&](int dof0, const Mat3& B, const Vec3& P) {
          free_rows(t, B, P, F);
          for (int k = 0; k < 6; ++k) write(dof0 + k, F.row(k));
        });
  }
  for (const ParameterLayout::Rotor& r : L.rotors) {
    body_terms(m, d, r.body, Vec3::Zero(), Mat3::Identity(), t);
    path_rows(
        m, d, r.body, t.p,
        [&](int dof, const Vec3& sw, const Vec3& sv, auto turns) {
          const Row10 row = unit_row<decltype(turns)::value>(t, sw, sv);
          out.at(L.dof_row[dof], r.column) += L.dof_scale[dof] * row.dot(r.weights);
        },
        [&](int dof0, const Mat3& B, const Vec3& P) {
          free_rows(t, B, P, F);
          const Vec6 Fw = F * r.weights;
          for (int k = 0; k < 6; ++k) out.at(L.dof_row[dof0 + k], r.column) += Fw[k];
        });
  }
}

// the coordinates' columns: fv qd, fc (the model's smoothed sign), offset 1, Ia qdd (gear-reduced)
void coordinate_columns(const Model& m, const ParameterLayout& L, Eigen::Ref<const VecX> qd,
                        Eigen::Ref<const VecX> qdd, const Out& out) {
  const int lead = m.independent.lead_v;
  for (int kc = 0; kc < m.independent.n; ++kc) {
    const int r = lead + kc, o0 = L.coord_offset(kc);
    const double v = qd[r];
    out.at(r, o0) = v;
    double fc = 0.0;
    if (L.coulomb_sum[kc] > 0.0) {
      for (const auto& [c, vs] : L.coulomb[kc]) fc += c * std::tanh(v / vs);
      fc /= L.coulomb_sum[kc];
    } else {
      fc = std::tanh(v / kRegressorCoulombSmoothing);
    }
    out.at(r, o0 + 1) = fc;
    out.at(r, o0 + 2) = 1.0;
    if (!L.gyroscopic[kc]) out.at(r, o0 + 3) = qdd[r];
  }
}

// Y at a checked state into out (every entry written)
void regressor_into(const Model& m, Data& d, const ParameterLayout& L, Eigen::Ref<const VecX> q,
                    Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> qdd, const Out& out) {
  std::fill(out.data, out.data + static_cast<long>(d.ni) * L.n_params, 0.0);  // (contiguous)
  load_state(m, d, q, qd, &qdd);
  body_columns(m, d, L, out);
  coordinate_columns(m, L, qd, qdd, out);
}

// a frame's kinetic and potential energy per unit parameter: 0.5 |v|^2 - g . p (mass),
// v x w - R^T g (first moment), 0.5 w^T U w (unit inertias U)
void unit_energies(const FrameMotion& f, const Vec3& g, double* h) {
  h[0] = 0.5 * f.v.squaredNorm() - g.dot(f.p);
  Eigen::Map<Vec3>(h + 1) = f.v.cross(f.w) - f.R.transpose() * g;
  for (int k = 0; k < 6; ++k) {
    const int i = kInertiaRow[k], j = kInertiaCol[k];
    h[4 + k] = i == j ? 0.5 * f.w[i] * f.w[i] : f.w[i] * f.w[j];
  }
}

// h at a checked state into h (every entry written)
void energy_into(const Model& m, Data& d, const ParameterLayout& L, Eigen::Ref<const VecX> q,
                 Eigen::Ref<const VecX> qd, double* h) {
  std::fill(h, h + L.n_params, 0.0);
  load_state(m, d, q, qd, nullptr);
  FrameMotion f;
  for (int i = 0; i < static_cast<int>(L.bodies.size()); ++i) {
    frame_motion(d, L.bodies[i], L.frame_point[i], L.frame_rotation[i], f);
    unit_energies(f, m.gravity, h + L.body_offset(i));
  }
  Weights e;
  for (const ParameterLayout::Rotor& r : L.rotors) {
    // (a rotor's mass is its link's: only its inertia, whose weights are the rotational ones)
    frame_motion(d, r.body, Vec3::Zero(), Mat3::Identity(), f);
    unit_energies(f, m.gravity, e.data());
    h[r.column] += r.weights.dot(e);
  }
  const int lead = m.independent.lead_v;
  for (int kc = 0; kc < m.independent.n; ++kc)
    if (!L.gyroscopic[kc]) h[L.coord_offset(kc) + 3] = 0.5 * qd[lead + kc] * qd[lead + kc];
}

}  // namespace regressor_detail

void joint_torque_regressor(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                            Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> qdd, MatX& Y) {
  // the checks first: a refused call leaves Y as it was
  const ParameterLayout& L =
      regressor_detail::checked_layout(m, d, q, qd, &qdd, "joint_torque_regressor");
  Y.resize(d.ni, L.n_params);
  regressor_detail::regressor_into(m, d, L, q, qd, qdd,
                                   regressor_detail::Out{Y.data(), 1, Y.rows()});
}

void joint_torque_regressor_into(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                                 Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> qdd,
                                 double* out) {
  const ParameterLayout& L =
      regressor_detail::checked_layout(m, d, q, qd, &qdd, "joint_torque_regressor");
  regressor_detail::regressor_into(m, d, L, q, qd, qdd, regressor_detail::Out{out, L.n_params, 1});
}

void energy_regressor(const Model& m, Data& d, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                      VecX& h) {
  const ParameterLayout& L =
      regressor_detail::checked_layout(m, d, q, qd, nullptr, "energy_regressor");
  h.resize(L.n_params);
  regressor_detail::energy_into(m, d, L, q, qd, h.data());
}

void energy_regressor_into(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                           Eigen::Ref<const VecX> qd, double* out) {
  const ParameterLayout& L =
      regressor_detail::checked_layout(m, d, q, qd, nullptr, "energy_regressor");
  regressor_detail::energy_into(m, d, L, q, qd, out);
}

}  // namespace armdyn
