// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/constraints.hpp"

#include "armdyn/algorithm/kinematics.hpp"
#include "armdyn/kernels/jets.hpp"

namespace armdyn {

ConstraintValues constraint_values(const Model& m, const VecX& u, const VecX& v, double t,
                                   const char* fn) {
  check_cartesian_state(m, u, v, fn);
  std::vector<BodyKin> kin;
  body_kinematics(m, u.data(), v.data(), kin);
  ConstraintEval ce;
  ce.init(m);
  eval_constraints(m, kin, t, true, ce);
  return ConstraintValues{ce.f, ce.xi, ce.rhs, dense_zeta(m, ce)};
}

}  // namespace armdyn
