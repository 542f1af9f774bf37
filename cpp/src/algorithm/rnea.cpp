// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/rnea.hpp"

#include <cmath>

#include "armdyn/algorithm/forces.hpp"
#include "armdyn/errors.hpp"

namespace armdyn {

const VecX& rnea(const Model& m, Data& d, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                 Eigen::Ref<const VecX> qdd, double t) {
  require_joint_space(m, "inverse_dynamics", true);
  check_data(m, d, "inverse_dynamics");
  check_joint_vector(q, d.niq, "inverse_dynamics", "q");
  check_joint_vector(qd, d.ni, "inverse_dynamics", "qd");
  check_joint_vector(qdd, d.ni, "inverse_dynamics", "qdd");
  if (!std::isfinite(t)) throw ModelError("inverse_dynamics: t is not finite");
  check_base_quaternions(m, q, "inverse_dynamics");
  if (d.ni != d.n) {
    // a coupled model: the full coordinates, tau = G^T tau_full
    Data::Coupled& w = d.coupled;
    const IndependentCoords& ic = m.independent;
    ic.expand_q(q.data(), w.q.data());
    ic.expand_v(qd.data(), w.qd.data());
    ic.expand_v(qdd.data(), w.qdd.data());
    rnea_full(m, d, w.q, w.qd, w.qdd, t);
    ic.reduce(d.tau.data(), w.tau.data());
    return w.tau;
  }
  rnea_full(m, d, q, qd, qdd, t);
  return d.tau;
}

void rnea_full(const Model& m, Data& d, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
               Eigen::Ref<const VecX> qdd, double t) {
  joint_space_kinematics(m, q, qd, d.kin, d.rne);
  body_forces(m, d.kin, t, d.eta);
  rne_residual(m, d.kin, qd, qdd, d.eta, d.rne, d.tau);
  if (!m.coord_forces.empty() || !m.gears.empty()) {
    // the coordinates follow the floating bases' blocks in q and qd
    coordinate_forces(m, q.data() + 7 * m.n_free, qd.data() + 6 * m.n_free, nullptr, t,
                      d.coord_tau);
    d.tau.tail(d.nco) -= d.coord_tau;
  }
}

}  // namespace armdyn
