// SPDX-License-Identifier: BSD-3-Clause
// Bindings of the joint-space tree dynamics of simulate(coordinates='joint') (_TreeDynamics) and
// of the Lagrange and geometric validators (armdyn/validate/validators.hpp).
#include <pybind11/stl.h>

#include "armdyn/algorithm/tree_dynamics.hpp"
#include "armdyn/validate/validators.hpp"
#include "common.hpp"
#include "rows.hpp"

namespace armdyn {

namespace py = pybind11;
using namespace py_helpers;

namespace {

/// TreeDynamics with its model kept alive.
struct TreeDynamicsPy {
  explicit TreeDynamicsPy(ModelHolder md) : m(std::move(md)), td(*m) {}
  ModelHolder m;
  TreeDynamics td;
};

std::unique_ptr<TreeDynamicsPy> tree_dynamics_new(ModelHolder md) {
  if (!md) throw ModelError("TreeDynamics: no model");
  return std::make_unique<TreeDynamicsPy>(md);
}

py::array_t<double> tree_accelerations_py(TreeDynamicsPy& self, const ArrayLike& q,
                                          const ArrayLike& qd, const ArrayLike& tau, double t) {
  const long n = self.td.n();
  const VecArg qa(q, "q", self.m->nq_joint), qda(qd, "qd", n), ta(tau, "tau", n);
  py::array_t<double> out(n);
  checked_accelerations(self.td, *qa, *qda, *ta, t, out.mutable_data());
  return out;
}

py::array_t<double> tree_mass_matrix_py(TreeDynamicsPy& self, const ArrayLike& q) {
  const long n = self.td.n();
  const VecArg qa(q, "q", self.m->nq_joint);
  const MatX& M = checked_mass_matrix(self.td, *qa);
  py::array_t<double> out({n, n});
  Eigen::Map<Eigen::Matrix<double, -1, -1, Eigen::RowMajor>>(out.mutable_data(), n, n) = M;
  return out;
}

std::unique_ptr<LagrangeValidator> lagrange_new(ModelHolder md, bool rot) {
  return std::make_unique<LagrangeValidator>(std::const_pointer_cast<const Model>(md), rot);
}

/// t of LagrangeValidator.torques: None (zero), a number, or one per row.
VecX row_times(const OptArrayLike& t, long rows) {
  if (t.is_none()) return VecX::Zero(rows);
  auto ta = as_array(t, "t");
  if (ta.ndim() == 0) return VecX::Constant(rows, ta.at());
  return to_vec(t, "t", rows);
}

py::array_t<double> lagrange_torques_py(const LagrangeValidator& self, const ArrayLike& q,
                                        const ArrayLike& qd, const ArrayLike& qdd,
                                        const OptArrayLike& t) {
  const long n = self.nv();
  const MatX Q = to_mat(q, "q", self.nq()), QD = to_mat(qd, "qd", n), QDD = to_mat(qdd, "qdd", n);
  const VecX tv = row_times(t, Q.rows());
  return rows_out(self.torques(Q, QD, QDD, tv), q, "q");
}

py::array_t<double> lagrange_mass_matrix_py(const LagrangeValidator& self, const ArrayLike& q) {
  return to_numpy(self.mass_matrix(to_vec(q, "q", self.nq())));
}

py::array_t<double> paper_3dof_torques_py(const ArrayLike& L, const ArrayLike& M, double g,
                                          const ArrayLike& th, const ArrayLike& thd) {
  const Vec3 Lv = to_vec3(L, "L"), Mv = to_vec3(M, "M");
  const MatX T = to_mat(th, "theta", 3), TD = to_mat(thd, "thetad", 3);
  return rows_out(paper_3dof_torques(Lv, Mv, g, T, TD), th, "theta");
}

py::array_t<double> paper_5dof_end_effector_py(double h, double L1, double L2, double L34,
                                               const ArrayLike& th) {
  return to_numpy(VecX(paper_5dof_end_effector(h, L1, L2, L34, to_vec4(th, "theta"))));
}

py::array_t<double> end_effector_position_py(const Model& md, const std::string& body,
                                             const ArrayLike& point, const ArrayLike& q) {
  const int b = md.find_body(body);
  const Vec3 p = to_vec3(point, "point");
  const MatX Q = to_mat(q, "q", md.nq_joint);
  return rows_out(end_effector_positions(md, b, p, Q), q, "q");
}

py::dict torque_error_metrics_py(const ArrayLike& a, const ArrayLike& ref) {
  auto aa = as_array(a, "a");
  const long k = aa.ndim() == 2 ? aa.shape(1) : 1;
  const TorqueErrorMetrics r = torque_error_metrics(to_mat(a, "a", k), to_mat(ref, "ref", k));
  py::dict d;
  d["percent"] = to_numpy(r.percent);
  d["rms"] = to_numpy(r.rms);
  d["max"] = to_numpy(r.max);
  d["ref_max"] = to_numpy(r.ref_max);
  d["average"] = r.average;
  return d;
}

}  // namespace

void bind_validate(py::module_& m) {
  py::class_<TreeDynamicsPy>(
      m, "_TreeDynamics",
      "Joint-space forward dynamics of a tree without drives, ideal gears allowed (the path of "
      "simulate(coordinates='joint')): the mass matrix by the composite-rigid-body algorithm, "
      "bias and applied forces by recursive Newton-Euler, gears eliminated by their null space. "
      "Keeps its workspace between calls.")
      .def(py::init(&tree_dynamics_new), py::arg("model"))
      .def("__call__", &tree_accelerations_py, py::arg("q"), py::arg("qd"), py::arg("tau"),
           py::arg("t") = 0.0,
           "Joint accelerations for joint forces tau at (q, qd, t); the model's coordinate "
           "forces and gear contacts are included, the ideal gears' rows are held.")
      .def("mass_matrix", &tree_mass_matrix_py, py::arg("q"),
           "The joint-space mass matrix M(q) (n_coords x n_coords).")
      .def_property_readonly("dof", [](const TreeDynamicsPy& s) { return s.td.dof(); })
      .def_property_readonly("description",
                             [](const TreeDynamicsPy& s) { return s.td.description(); });

  py::class_<LagrangeValidator>(
      m, "LagrangeValidator",
      "Complete Euler-Lagrange equations of a tree model in its joint coordinates, derived "
      "from joint-space kinematics by automatic differentiation, independently of the "
      "Newton-Euler/KKT path.")
      .def(py::init(&lagrange_new), py::arg("model"), py::arg("rotational_inertia") = true,
           "The Euler-Lagrange equations of a tree `model` (rotational_inertia=False: the "
           "bodies as point masses).")
      .def_property_readonly("rotational_inertia", &LagrangeValidator::rotational_inertia,
                             "False when the bodies count as point masses.")
      .def("torques", &lagrange_torques_py, py::arg("q"), py::arg("qd"), py::arg("qdd"),
           py::arg("t") = py::none(),
           "Torques for one sample (1-D inputs) or many (rows); t a scalar or one per row.")
      .def("mass_matrix", &lagrange_mass_matrix_py, py::arg("q"),
           "The joint-space mass matrix M(q) (n_dofs, n_dofs) [kg m^2, kg] of the Lagrangian at "
           "q (n_coords,).");

  m.def("paper_3dof_torques", &paper_3dof_torques_py, py::arg("L"), py::arg("M"), py::arg("g"),
        py::arg("theta"), py::arg("thetad"));
  m.def("paper_5dof_end_effector", &paper_5dof_end_effector_py, py::arg("h"), py::arg("L1"),
        py::arg("L2"), py::arg("L34"), py::arg("theta"));
  m.def("end_effector_position", &end_effector_position_py, py::arg("model"), py::arg("body"),
        py::arg("point"), py::arg("q"));
  m.def("torque_error_metrics", &torque_error_metrics_py, py::arg("a"), py::arg("ref"));
}

}  // namespace armdyn
