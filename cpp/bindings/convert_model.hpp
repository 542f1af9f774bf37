// SPDX-License-Identifier: BSD-3-Clause
// Conversions of the model family's bindings (bind_model, bind_motor, bind_profile,
// bind_pickle): the C++ values the Model's properties and methods return, as the Python dicts,
// tuples, arrays and objects they hand out, and the Motor and Profile pickled states.
#pragma once

#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "armdyn/builder/builder.hpp"
#include "armdyn/io/serialize.hpp"
#include "armdyn/kernels/block_sparse.hpp"
#include "armdyn/model/model.hpp"
#include "armdyn/model/properties.hpp"
#include "common.hpp"

namespace armdyn::py_helpers {

using ModelClass = py::class_<Model, std::shared_ptr<Model>>;

/// Motor.from_row's row and with_payloads' list, typed for the stubs (common.hpp's hinted
/// objects: any object, checked where it is taken).
class RowArg : public py::object {
 public:
  PYBIND11_OBJECT_DEFAULT(RowArg, py::object, accept_any)
};
class PayloadList : public py::object {
 public:
  PYBIND11_OBJECT_DEFAULT(PayloadList, py::object, accept_any)
};

// --- Motor ------------------------------------------------------------------------------------

/// A Motor field from Python: None (not given) or a finite number (> 0: MotorSpec::validate).
inline double motor_field(const py::handle& v, const char* name) {
  if (v.is_none()) return MotorSpec::kUnset;
  return opt_float_arg(v, "Motor", name, MotorSpec::kUnset, true);
}

/// A Motor field for Python: None when not given.
inline OptFloat motor_get(const MotorSpec& s, double MotorSpec::* p) {
  const double v = s.*p;
  return py::reinterpret_steal<OptFloat>(std::isnan(v) ? py::none().release()
                                                       : py::float_(v).release());
}

/// The Motor of the constructor's arguments: name, then the fields in MotorSpec::fields() order.
inline MotorSpec motor_from_args(const StrArg& name, const std::vector<py::object>& given) {
  MotorSpec s;
  s.name = str_arg(name, "Motor", "name");
  size_t k = 0;
  for (const auto& [n, p] : MotorSpec::fields()) s.*p = motor_field(given[k++], n);
  s.validate("Motor");
  return s;
}

/// A Motor field's unit and description (MotorSpec::fields()), for the docstrings.
struct MotorFieldDoc {
  const char* name;
  const char* unit;
  const char* text;
};

inline const MotorFieldDoc* motor_field_docs() {
  static const MotorFieldDoc docs[MotorSpec::kNumFields] = {
      {"torque_constant", "N m/A", "Torque constant k_t (motor side)"},
      {"resistance", "ohm", "Terminal resistance"},
      {"voltage", "V", "Supply voltage"},
      {"no_load_speed", "rad/s", "No-load speed at the supply voltage"},
      {"continuous_torque", "N m", "Rated continuous torque (motor side)"},
      {"peak_torque", "N m", "Peak torque (motor side)"},
      {"max_speed", "rad/s", "Maximum permissible speed"},
      {"thermal_resistance", "K/W", "Thermal resistance winding to ambient (one-node model)"},
      {"thermal_time_constant", "s", "Thermal time constant of the winding (one-node model)"},
      {"rotor_inertia", "kg m^2", "Rotor inertia (motor side)"},
      {"mass", "kg", "Motor mass"},
      {"thermal_resistance_winding", "K/W",
       "Thermal resistance winding to housing (two-node model)"},
      {"thermal_resistance_housing", "K/W",
       "Thermal resistance housing to ambient (two-node model)"},
      {"thermal_time_constant_winding", "s",
       "Thermal time constant of the winding (two-node model)"},
      {"thermal_time_constant_housing", "s",
       "Thermal time constant of the housing (two-node model)"},
      {"max_winding_temperature", "degC", "Maximum permissible winding temperature"},
      {"brake_torque", "N m", "Holding brake torque (motor side)"},
  };
  return docs;
}

/// The docstring of a Motor field (MotorSpec::fields()): "<text> [<unit>], or None."
inline std::string motor_field_doc(const std::string& n) {
  for (std::size_t k = 0; k < MotorSpec::kNumFields; ++k) {
    const MotorFieldDoc& d = motor_field_docs()[k];
    if (n == d.name) return msg(d.text, " [", d.unit, "], or None.");
  }
  return "Datasheet value '" + n + "' (SI units, motor side), or None.";
}

/// "torque_constant [N m/A], resistance [ohm], ..." (every field, MotorSpec::fields() order).
inline std::string motor_fields_with_units() {
  std::string r;
  for (std::size_t k = 0; k < MotorSpec::kNumFields; ++k) {
    const MotorFieldDoc& d = motor_field_docs()[k];
    r += msg(k ? ", " : "", MotorSpec::fields()[k].first, " [", d.unit, "]");
  }
  return r;
}

/// armdyn.Motor(name=..., <the given fields>=...), Python's reprs of the values.
inline std::string motor_repr(const MotorSpec& s) {
  std::string r = "armdyn.Motor(";
  bool first = true;
  if (!s.name.empty()) {
    r += "name=" + py::repr(py::str(s.name)).cast<std::string>();
    first = false;
  }
  for (const auto& [n, p] : MotorSpec::fields()) {
    if (std::isnan(s.*p)) continue;
    r += msg(first ? "" : ", ", n, "=", py::repr(py::float_(s.*p)).cast<std::string>());
    first = false;
  }
  return r + ")";
}

/// A value of Motor.from_row's row: None, NaN (Python's or numpy's) or pandas' NA = not given;
/// else a real number (finite and > 0: MotorSpec::validate, naming the field).
inline double motor_row_value(const py::object& v, const std::string& who, const char* name) {
  if (v.is_none() || py::str(py::type::of(v).attr("__name__")).cast<std::string>() == "NAType")
    return MotorSpec::kUnset;
  const double x = float_arg(v, who.c_str(), name);
  return std::isnan(x) ? MotorSpec::kUnset : x;
}

/// The name of Motor.from_row's row: its "name" entry when given (a str), else the pandas
/// Series' name when a str, else ''.
inline std::string motor_row_name(const py::object& row, const py::object& get) {
  const py::object n = get("name", py::none());
  const bool missing =
      n.is_none() || (PyFloat_Check(n.ptr()) && std::isnan(PyFloat_AS_DOUBLE(n.ptr())));
  if (!missing) return str_arg(n, "Motor.from_row", "name");
  if (py::isinstance<py::dict>(row)) return "";
  const py::object series_name = py::getattr(row, "name", py::none());
  return PyUnicode_Check(series_name.ptr()) ? str_arg(series_name, "Motor.from_row", "name") : "";
}

/// Motor.from_row: the motor fields a mapping (dict, pandas Series) holds, other keys ignored.
inline MotorSpec motor_from_row(const RowArg& row) {
  if (PyUnicode_Check(row.ptr()) || PyBytes_Check(row.ptr()) || !py::hasattr(row, "get"))
    throw ModelError(
        msg("Motor.from_row: row must be a mapping (a dict, a pandas Series), got ", shown(row)));
  const py::object get = row.attr("get");
  MotorSpec s;
  s.name = motor_row_name(row, get);
  const std::string who = s.name.empty() ? "Motor.from_row" : msg("Motor.from_row '", s.name, "'");
  for (const auto& [n, p] : MotorSpec::fields()) s.*p = motor_row_value(get(n, py::none()), who, n);
  s.validate(who);
  return s;
}

/// == with any Python object (False unless a Motor).
inline bool motor_equals(const MotorSpec& a, const py::object& b) {
  return py::isinstance<MotorSpec>(b) && a == b.cast<const MotorSpec&>();
}

/// An optional motor argument: None, or an armdyn.Motor (else ModelError naming fn and joint).
inline std::optional<MotorSpec> opt_motor_arg(const OptMotor& motor, const char* fn,
                                              const std::string& joint) {
  if (motor.is_none()) return std::nullopt;
  if (!py::isinstance<MotorSpec>(motor))
    throw ModelError(msg(fn, " on joint '", joint, "': motor must be an armdyn.Motor or None, got ",
                         shown(motor)));
  return motor.cast<MotorSpec>();
}

// --- Actuator ---------------------------------------------------------------------------------

/// What Model.actuators lists: an Actuator with its joints named and its degree of freedom.
struct ActuatorView {
  std::string joint, rotor_joint;
  int dof = -1;
  double gear_ratio = 1.0, rotor_inertia = 0.0, efficiency = 1.0;
  double friction_viscous = 0.0, friction_coulomb = 0.0, friction_smoothing = 0.0;
  bool gyroscopic = false;
  OptMotor motor = py::reinterpret_borrow<OptMotor>(py::none());
};

inline std::vector<ActuatorView> actuator_views(const Model& md) {
  std::vector<ActuatorView> r;
  for (const Actuator& a : md.actuators) {
    ActuatorView v;
    v.joint = md.joints[a.joint].name;
    v.rotor_joint = md.joints[a.rotor_joint].name;
    v.dof = independent_dof(md, md.joints[a.joint].coord0);
    v.gear_ratio = a.gear_ratio;
    v.rotor_inertia = a.rotor_inertia;
    v.efficiency = a.efficiency;
    v.friction_viscous = a.friction_viscous;
    v.friction_coulomb = a.friction_coulomb;
    v.friction_smoothing = a.friction_smoothing;
    v.gyroscopic = a.gyroscopic;
    if (a.has_motor) v.motor = py::reinterpret_steal<OptMotor>(py::cast(a.motor).release());
    r.push_back(v);
  }
  return r;
}

inline std::string actuator_repr(const ActuatorView& a) {
  auto num = [](double x) { return py::repr(py::float_(x)).cast<std::string>(); };
  return msg("<armdyn.Actuator on '", a.joint, "': gear_ratio ", num(a.gear_ratio),
             ", rotor_inertia ", num(a.rotor_inertia), " kg m^2",
             a.gyroscopic ? ", gyroscopic" : "", ">");
}

// --- Model ------------------------------------------------------------------------------------

inline py::list coupling_dicts(const Model& md) {
  py::list r;
  for (const CouplingInfo& g : couplings(md))
    r.append(py::dict(py::arg("name") = g.name, py::arg("follower") = g.follower,
                      py::arg("leader") = g.leader, py::arg("multiplier") = g.multiplier,
                      py::arg("offset") = g.offset));
  return r;
}

/// (nb, 3, 3) the body inertia tensors.
inline py::array_t<double> body_inertias(const Model& md) {
  py::array_t<double> a({md.nb, 3, 3});
  for (int i = 0; i < md.nb; ++i)
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) a.mutable_at(i, r, c) = md.bodies[i].inertia(r, c);
  return a;
}

