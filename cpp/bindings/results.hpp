// SPDX-License-Identifier: BSD-3-Clause
// Results to Python: a run's SimResult and driven inverse dynamics' InverseDynamicsResult as the
// dicts armdyn.simulation and armdyn.dynamics make their dataclasses of, expanded from the field
// lists of the C++ headers (ARMDYN_SIM_TABLES, ARMDYN_SIM_STATS, ARMDYN_DRIVEN_ID_TABLES, ...);
// the same lists as (name, doc) tuples for armdyn._core (tests/docs/test_schema.py); the
// exception that stopped a run; the options of a run from simulate's arguments.
#pragma once

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "armdyn/algorithm/driven_inverse_dynamics.hpp"
#include "armdyn/model/columns.hpp"
#include "armdyn/simulate/simulate.hpp"
#include "common.hpp"

namespace armdyn::py_helpers {

/// A table of n rows as a float64 array of shape (n, *row_shape).
inline py::array_t<double> table_array(const Model& m, const std::vector<double>& table, long n,
                                       Columns c, long limits = 0) {
  std::vector<py::ssize_t> shape{n};
  for (long k : row_shape(m, c, limits)) shape.push_back(k);
  return to_numpy(table.data(), shape);
}

/// {"names": names, "force": table}: a table whose columns are named.
inline py::dict named_table(const std::vector<std::string>& names, py::array_t<double> force) {
  py::dict d;
  d["names"] = names;
  d["force"] = std::move(force);
  return d;
}

/// result.stats: every entry of ARMDYN_SIM_STATS.
inline py::dict sim_stats_dict(const SimResult& r) {
  py::dict s;
#define ARMDYN_STEP_STAT(key, member, doc) s[#key] = r.stats.member;
#define ARMDYN_OWN_STAT(key, type, member, doc) s[#key] = r.member;
  ARMDYN_SIM_STATS(ARMDYN_STEP_STAT, ARMDYN_OWN_STAT)
#undef ARMDYN_STEP_STAT
#undef ARMDYN_OWN_STAT
  return s;
}

/// result.events: the gear contacts' (t, gear, onset) and the joint stops' (limits: t, joint,
/// side, kind).
inline py::dict sim_events_dict(const Model& m, const SimResult& r) {
  py::dict ev;
  ev["t"] = to_numpy(r.event_t.data(), {static_cast<py::ssize_t>(r.event_t.size())});
  std::vector<std::string> gears;
  for (int i : r.event_index) gears.push_back(m.gears[i].name);
  ev["gear"] = gears;
  std::vector<bool> onset;
  for (int dir : r.event_direction) onset.push_back(dir > 0);
  ev["onset"] = onset;
  py::dict lim;
  lim["t"] = to_numpy(r.limit_event_t.data(), {static_cast<py::ssize_t>(r.limit_event_t.size())});
  lim["joint"] = r.limit_event_joint;
  std::vector<std::string> side, kind;
  for (int sd : r.limit_event_side) side.emplace_back(limit_side_name(sd));
  for (int k : r.limit_event_kind) kind.emplace_back(limit_event_kind_name(k));
  lim["side"] = side;
  lim["kind"] = kind;
  ev["limits"] = lim;
  return ev;
}

/// The dict of a run, one key per field of ARMDYN_SIM_TABLES, ARMDYN_SIM_NAMED_TABLES and
/// ARMDYN_SIM_RECORDS.
inline py::dict sim_result_dict(const Model& m, const SimResult& r) {
  py::dict d;
#define ARMDYN_TABLE(name, columns, doc) d[#name] = table_array(m, r.name, r.n, Columns::columns);
  ARMDYN_SIM_TABLES(ARMDYN_TABLE)
#undef ARMDYN_TABLE
  const long nl = static_cast<long>(r.limit_joints.size());
  d["gear_forces"] = named_table(gear_names(m), table_array(m, r.gear_forces, r.n, Columns::Gears));
  d["limit_forces"] =
      named_table(r.limit_joints, table_array(m, r.limit_forces, r.n, Columns::Limits, nl));
  d["stats"] = sim_stats_dict(r);
  d["events"] = sim_events_dict(m, r);
  d["error"] = r.error;
  return d;
}

/// The Python exceptions that stopped a run, for armdyn.simulate to raise: "interrupt" (to
/// raise as itself, with .result) and "cause" (a SolverError's __cause__), or None.
inline void add_run_exception(const SimResult& r, py::dict& d) {
  d["interrupt"] = py::none();
  d["cause"] = py::none();
  if (!r.exception) return;
  try {
    std::rethrow_exception(r.exception);
  } catch (PyInterrupted& e) {
    d["interrupt"] = e.err.value();
  } catch (const SolverError& e) {
    d["cause"] = py_cause(e);
  } catch (const Interrupted& e) {
    d["interrupt"] = py::reinterpret_steal<py::object>(
        PyObject_CallFunction(PyExc_KeyboardInterrupt, "s", e.what()));
  } catch (...) {
  }
}

/// The dict of driven inverse dynamics, one key per field of ARMDYN_DRIVEN_ID_TABLES and
/// ARMDYN_DRIVEN_ID_RECORDS.
inline py::dict driven_id_result_dict(const Model& m, const InverseDynamicsResult& r) {
  py::dict d;
#define ARMDYN_TABLE(name, columns, doc) d[#name] = table_array(m, r.name, r.n, Columns::columns);
  ARMDYN_DRIVEN_ID_TABLES(ARMDYN_TABLE)
#undef ARMDYN_TABLE
  py::dict s;
#define ARMDYN_STAT(key, type, member, doc) s[#key] = r.member;
  ARMDYN_DRIVEN_ID_STATS(ARMDYN_STAT)
#undef ARMDYN_STAT
  d["stats"] = s;
  return d;
}

/// The field lists as tuples of (name, doc), for armdyn._core.
struct FieldDocs {
  std::vector<std::pair<std::string, std::string>> items;
  void add(const char* name, const char* doc) { items.emplace_back(name, doc); }
  py::tuple tuple() const {
    py::tuple t(items.size());
    for (size_t k = 0; k < items.size(); ++k)
      t[k] = py::make_tuple(items[k].first, items[k].second);
    return t;
  }
};

/// (_SIM_FIELDS, _SIM_STATS, _DRIVEN_ID_FIELDS, _DRIVEN_ID_STATS) of armdyn._core: the keys of
/// the result dicts and of their stats, in order, with their docs.
inline void add_result_schema(py::module_& m) {
  FieldDocs sim, sim_stats, id, id_stats;
#define ARMDYN_FIELD2(name, doc) sim.add(#name, doc);
#define ARMDYN_FIELD3(name, columns, doc) sim.add(#name, doc);
  ARMDYN_SIM_TABLES(ARMDYN_FIELD3)
  ARMDYN_SIM_NAMED_TABLES(ARMDYN_FIELD3)
  ARMDYN_SIM_RECORDS(ARMDYN_FIELD2)
#undef ARMDYN_FIELD2
#undef ARMDYN_FIELD3
#define ARMDYN_STEP_STAT(key, member, doc) sim_stats.add(#key, doc);
#define ARMDYN_OWN_STAT(key, type, member, doc) sim_stats.add(#key, doc);
  ARMDYN_SIM_STATS(ARMDYN_STEP_STAT, ARMDYN_OWN_STAT)
#undef ARMDYN_STEP_STAT
#undef ARMDYN_OWN_STAT
#define ARMDYN_FIELD2(name, doc) id.add(#name, doc);
#define ARMDYN_FIELD3(name, columns, doc) id.add(#name, doc);
  ARMDYN_DRIVEN_ID_TABLES(ARMDYN_FIELD3)
  ARMDYN_DRIVEN_ID_RECORDS(ARMDYN_FIELD2)
#undef ARMDYN_FIELD2
#undef ARMDYN_FIELD3
#define ARMDYN_STAT(key, type, member, doc) id_stats.add(#key, doc);
  ARMDYN_DRIVEN_ID_STATS(ARMDYN_STAT)
#undef ARMDYN_STAT
  m.attr("_SIM_FIELDS") = sim.tuple();
  m.attr("_SIM_STATS") = sim_stats.tuple();
  m.attr("_DRIVEN_ID_FIELDS") = id.tuple();
  m.attr("_DRIVEN_ID_STATS") = id_stats.tuple();
}

/// The options of a run from simulate's arguments (the modes by their names).
inline SimOptions sim_options(const std::string& integrator, double rtol, double atol, double dt,
                              double output_dt, const std::string& projection, long max_steps,
                              double max_step, bool merge_welded, const std::string& coordinates,
                              bool limits, double restitution) {
  SimOptions o;
  o.merge_welded = merge_welded;
  o.limits = limits;
  o.restitution = restitution;
  o.coordinates = coordinates_from_name(coordinates);
  o.step.max_step = max_step;
  o.integrator = integrator_from_name(integrator);
  o.step.rtol = rtol;
  o.step.atol = atol;
  o.step.dt = dt;
  o.step.output_dt = output_dt;
  o.step.max_steps = max_steps;
  o.projection = projection_from_name(projection);
  return o;
}

}  // namespace armdyn::py_helpers
