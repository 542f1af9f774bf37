// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/model/properties.hpp"

#include <limits>

#include "armdyn/errors.hpp"

namespace armdyn {

std::vector<std::string> joint_type_names(const Model& m) {
  std::vector<std::string> r;
  for (const Joint& j : m.joints) r.push_back(joint_type_name(j.type));
  return r;
}

std::vector<int> independent_coord_indices(const Model& m) {
  const IndependentCoords& ic = m.independent;
  std::vector<int> r;
  for (int i = 0; i < ic.lead_q; ++i) r.push_back(i);
  for (int c : ic.full) r.push_back(ic.lead_q + c);
  return r;
}

namespace {

// the floating bases' `lead` names, then those of the independent coordinates
std::vector<std::string> independent_names(const std::vector<std::string>& all, int lead,
                                           const IndependentCoords& ic) {
  std::vector<std::string> r(all.begin(), all.begin() + lead);
  for (int c : ic.full) r.push_back(all[lead + c]);
  return r;
}

// the limit of one coordinate: its joint's, on the joint's first coordinate only
double coord_limit(const Joint& j, bool first, LimitKind which) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  if (!first) return which == LimitKind::Lower ? -inf : inf;
  switch (which) {
    case LimitKind::Lower:
      return j.lower <= -1e300 ? -inf : j.lower;
    case LimitKind::Upper:
      return j.upper >= 1e300 ? inf : j.upper;
    case LimitKind::Effort:
      return j.effort > 0 && j.effort < 1e300 ? j.effort : inf;
    case LimitKind::Velocity:
      return j.velocity_limit > 0 && j.velocity_limit < 1e300 ? j.velocity_limit : inf;
  }
  return inf;
}

}  // namespace

std::vector<std::string> independent_coord_names(const Model& m) {
  return independent_names(m.q_names, m.independent.lead_q, m.independent);
}

std::vector<std::string> independent_dof_names(const Model& m) {
  return independent_names(m.dof_names, m.independent.lead_v, m.independent);
}

int independent_dof(const Model& m, int coord) {
  // a loop model's dependent coordinate (Model::loop_coordinates) has none: -1
  const int s = m.independent.source[coord];
  return s < 0 ? -1 : m.independent.lead_v + s;
}

VecX coord_limits(const Model& m, LimitKind which) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  // over q (Lower, Upper: n_coords) or qd (Effort, Velocity: n_dofs); the floating bases'
  // entries lead and are unbounded
  const bool position = which == LimitKind::Lower || which == LimitKind::Upper;
  const long off = position ? 7 * m.n_free : 6 * m.n_free;
  const IndependentCoords& ic = m.independent;
  VecX r = VecX::Constant(off + ic.n, which == LimitKind::Lower ? -inf : inf);
  for (int k = 0; k < ic.n; ++k) {
    const Coord& c = m.coords[ic.full[k]];
    r[off + k] = coord_limit(m.joints[c.joint], c.sub == 0, which);
  }
  return r;
}

std::vector<CouplingInfo> couplings(const Model& m) {
  std::vector<CouplingInfo> r;
  for (const GearConstraint& g : m.gear_constraints) {
    if (!g.coupling) continue;
    r.push_back({g.name, m.joints[m.coords[g.coord_a].joint].name,
                 m.joints[m.coords[g.coord_b].joint].name, g.multiplier(), g.offset});
  }
  return r;
}

VecX reflected_inertia(const Model& m) {
  // G^T diag(J) G over the rotors: (N s)^2 J at the independent dof of each rotor, s the
  // actuated joint's own coupling scale (1 unless it follows another joint)
  const IndependentCoords& ic = m.independent;
  VecX r = VecX::Zero(ic.nv());
  for (const Actuator& a : m.actuators) {
    const int c = m.joints[a.rotor_joint].coord0;
    // the armature (gear-reduced) turns with the joint carrying N^2 J; the gyroscopic rotor
    // turns at N qdot carrying J
    const double j_el =
        a.gyroscopic ? a.rotor_inertia : a.gear_ratio * a.gear_ratio * a.rotor_inertia;
    // (a rotor on a dependent joint of a loop model reflects onto no single independent dof)
    if (const int k = independent_dof(m, c); k >= 0) r[k] += ic.scale[c] * ic.scale[c] * j_el;
  }
  return r;
}

std::vector<int> drive_dofs(const Model& m) {
  std::vector<int> r;
  for (const Drive& d : m.drives) r.push_back(m.joints[d.joint].dof0 + d.coord);
  return r;
}

VecX body_masses(const Model& m) {
  VecX r(m.nb);
  for (int i = 0; i < m.nb; ++i) r[i] = m.bodies[i].mass;
  return r;
}

std::shared_ptr<Model> with_kkt_path(const Model& m, const std::string& path) {
  if (path != "dense" && path != "auto")
    throw ModelError("with_kkt_path: path must be 'dense' or 'auto', got '" + path + "'");
  // a copy derives its plans and welded form afresh (the welded model inherits the forced
  // path: simulate() integrates it)
  auto c = std::make_shared<Model>(m);
  c->force_dense_kkt = path == "dense";
  return c;
}

}  // namespace armdyn
