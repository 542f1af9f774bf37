// SPDX-License-Identifier: BSD-3-Clause
// The conversions of common.hpp that are not inline.
#include "common.hpp"

namespace armdyn::py_helpers {

Profile to_profile(const py::handle& obj, const std::string& name) {
  if (py::isinstance<Profile>(obj)) return obj.cast<Profile>();
  if (py::isinstance<py::float_>(obj) || py::isinstance<py::int_>(obj))
    return Profile::constant(obj.cast<double>());
  if (PyCallable_Check(obj.ptr())) {
    // keep the callable alive; release it with the GIL held
    auto fn = std::shared_ptr<py::object>(new py::object(py::reinterpret_borrow<py::object>(obj)),
                                          [](py::object* p) {
                                            py::gil_scoped_acquire g;
                                            delete p;
                                          });
    const std::string desc = py::str(obj).cast<std::string>();
    return Profile::callback(
        [fn, desc](double t) {
          py::gil_scoped_acquire g;
          try {
            py::tuple r = py::tuple((*fn)(t));
            if (r.size() != 3) throw SolverError("");
            return ProfileValue{r[0].cast<double>(), r[1].cast<double>(), r[2].cast<double>()};
          } catch (py::error_already_set& e) {
            // SystemExit, KeyboardInterrupt, GeneratorExit: themselves (the run's outputs kept)
            if (propagates_as_itself(e)) throw PyInterrupted(std::move(e));
            const std::string what =
                msg("profile callback ", desc, " raised at t=", t, ": ", py_error_summary(e));
            throw PyCallbackError(what, std::move(e));
          } catch (...) {
            throw SolverError(msg("profile callback ", desc,
                                  " must return (y, dy/dt, d2y/dt2) as 3 numbers (t=", t, ")"));
          }
        },
        desc);
  }
  throw ModelError(msg(name,
                       ": expected an armdyn profile, a number or a callable "
                       "t -> (y, yd, ydd)"));
}

}  // namespace armdyn::py_helpers