inline py::dict frame_dict(const Model& md, const StrArg& frame) {
  const int k = md.find_frame(str_arg(frame, "Model.frame", "frame"));
  const NamedFrame& f = md.frames[k];
  return py::dict(py::arg("index") = k, py::arg("body") = md.body_name(f.body),
                  py::arg("point") = to_numpy(VecX(f.point)),
                  py::arg("rotation") = to_numpy(MatX(f.rotation)));
}

inline py::dict joint_limits_dict(const Model& md, const StrArg& joint) {
  const Joint& j = md.joints[md.find_joint(str_arg(joint, "Model.joint_limits", "joint"))];
  return py::dict(py::arg("lower") = j.lower, py::arg("upper") = j.upper,
                  py::arg("effort") = j.effort, py::arg("velocity") = j.velocity_limit);
}

inline py::dict joint_frame_dict(const Model& md, const StrArg& joint) {
  const Joint& j = md.joints[md.find_joint(str_arg(joint, "Model.joint_frame", "joint"))];
  return py::dict(
      py::arg("type") = joint_type_name(j.type), py::arg("parent") = md.body_name(j.parent),
      py::arg("child") = md.body_name(j.child),
      py::arg("point_parent") = to_numpy(VecX(j.point_parent)),
      py::arg("point_child") = to_numpy(VecX(j.point_child)),
      py::arg("frame_parent") = to_numpy(MatX(j.frame_parent)),
      py::arg("frame_child") = to_numpy(MatX(j.frame_child)), py::arg("coord") = j.coord0);
}

