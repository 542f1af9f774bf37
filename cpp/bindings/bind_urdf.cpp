// SPDX-License-Identifier: BSD-3-Clause
// armdyn._core.urdf_builder and the URDF reader's limits (armdyn/io/urdf.hpp).
#include "armdyn/io/urdf.hpp"
#include "convert_builder.hpp"

namespace armdyn {

namespace py = pybind11;
using namespace py_helpers;

void bind_urdf(py::module_& m) {
  m.attr("URDF_MAX_BYTES") = kUrdfMaxBytes;
  m.attr("URDF_MAX_ATTRIBUTES") = kUrdfMaxAttributes;
  m.attr("URDF_COULOMB_SMOOTHING") = kUrdfCoulombSmoothing;
  m.def(
      "urdf_builder",
      [](const StrArg& src_, const BoolArg& fixed_base_, const ArrayLike& g,
         const BoolArg& physical_inertia_, const BoolArg& mimic_) {
        const char* fn = "urdf_builder";
        const std::string src = urdf_source_arg(src_, fn);
        const bool fixed_base = bool_arg(fixed_base_, fn, "fixed_base");
        const bool physical_inertia = bool_arg(physical_inertia_, fn, "physical_inertia");
        const bool mimic = bool_arg(mimic_, fn, "mimic");
        const Vec3 gravity = to_vec3(g, "gravity");
        return with_python_poll([&] {
          return urdf_utf8_errors(
              [&] { return urdf_builder(src, fixed_base, gravity, physical_inertia, mimic); });
        });
      },
      py::arg("path_or_xml"), py::arg("fixed_base") = true,
      py::arg("gravity") = py::make_tuple(0.0, 0.0, -9.81), py::kw_only(),
      py::arg("physical_inertia") = true, py::arg("mimic") = true,
      "A ModelBuilder holding a URDF robot (add drives or loads, then finalize()): "
      "path_or_xml is a file path or the XML text; fixed_base=False adds a free joint (a "
      "floating base) on the root link; gravity (3,) [m/s^2] in world axes; physical_inertia as "
      "ModelBuilder's; mimic=True turns <mimic> joints into couplings. UrdfError naming the "
      "element on a malformed or unsupported file.");
}

}  // namespace armdyn
