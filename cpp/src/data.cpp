// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/data.hpp"

#include <algorithm>

#include "armdyn/errors.hpp"

namespace armdyn {

Data::Data(const Model& m)
    : model(&m), n(m.nv_joint), nq(m.nq_joint), nco(static_cast<int>(m.coords.size())), kkt(m) {
  // the Cartesian pipeline's buffers first, next to the KKT solver's (allocated just above)
  eta = VecX::Zero(m.nv);
  delta = VecX::Zero(m.nc);
  tmp_nv = VecX::Zero(m.nv);
  tmp_nc = VecX::Zero(m.nc);
  mu = VecX::Zero(m.nc);
  vd_work = VecX::Zero(m.nv);
  track_ref = VecX::Zero(nco);
  cq = VecX::Zero(nco);
  cqd = VecX::Zero(nco);
  nrows = m.nc;
  tol_f = 1e-13 * std::max(1.0, m.length_scale);
  kin.resize(m.nb);
  ce.init(m);
  light = &light_bodies(m);
  // each joint's row block: the first block starting at its first row (linear: by row)
  joint_block.assign(m.joints.size(), -1);
  std::vector<int> block_at(static_cast<size_t>(m.nc) + 1, -1);
  for (size_t b = ce.blocks.size(); b-- > 0;) {
    const int r = ce.blocks[b].row0;
    if (r >= 0 && r <= m.nc) block_at[r] = static_cast<int>(b);
  }
  for (size_t j = 0; j < m.joints.size(); ++j) {
    const int r = m.joints[j].row0;
    if (joint_rows(m.joints[j].type) > 0 && r >= 0 && r <= m.nc) joint_block[j] = block_at[r];
  }
  jets.init(m);
  ce.coord_cache = &jets;
  ce.track_ref = &track_ref;
  sweep.plan(m, ce);
  artic.plan(m, ce);
  vd = VecX::Zero(m.nv);
  tau_in = VecX::Zero(n);
  tau_jets.resize(nco);
  // the joint-space algorithms'
  coord_tau = VecX::Zero(nco);
  rne.resize(m);
  tau = VecX::Zero(n);
  joint_of_body.assign(m.nb, -1);
  for (size_t j = 0; j < m.joints.size(); ++j)
    if (m.joints[j].child != kGround) joint_of_body[m.joints[j].child] = static_cast<int>(j);
  ic.assign(m.nb, Composite{});
  s.assign(n, Vec6::Zero());
  aba.IA.assign(m.nb, Mat6::Zero());
  for (auto* x : {&aba.pA, &aba.v, &aba.a}) x->assign(m.nb, Vec6::Zero());
  for (auto* x : {&aba.U, &aba.c}) x->assign(n, Vec6::Zero());
  aba.Dinv.assign(n, 0.0);
  aba.u.assign(n, 0.0);
  // M and L (n x n, dense) are allocated by their first use (ensure_mass_matrix,
  // algorithm/crba.hpp): a Data of a long chain stays linear in its size for the Cartesian, ABA and
  // Newton-Euler paths
  rhs = VecX::Zero(n);
  qdd = VecX::Zero(n);
  zero = VecX::Zero(n);
  frame_jacobian = Mat6X::Zero(6, n);
  frame_jacobian_v = MatX::Zero(6, m.nv);
  niq = m.independent.source.empty() ? nq : m.independent.nq();
  ni = m.independent.source.empty() ? n : m.independent.nv();
  frame_jacobian_independent = Mat6X::Zero(6, ni);
  if (ni != n) {
    coupled.q = VecX::Zero(nq);
    for (VecX* x : {&coupled.qd, &coupled.qdd, &coupled.tau_full}) *x = VecX::Zero(n);
    for (VecX* x : {&coupled.tau, &coupled.qdd_out, &coupled.rhs}) *x = VecX::Zero(ni);
  }
}

Data::~Data() = default;

void reset_pipeline(Data& d) {
  d.nrows = d.model->nc;
  d.aux = nullptr;
  d.joint_torques = nullptr;
  d.joint_q = d.joint_qd = nullptr;
  d.with_coordinate_forces = true;
  d.track_ref.setZero();
  d.track_by_rates = false;
  d.track_commit = Data::TrackCommit{};
  d.swept = false;
  d.augmented = false;
  d.stats = PipelineStats{};
  d.kkt.reset();
  d.artic.mark_stale();
}

void check_data(const Model& m, const Data& d, const char* fn) {
  if (d.model != &m) throw ModelError(msg(fn, ": data was made for another model"));
}

}  // namespace armdyn