inline py::dict kkt_plan_dict(const Model& md) {
  const KktPlan& p = kkt_plans(md).all;
  return py::dict(py::arg("path") = kkt_path_name(kkt_path(md)),
                  py::arg("description") = kkt_path_description(md),
                  py::arg("blocks") = p.order.size(), py::arg("factor_entries") = p.factor_entries,
                  py::arg("fill_blocks") = p.fill_blocks, py::arg("loop_rows") = p.loop_rows,
                  py::arg("flops") = p.flops);
}

inline std::string model_repr(const Model& md) {
  return msg("<armdyn.Model nb=", md.nb, " joints=", md.joints.size(), " drives=", md.drives.size(),
             " mobility=", md.mobility, ">");
}

// --- Profile ----------------------------------------------------------------------------------

/// Profile.eval: (y, yd, ydd) as floats for a number t, as float64 arrays of t's shape for an
/// array.
inline ProfileValues profile_eval(const Profile& p, const FloatOrArray& t) {
  const char* who = "Profile.eval: t";
  if (t.is_none() || py::isinstance<py::str>(t) || py::isinstance<py::bytes>(t))
    throw ModelError(msg(who, ": expected a number or an array of numbers, got ",
                         py::repr(t).cast<std::string>()));
  const py::array_t<double> ta = as_array(t, who);
  if (ta.ndim() == 0 && !py::isinstance<py::array>(t)) {  // a number: floats
    const ProfileValue v = p.eval(*ta.data());
    return py::reinterpret_steal<ProfileValues>(py::make_tuple(v.y, v.yd, v.ydd).release());
  }
  std::vector<py::ssize_t> shape(ta.shape(), ta.shape() + ta.ndim());
  py::array_t<double> y(shape), yd(shape), ydd(shape);
  p.eval(ta.data(), ta.size(), y.mutable_data(), yd.mutable_data(), ydd.mutable_data());
  return py::reinterpret_steal<ProfileValues>(py::make_tuple(y, yd, ydd).release());
}

