// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/builder/weld.hpp"

#include <algorithm>
#include <deque>
#include <numeric>

#include "armdyn/builder/builder.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/math/quaternion.hpp"

namespace armdyn {

namespace {

// The composite bodies of the fixed joints: which joints merge, each body's composite (kGround:
// welded to ground) and each composite's root (its first body), then the composites' mass,
// centre of mass and inertia and each body's place in its composite (Weld)
struct Composites {
  std::vector<char> merged;  // per joint: a fixed joint merged away
  std::vector<int> comp;     // per body: its composite
  std::vector<int> roots;    // per composite: its first body
  std::vector<double> mass;
  std::vector<Vec3> com;
  std::vector<Mat3> inertia;
  std::vector<Weld> weld;  // per body
};

// The groups of bodies joined by fixed joints (union-find; ground, node nb, stays its group's
// representative). False when none merges, when fixed joints form a loop, or when everything is
// welded to ground.
bool group_fixed_joints(const Model& m, Composites& c) {
  const int nb = m.nb;
  const int ground = nb;  // union-find node of ground
  std::vector<int> uf(nb + 1);
  std::iota(uf.begin(), uf.end(), 0);
  auto find = [&](int x) {
    while (uf[x] != x) x = uf[x] = uf[uf[x]];
    return x;
  };
  auto node = [&](int b) { return b == kGround ? ground : b; };
  const int nj = static_cast<int>(m.joints.size());
  c.merged.assign(nj, 0);
  int n_merged = 0;
  for (int j = 0; j < nj; ++j) {
    const Joint& jt = m.joints[j];
    if (jt.type != JointType::Fixed) continue;
    int a = find(node(jt.parent)), ch = find(node(jt.child));
    if (a == ch) return false;  // a loop of fixed joints
    if (ch == ground) std::swap(a, ch);
    uf[ch] = a;  // ground stays its group's representative
    c.merged[j] = 1;
    ++n_merged;
  }
  if (n_merged == 0) return false;
  // composites: one per group without ground, rooted at its first body
  c.comp.assign(nb, kGround);
  std::vector<int> comp_of(nb + 1, -2);
  for (int b = 0; b < nb; ++b) {
    const int r = find(b);
    if (r == ground) continue;
    if (comp_of[r] == -2) {
      comp_of[r] = static_cast<int>(c.roots.size());
      c.roots.push_back(b);
    }
    c.comp[b] = comp_of[r];
  }
  return !c.roots.empty();  // empty: everything is welded to ground
}

// composite frames at the assembled state: the root's axes, origin at the centre of mass; each
// body's place in its composite and the composites' inertias about their centres of mass
void place_in_composites(const Model& m, Composites& c) {
  const int nb = m.nb, nc = static_cast<int>(c.roots.size());
  auto pos = [&](int b) { return Vec3(m.u0.segment<3>(7 * b)); };
  auto rot = [&](int b) { return quat_to_rot(m.u0.segment<4>(7 * b + 3)); };
  c.mass.assign(nc, 0.0);
  c.com.assign(nc, Vec3::Zero());
  for (int b = 0; b < nb; ++b)
    if (c.comp[b] >= 0) {
      c.mass[c.comp[b]] += m.bodies[b].mass;
      c.com[c.comp[b]] += m.bodies[b].mass * pos(b);
    }
  // a massless composite (massless links welded together) keeps its root's frame origin
  for (int k = 0; k < nc; ++k)
    c.com[k] = c.mass[k] > 0.0 ? Vec3(c.com[k] / c.mass[k]) : pos(c.roots[k]);
  c.weld.assign(nb, Weld());
  c.inertia.assign(nc, Mat3::Zero());
  for (int b = 0; b < nb; ++b) {
    Weld& w = c.weld[b];
    w.composite = c.comp[b];
    if (c.comp[b] == kGround) {  // ground's frame is the world
      w.offset = pos(b);
      w.rotation = rot(b);
      continue;
    }
    const Mat3 Rc = rot(c.roots[c.comp[b]]);
    w.offset = Rc.transpose() * (pos(b) - c.com[c.comp[b]]);
    w.rotation = Rc.transpose() * rot(b);
    const Vec3& o = w.offset;
    c.inertia[c.comp[b]] +=
        w.rotation * m.bodies[b].inertia * w.rotation.transpose() +
        m.bodies[b].mass * (o.squaredNorm() * Mat3::Identity() - o * o.transpose());
  }
}

// a point and frame on body b of m to its composite's: the composite (kGround: ground's)
int place(const Composites& c, int b, Vec3& point, Mat3& frame) {
  if (b == kGround) return kGround;
  const Weld& w = c.weld[b];
  point = w.offset + w.rotation * point;
  frame = w.rotation * frame;
  return w.composite;
}

// the composites as the bodies of the merged draft
void add_composite_bodies(const Model& m, const Composites& c, Model& d) {
  const int nc = static_cast<int>(c.roots.size());
  for (int k = 0; k < nc; ++k) {
    Body bd;
    int members = 0;
    for (int b = 0; b < m.nb; ++b) members += c.comp[b] == k;
    bd.name = m.bodies[c.roots[k]].name;
    if (members > 1) bd.name += msg(" (+", members - 1, " welded)");
    bd.mass = c.mass[k];
    bd.inertia = 0.5 * (c.inertia[k] + c.inertia[k].transpose());
    bd.position = c.com[k];
    bd.orientation = m.u0.segment<4>(7 * c.roots[k] + 3);
    d.body_index[bd.name] = k;
    d.bodies.push_back(bd);
  }
}

// The merged draft: the composites, the joints that move (weld_joint: each joint's index in it,
// -1 merged) and every other element moved onto the composites. False when a moving joint or a
// spring falls inside one composite (merging would change the model's meaning).
bool merged_draft(const Model& m, const Composites& c, Model& d, std::vector<int>& weld_joint) {
  const Model& draft = m;  // the description: the same in the finalized model
  const int nj = static_cast<int>(m.joints.size());
  d.gravity = draft.gravity;
  add_composite_bodies(m, c, d);
  weld_joint.assign(nj, -1);
  for (int j = 0; j < nj; ++j) {
    if (c.merged[j]) continue;
    Joint jt = draft.joints[j];
    jt.parent = place(c, jt.parent, jt.point_parent, jt.frame_parent);
    jt.child = place(c, jt.child, jt.point_child, jt.frame_child);
    if (jt.parent == jt.child) return false;  // a moving joint inside one composite
    jt.row0 = d.nc_joint;
    d.nc_joint += joint_rows(jt.type);
    weld_joint[j] = static_cast<int>(d.joints.size());
    d.joint_index[jt.name] = weld_joint[j];
    d.joints.push_back(jt);
  }
  d.coords = draft.coords;
  for (Coord& k : d.coords) k.joint = weld_joint[k.joint];
  d.drives = draft.drives;
  for (Drive& dr : d.drives) dr.joint = weld_joint[dr.joint];
  d.drive_index = draft.drive_index;
  for (BodyLoad l : draft.body_loads) {
    if (c.comp[l.body] == kGround) continue;  // acts on ground
    l.point = c.weld[l.body].offset + c.weld[l.body].rotation * l.point;
    l.body = c.comp[l.body];
    d.body_loads.push_back(l);
  }
  for (SpringDamper sd : draft.springs) {
    Mat3 unused = Mat3::Identity();
    sd.body_a = place(c, sd.body_a, sd.point_a, unused);
    sd.body_b = place(c, sd.body_b, sd.point_b, unused);
    if (sd.body_a == sd.body_b) return false;  // a spring inside one composite
    d.springs.push_back(sd);
  }
  d.coord_forces = draft.coord_forces;
  d.gears = draft.gears;
  d.gear_constraints = draft.gear_constraints;
  d.actuators = draft.actuators;  // their joints are revolute or prismatic: never merged
  for (Actuator& a : d.actuators) {
    a.joint = weld_joint[a.joint];
    a.rotor_joint = weld_joint[a.rotor_joint];
  }
  d.tracked_coords = draft.tracked_coords;
  d.n_aux = draft.n_aux;
  return true;
}

// the merged joints, far bodies first: breadth-first from each composite's root (and ground),
// reversed; (joint, the body on the far side)
std::vector<std::pair<int, int>> weld_sweep(const Model& m, const Composites& c) {
  const int nb = m.nb, ground = nb, nj = static_cast<int>(m.joints.size());
  auto node = [&](int b) { return b == kGround ? ground : b; };
  std::vector<std::vector<std::pair<int, int>>> adj(nb + 1);  // node -> (joint, other node)
  for (int j = 0; j < nj; ++j)
    if (c.merged[j]) {
      const int p = node(m.joints[j].parent), ch = node(m.joints[j].child);
      adj[p].push_back({j, ch});
      adj[ch].push_back({j, p});
    }
  std::vector<char> seen(nb + 1, 0);
  std::vector<std::pair<int, int>> order;
  std::deque<int> queue{ground};
  for (int r : c.roots) queue.push_back(r);
  for (int n : queue) seen[n] = 1;
  while (!queue.empty()) {
    const int n = queue.front();
    queue.pop_front();
    for (const auto& [j, o] : adj[n]) {
      if (seen[o]) continue;
      seen[o] = 1;
      order.push_back({j, o});
      queue.push_back(o);
    }
  }
  std::reverse(order.begin(), order.end());
  return order;
}

// per row and coordinate of m: its row and coordinate in the welded model (-1: merged away)
void map_rows_and_coords(const Model& m, Welding& out) {
  const Model& wm = *out.model;
  out.row_map.assign(m.nc, -1);
  out.coord_map.assign(m.coords.size(), -1);
  for (int j = 0; j < static_cast<int>(m.joints.size()); ++j) {
    const int jw = out.weld_joint[j];
    if (jw < 0) continue;
    for (int k = 0; k < joint_rows(m.joints[j].type); ++k)
      out.row_map[m.joints[j].row0 + k] = wm.joints[jw].row0 + k;
    for (int k = 0; k < joint_coords(m.joints[j].type); ++k)
      out.coord_map[m.joints[j].coord0 + k] = wm.joints[jw].coord0 + k;
  }
  for (size_t g = 0; g < m.gear_constraints.size(); ++g)
    out.row_map[m.gear_constraints[g].row] = wm.gear_constraints[g].row;
  for (size_t k = 0; k < m.drives.size(); ++k) out.row_map[m.drives[k].row] = wm.drives[k].row;
}

// The composite bodies of the fixed joints, from the assembled state of m; nullptr when nothing
// merges or when merging would change the model's meaning (a loop of fixed joints, a moving
// joint or a spring inside one composite, or no body left).
std::shared_ptr<const Welding> build_welding(const Model& m) {
  Composites c;
  if (!group_fixed_joints(m, c)) return nullptr;
  place_in_composites(m, c);
  Model d;
  std::vector<int> weld_joint;
  if (!merged_draft(m, c, d, weld_joint)) return nullptr;
  std::shared_ptr<Model> w;
  try {
    w = detail::finalize_draft(d, m.finalize_options);
  } catch (const std::exception&) {
    return nullptr;  // keep the model unmerged rather than fail a valid model
  }
  w->force_dense_kkt = m.force_dense_kkt;
  auto out = std::make_shared<Welding>();
  out->model = w;
  out->sweep = weld_sweep(m, c);
  out->weld = std::move(c.weld);
  out->weld_joint = std::move(weld_joint);
  out->roots = std::move(c.roots);
  for (const Weld& wb : out->weld) out->qrel.push_back(rot_to_quat(wb.rotation));
  map_rows_and_coords(m, *out);
  return out;
}

}  // namespace

const Welding* welding(const Model& m) {
  using Ptr = std::shared_ptr<const Welding>;
  return m.derived.get<Ptr>([&] { return build_welding(m); }).get();
}

}  // namespace armdyn
