// SPDX-License-Identifier: BSD-3-Clause
// Bindings of inverse dynamics and the Lagrange and geometric validators.
#include <pybind11/stl.h>

#include "armdyn/algorithm/driven_inverse_dynamics.hpp"
#include "armdyn/algorithm/tree_dynamics.hpp"
#include "armdyn/validate/validators.hpp"
#include "common.hpp"

namespace armdyn {

namespace py = pybind11;

using namespace py_helpers;

namespace {

using ModelHolder = std::shared_ptr<Model>;

/// TreeDynamics with its model kept alive.
struct TreeDynamicsPy {
  explicit TreeDynamicsPy(ModelHolder md) : m(std::move(md)), td(*m) {}
  ModelHolder m;
  TreeDynamics td;
};

MatX to_mat(const py::handle& obj, const std::string& name, long cols) {
  auto a = as_array(obj, name);
  if (a.ndim() == 1 && a.shape(0) == cols) {
    MatX m(1, cols);
    for (long j = 0; j < cols; ++j) m(0, j) = a.at(j);
    return m;
  }
  if (a.ndim() != 2 || a.shape(1) != cols)
    throw ModelError(msg(name, ": expected shape (n, ", cols, "), got ", shape_str(a)));
  MatX m(a.shape(0), cols);
  for (long i = 0; i < a.shape(0); ++i)
    for (long j = 0; j < cols; ++j) m(i, j) = a.at(i, j);
  return m;
}

py::dict id_result_dict(const Model& md, const InverseDynamicsResult& r) {
  const py::ssize_t n = r.n, nj = static_cast<py::ssize_t>(md.joints.size());
  const py::ssize_t nco = static_cast<py::ssize_t>(md.coords.size());
  py::dict d;
  d["t"] = to_numpy(r.t.data(), {n});
  d["u"] = to_numpy(r.u.data(), {n, md.nq});
  d["v"] = to_numpy(r.v.data(), {n, md.nv});
  d["q"] = to_numpy(r.q.data(), {n, nco});
  d["qd"] = to_numpy(r.qd.data(), {n, nco});
  d["qdd"] = to_numpy(r.qdd.data(), {n, nco});
  d["drive_forces"] = to_numpy(r.efforts.data(), {n, static_cast<py::ssize_t>(md.drives.size())});
  d["reaction_forces"] = to_numpy(r.reaction_forces.data(), {n, nj, 3});
  d["reaction_torques"] = to_numpy(r.reaction_torques.data(), {n, nj, 3});
  d["position_residual"] = to_numpy(r.position_residual.data(), {n});
  d["velocity_residual"] = to_numpy(r.velocity_residual.data(), {n});
  py::dict s;
  s["newton_iterations"] = r.newton_iterations;
  s["factorizations"] = r.factorizations;
  s["seconds"] = r.cpu_seconds;
  d["stats"] = s;
  return d;
}

}  // namespace

void bind_validate(py::module_& m) {
  m.def(
      "_inverse_dynamics_driven",
      [](const Model& md, const ArrayLike& times) {
        const VecX t = to_vec(times, "t");
        std::vector<double> tv(t.data(), t.data() + t.size());
        InverseDynamicsResult r;
        Poll poll = python_poll();  // Ctrl-C
        {
          py::gil_scoped_release nogil;
          r = inverse_dynamics_driven(md, tv, &poll);
        }
        return id_result_dict(md, r);
      },
      py::arg("model"), py::arg("t"));

  py::class_<TreeDynamicsPy>(
      m, "_TreeDynamics",
      "Joint-space forward dynamics of a tree without drives, ideal gears allowed (the path of "
      "simulate(coordinates='joint')): the mass matrix by the composite-rigid-body algorithm, "
      "bias and applied forces by recursive Newton-Euler, gears eliminated by their null space. "
      "Keeps its workspace between calls.")
      .def(py::init([](ModelHolder md) {
             if (!md) throw ModelError("TreeDynamics: no model");
             return std::make_unique<TreeDynamicsPy>(md);
           }),
           py::arg("model"))
      .def(
          "__call__",
          [](TreeDynamicsPy& self, const ArrayLike& q, const ArrayLike& qd, const ArrayLike& tau,
             double t) {
            const long n = self.td.n(), nq = self.m->nq_joint;
            const VecArg qa(q, "q", nq), qda(qd, "qd", n), ta(tau, "tau", n);
            check_joint_vector(*qa, nq, "TreeDynamics", "q");
            check_base_quaternions(*self.m, *qa, "TreeDynamics");
            check_joint_vector(*qda, n, "TreeDynamics", "qd");
            check_joint_vector(*ta, n, "TreeDynamics", "tau");
            if (!std::isfinite(t)) throw ModelError("TreeDynamics: t is not finite");
            if (self.m->n_aux)
              throw ModelError(
                  "TreeDynamics: the model's PI motors have integral states; "
                  "simulate() integrates them");
            py::array_t<double> out(n);
            self.td.accelerations(t, (*qa).data(), (*qda).data(), nullptr, (*ta).data(),
                                  out.mutable_data());
            return out;
          },
          py::arg("q"), py::arg("qd"), py::arg("tau"), py::arg("t") = 0.0,
          "Joint accelerations for joint forces tau at (q, qd, t); the model's coordinate "
          "forces and gear contacts are included, the ideal gears' rows are held.")
      .def(
          "mass_matrix",
          [](TreeDynamicsPy& self, const ArrayLike& q) {
            const long n = self.td.n(), nq = self.m->nq_joint;
            const VecArg qa(q, "q", nq);
            check_joint_vector(*qa, nq, "TreeDynamics.mass_matrix", "q");
            check_base_quaternions(*self.m, *qa, "TreeDynamics.mass_matrix");
            const MatX& M = self.td.mass_matrix((*qa).data());
            py::array_t<double> out({n, n});
            Eigen::Map<Eigen::Matrix<double, -1, -1, Eigen::RowMajor>>(out.mutable_data(), n, n) =
                M;
            return out;
          },
          py::arg("q"), "The joint-space mass matrix M(q) (n_coords x n_coords).")
      .def_property_readonly("dof", [](const TreeDynamicsPy& s) { return s.td.dof(); })
      .def_property_readonly("description",
                             [](const TreeDynamicsPy& s) { return s.td.description(); });

  py::class_<LagrangeValidator>(
      m, "LagrangeValidator",
      "Complete Euler-Lagrange equations of a tree model in its joint coordinates, derived "
      "from joint-space kinematics by automatic differentiation, independently of the "
      "Newton-Euler/KKT path.")
      .def(py::init([](ModelHolder md, bool rot) {
             return std::make_unique<LagrangeValidator>(std::const_pointer_cast<const Model>(md),
                                                        rot);
           }),
           py::arg("model"), py::arg("rotational_inertia") = true,
           "The Euler-Lagrange equations of a tree `model` (rotational_inertia=False: the "
           "bodies as point masses).")
      .def_property_readonly("rotational_inertia", &LagrangeValidator::rotational_inertia,
                             "False when the bodies count as point masses.")
      .def(
          "torques",
          [](const LagrangeValidator& self, const ArrayLike& q, const ArrayLike& qd,
             const ArrayLike& qdd, const OptArrayLike& t) {
            const long n = self.nv();
            const MatX Q = to_mat(q, "q", self.nq()), QD = to_mat(qd, "qd", n),
                       QDD = to_mat(qdd, "qdd", n);
            if (QD.rows() != Q.rows() || QDD.rows() != Q.rows())
              throw ModelError(
                  "LagrangeValidator.torques: q, qd, qdd need the same number of rows");
            VecX tv = VecX::Zero(Q.rows());
            if (!t.is_none()) {
              auto ta = as_array(t, "t");
              if (ta.ndim() == 0)
                tv.setConstant(ta.at());
              else
                tv = to_vec(t, "t", Q.rows());
            }
            MatX out(Q.rows(), n);
            for (long i = 0; i < Q.rows(); ++i)
              out.row(i) = self.torques(Q.row(i).transpose(), QD.row(i).transpose(),
                                        QDD.row(i).transpose(), tv[i])
                               .transpose();
            if (as_array(q, "q").ndim() == 1) return to_numpy(VecX(out.row(0).transpose()));
            return to_numpy(out);
          },
          py::arg("q"), py::arg("qd"), py::arg("qdd"), py::arg("t") = py::none(),
          "Torques for one sample (1-D inputs) or many (rows); t a scalar or one per row.")
      .def(
          "mass_matrix",
          [](const LagrangeValidator& self, const ArrayLike& q) {
            return to_numpy(self.mass_matrix(to_vec(q, "q", self.nq())));
          },
          py::arg("q"),
          "The joint-space mass matrix M(q) (n_dofs, n_dofs) [kg m^2, kg] of the Lagrangian at "
          "q (n_coords,).");

  m.def(
      "paper_3dof_torques",
      [](const ArrayLike& L, const ArrayLike& M, double g, const ArrayLike& th,
         const ArrayLike& thd) {
        const Vec3 Lv = to_vec3(L, "L"), Mv = to_vec3(M, "M");
        const MatX T = to_mat(th, "theta", 3), TD = to_mat(thd, "thetad", 3);
        if (T.rows() != TD.rows())
          throw ModelError("paper_3dof_torques: theta and thetad need the same number of rows");
        MatX out(T.rows(), 3);
        for (long i = 0; i < T.rows(); ++i)
          out.row(i) = paper_3dof_torques(Lv, Mv, g, T.row(i).transpose(), TD.row(i).transpose())
                           .transpose();
        if (as_array(th, "theta").ndim() == 1) return to_numpy(VecX(out.row(0).transpose()));
        return to_numpy(out);
      },
      py::arg("L"), py::arg("M"), py::arg("g"), py::arg("theta"), py::arg("thetad"));

  m.def(
      "paper_5dof_end_effector",
      [](double h, double L1, double L2, double L34, const ArrayLike& th) {
        return to_numpy(VecX(paper_5dof_end_effector(h, L1, L2, L34, to_vec4(th, "theta"))));
      },
      py::arg("h"), py::arg("L1"), py::arg("L2"), py::arg("L34"), py::arg("theta"));

  m.def(
      "end_effector_position",
      [](const Model& md, const std::string& body, const ArrayLike& point, const ArrayLike& q) {
        const int b = md.find_body(body);
        const Vec3 p = to_vec3(point, "point");
        const long n = md.nq_joint;
        const MatX Q = to_mat(q, "q", n);
        MatX out(Q.rows(), 3);
        for (long i = 0; i < Q.rows(); ++i)
          out.row(i) = end_effector_position(md, b, p, Q.row(i).transpose()).transpose();
        if (as_array(q, "q").ndim() == 1) return to_numpy(VecX(out.row(0).transpose()));
        return to_numpy(out);
      },
      py::arg("model"), py::arg("body"), py::arg("point"), py::arg("q"));

  m.def(
      "torque_error_metrics",
      [](const ArrayLike& a, const ArrayLike& ref) {
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
      },
      py::arg("a"), py::arg("ref"));
}

}  // namespace armdyn
