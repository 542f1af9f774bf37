// SPDX-License-Identifier: BSD-3-Clause
// model_with_dynamic_parameters (armdyn/io/parameter_model.hpp).
#include "armdyn/io/parameter_model.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "armdyn/algorithm/regressor.hpp"
#include "armdyn/builder/builder.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/io/model_copy.hpp"
#include "armdyn/math/quaternion.hpp"

namespace armdyn {

// (a named namespace: the set-up sources share one unity translation unit)
namespace parameter_model_detail {

constexpr const char* kFn = "model_with_dynamic_parameters";

/// One body's new inertial description: mass, the centre of mass's shift from the old one and
/// the inertia about the new one (both in the body's axes).
struct BodyInertial {
  double mass = 0.0;
  Vec3 shift = Vec3::Zero();
  Mat3 inertia = Mat3::Zero();
};

void check_vector(const ParameterLayout& L, const VecX& pi, const std::vector<std::string>& names) {
  if (pi.size() != L.n_params)
    throw ModelError(msg(kFn, ": pi must have ", L.n_params,
                         " entries (dynamic_parameter_names(model)), got ", pi.size()));
  for (int i = 0; i < pi.size(); ++i)
    if (!std::isfinite(pi[i]))
      throw ModelError(msg(kFn, ": pi[", i, "] ('", names[i], "') must be finite, got ", pi[i]));
}

/// Body i of the layout from its 10 numbers (checked: mass, first moment, inertia).
BodyInertial body_inertial(const ParameterLayout& L, int i, const Eigen::Matrix<double, 10, 1>& p,
                           const std::string& body, bool physical) {
  const std::string who = msg(kFn, ": body '", body, "'");
  BodyInertial out;
  out.mass = p[0];
  if (!(p[0] >= 0.0))
    throw ModelError(msg(who, ": mass ('", body, ".m') must be >= 0, got ", p[0],
                         " (not physically consistent: the pseudo-inertia is not positive "
                         "semidefinite)"));
  const Vec3 h = p.segment<3>(1);  // first moment about the parameter frame, its axes
  Mat3 Io;
  Io << p[4], p[5], p[7], p[5], p[6], p[8], p[7], p[8], p[9];
  const Mat3& R = L.frame_rotation[i];
  if (p[0] == 0.0) {
    if (h.squaredNorm() != 0.0)
      throw ModelError(msg(who, ": zero mass with a nonzero first moment (", h.transpose(),
                           "): not physically consistent (the pseudo-inertia is not positive "
                           "semidefinite) and no centre of mass"));
    out.inertia = R * Io * R.transpose();  // the old frame kept (shift 0)
  } else {
    const Vec3 c = h / p[0];  // the centre of mass in the parameter frame
    const Mat3 Ic = Io - p[0] * (c.squaredNorm() * Mat3::Identity() - c * c.transpose());
    out.shift = L.frame_point[i] + R * c;
    out.inertia = R * Ic * R.transpose();
  }
  out.inertia = 0.5 * (out.inertia + out.inertia.transpose());
  const InertiaCheck ic = check_inertia(out.inertia, physical);
  if (!ic.problem.empty())
    throw ModelError(
        msg(who, ": the inertia about the centre of mass ", ic.problem, " (principal moments ",
            ic.moments.transpose(), ")",
            ic.kind == InertiaProblem::TriangleInequality
                ? ": not physically consistent (physical_inertia=False accepts it)"
                : ": not physically consistent (the pseudo-inertia is not positive semidefinite)"));
  out.inertia = ic.tensor;
  return out;
}

/// Move body b's frame origin by `shift` (its axes): every point held in the body moves back.
void move_body_origin(Model& d, int b, const Vec3& shift) {
  Body& body = d.bodies[b];
  body.position += quat_to_rot(body.orientation) * shift;
  for (Joint& j : d.joints) {
    if (j.parent == b) j.point_parent -= shift;
    if (j.child == b) j.point_child -= shift;
  }
  for (NamedFrame& f : d.frames)
    if (f.body == b) f.point -= shift;
  for (SpringDamper& s : d.springs) {
    if (s.body_a == b) s.point_a -= shift;
    if (s.body_b == b) s.point_b -= shift;
  }
  for (BodyLoad& l : d.body_loads)
    if (l.body == b) l.point -= shift;
}

/// A frame to add: the parameter frame of a body that had none of its name (the old body frame).
struct NewFrame {
  std::string name;
  Vec3 position;  ///< world, build pose
  Vec4 orientation;
};

/// Set the bodies from pi; a body whose parameter frame was its body frame (no frame of its
/// name) gets a frame of its name at the old body frame, so that pi stays about the same frame.
std::vector<NewFrame> set_bodies(const Model& m, const ParameterLayout& L, const VecX& pi,
                                 bool physical, Model& d) {
  std::vector<BodyInertial> news;
  for (int i = 0; i < static_cast<int>(L.bodies.size()); ++i)
    news.push_back(body_inertial(L, i, pi.segment<10>(L.body_offset(i)), m.bodies[L.bodies[i]].name,
                                 physical));
  std::vector<NewFrame> frames;
  for (int i = 0; i < static_cast<int>(L.bodies.size()); ++i) {
    const int b = L.bodies[i];
    if (L.frame_name[i].empty())
      frames.push_back({d.bodies[b].name, d.bodies[b].position, d.bodies[b].orientation});
    d.bodies[b].mass = news[i].mass;
    d.bodies[b].inertia = news[i].inertia;
    move_body_origin(d, b, news[i].shift);
  }
  return frames;
}

/// Friction to add on a coordinate without a CoordForce of its own (add_joint_friction).
struct NewFriction {
  std::string joint;
  int sub = 0;
  double viscous = 0.0, coulomb = 0.0;
};

void check_nonnegative(double v, const std::string& name) {
  if (!(v >= 0.0))
    throw ModelError(msg(kFn, ": '", name, "' must be >= 0, got ", v,
                         " (friction and rotor inertia are not negative)"));
}

/// The index in d.coord_forces of a friction element on coordinate c itself, or -1.
int own_friction(const Model& d, int c) {
  for (int f = 0; f < static_cast<int>(d.coord_forces.size()); ++f)
    if (d.coord_forces[f].coord == c) return f;
  return -1;
}

/// Scale independent coordinate k's friction sources to pi's fv, fc (d's coord_forces are m's,
/// same order); the friction a coordinate without sources needs goes to `added`.
void set_friction(const Model& m, const ParameterLayout& L, const VecX& pi,
                  const std::vector<std::string>& names, Model& d,
                  std::vector<NewFriction>& added) {
  for (int k = 0; k < m.independent.n; ++k) {
    const int o = L.coord_offset(k);
    const double fv = pi[o], fc = pi[o + 1];
    check_nonnegative(fv, names[o]);
    check_nonnegative(fc, names[o + 1]);
    double coulomb_sum = 0.0;
    for (const auto& [c, v] : L.coulomb[k]) coulomb_sum += c;
    const double sv = L.viscous[k] > 0.0 ? fv / L.viscous[k] : 0.0;
    const double sc = coulomb_sum > 0.0 ? fc / coulomb_sum : 0.0;
    for (CoordForce& cf : d.coord_forces) {
      if (m.independent.source[cf.coord] != k) continue;
      if (L.viscous[k] > 0.0) cf.damping *= sv;
      if (coulomb_sum > 0.0) cf.coulomb *= sc;
    }
    for (Actuator& a : d.actuators) {
      const int rc = d.joints[a.rotor_joint].coord0;
      if (rc < 0 || m.independent.source[rc] != k) continue;
      if (L.viscous[k] > 0.0) a.friction_viscous *= sv;
      if (coulomb_sum > 0.0) a.friction_coulomb *= sc;
    }
    const double need_v = L.viscous[k] > 0.0 ? 0.0 : fv;
    const double need_c = coulomb_sum > 0.0 ? 0.0 : fc;
    if (need_v == 0.0 && need_c == 0.0) continue;
    const int c = m.independent.full[k];
    if (const int f = own_friction(d, c); f >= 0) {
      CoordForce& cf = d.coord_forces[f];
      if (need_v != 0.0) cf.damping = need_v;
      if (need_c != 0.0) {
        cf.coulomb = need_c;
        cf.v_smooth = kRegressorCoulombSmoothing;
      }
    } else {
      added.push_back({m.joints[m.coords[c].joint].name, m.coords[c].sub, need_v, need_c});
    }
  }
}

/// Independent coordinate k's actuators' rotor inertias scaled to pi's Ia (their thin-disc
/// rotor bodies with them); the joints of coordinates needing a new actuator go to `added`.
void set_rotors(const Model& m, const ParameterLayout& L, const VecX& pi,
                const std::vector<std::string>& names, Model& d,
                std::vector<std::pair<std::string, double>>& added) {
  for (int k = 0; k < m.independent.n; ++k) {
    const int o = L.coord_offset(k);
    const double Ia = pi[o + 3];
    check_nonnegative(Ia, names[o + 3]);
    if (L.actuators[k].empty()) {
      if (Ia > 0.0) {
        const Coord& c = m.coords[m.independent.full[k]];
        if (c.sub != 0)
          throw ModelError(msg(kFn, ": '", names[o + 3], "' = ", Ia,
                               ": the coordinate is a cylindrical joint's displacement, which "
                               "takes no actuator"));
        added.emplace_back(m.joints[c.joint].name, Ia);
      }
      continue;
    }
    double sum = 0.0;
    for (int a : L.actuators[k]) {
      const Actuator& act = m.actuators[a];
      sum += L.reflection[a] * act.rotor_inertia;
    }
    for (int a : L.actuators[k]) {
      Actuator& act = d.actuators[a];
      const double n2 = act.gear_ratio * act.gear_ratio;
      if (sum > 0.0)
        act.rotor_inertia *= Ia / sum;
      else
        act.rotor_inertia = a == L.actuators[k].front() ? Ia / L.reflection[a] : 0.0;
      const Vec3 ax = d.joints[act.rotor_joint].frame_child.col(2);
      const double axial = act.gyroscopic ? act.rotor_inertia : n2 * act.rotor_inertia;
      d.bodies[d.joints[act.rotor_joint].child].inertia =
          0.5 * axial * (Mat3::Identity() + ax * ax.transpose());
    }
  }
}

}  // namespace parameter_model_detail

using namespace parameter_model_detail;

ModelPtr model_with_dynamic_parameters(const Model& m, const VecX& pi, bool physical_inertia) {
  const ParameterLayout L = dynamic_parameter_layout(m);
  const std::vector<std::string> names = dynamic_parameter_names(m);
  check_vector(L, pi, names);
  std::vector<std::string> notes;
  Model draft = model_draft(m, kFn, notes);
  if (draft.coord_forces.size() != m.coord_forces.size() ||
      draft.actuators.size() != m.actuators.size() || draft.bodies.size() != m.bodies.size())
    throw ModelError(msg(kFn, ": internal: the model's draft differs from the model"));
  const std::vector<NewFrame> frames = set_bodies(m, L, pi, physical_inertia, draft);
  std::vector<NewFriction> frictions;
  set_friction(m, L, pi, names, draft, frictions);
  std::vector<std::pair<std::string, double>> actuators;
  set_rotors(m, L, pi, names, draft, actuators);
  ModelBuilder b(std::move(draft), physical_inertia);
  for (const NewFrame& f : frames) {
    try {
      b.add_frame(f.name, f.name, f.position, f.orientation);
    } catch (const ModelError& e) {
      throw ModelError(msg(kFn, ": body '", f.name, "' needs a frame of its name (pi's parameter ",
                           "frame, its old centre of mass): ", e.what()));
    }
  }
  for (const NewFriction& f : frictions)
    b.add_joint_friction(f.joint, f.viscous, f.coulomb, kRegressorCoulombSmoothing, f.sub);
  for (const auto& [joint, Ia] : actuators) {
    try {
      b.add_actuator(joint, 1.0, Ia);
    } catch (const ModelError& e) {
      throw ModelError(msg(kFn, ": the rotor inertia Ia of joint '", joint,
                           "' needs an actuator, which the joint cannot take: ", e.what()));
    }
  }
  return finalize_like(b, m, std::move(notes), kFn, "these parameters");
}

}  // namespace armdyn
