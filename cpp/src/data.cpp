// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/data.hpp"

#include "armdyn/errors.hpp"
#include "armdyn/solver/engine.hpp"

namespace armdyn {

Data::Data(const Model& m) : model(&m), n(static_cast<int>(m.coords.size())) {
  kin.resize(m.nb);
  eta = VecX::Zero(m.nv);
  coord_tau = VecX::Zero(n);
  rne.resize(m);
  tau = VecX::Zero(n);
  joint_of_body.assign(m.nb, -1);
  for (size_t j = 0; j < m.joints.size(); ++j)
    if (m.joints[j].child != kGround) joint_of_body[m.joints[j].child] = static_cast<int>(j);
  ic.assign(m.nb, Composite{});
  s.assign(n, Vec6::Zero());
  M = MatX::Zero(n, n);
  rhs = VecX::Zero(n);
  qdd = VecX::Zero(n);
  zero = VecX::Zero(n);
  L = MatX::Zero(n, n);
}

Data::~Data() = default;

void check_data(const Model& m, const Data& d, const char* fn) {
  if (d.model != &m) throw ModelError(msg(fn, ": data was made for another model"));
}

}  // namespace armdyn