// --- pickled states (bind_pickle.cpp) ---------------------------------------------------------

inline py::dict motor_state(const MotorSpec& s) {
  py::dict d;
  d["name"] = s.name;
  for (const auto& [n, p] : MotorSpec::fields()) d[n] = motor_get(s, p);
  return d;
}

inline MotorSpec motor_from_state(const py::dict& d) {
  MotorSpec s;
  s.name = d["name"].cast<std::string>();
  for (const auto& [n, p] : MotorSpec::fields())
    if (d.contains(n)) s.*p = motor_field(d[n], n);
  s.validate("Motor");
  return s;
}

/// (1, kind, (p0..p3), t, y, m, description); a user function cannot be stored (ModelError).
inline auto profile_state(const Profile& p) {
  const Profile::Raw r = p.raw();
  return py::make_tuple(1, static_cast<int>(r.kind), py::make_tuple(r.p[0], r.p[1], r.p[2], r.p[3]),
                        r.t, r.y, r.m, r.description);
}

inline Profile profile_from_state(const py::tuple& st) {
  const char* unknown = "Profile: unknown pickled state (another armdyn version?)";
  if (st.size() != 7 || !py::isinstance<py::int_>(st[0]) || st[0].cast<int>() != 1)
    throw ModelError(unknown);
  Profile::Raw r;
  try {
    const long long kind = st[1].cast<long long>();
    if (kind < 0 || kind >= static_cast<long long>(Profile::Kind::Callback))
      throw ModelError(msg("Profile: unknown pickled kind ", kind));
    r.kind = static_cast<Profile::Kind>(kind);
    const auto p = st[2].cast<py::tuple>();
    if (p.size() != 4) throw ModelError("Profile: pickled parameters are not 4 numbers");
    for (int i = 0; i < 4; ++i) r.p[i] = p[i].cast<double>();
    r.t = st[3].cast<std::vector<double>>();
    r.y = st[4].cast<std::vector<double>>();
    r.description = st[6].cast<std::string>();
  } catch (const py::cast_error&) {
    throw ModelError(unknown);
  }
  return Profile::restore(r);  // the factory's checks (pickled second derivatives unread)
}

/// Every field of the model, doubles bit for bit (armdyn/io/serialize.hpp).
inline auto model_state(const Model& md) { return py::make_tuple(py::bytes(serialize_model(md))); }

inline std::shared_ptr<Model> model_from_state(const py::tuple& st) {
  if (st.size() != 1 || !py::isinstance<py::bytes>(st[0]))
    throw ModelError("Model: unknown pickled state (not one bytes object)");
  return std::make_shared<Model>(deserialize_model(st[0].cast<std::string>()));
}

inline auto builder_state(const ModelBuilder& b) {
  return py::make_tuple(py::bytes(serialize_draft(b.draft())), b.physical_inertia());
}

inline ModelBuilder builder_from_state(const py::tuple& st) {
  if (st.size() != 2 || !py::isinstance<py::bytes>(st[0]) || !py::isinstance<py::bool_>(st[1]))
    throw ModelError("ModelBuilder: unknown pickled state (not bytes and a bool)");
  return ModelBuilder(deserialize_draft(st[0].cast<std::string>()), st[1].cast<bool>());
}

}  // namespace armdyn::py_helpers

namespace pybind11::detail {
template <>
struct handle_type_name<armdyn::py_helpers::RowArg> {
  static constexpr auto name =
      const_name("collections.abc.Mapping[str, typing.SupportsFloat | str | None]");
};
template <>
struct handle_type_name<armdyn::py_helpers::PayloadList> {
  static constexpr auto name = const_name(
      "collections.abc.Iterable[collections.abc.Mapping[str, numpy.typing.ArrayLike | None]]");
};
}  // namespace pybind11::detail
