// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/builder/summary.hpp"

#include <sstream>

#include "armdyn/builder/weld.hpp"
#include "armdyn/kernels/block_sparse.hpp"
#include "armdyn/kernels/kkt_factor.hpp"

namespace armdyn {

std::string summary(const Model& m) {
  std::ostringstream os;
  os << "armdyn Model: " << m.nb << " bodies, " << m.joints.size() << " joints, " << m.drives.size()
     << " drives\n";
  os << "  sizes: nq=" << m.nq << " nv=" << m.nv << " nc=" << m.nc << " (joint rows " << m.nc_joint
     << ", drive rows " << m.nc - m.nc_joint << "), joint coordinates " << m.coords.size() << "\n";
  os << "  topology: " << (m.is_tree ? "tree" : "closed loops") << "; mobility " << m.mobility
     << " DOF (nv - rank " << m.rank_joint << ")";
  if (!m.drives.empty()) os << ", " << m.mobility_driven << " left free by the drives";
  os << "\n";
  if (m.redundant) {
    os << "  redundant constraint rows (" << m.redundant_rows.size() << "):";
    for (const auto& r : m.redundant_rows) os << "\n    " << r;
    os << "\n  multipliers: minimum-norm (reactions of redundant joints are not unique)\n";
  }
  os << "  KKT path: " << kkt_path_name(kkt_path(m)) << " -- " << kkt_path_description(m) << "\n";
  if (const LightBodies& light = light_bodies(m); !light.bodies.empty())
    os << "  " << light.note << "\n";
  const Welding* w = welding(m);
  if (w) {
    int merged = 0;
    for (int jw : w->weld_joint) merged += jw < 0;
    const Model& wm = *w->model;
    os << "  welded: " << merged << " fixed joints merged into composite bodies; simulate() "
       << "integrates " << wm.nb << " bodies and " << wm.nc << " rows (KKT path "
       << kkt_path_name(kkt_path(wm)) << ", ~" << kkt_plans(wm).all.flops
       << " flops per factorisation) and reports all " << m.nb << " bodies\n";
  }
  {
    // simulate(coordinates="joint"): the integrated model (welded, when fixed joints merge)
    const Model& s = w ? *w->model : m;
    const std::string why = s.joint_path_reason();
    os << "  joint-space path (simulate coordinates='joint'): ";
    if (!why.empty())
      os << "not available (" << why << ")\n";
    else
      os << "available: " << s.coords.size() << " coordinates"
         << (s.gear_constraints.empty() ? std::string()
                                        : ", " + std::to_string(s.gear_constraints.size()) +
                                              " ideal-gear rows eliminated by their null space")
         << "; mass matrix by CRBA\n";
  }
  os << "  gravity: [" << m.gravity.x() << ", " << m.gravity.y() << ", " << m.gravity.z() << "]\n";
  os << "  bodies:\n";
  for (const Body& b : m.bodies) os << "    " << b.name << "  mass " << b.mass << " kg\n";
  os << "  joints:\n";
  for (const Joint& j : m.joints)
    os << "    " << j.name << "  " << joint_type_name(j.type) << "  " << m.body_name(j.parent)
       << " -> " << m.body_name(j.child) << "\n";
  for (const GearConstraint& g : m.gear_constraints)
    if (g.coupling)
      os << "  coupling " << g.name << ": " << m.coords[g.coord_a].name << " = " << g.multiplier()
         << " " << m.coords[g.coord_b].name << " + " << g.offset << "\n";
    else
      os << "  gear " << g.name << ": " << m.coords[g.coord_a].name << " (r " << g.r_a << ") - "
         << m.coords[g.coord_b].name << " (r " << g.r_b << "), ideal\n";
  for (const GearPair& g : m.gears)
    os << "  gear pair " << g.name << ": " << m.coords[g.coord_a].name << " (r " << g.r_a << ") - "
       << m.coords[g.coord_b].name << " (r " << g.r_b << "), backlash " << g.backlash << " m\n";
  for (const Drive& d : m.drives)
    os << "  drive " << d.name << ": " << d.profile.describe() << "\n";
  const size_t nforce =
      m.body_loads.size() + m.springs.size() + m.coord_forces.size() + m.gears.size();
  if (nforce) os << "  force elements: " << nforce << " (besides gravity)\n";
  return os.str();
}

}  // namespace armdyn
