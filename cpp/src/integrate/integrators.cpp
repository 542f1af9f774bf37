// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/integrate/integrators.hpp"

#include <string>
#include <utility>
#include <vector>

#include "armdyn/errors.hpp"

namespace armdyn {

namespace {
constexpr std::pair<Integrator, const char*> kIntegratorNames[] = {
    {Integrator::Dopri5, "dopri5"},
    {Integrator::Dop853, "dop853"},
    {Integrator::Rk4, "rk4"},
    {Integrator::Trbdf2, "trbdf2"},
    {Integrator::Kinematic, "kinematic"},
    {Integrator::Auto, "auto"},
    {Integrator::Default, "default"}};

}  // namespace

const char* integrator_name(Integrator i) {
  for (const auto& [value, name] : kIntegratorNames)
    if (value == i) return name;
  return "?";
}

Integrator integrator_from_name(const std::string& name) {
  for (const auto& [value, n] : kIntegratorNames)
    if (name == n) return value;
  throw ModelError(msg("simulate: unknown integrator '", name,
                       "' (expected 'dopri5', 'dop853', 'rk4', 'trbdf2', 'kinematic' or 'auto')"));
}

void output_times(double t0, double t1, double dt, std::vector<double>& ts) {
  ts.clear();
  if (!(dt > 0)) return;
  const double eps = 1e-9 * dt;
  for (long k = 0;; ++k) {
    const double t = t0 + static_cast<double>(k) * dt;
    if (t >= t1 - eps) break;
    ts.push_back(t);
  }
  ts.push_back(t1);
}

std::vector<double> output_times(double t0, double t1, double dt) {
  std::vector<double> ts;
  output_times(t0, t1, dt, ts);
  return ts;
}

}  // namespace armdyn
