// SPDX-License-Identifier: BSD-3-Clause
// Running C++ from Python: Python exceptions carried through a C++ run (PyInterrupted,
// PyCallbackError) and found again (py_cause), the poll that runs Python's signal handlers and
// a progress callable during a run (python_poll), and the guard against re-entering simulate.
#pragma once

#include <pybind11/pybind11.h>

#include <chrono>
#include <exception>
#include <string>

#include "armdyn/errors.hpp"
#include "armdyn/poll.hpp"

namespace armdyn::py_helpers {

namespace py = pybind11;

/// A Python exception that must propagate as itself (KeyboardInterrupt from the signal handler,
/// SystemExit, GeneratorExit, anything a progress callable raises) carried through a C++ run as
/// an Interrupted: simulate() then keeps the outputs so far, and the binding hands the Python
/// exception back (module.cpp translates one escaping elsewhere back into itself).
class PyInterrupted : public Interrupted {
 public:
  explicit PyInterrupted(py::error_already_set e) : Interrupted(e.what()), err(std::move(e)) {}
  py::error_already_set err;
};

/// An ordinary Python exception raised by a callback: a SolverError naming the callback, with
/// the Python exception kept as its cause (__cause__).
class PyCallbackError : public SolverError {
 public:
  PyCallbackError(const std::string& what, py::error_already_set e)
      : SolverError(what), err(std::move(e)) {}
  py::error_already_set err;
};

/// "Type: message" of a Python error (its traceback is in the chained exception).
inline std::string py_error_summary(const py::error_already_set& e) {
  return msg(py::str(e.type().attr("__name__")).cast<std::string>(), ": ",
             py::str(e.value()).cast<std::string>());
}

/// The Python exception behind a SolverError: a PyCallbackError's, also when wrapped by
/// std::throw_with_nested (the C++ code adding context: the force, the row); None otherwise.
/// The GIL must be held.
inline py::object py_cause(const std::exception& e) {
  if (const auto* p = dynamic_cast<const PyCallbackError*>(&e)) return p->err.value();
  if (const auto* n = dynamic_cast<const std::nested_exception*>(&e)) {
    try {
      n->rethrow_nested();
    } catch (const std::exception& inner) {
      return py_cause(inner);
    } catch (...) {
    }
  }
  return py::none();
}

/// Whether a Python error must propagate as itself rather than become a SolverError.
inline bool propagates_as_itself(const py::error_already_set& e) {
  return e.matches(PyExc_KeyboardInterrupt) || e.matches(PyExc_SystemExit) ||
         e.matches(PyExc_GeneratorExit);
}

/// The poll of a run started from Python (poll.hpp): every 5 ms of wall time it takes
/// the GIL briefly (on the main thread, or with a progress callable) to run the signal handlers
/// (PyErr_CheckSignals: Ctrl-C raises KeyboardInterrupt there) and, every 0.1 s and when not None,
/// calls progress(t, t_end). A Python exception from either stops the run as a PyInterrupted
/// (propagating as itself). progress (may be null) must outlive the poll.
inline Poll python_poll(const py::object* progress = nullptr) {
  // signal handlers run only on the main thread: elsewhere, without progress, no callback (a
  // run on a worker thread never takes the GIL for it)
  const auto main_ident =
      py::module_::import("threading").attr("main_thread")().attr("ident").cast<unsigned long>();
  const bool main_thread = PyThread_get_thread_ident() == main_ident;
  if (!main_thread && (!progress || progress->is_none())) return Poll();
  auto last = std::make_shared<Poll::Clock::time_point>(Poll::Clock::now());
  return Poll(
      [progress, last](double t, double t_end) {
        py::gil_scoped_acquire g;
        if (PyErr_CheckSignals() != 0) throw PyInterrupted(py::error_already_set());
        if (!progress || progress->is_none()) return;
        const auto now = Poll::Clock::now();
        if (std::chrono::duration<double>(now - *last).count() < 0.1) return;
        *last = now;
        try {
          (*progress)(t, t_end);
        } catch (py::error_already_set& e) {
          throw PyInterrupted(std::move(e));
        }
      },
      0.005);
}

/// Refuses a simulate started on a thread already running one (a profile or progress callable
/// that calls simulate): re-entry would recurse until the C stack overflows. One per run, on
/// the thread that runs it (the bindings of simulate; rollout's threads may take one each).
class SimulateGuard {
 public:
  explicit SimulateGuard(const char* fn) {
    if (depth() > 0)
      throw ModelError(msg(fn,
                           ": called from inside a running simulation (a profile or progress "
                           "callable); re-entrant runs are refused. Run it after the outer run "
                           "returns"));
    ++depth();
  }
  ~SimulateGuard() { --depth(); }
  SimulateGuard(const SimulateGuard&) = delete;
  SimulateGuard& operator=(const SimulateGuard&) = delete;

 private:
  static int& depth() {
    static thread_local int d = 0;
    return d;
  }
};

}  // namespace armdyn::py_helpers
