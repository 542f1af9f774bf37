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

// The composite bodies of the fixed joints, from the assembled state of m; nullptr when nothing
// merges or when merging would change the model's meaning (a loop of fixed joints, a moving
// joint or a spring inside one composite, or no body left).
std::shared_ptr<const Welding> build_welding(const Model& m) {
  const Model& draft = m;  // the description: the same in the finalized model
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
  std::vector<char> merged(nj, 0);
  int n_merged = 0;
  for (int j = 0; j < nj; ++j) {
    const Joint& jt = m.joints[j];
    if (jt.type != JointType::Fixed) continue;
    int a = find(node(jt.parent)), c = find(node(jt.child));
    if (a == c) return nullptr;  // a loop of fixed joints
    if (c == ground) std::swap(a, c);
    uf[c] = a;  // ground stays its group's representative
    merged[j] = 1;
    ++n_merged;
  }
  if (n_merged == 0) return nullptr;
  // composites: one per group without ground, rooted at its first body
  std::vector<int> comp(nb, kGround), comp_of(nb + 1, -2);
  std::vector<int> roots;
  for (int b = 0; b < nb; ++b) {
    const int r = find(b);
    if (r == ground) continue;
    if (comp_of[r] == -2) {
      comp_of[r] = static_cast<int>(roots.size());
      roots.push_back(b);
    }
    comp[b] = comp_of[r];
  }
  const int nc = static_cast<int>(roots.size());
  if (nc == 0) return nullptr;  // everything is welded to ground
  // composite frames at the assembled state: the root's axes, origin at the centre of mass
  auto pos = [&](int b) { return Vec3(m.u0.segment<3>(7 * b)); };
  auto rot = [&](int b) { return quat_to_rot(m.u0.segment<4>(7 * b + 3)); };
  std::vector<double> mass(nc, 0.0);
  std::vector<Vec3> com(nc, Vec3::Zero());
  for (int b = 0; b < nb; ++b)
    if (comp[b] >= 0) {
      mass[comp[b]] += m.bodies[b].mass;
      com[comp[b]] += m.bodies[b].mass * pos(b);
    }
  // a massless composite (massless links welded together) keeps its root's frame origin
  for (int c = 0; c < nc; ++c) com[c] = mass[c] > 0.0 ? Vec3(com[c] / mass[c]) : pos(roots[c]);
  std::vector<Weld> weld(nb);
  std::vector<Mat3> inertia(nc, Mat3::Zero());
  for (int b = 0; b < nb; ++b) {
    Weld& w = weld[b];
    w.composite = comp[b];
    if (comp[b] == kGround) {  // ground's frame is the world
      w.offset = pos(b);
      w.rotation = rot(b);
      continue;
    }
    const Mat3 Rc = rot(roots[comp[b]]);
    w.offset = Rc.transpose() * (pos(b) - com[comp[b]]);
    w.rotation = Rc.transpose() * rot(b);
    const Vec3& o = w.offset;
    inertia[comp[b]] += w.rotation * m.bodies[b].inertia * w.rotation.transpose() +
                        m.bodies[b].mass * (o.squaredNorm() * Mat3::Identity() - o * o.transpose());
  }
  // the merged draft
  Model d;
  d.gravity = draft.gravity;
  for (int c = 0; c < nc; ++c) {
    Body bd;
    int members = 0;
    for (int b = 0; b < nb; ++b) members += comp[b] == c;
    bd.name = m.bodies[roots[c]].name;
    if (members > 1) bd.name += msg(" (+", members - 1, " welded)");
    bd.mass = mass[c];
    bd.inertia = 0.5 * (inertia[c] + inertia[c].transpose());
    bd.position = com[c];
    bd.orientation = m.u0.segment<4>(7 * roots[c] + 3);
    d.body_index[bd.name] = c;
    d.bodies.push_back(bd);
  }
  std::vector<int> weld_joint(nj, -1);
  auto place = [&](int b, Vec3& point, Mat3& frame) {
    if (b == kGround) return kGround;
    const Weld& w = weld[b];
    point = w.offset + w.rotation * point;
    frame = w.rotation * frame;
    return w.composite;
  };
  for (int j = 0; j < nj; ++j) {
    if (merged[j]) continue;
    Joint jt = draft.joints[j];
    jt.parent = place(jt.parent, jt.point_parent, jt.frame_parent);
    jt.child = place(jt.child, jt.point_child, jt.frame_child);
    if (jt.parent == jt.child) return nullptr;  // a moving joint inside one composite
    jt.row0 = d.nc_joint;
    d.nc_joint += joint_rows(jt.type);
    weld_joint[j] = static_cast<int>(d.joints.size());
    d.joint_index[jt.name] = weld_joint[j];
    d.joints.push_back(jt);
  }
  d.coords = draft.coords;
  for (Coord& c : d.coords) c.joint = weld_joint[c.joint];
  d.drives = draft.drives;
  for (Drive& dr : d.drives) dr.joint = weld_joint[dr.joint];
  d.drive_index = draft.drive_index;
  for (BodyLoad l : draft.body_loads) {
    if (comp[l.body] == kGround) continue;  // acts on ground
    l.point = weld[l.body].offset + weld[l.body].rotation * l.point;
    l.body = comp[l.body];
    d.body_loads.push_back(l);
  }
  for (SpringDamper sd : draft.springs) {
    Mat3 unused = Mat3::Identity();
    sd.body_a = place(sd.body_a, sd.point_a, unused);
    sd.body_b = place(sd.body_b, sd.point_b, unused);
    if (sd.body_a == sd.body_b) return nullptr;  // a spring inside one composite
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
  std::shared_ptr<Model> w;
  try {
    w = detail::finalize_draft(d, m.finalize_options);
  } catch (const std::exception&) {
    return nullptr;  // keep the model unmerged rather than fail a valid model
  }
  // the merged joints, far bodies first: breadth-first from each composite's root (and ground)
  std::vector<std::vector<std::pair<int, int>>> adj(nb + 1);  // node -> (joint, other node)
  for (int j = 0; j < nj; ++j)
    if (merged[j]) {
      const int p = node(m.joints[j].parent), c = node(m.joints[j].child);
      adj[p].push_back({j, c});
      adj[c].push_back({j, p});
    }
  std::vector<char> seen(nb + 1, 0);
  std::vector<std::pair<int, int>> order;
  std::deque<int> queue{ground};
  for (int r : roots) queue.push_back(r);
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
  w->force_dense_kkt = m.force_dense_kkt;
  auto out = std::make_shared<Welding>();
  out->model = w;
  out->weld = std::move(weld);
  out->weld_joint = std::move(weld_joint);
  out->sweep = std::move(order);
  out->roots = std::move(roots);
  for (const Weld& wb : out->weld) out->qrel.push_back(rot_to_quat(wb.rotation));
  const Model& wm = *w;
  out->row_map.assign(m.nc, -1);
  out->coord_map.assign(m.coords.size(), -1);
  for (int j = 0; j < nj; ++j) {
    const int jw = out->weld_joint[j];
    if (jw < 0) continue;
    for (int k = 0; k < joint_rows(m.joints[j].type); ++k)
      out->row_map[m.joints[j].row0 + k] = wm.joints[jw].row0 + k;
    for (int k = 0; k < joint_coords(m.joints[j].type); ++k)
      out->coord_map[m.joints[j].coord0 + k] = wm.joints[jw].coord0 + k;
  }
  for (size_t g = 0; g < m.gear_constraints.size(); ++g)
    out->row_map[m.gear_constraints[g].row] = wm.gear_constraints[g].row;
  for (size_t k = 0; k < m.drives.size(); ++k) out->row_map[m.drives[k].row] = wm.drives[k].row;
  return out;
}

}  // namespace

const Welding* welding(const Model& m) {
  using Ptr = std::shared_ptr<const Welding>;
  return m.derived.get<Ptr>([&] { return build_welding(m); }).get();
}

}  // namespace armdyn
