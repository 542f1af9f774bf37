// SPDX-License-Identifier: BSD-3-Clause
// Bindings of the frames (armdyn/algorithm/frames.hpp): a named frame's world pose and Jacobian
// from joint-space q or from the Cartesian state u; one state per row of a 2-D argument.
#include "armdyn/algorithm/frames.hpp"
#include "armdyn/kernels/joint_space.hpp"
#include "common.hpp"
#include "rows.hpp"

namespace armdyn {

namespace py = pybind11;
using namespace py_helpers;

namespace {

py::array_t<double> frame_pose_py(const ModelArg& model, const ArrayLike& q, const FrameRef& frame,
                                  const OptData& data) {
  constexpr const char* fn = "frame_pose";
  const CallArgs a = call_args(model, data, fn);
  if (!a.model().loop_coordinates) require_joint_space(a.model(), fn, true);
  const int f = frame_arg(a.model(), frame, fn);
  return per_state(fn, "q", a.data.niq, q, {4, 4}, [&](const auto& qi, double* out) {
    copy_row_major(frame_pose(a.model(), a.data, qi, f), out);
  });
}

py::array_t<double> frame_jacobian_py(const ModelArg& model, const ArrayLike& q,
                                      const FrameRef& frame, const OptData& data) {
  constexpr const char* fn = "frame_jacobian";
  const CallArgs a = call_args(model, data, fn);
  if (!a.model().loop_coordinates) require_joint_space(a.model(), fn, true);
  const int f = frame_arg(a.model(), frame, fn);
  return per_state(fn, "q", a.data.niq, q, {6, a.data.ni}, [&](const auto& qi, double* out) {
    copy_row_major(frame_jacobian(a.model(), a.data, qi, f), out);
  });
}

py::array_t<double> frame_pose_cartesian_py(const ModelArg& model, const ArrayLike& u,
                                            const FrameRef& frame, const OptData& data) {
  constexpr const char* fn = "frame_pose_cartesian";
  const CallArgs a = call_args(model, data, fn);
  const int f = frame_arg(a.model(), frame, fn);
  return per_state(fn, "u", a.model().nq, u, {4, 4}, [&](const auto& ui, double* out) {
    copy_row_major(frame_pose_cartesian(a.model(), a.data, ui, f), out);
  });
}

py::array_t<double> frame_jacobian_cartesian_py(const ModelArg& model, const ArrayLike& u,
                                                const FrameRef& frame, const OptData& data) {
  constexpr const char* fn = "frame_jacobian_cartesian";
  const CallArgs a = call_args(model, data, fn);
  const int f = frame_arg(a.model(), frame, fn);
  return per_state(fn, "u", a.model().nq, u, {6, a.model().nv}, [&](const auto& ui, double* out) {
    copy_row_major(frame_jacobian_cartesian(a.model(), a.data, ui, f), out);
  });
}

}  // namespace

void bind_frames(py::module_& m) {
  m.def("frame_pose", &frame_pose_py, py::arg("model"), py::arg("q"), py::arg("frame"),
        py::arg("data") = py::none(),
        "The world pose of a named frame (a name of model.frame_names or its index) at joint "
        "coordinates q: the 4x4 homogeneous transform [R p; 0 1], R the frame's axes in world "
        "(frame -> world) and p its origin [m]; 2-D q (one state per row) gives (rows, 4, 4).");

  m.def("frame_jacobian", &frame_jacobian_py, py::arg("model"), py::arg("q"), py::arg("frame"),
        py::arg("data") = py::none(),
        "The Jacobian (6, n_dofs) of a named frame at joint-space q (n_coords): linear rows then "
        "angular rows, world axes, at the frame's origin (Pinocchio's LOCAL_WORLD_ALIGNED), so "
        "that [v; omega] of the frame = J qd (a floating base's six columns first; a coupled "
        "model's independent coordinates, J G). 2-D q gives (rows, 6, n_dofs).");

  m.def("frame_pose_cartesian", &frame_pose_cartesian_py, py::arg("model"), py::arg("u"),
        py::arg("frame"), py::arg("data") = py::none(),
        "frame_pose from the Cartesian state u (nq; any model, loops included): the 4x4 world "
        "pose of a named frame; 2-D u gives (rows, 4, 4).");

  m.def("frame_jacobian_cartesian", &frame_jacobian_cartesian_py, py::arg("model"), py::arg("u"),
        py::arg("frame"), py::arg("data") = py::none(),
        "The Jacobian (6, nv) of a named frame with respect to the bodies' velocities v of the "
        "Cartesian state (any model): linear rows then angular rows, world axes, at the frame's "
        "origin, so that [v; omega] of the frame = J v. 2-D u gives (rows, 6, nv).");
}

}  // namespace armdyn
