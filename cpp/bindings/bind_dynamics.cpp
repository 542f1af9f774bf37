// SPDX-License-Identifier: BSD-3-Clause
// Bindings of the Cartesian dynamics (armdyn/algorithm/: kinematics, constraints, forces, kkt,
// energy) and of the conversions between the joint-space and the Cartesian state.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "armdyn/algorithm/constraints.hpp"
#include "armdyn/algorithm/energy.hpp"
#include "armdyn/algorithm/forces.hpp"
#include "armdyn/algorithm/kinematics.hpp"
#include "armdyn/algorithm/kkt.hpp"
#include "armdyn/algorithm/loop_coordinates.hpp"
#include "armdyn/data.hpp"
#include "armdyn/kernels/joint_space.hpp"
#include "common.hpp"
#include "rows.hpp"

namespace armdyn {

namespace py = pybind11;
using namespace py_helpers;

namespace {

auto state_from_joints_py(const ModelArg& model, const ArrayLike& q, const OptArrayLike& qd,
                          const OptData& data) {
  const ModelHolder holder = model_of(model, "state_from_joints");
  const Model& md = *holder;
  Data& d = data_for(holder, data, "state_from_joints");
  if (md.loop_coordinates) {
    // a model with loops or ideal gears: the position and velocity problems from the Data's
    // last state (this thread's by default)
    const long n = md.independent.n;
    const VecX qi = to_vec(q, "q", n), qdi = qd.is_none() ? VecX::Zero(n) : to_vec(qd, "qd", n);
    VecX u, v;
    loop_state(md, d, qi, qdi, u, v, "state_from_joints");
    return py::make_tuple(to_numpy(u), to_numpy(v));
  }
  // the sizes below are the joint space's: refused first for a model without one
  require_joint_space(md, "state_from_joints", true);
  const long nq = md.independent.nq(), n = md.independent.nv();
  const VecX qi = to_vec(q, "q", nq), qdi = qd.is_none() ? VecX::Zero(n) : to_vec(qd, "qd", n);
  VecX u, v;
  state_from_independent(md, qi, qdi, u, v, "state_from_joints");
  return py::make_tuple(to_numpy(u), to_numpy(v));
}

auto joint_coordinates_py(const Model& md, const ArrayLike& u, const ArrayLike& v) {
  VecX q, qd;
  if (md.loop_coordinates) {
    loop_joint_coordinates(md, to_vec(u, "u", md.nq), to_vec(v, "v", md.nv), q, qd);
    return py::make_tuple(to_numpy(q), to_numpy(qd));
  }
  independent_joint_coordinates(md, to_vec(u, "u", md.nq), to_vec(v, "v", md.nv), q, qd);
  return py::make_tuple(to_numpy(q), to_numpy(qd));
}

py::dict evaluate_constraints_py(const Model& md, const ArrayLike& u, const ArrayLike& v,
                                 double t) {
  const ConstraintValues c = constraint_values(md, to_vec(u, "u", md.nq), to_vec(v, "v", md.nv), t,
                                               "evaluate_constraints");
  py::dict d;
  d["f"] = to_numpy(c.f);
  d["zeta"] = to_numpy(c.zeta);
  d["xi"] = to_numpy(c.xi);
  d["rhs"] = to_numpy(c.rhs);
  return d;
}

auto body_accelerations_py(const Model& md, const ArrayLike& u, const ArrayLike& v, double t) {
  const VecX uu = to_vec(u, "u", md.nq), vv = to_vec(v, "v", md.nv);
  check_cartesian_state(md, uu, vv, "body_accelerations");
  Data d(md);
  VecX vd(md.nv);
  body_accelerations(md, d, t, uu.data(), vv.data(), vd.data());
  return py::make_tuple(to_numpy(vd), to_numpy(d.delta));
}

py::array_t<double> body_forces_py(const Model& md, const ArrayLike& u, const ArrayLike& v,
                                   double t) {
  const VecX uu = to_vec(u, "u", md.nq), vv = to_vec(v, "v", md.nv);
  check_cartesian_state(md, uu, vv, "body_forces");
  Data d(md);
  return to_numpy(cartesian_forces_at(md, d, uu.data(), vv.data(), t));
}

auto energy_py(const Model& md, const ArrayLike& u, const ArrayLike& v) {
  const VecX uu = to_vec(u, "u", md.nq), vv = to_vec(v, "v", md.nv);
  Data d(md);
  double ke, pe;
  energy(md, d, uu.data(), vv.data(), ke, pe);
  return py::make_tuple(ke, pe);
}

py::array_t<double> body_mass_matrix_py(const Model& md) {
  return to_numpy(cartesian_mass_matrix(md));
}

}  // namespace

void bind_dynamics(py::module_& m) {
  m.def(
      "state_from_joints", &state_from_joints_py, py::arg("model"), py::arg("q"),
      py::arg("qd") = py::none(), py::arg("data") = py::none(),
      "Cartesian state (u, v) of a joint-space tree model from joint-space q (n_coords) and qd "
      "(n_dofs; default zero): a coupled model's independent coordinates, the followers set by "
      "their couplings. Returns (u (nq,), v (nv,)) float64 arrays: per body CoM [m] and unit "
      "Euler parameters; CoM velocity [m/s, world] and angular velocity [rad/s, body]. "
      "ModelError on a model without a joint space or wrong shapes. A model with closed loops or a "
      "fixed-base tree with ideal gears: its independent coordinates (model.coord_names), the "
      "others solved from the loop and gear constraints (continuation from the last solution of "
      "data, an armdyn.Data, or this thread's when None: the assembly branch and the gears' "
      "turns kept; SolverError at a singular configuration).");

  m.def("joint_coordinates", &joint_coordinates_py, py::arg("model"), py::arg("u"), py::arg("v"),
        "Joint-space q (n_coords: floating bases' poses, then joint coordinates with angles in "
        "(-pi, pi]) and qd (n_dofs) at the Cartesian state (u, v): a coupled model's independent "
        "coordinates, as state_from_joints takes.");

  m.def("evaluate_constraints", &evaluate_constraints_py, py::arg("model"), py::arg("u"),
        py::arg("v"), py::arg("t") = 0.0,
        "The constraints at the Cartesian state u (nq,), v (nv,) and time t [s]: a dict of float64 "
        "arrays f (nc,) (the residuals, [m or rad]), zeta (nc, nv) (the Jacobian), xi (nc,) and "
        "rhs (nc,), with zeta v = rhs and zeta v' = -xi. ModelError on wrong shapes.");

  m.def("body_accelerations", &body_accelerations_py, py::arg("model"), py::arg("u"), py::arg("v"),
        py::arg("t") = 0.0,
        "Solve the KKT system at the Cartesian state u (nq,), v (nv,) and time t [s]: returns "
        "(v' (nv,) the bodies' accelerations [m/s^2, rad/s^2], delta (nc,) the Lagrange "
        "multipliers [N, N m]). ModelError on wrong shapes, SolverError on a singular system.");

  m.def("body_mass_matrix", &body_mass_matrix_py, py::arg("model"),
        "The constant Cartesian mass matrix Gamma = blockdiag(m_i I3, J_i) (nv, nv) [kg, kg m^2] "
        "of the bodies (J_i about the CoM in body axes).");

  m.def("body_forces", &body_forces_py, py::arg("model"), py::arg("u"), py::arg("v"),
        py::arg("t") = 0.0,
        "The applied Cartesian forces eta (nv,) at the state u (nq,), v (nv,) and time t [s]: per "
        "body the force [N, world] and torque [N m, body axes] of gravity, the gyroscopic -w x Jw, "
        "loads, springs and joint forces. ModelError on wrong shapes.");

  m.def("energy", &energy_py, py::arg("model"), py::arg("u"), py::arg("v"),
        "(kinetic, potential) energy [J] at the Cartesian state u (nq,), v (nv,); the potential "
        "includes gravity and springs. ModelError on wrong shapes.");
}

}  // namespace armdyn
