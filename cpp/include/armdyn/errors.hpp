// SPDX-License-Identifier: BSD-3-Clause
// Exception types. User input errors derive from std::invalid_argument (Python ValueError);
// numerical failures are SolverError (Python armdyn.SolverError, a RuntimeError).
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace armdyn {

/// Invalid model data: names, masses, inertias, axes, topology, array shapes.
class ModelError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Malformed or unsupported URDF.
class UrdfError : public ModelError {
 public:
  using ModelError::ModelError;
};

/// Numerical failure: singular system, projection or assembly that does not converge,
/// non-finite values during a run.
class SolverError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A run stopped from outside: a Poll's callback threw it (the Python bindings: a signal such as
/// SIGINT, or an exception raised by a progress or profile callable that must propagate as
/// itself) or its cancel flag was set. Not a SolverError: the integrators' step rejection does
/// not swallow it. simulate() returns the outputs up to the last good one with
/// SimResult::interrupt holding it (as `error` holds a SolverError's message).
class Interrupted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Concatenate streamable parts into a message.
template <typename... Args>
std::string msg(const Args&... args) {
  std::ostringstream os;
  os.precision(17);
  (os << ... << args);
  return os.str();
}

}  // namespace armdyn
