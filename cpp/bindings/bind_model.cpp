// SPDX-License-Identifier: BSD-3-Clause
#include <pybind11/stl.h>

#include <limits>

#include "armdyn/builder/builder.hpp"
#include "armdyn/builder/summary.hpp"
#include "armdyn/io/serialize.hpp"
#include "armdyn/io/urdf.hpp"
#include "armdyn/kernels/block_sparse.hpp"
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

namespace armdyn {

namespace py = pybind11;
using namespace py_helpers;

namespace {

enum class CoordLimit { Lower, Upper, Effort, Velocity };

// one limit per joint coordinate; a joint's limits belong to its first coordinate
py::array_t<double> coord_limit(const Model& md, CoordLimit which) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  // over q (Lower, Upper: n_coords) or qd (Effort, Velocity: n_dofs); the floating bases' entries
  // lead and are unbounded
  const bool position = which == CoordLimit::Lower || which == CoordLimit::Upper;
  const long off = position ? 7 * md.n_free : 6 * md.n_free;
  VecX r = VecX::Constant(off + static_cast<long>(md.coords.size()),
                          which == CoordLimit::Lower ? -inf : inf);
  for (size_t k = 0; k < md.coords.size(); ++k) {
    const Coord& c = md.coords[k];
    const Joint& j = md.joints[c.joint];
    double v = which == CoordLimit::Lower ? -inf : inf;
    if (c.sub == 0) {
      switch (which) {
        case CoordLimit::Lower:
          v = j.lower <= -1e300 ? -inf : j.lower;
          break;
        case CoordLimit::Upper:
          v = j.upper >= 1e300 ? inf : j.upper;
          break;
        case CoordLimit::Effort:
          v = j.effort > 0 && j.effort < 1e300 ? j.effort : inf;
          break;
        case CoordLimit::Velocity:
          v = j.velocity_limit > 0 && j.velocity_limit < 1e300 ? j.velocity_limit : inf;
          break;
      }
    }
    r[off + static_cast<long>(k)] = v;
  }
  // a coupled model: the independent entries (n_coords, n_dofs)
  const IndependentCoords& ic = md.independent;
  if (!ic.identity()) {
    VecX ri(off + ic.n);
    ri.head(off) = r.head(off);
    for (int k = 0; k < ic.n; ++k) ri[off + k] = r[off + ic.full[k]];
    return to_numpy(ri);
  }
  return to_numpy(r);
}

// a joint's name, bodies, point and axis from Python, checked: a ModelError naming the argument
// (point or axis null: the method takes none)
struct JointArgs {
  std::string name, parent, child;
  Vec3 point = Vec3::Zero(), axis = Vec3::Zero();
  JointArgs(const py::handle& n, const py::handle& p, const py::handle& c, const py::handle* pt,
            const py::handle* ax, const char* fn)
      : name(str_arg(n, fn, "name")),
        parent(str_arg(p, fn, "parent")),
        child(str_arg(c, fn, "child")) {
    const std::string who = "joint '" + name + "'";
    if (pt) point = to_vec3(*pt, who + ": point");
    if (ax) axis = to_vec3(*ax, who + ": axis");
  }
};

// what Model.actuators lists: an Actuator with its joints named and its degree of freedom
struct ActuatorView {
  std::string joint, rotor_joint;
  int dof = -1;
  double gear_ratio = 1.0, rotor_inertia = 0.0, efficiency = 1.0;
  double friction_viscous = 0.0, friction_coulomb = 0.0, friction_smoothing = 0.0;
  bool gyroscopic = false;
  OptMotor motor = py::reinterpret_borrow<OptMotor>(py::none());
};

// the independent degree of freedom (into qd, model.dof_names) that moves coordinate c
int independent_dof(const Model& md, int c) {
  const IndependentCoords& ic = md.independent;
  return ic.lead_v + ic.source[c];
}

// a Motor field from Python: None (not given) or a finite number
double motor_field(const py::object& v, const char* name) {
  if (v.is_none()) return MotorSpec::kUnset;
  return opt_float_arg(v, "Motor", name, MotorSpec::kUnset, true);  // > 0: MotorSpec::validate
}

py::object motor_get(const MotorSpec& s, double MotorSpec::* p) {
  const double v = s.*p;
  return std::isnan(v) ? py::none() : py::object(py::float_(v));
}

// the docstring of a Motor field (MotorSpec::fields())
std::string motor_field_doc(const std::string& n) {
  static const std::pair<const char*, const char*> docs[] = {
      {"torque_constant", "Torque constant k_t [N m/A] (motor side), or None."},
      {"resistance", "Terminal resistance [ohm], or None."},
      {"voltage", "Supply voltage [V], or None."},
      {"no_load_speed", "No-load speed at the supply voltage [rad/s], or None."},
      {"continuous_torque", "Rated continuous torque [N m] (motor side), or None."},
      {"peak_torque", "Peak torque [N m] (motor side), or None."},
      {"max_speed", "Maximum permissible speed [rad/s], or None."},
      {"thermal_resistance", "Thermal resistance winding to ambient [K/W], or None."},
      {"thermal_time_constant", "Thermal time constant of the winding [s], or None."},
  };
  for (const auto& [k, d] : docs)
    if (n == k) return d;
  return "Datasheet value '" + n + "' (SI units, motor side), or None.";
}

std::string motor_repr(const MotorSpec& s) {
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

}  // namespace

void bind_model(py::module_& m) {
  {
    py::class_<MotorSpec> motor(
        m, "Motor",
        "A motor's datasheet values, motor side, SI units, every one optional (None when not "
        "given): torque_constant [N m/A], resistance [ohm, terminal], voltage [V, supply], "
        "no_load_speed [rad/s], continuous_torque [N m], peak_torque [N m], max_speed [rad/s], "
        "thermal_resistance [K/W, winding to ambient], thermal_time_constant [s], and a name. "
        "Given values must be finite and > 0 (ModelError naming the field). Attach one with "
        "ModelBuilder.add_actuator(..., motor=armdyn.Motor(...)); it does not enter the "
        "dynamics (the rotor inertia, gear ratio and friction do), the motor-side sizing reads "
        "it. Keyword-only constructor; comparable (==) and picklable.");
    motor.def(py::init([](const StrArg& name, OptFloat kt, OptFloat r, OptFloat u, OptFloat w0,
                          OptFloat tc, OptFloat tp, OptFloat wmax, OptFloat rth, OptFloat tau_th) {
                MotorSpec s;
                s.name = str_arg(name, "Motor", "name");
                const py::object given[] = {kt, r, u, w0, tc, tp, wmax, rth, tau_th};
                int k = 0;
                for (const auto& [n, p] : MotorSpec::fields()) s.*p = motor_field(given[k++], n);
                s.validate("Motor");
                return s;
              }),
              py::kw_only(), py::arg("name") = "", py::arg("torque_constant") = py::none(),
              py::arg("resistance") = py::none(), py::arg("voltage") = py::none(),
              py::arg("no_load_speed") = py::none(), py::arg("continuous_torque") = py::none(),
              py::arg("peak_torque") = py::none(), py::arg("max_speed") = py::none(),
              py::arg("thermal_resistance") = py::none(),
              py::arg("thermal_time_constant") = py::none(),
              "A motor's datasheet values (every one optional, None when not given; given ones "
              "finite and > 0, else ModelError naming the field): torque_constant [N m/A], "
              "resistance [ohm, terminal], voltage [V, supply], no_load_speed [rad/s], "
              "continuous_torque [N m], peak_torque [N m], max_speed [rad/s], thermal_resistance "
              "[K/W, winding to ambient], thermal_time_constant [s], all motor side.");
    motor.def_readonly("name", &MotorSpec::name, "The motor's name ('' when not given).");
    for (const auto& [n, p] : MotorSpec::fields()) {
      auto ptr = p;
      const std::string doc = motor_field_doc(n);
      motor.def_property_readonly(
          n,
          [ptr](const MotorSpec& s) {
            return py::reinterpret_steal<OptFloat>(motor_get(s, ptr).release());
          },
          doc.c_str());
    }
    motor.def("__repr__", &motor_repr);
    motor.def("__eq__", [](const MotorSpec& a, py::object b) {
      return py::isinstance<MotorSpec>(b) && a == b.cast<const MotorSpec&>();
    });
    motor.attr("__hash__") = py::none();
    motor.def(py::pickle(
        [](const MotorSpec& s) {
          py::dict d;
          d["name"] = s.name;
          for (const auto& [n, p] : MotorSpec::fields()) d[n] = motor_get(s, p);
          return d;
        },
        [](const py::dict& d) {
          MotorSpec s;
          s.name = d["name"].cast<std::string>();
          for (const auto& [n, p] : MotorSpec::fields())
            if (d.contains(n)) s.*p = motor_field(d[n], n);
          s.validate("Motor");
          return s;
        }));
  }
  py::class_<ActuatorView>(
      m, "Actuator",
      "A gearbox and motor rotor on a joint (ModelBuilder.add_actuator), as Model.actuators "
      "lists it: joint (the actuated joint's name), rotor_joint (the rotor's revolute joint and "
      "body, a coupling follower: '<joint>_armature' turning with the joint, qdot, with inertia "
      "N^2 J by default (gyroscopic=False), '<joint>_rotor' turning at gear_ratio * qdot with "
      "gyroscopic=True), dof (the "
      "index into the independent qd / model.dof_names the actuator moves), gear_ratio, "
      "rotor_inertia [kg m^2], efficiency, friction_viscous [N m s/rad, motor side], "
      "friction_coulomb [N m, motor side], friction_smoothing [rad/s, motor side], gyroscopic, "
      "motor (armdyn.Motor or None).")
      .def_readonly("joint", &ActuatorView::joint, "Name of the actuated joint.")
      .def_readonly("rotor_joint", &ActuatorView::rotor_joint,
                    "Name of the rotor's revolute joint and body: '<joint>_armature' "
                    "(gyroscopic=False, the default) or '<joint>_rotor' (gyroscopic=True).")
      .def_readonly(
          "dof", &ActuatorView::dof,
          "Index into the independent qd / model.dof_names of the dof the actuator moves.")
      .def_readonly("gear_ratio", &ActuatorView::gear_ratio,
                    "Gear ratio N = rotor speed / joint speed (negative: reversed rotor; rad/m for "
                    "a prismatic joint).")
      .def_readonly("rotor_inertia", &ActuatorView::rotor_inertia,
                    "Rotor inertia J about its axis [kg m^2].")
      .def_readonly("efficiency", &ActuatorView::efficiency,
                    "Gearbox efficiency in (0, 1] (motor-side maths only, not in the dynamics).")
      .def_readonly("friction_viscous", &ActuatorView::friction_viscous,
                    "Viscous friction [N m s/rad], motor side (reflected as N^2 b).")
      .def_readonly("friction_coulomb", &ActuatorView::friction_coulomb,
                    "Coulomb friction [N m], motor side (reflected as |N| c).")
      .def_readonly(
          "friction_smoothing", &ActuatorView::friction_smoothing,
          "Coulomb smoothing velocity [rad/s], motor side: tanh(omega / friction_smoothing).")
      .def_readonly("gyroscopic", &ActuatorView::gyroscopic,
                    "True: the rotor turns on the joint's parent body (full kinetic energy); "
                    "False: the gear-reduced (armature) model.")
      .def_readonly("motor", &ActuatorView::motor, "The attached armdyn.Motor, or None.")
      .def("__repr__", [](const ActuatorView& a) {
        auto num = [](double x) { return py::repr(py::float_(x)).cast<std::string>(); };
        return msg("<armdyn.Actuator on '", a.joint, "': gear_ratio ", num(a.gear_ratio),
                   ", rotor_inertia ", num(a.rotor_inertia), " kg m^2",
                   a.gyroscopic ? ", gyroscopic" : "", ">");
      });

  py::class_<Profile>(m, "Profile", "A time profile y(t) with derivatives, evaluated in C++.")
      .def(
          "eval",
          [](const Profile& p, const FloatOrArray& t) -> ProfileValues {
            const char* who = "Profile.eval: t";
            if (t.is_none() || py::isinstance<py::str>(t) || py::isinstance<py::bytes>(t))
              throw ModelError(msg(who, ": expected a number or an array of numbers, got ",
                                   py::repr(t).cast<std::string>()));
            const py::array_t<double> ta = as_array(t, who);
            if (ta.ndim() == 0 && !py::isinstance<py::array>(t)) {  // a number: floats
              const ProfileValue v = p.eval(*ta.data());
              return py::reinterpret_steal<ProfileValues>(
                  py::make_tuple(v.y, v.yd, v.ydd).release());
            }
            std::vector<py::ssize_t> shape(ta.shape(), ta.shape() + ta.ndim());
            py::array_t<double> y(shape), yd(shape), ydd(shape);
            const double* tp = ta.data();
            double *py_ = y.mutable_data(), *pyd = yd.mutable_data(), *pydd = ydd.mutable_data();
            for (py::ssize_t k = 0; k < ta.size(); ++k) {
              const ProfileValue v = p.eval(tp[k]);
              py_[k] = v.y;
              pyd[k] = v.yd;
              pydd[k] = v.ydd;
            }
            return py::reinterpret_steal<ProfileValues>(py::make_tuple(y, yd, ydd).release());
          },
          py::arg("t"),
          "The profile's value y, rate dy/dt and second derivative d2y/dt2 at time t [s]: a "
          "tuple of 3 floats for a number t; for an array t (any shape), a tuple of 3 float64 "
          "arrays of t's shape (one evaluation per element). Units follow the profile's use "
          "(rad, m, N m, N or a load scale, per s and s^2). ModelError if t is not numeric.")
      .def("__repr__", [](const Profile& p) { return "<armdyn.Profile " + p.describe() + ">"; })
      .def(py::pickle(
          [](const Profile& p) {
            // a user function cannot be stored: ModelError naming it
            const Profile::Raw r = p.raw();
            return py::make_tuple(1, static_cast<int>(r.kind),
                                  py::make_tuple(r.p[0], r.p[1], r.p[2], r.p[3]), r.t, r.y, r.m,
                                  r.description);
          },
          [](const py::tuple& st) {
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
          }));

  auto prof = m.def_submodule("profiles", "Built-in drive and load profiles (evaluated in C++).");
  prof.def(
      "constant",
      [](const FloatArg& value) {
        return Profile::constant(float_arg(value, "profiles.constant", "value"));
      },
      py::arg("value"), "The constant profile y(t) = value (zero derivatives).");
  prof.def(
      "cubic",
      [](const FloatArg& y0, const FloatArg& y1, const FloatArg& t0, const FloatArg& t1) {
        const char* fn = "profiles.cubic";
        return Profile::cubic(float_arg(y0, fn, "y0"), float_arg(y1, fn, "y1"),
                              float_arg(t0, fn, "t0"), float_arg(t1, fn, "t1"));
      },
      py::arg("y0"), py::arg("y1"), py::arg("t0"), py::arg("t1"),
      "Cubic rest-to-rest from y0 at t0 to y1 at t1 (3s^2 - 2s^3); constant outside.");
  prof.def(
      "quintic",
      [](const FloatArg& y0, const FloatArg& y1, const FloatArg& t0, const FloatArg& t1) {
        const char* fn = "profiles.quintic";
        return Profile::quintic(float_arg(y0, fn, "y0"), float_arg(y1, fn, "y1"),
                                float_arg(t0, fn, "t0"), float_arg(t1, fn, "t1"));
      },
      py::arg("y0"), py::arg("y1"), py::arg("t0"), py::arg("t1"),
      "Quintic rest-to-rest (zero velocity and acceleration at both ends).");
  prof.def(
      "sine",
      [](const FloatArg& amplitude, const FloatArg& frequency, const FloatArg& phase,
         const FloatArg& offset) {
        const char* fn = "profiles.sine";
        return Profile::sine(float_arg(amplitude, fn, "amplitude"),
                             float_arg(frequency, fn, "frequency"), float_arg(phase, fn, "phase"),
                             float_arg(offset, fn, "offset"));
      },
      py::arg("amplitude"), py::arg("frequency"), py::arg("phase") = 0.0, py::arg("offset") = 0.0,
      "offset + amplitude * sin(2 pi frequency t + phase); frequency in Hz.");
  prof.def(
      "spline",
      [](const ArrayLike& t, const ArrayLike& y) {
        const VecX tv = to_vec(t, "profiles.spline: t"), yv = to_vec(y, "profiles.spline: y");
        return Profile::spline(std::vector<double>(tv.data(), tv.data() + tv.size()),
                               std::vector<double>(yv.data(), yv.data() + yv.size()));
      },
      py::arg("t"), py::arg("y"),
      "Natural cubic spline through the samples (t[k], y[k]), t (n,) increasing [s], y (n,); "
      "linear extrapolation outside [t[0], t[-1]].");

  py::class_<Model, std::shared_ptr<Model>>(m, "Model",
                                            "Immutable multibody model (from ModelBuilder.finalize "
                                            "or load_urdf).")
      .def_readonly("nb", &Model::nb, "Number of bodies.")
      .def_readonly(
          "nq", &Model::nq,
          "Length of the Cartesian position state u: 7 per body (CoM [m], unit Euler parameters).")
      .def_readonly("nv", &Model::nv,
                    "Length of the Cartesian velocity state v: 6 per body (CoM velocity [m/s, "
                    "world], angular velocity [rad/s, body]).")
      .def_readonly(
          "nc", &Model::nc,
          "Number of constraint rows: the joints' and ideal gears' rows, then the drives'.")
      .def_readonly(
          "nc_joint", &Model::nc_joint,
          "Number of the joints' and ideal gears' constraint rows (the rows before the drives').")
      // the joint-space functions take the independent q and qd (a coupled model's followers
      // removed; all of them without couplings); simulation results report every joint's
      .def_property_readonly(
          "n_coords", [](const Model& md) { return md.independent.nq(); },
          "Length of the joint-space q: 7 per floating base (position, scalar-first quaternion), "
          "then one per independent joint coordinate (couplings' followers removed).")
      .def_property_readonly(
          "n_dofs", [](const Model& md) { return md.independent.nv(); },
          "Length of qd, qdd and tau: 6 per floating base (linear, angular velocity in the base "
          "frame), then one per independent joint coordinate (= n_coords without a floating "
          "base).")
      .def_readonly("n_free", &Model::n_free, "Free joints (floating bases) of the joint space.")
      .def_readonly("n_joint_coords", &Model::nq_joint,
                    "Columns of SimulationResult.q: n_coords with the couplings' followers.")
      .def_readonly("n_joint_dofs", &Model::nv_joint,
                    "Columns of SimulationResult.qd, qdd: n_dofs with the couplings' followers.")
      .def_readonly("joint_coord_names", &Model::q_names,
                    "Names of the columns of SimulationResult.q (every joint's coordinate).")
      .def_readonly("joint_dof_names", &Model::dof_names,
                    "Names of the columns of SimulationResult.qd and qdd.")
      .def_property_readonly(
          "independent_coords",
          [](const Model& md) {
            const IndependentCoords& ic = md.independent;
            std::vector<int> r;
            for (int i = 0; i < ic.lead_q; ++i) r.push_back(i);
            for (int c : ic.full) r.push_back(ic.lead_q + c);
            return r;
          },
          "Index of each entry of q in joint_coord_names.")
      .def_property_readonly(
          "couplings",
          [](const Model& md) {
            py::list r;
            for (const auto& g : md.gear_constraints) {
              if (!g.coupling) continue;
              py::dict c;
              c["name"] = g.name;
              c["follower"] = md.joints[md.coords[g.coord_a].joint].name;
              c["leader"] = md.joints[md.coords[g.coord_b].joint].name;
              c["multiplier"] = g.multiplier();
              c["offset"] = g.offset;
              r.append(c);
            }
            return r;
          },
          "The couplings (add_coupling, URDF <mimic>): a list of dicts with 'name', 'follower' and "
          "'leader' (joint names), 'multiplier' and 'offset' [rad or m] of q_follower = multiplier "
          "* q_leader + offset.")
      .def_property_readonly(
          "actuators",
          [](const Model& md) {
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
              if (a.has_motor)
                v.motor = py::reinterpret_steal<OptMotor>(py::cast(a.motor).release());
              r.push_back(v);
            }
            return r;
          },
          "The actuators (ModelBuilder.add_actuator), as armdyn.Actuator objects.")
      .def_property_readonly(
          "reflected_inertia",
          [](const Model& md) {
            // G^T diag(J) G over the rotors: (N s)^2 J at the independent dof of each rotor,
            // s the actuated joint's own coupling scale (1 unless it follows another joint)
            const IndependentCoords& ic = md.independent;
            VecX r = VecX::Zero(ic.nv());
            for (const Actuator& a : md.actuators) {
              const int c = md.joints[a.rotor_joint].coord0;
              // the armature (gear-reduced) turns with the joint carrying N^2 J; the
              // gyroscopic rotor turns at N qdot carrying J
              const double j_el =
                  a.gyroscopic ? a.rotor_inertia : a.gear_ratio * a.gear_ratio * a.rotor_inertia;
              r[independent_dof(md, c)] += ic.scale[c] * ic.scale[c] * j_el;
            }
            return to_numpy(r);
          },
          "(n_dofs,) the rotors' inertia reflected through their gears, N^2 J at each "
          "actuated dof and 0 elsewhere [kg m^2, or kg for a prismatic joint]: the armature of "
          "Pinocchio's model (the gear-reduced rotor model adds exactly this to the mass "
          "matrix's diagonal).")
      .def_property_readonly(
          "n_drives", [](const Model& md) { return md.drives.size(); },
          "Number of drives (prescribed joint coordinates, add_drive).")
      .def_property_readonly(
          "body_names",
          [](const Model& md) {
            std::vector<std::string> r;
            for (const auto& b : md.bodies) r.push_back(b.name);
            return r;
          },
          "Names of the bodies, in the order they were added (index = body index; the URDF's links "
          "with mass or a child joint).")
      .def_property_readonly(
          "joint_names",
          [](const Model& md) {
            std::vector<std::string> r;
            for (const auto& j : md.joints) r.push_back(j.name);
            return r;
          },
          "Names of the joints, in the order they were added (index = joint index).")
      .def_property_readonly(
          "joint_types",
          [](const Model& md) {
            std::vector<std::string> r;
            for (const auto& j : md.joints) r.push_back(joint_type_name(j.type));
            return r;
          },
          "Type of each joint of joint_names: 'revolute', 'prismatic', 'spherical', 'fixed', "
          "'free', ...")
      .def_property_readonly(
          "coord_names",
          [](const Model& md) {
            const IndependentCoords& ic = md.independent;
            std::vector<std::string> r(md.q_names.begin(), md.q_names.begin() + ic.lead_q);
            for (int c : ic.full) r.push_back(md.q_names[ic.lead_q + c]);
            return r;
          },
          "Names of the entries of q (n_coords): a floating base's 'name:x' .. 'name:e3', then "
          "the independent joint coordinates.")
      .def_property_readonly(
          "dof_names",
          [](const Model& md) {
            const IndependentCoords& ic = md.independent;
            std::vector<std::string> r(md.dof_names.begin(), md.dof_names.begin() + ic.lead_v);
            for (int c : ic.full) r.push_back(md.dof_names[ic.lead_v + c]);
            return r;
          },
          "Names of the entries of qd, qdd and tau (n_dofs): a floating base's 'name:vx' .. "
          "'name:wz', then the independent joint coordinates.")
      .def_property_readonly(
          "frame_names",
          [](const Model& md) {
            std::vector<std::string> r;
            for (const auto& f : md.frames) r.push_back(f.name);
            return r;
          },
          "Names of the named frames (add_frame, URDF links), in the order they were added.")
      .def(
          "frame",
          [](const Model& md, const StrArg& frame) {
            const int k = md.find_frame(str_arg(frame, "Model.frame", "frame"));
            const NamedFrame& f = md.frames[k];
            return py::dict(py::arg("index") = k, py::arg("body") = md.body_name(f.body),
                            py::arg("point") = to_numpy(VecX(f.point)),
                            py::arg("rotation") = to_numpy(MatX(f.rotation)));
          },
          py::arg("frame"),
          "A named frame's placement on its body: 'index' (into frame_names), 'body' (or "
          "'ground'), 'point' (its origin in the body's frame, relative to the centre of mass; "
          "the world for 'ground') and 'rotation' (its axes as columns in the body's axes).")
      .def_property_readonly(
          "drive_names",
          [](const Model& md) {
            std::vector<std::string> r;
            for (const auto& d : md.drives) r.push_back(d.name);
            return r;
          },
          "Names of the drives, in the order they were added (columns of "
          "SimulationResult.drive_forces).")
      .def_property_readonly(
          "drive_coords",
          [](const Model& md) {
            std::vector<int> r;
            for (const auto& d : md.drives) r.push_back(md.joints[d.joint].dof0 + d.coord);
            return r;
          },
          "Index into the joint dofs (model.joint_dof_names) of each drive's coordinate.")
      .def_property_readonly(
          "gravity", [](const Model& md) { return to_numpy(VecX(md.gravity)); },
          "(3,) gravity vector in world axes [m/s^2].")
      .def_property_readonly(
          "masses",
          [](const Model& md) {
            VecX r(md.nb);
            for (int i = 0; i < md.nb; ++i) r[i] = md.bodies[i].mass;
            return to_numpy(r);
          },
          "(nb,) body masses [kg], in body_names order.")
      .def_property_readonly(
          "inertias",
          [](const Model& md) {
            py::array_t<double> a({md.nb, 3, 3});
            for (int i = 0; i < md.nb; ++i)
              for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c) a.mutable_at(i, r, c) = md.bodies[i].inertia(r, c);
            return a;
          },
          "(nb, 3, 3) body inertia tensors about the centre of mass in body axes [kg m^2].")
      .def_readonly("is_tree", &Model::is_tree,
                    "True when every body has exactly one joint path to ground (no closed loops).")
      .def_readonly("joint_space", &Model::joint_space_ok,
                    "True when the joint-space functions (forward_dynamics, inverse_dynamics, "
                    "mass_matrix, state_from_joints) take the model: a tree of revolute, "
                    "prismatic, cylindrical and fixed joints (a free joint from ground as a "
                    "floating base) defined parent to child.")
      // why simulate(coordinates="joint") does not take the model; empty when it does
      .def_property_readonly(
          "joint_path_reason", [](const Model& md) { return md.joint_path_reason(); },
          "Why simulate(coordinates='joint') does not take the model; '' when it does.")
      .def_readonly("mobility", &Model::mobility,
                    "Degrees of freedom of the mechanism without its drives.")
      .def_readonly("mobility_driven", &Model::mobility_driven,
                    "Degrees of freedom left with the drives (0: fully prescribed motion).")
      .def_readonly(
          "redundant_rows", &Model::redundant_rows,
          "Names of the redundant constraint rows finalize() found (empty when the rows are "
          "independent).")
      .def_property_readonly(
          "u0", [](const Model& md) { return to_numpy(md.u0); },
          "(nq,) the assembled Cartesian positions u: per body CoM [m] and unit Euler parameters.")
      .def_property_readonly(
          "v0", [](const Model& md) { return to_numpy(md.v0); },
          "(nv,) the initial Cartesian velocities v (zero unless set): per body CoM velocity [m/s] "
          "and angular velocity [rad/s].")
      // URDF <limit> per joint coordinate: +-inf where none (the joints store +-1e300), effort
      // and velocity limits inf where none or 0 (unset)
      .def_property_readonly(
          "coord_lower", [](const Model& md) { return coord_limit(md, CoordLimit::Lower); },
          "Lower position limit of each entry of q (n_coords; URDF <limit lower>; -inf where none "
          "and on a floating base; a coupled model's independent entries).")
      .def_property_readonly(
          "coord_upper", [](const Model& md) { return coord_limit(md, CoordLimit::Upper); },
          "Upper position limit of each entry of q (n_coords; URDF <limit upper>; inf where none "
          "and on a floating base).")
      .def_property_readonly(
          "coord_effort_limit", [](const Model& md) { return coord_limit(md, CoordLimit::Effort); },
          "Effort limit of each entry of tau (n_dofs) [N m or N] (URDF <limit effort>; inf where "
          "none or 0, and on a floating base).")
      .def_property_readonly(
          "coord_velocity_limit",
          [](const Model& md) { return coord_limit(md, CoordLimit::Velocity); },
          "Velocity limit of each entry of qd (n_dofs) [rad/s or m/s] (URDF <limit velocity>; inf "
          "where none or 0, and on a floating base).")
      .def(
          "joint_limits",
          [](const Model& md, const StrArg& joint) {
            const Joint& j =
                md.joints[md.find_joint(str_arg(joint, "Model.joint_limits", "joint"))];
            return py::dict(py::arg("lower") = j.lower, py::arg("upper") = j.upper,
                            py::arg("effort") = j.effort, py::arg("velocity") = j.velocity_limit);
          },
          py::arg("joint"),
          "A joint's limits as a dict: 'lower' and 'upper' position limits [rad or m] (+-1e300 "
          "where none), 'effort' [N m or N] and 'velocity' [rad/s or m/s] (0 where none).")
      .def(
          "joint_frame",
          [](const Model& md, const StrArg& joint) {
            const Joint& j = md.joints[md.find_joint(str_arg(joint, "Model.joint_frame", "joint"))];
            auto body = [&](int b) {
              return b == kGround ? std::string("ground") : md.bodies[b].name;
            };
            return py::dict(py::arg("type") = joint_type_name(j.type),
                            py::arg("parent") = body(j.parent), py::arg("child") = body(j.child),
                            py::arg("point_parent") = to_numpy(VecX(j.point_parent)),
                            py::arg("point_child") = to_numpy(VecX(j.point_child)),
                            py::arg("frame_parent") = to_numpy(MatX(j.frame_parent)),
                            py::arg("frame_child") = to_numpy(MatX(j.frame_child)),
                            py::arg("coord") = j.coord0);
          },
          py::arg("joint"),
          "The joint's bodies and frames: 'point_parent'/'point_child' (the joint point in each "
          "body's frame, relative to its centre of mass; the world for 'ground'), "
          "'frame_parent'/'frame_child' (the joint frame's axes as columns in each body's "
          "frame; z is the joint axis) and 'coord' (its first joint coordinate, -1 if none).")
      .def(
          "summary", [](const Model& m) { return summary(m); },
          "Readable description: sizes, topology, solver path.")
      .def_property_readonly(
          "kkt_path", [](const Model& m) { return kkt_path_name(kkt_path(m)); },
          "KKT solver path chosen at finalize(): 'tree', 'tree+loops', 'sparse', or 'dense' "
          "(redundant rows).")
      .def(
          "with_kkt_path",
          [](const Model& m, const StrArg& path_arg) {
            const std::string path = str_arg(path_arg, "with_kkt_path", "path");
            if (path != "dense" && path != "auto")
              throw ModelError("with_kkt_path: path must be 'dense' or 'auto', got '" + path + "'");
            // a copy derives its plans and welded form afresh (the welded model inherits the
            // forced path: simulate() integrates it)
            auto c = std::make_shared<Model>(m);
            c->force_dense_kkt = path == "dense";
            return std::const_pointer_cast<const Model>(c);
          },
          py::arg("path"),
          "A copy of the model on another KKT path: 'dense' (the reference: one dense Cholesky "
          "of the Schur complement) or 'auto' (the plan finalize() picks).")
      .def_property_readonly(
          "kkt_plan",
          [](const Model& m) {
            py::dict d;
            const KktPlan& p = kkt_plans(m).all;
            d["path"] = kkt_path_name(kkt_path(m));
            d["description"] = kkt_path_description(m);
            d["blocks"] = p.order.size();
            d["factor_entries"] = p.factor_entries;
            d["fill_blocks"] = p.fill_blocks;
            d["loop_rows"] = p.loop_rows;
            d["flops"] = p.flops;
            return d;
          },
          "The KKT plan's statistics (path, row blocks, factor entries, fill, flops).")
      .def("__repr__",
           [](const Model& md) {
             return msg("<armdyn.Model nb=", md.nb, " joints=", md.joints.size(),
                        " drives=", md.drives.size(), " mobility=", md.mobility, ">");
           })
      // Pickling (and copy.copy / copy.deepcopy through it): every field of the model, doubles
      // bit for bit (armdyn/io/serialize.hpp); a Python-callable profile cannot travel
      // (ModelError naming it).
      .def(
          py::pickle([](const Model& md) { return py::make_tuple(py::bytes(serialize_model(md))); },
                     [](const py::tuple& st) {
                       if (st.size() != 1 || !py::isinstance<py::bytes>(st[0]))
                         throw ModelError("Model: unknown pickled state (not one bytes object)");
                       return std::make_shared<Model>(deserialize_model(st[0].cast<std::string>()));
                     }));

  auto cast_model = [](ModelPtr p) { return std::const_pointer_cast<Model>(p); };

  py::class_<ModelBuilder>(
      m, "ModelBuilder", "Build a model: bodies, joints, drives, force elements; then finalize().")
      .def(py::init([](const ArrayLike& g, const BoolArg& physical_inertia) {
             const bool pi = bool_arg(physical_inertia, "ModelBuilder", "physical_inertia");
             return ModelBuilder(to_vec3(g, "gravity"), pi);
           }),
           py::arg("gravity") = py::make_tuple(0.0, 0.0, -9.81), py::kw_only(),
           py::arg("physical_inertia") = true,
           "An empty builder. gravity: (3,) in world axes [m/s^2]; physical_inertia: see the "
           "property of that name. ModelError if gravity is not 3 finite numbers.")
      .def(py::pickle(
          [](const ModelBuilder& b) {
            return py::make_tuple(py::bytes(serialize_draft(b.draft())), b.physical_inertia());
          },
          [](const py::tuple& st) {
            if (st.size() != 2 || !py::isinstance<py::bytes>(st[0]) ||
                !py::isinstance<py::bool_>(st[1]))
              throw ModelError("ModelBuilder: unknown pickled state (not bytes and a bool)");
            return ModelBuilder(deserialize_draft(st[0].cast<std::string>()), st[1].cast<bool>());
          }))
      .def_property(
          "physical_inertia", &ModelBuilder::physical_inertia,
          [](ModelBuilder& b, const BoolArg& v) {
            b.set_physical_inertia(bool_arg(v, "ModelBuilder", "physical_inertia"));
          },
          "True (default): add_body accepts physically consistent inertias only "
          "(positive semidefinite, triangle inequality). False: any positive "
          "semidefinite tensor; negative round-off moments down to -1e-12 of the "
          "largest are clamped to zero with a warning. Applies to bodies added after "
          "it is set.")
      .def(
          "add_body",
          [](ModelBuilder& b, const StrArg& name_, const FloatArg& mass, const ArrayLike& inertia,
             const ArrayLike& position, const ArrayLike& orientation) {
            const char* fn = "ModelBuilder.add_body";
            const std::string name = str_arg(name_, fn, "name");
            const double m = float_arg(mass, fn, "mass");
            const std::string who = "body '" + name + "'";
            return b.add_body(name, m, to_inertia(inertia, who + ": inertia"),
                              to_vec3(position, who + ": position"),
                              to_vec4(orientation, who + ": orientation"));
          },
          py::arg("name"), py::arg("mass"), py::arg("inertia"),
          py::arg("position") = py::make_tuple(0.0, 0.0, 0.0),
          py::arg("orientation") = py::make_tuple(1.0, 0.0, 0.0, 0.0),
          "Add a body: mass [kg], inertia (3,3) about the CoM in body axes [kg m^2] (or its (3,) "
          "diagonal), CoM position [m], orientation as unit Euler parameters [e0, e1, e2, e3].")
      .def(
          "add_revolute",
          [](ModelBuilder& b, const StrArg& n, const StrArg& p, const StrArg& c,
             const ArrayLike& point, const ArrayLike& axis) {
            const JointArgs a(n, p, c, &point, &axis, "ModelBuilder.add_revolute");
            return b.add_revolute(a.name, a.parent, a.child, a.point, a.axis);
          },
          py::arg("name"), py::arg("parent"), py::arg("child"), py::arg("point"), py::arg("axis"),
          "Add a revolute (hinge) joint `name` between bodies `parent` and `child` (either may be "
          "'ground'): rotation about `axis` (3,) (world axes, need not be unit) through `point` "
          "(3,) [m], both in world at the assembly pose. One coordinate q [rad], positive by the "
          "right-hand rule about axis; q = 0 at assembly. Returns the joint index. ModelError "
          "(builder unchanged) on a duplicate name, an unknown body, a zero or non-finite axis or "
          "point.")
      .def(
          "add_prismatic",
          [](ModelBuilder& b, const StrArg& n, const StrArg& p, const StrArg& c,
             const ArrayLike& point, const ArrayLike& axis) {
            const JointArgs a(n, p, c, &point, &axis, "ModelBuilder.add_prismatic");
            return b.add_prismatic(a.name, a.parent, a.child, a.point, a.axis);
          },
          py::arg("name"), py::arg("parent"), py::arg("child"), py::arg("point"), py::arg("axis"),
          "Add a prismatic (slider) joint `name` between `parent` and `child` (either may be "
          "'ground'): translation along `axis` (3,) (world axes) through `point` (3,) [m], world "
          "at assembly. One coordinate q [m] along the unit axis; q = 0 at assembly. Returns the "
          "joint index; ModelError on a duplicate name, an unknown body, a zero or non-finite axis "
          "or point.")
      .def(
          "add_cylindrical",
          [](ModelBuilder& b, const StrArg& n, const StrArg& p, const StrArg& c,
             const ArrayLike& point, const ArrayLike& axis) {
            const JointArgs a(n, p, c, &point, &axis, "ModelBuilder.add_cylindrical");
            return b.add_cylindrical(a.name, a.parent, a.child, a.point, a.axis);
          },
          py::arg("name"), py::arg("parent"), py::arg("child"), py::arg("point"), py::arg("axis"),
          "Add a cylindrical joint `name` between `parent` and `child`: rotation about and "
          "translation along `axis` (3,) through `point` (3,) [m] (world at assembly). Two "
          "coordinates: the angle [rad], then the slide [m]. Returns the joint index; ModelError "
          "on bad input.")
      .def(
          "add_inline",
          [](ModelBuilder& b, const StrArg& n, const StrArg& p, const StrArg& c,
             const ArrayLike& point, const ArrayLike& axis) {
            const JointArgs a(n, p, c, &point, &axis, "ModelBuilder.add_inline");
            return b.add_inline(a.name, a.parent, a.child, a.point, a.axis);
          },
          py::arg("name"), py::arg("parent"), py::arg("child"), py::arg("point"), py::arg("axis"),
          "Inline (point-on-line) joint, 2 rows: the child's point stays on the parent's line "
          "through `point` along `axis`. Closes a planar loop without redundant rows.")
      .def(
          "add_distance",
          [](ModelBuilder& b, const StrArg& n_, const StrArg& ba_, const ArrayLike& pa,
             const StrArg& bb_, const ArrayLike& pb) {
            const char* fn = "ModelBuilder.add_distance";
            const std::string n = str_arg(n_, fn, "name"), ba = str_arg(ba_, fn, "body_a"),
                              bb = str_arg(bb_, fn, "body_b");
            const std::string who = "joint '" + n + "'";
            return b.add_distance(n, ba, to_vec3(pa, who + ": point_a"), bb,
                                  to_vec3(pb, who + ": point_b"));
          },
          py::arg("name"), py::arg("body_a"), py::arg("point_a"), py::arg("body_b"),
          py::arg("point_b"),
          "Distance joint, 1 row: a massless rod with ball ends between point_a of body_a and "
          "point_b of body_b (world coordinates at assembly); it holds their assembly distance.")
      .def(
          "add_spherical",
          [](ModelBuilder& b, const StrArg& n, const StrArg& p, const StrArg& c,
             const ArrayLike& point) {
            const JointArgs a(n, p, c, &point, nullptr, "ModelBuilder.add_spherical");
            return b.add_spherical(a.name, a.parent, a.child, a.point);
          },
          py::arg("name"), py::arg("parent"), py::arg("child"), py::arg("point"),
          "Add a spherical (ball) joint `name` between `parent` and `child` at `point` (3,) [m], "
          "world at assembly: 3 constraint rows, 3 rotational dofs (joint space: a quaternion). "
          "Returns the joint index; ModelError on a duplicate name, an unknown body, a "
          "non-finite point.")
      .def(
          "add_fixed",
          [](ModelBuilder& b, const StrArg& n, const StrArg& p, const StrArg& c,
             const OptArrayLike& point) {
            const JointArgs a(n, p, c, nullptr, nullptr, "ModelBuilder.add_fixed");
            Vec3 pt;
            if (point.is_none()) {
              const int ci = a.child == "ground" ? -1 : b.draft().find_body(a.child);
              pt = ci < 0 ? Vec3::Zero() : b.draft().bodies[ci].position;
            } else {
              pt = to_vec3(point, "joint '" + a.name + "': point");
            }
            return b.add_fixed(a.name, a.parent, a.child, pt);
          },
          py::arg("name"), py::arg("parent"), py::arg("child"), py::arg("point") = py::none(),
          "Weld `child` rigidly to `parent` (either may be 'ground'): 6 rows, no dof. `point` "
          "(3,) [m], world at assembly, only sets where the reaction is reported (default: the "
          "child's CoM, the world origin for 'ground'). Returns the joint index; ModelError on "
          "a duplicate name or an unknown body.")
      .def(
          "add_universal",
          [](ModelBuilder& b, const StrArg& n, const StrArg& p, const StrArg& c,
             const ArrayLike& point, const ArrayLike& a1, const ArrayLike& a2) {
            const JointArgs a(n, p, c, &point, nullptr, "ModelBuilder.add_universal");
            return b.add_universal(a.name, a.parent, a.child, a.point,
                                   to_vec3(a1, "joint '" + a.name + "': axis1"),
                                   to_vec3(a2, "joint '" + a.name + "': axis2"));
          },
          py::arg("name"), py::arg("parent"), py::arg("child"), py::arg("point"), py::arg("axis1"),
          py::arg("axis2"),
          "Add a universal (Cardan) joint at `point` (3,) [m]: `axis1` (3,) fixed in the parent, "
          "`axis2` (3,) fixed in the child, perpendicular, world at assembly. Two coordinates "
          "[rad] (about axis1, then axis2). Returns the joint index; ModelError on bad input "
          "(axes not perpendicular, zero, or not finite).")
      .def(
          "add_free",
          [](ModelBuilder& b, const StrArg& n_, const StrArg& c_, const OptArrayLike& origin) {
            const char* fn = "ModelBuilder.add_free";
            const std::string n = str_arg(n_, fn, "name"), c = str_arg(c_, fn, "child");
            if (origin.is_none()) return b.add_free(n, c);
            const Vec3 o = to_vec3(origin, "free joint '" + n + "': origin");
            return b.add_free(n, c, &o);
          },
          py::arg("name"), py::arg("child"), py::arg("origin") = py::none(),
          "Declare body `child` free (a floating base). In joint space its frame -- the body's "
          "axes at `origin` (world at assembly, m; default its centre of mass) -- takes 7 entries "
          "of q (x, y, z, then the scalar-first unit quaternion e0..e3) and 6 of qd (linear, "
          "then angular velocity, both in the frame's own axes).")
      .def(
          "add_frame",
          [](ModelBuilder& b, const StrArg& name_, const StrArg& body_, const ArrayLike& position,
             const ArrayLike& orientation) {
            const char* fn = "ModelBuilder.add_frame";
            const std::string name = str_arg(name_, fn, "name"), body = str_arg(body_, fn, "body");
            const std::string who = "frame '" + name + "'";
            return b.add_frame(name, body, to_vec3(position, who + ": position"),
                               to_vec4(orientation, who + ": orientation"));
          },
          py::arg("name"), py::arg("body"), py::arg("position") = py::make_tuple(0.0, 0.0, 0.0),
          py::arg("orientation") = py::make_tuple(1.0, 0.0, 0.0, 0.0),
          "Add a named frame rigidly attached to `body` (or 'ground'): its origin [m] and axes "
          "(unit Euler parameters [e0, e1, e2, e3], frame -> world), both in world at the "
          "assembly pose like every builder input. Read it back with armdyn.frame_pose and "
          "armdyn.frame_jacobian.")
      .def(
          "set_joint_limits",
          [](ModelBuilder& b, const StrArg& joint, const FloatArg& lower, const FloatArg& upper,
             const FloatArg& effort, const FloatArg& velocity) {
            const char* fn = "ModelBuilder.set_joint_limits";
            // infinities: no limit; NaN refused naming the argument
            auto limit = [fn](const py::handle& v, const char* name) {
              const double x = float_arg(v, fn, name);
              if (std::isnan(x))
                throw ModelError(msg(fn, ": ", name,
                                     " must be a real number (inf: no limit), "
                                     "got nan"));
              return x;
            };
            b.set_joint_limits(str_arg(joint, fn, "joint"), limit(lower, "lower"),
                               limit(upper, "upper"), limit(effort, "effort"),
                               limit(velocity, "velocity"));
          },
          py::arg("joint"), py::arg("lower"), py::arg("upper"), py::arg("effort") = 0.0,
          py::arg("velocity") = 0.0,
          "Set a joint's limits (of its first coordinate): position lower <= q <= upper [rad or "
          "m] (stops enforced by simulate(limits=True)), effort [N m or N] and velocity [rad/s "
          "or m/s] (informative, 0 = none; read by the sizing). ModelError on an unknown "
          "joint, lower > upper, NaN, or negative effort/velocity.")
      .def(
          "add_drive",
          [](ModelBuilder& b, const StrArg& joint_, const ProfileLike& profile, const IntArg& coord,
             const OptStr& name) {
            const char* fn = "ModelBuilder.add_drive";
            const std::string joint = str_arg(joint_, fn, "joint");
            const int k = int_arg(coord, fn, "coord");
            const std::string nm = opt_str_arg(name, fn, "name");
            return b.add_drive(joint, to_profile(profile, "add_drive '" + joint + "': profile"), k,
                               nm);
          },
          py::arg("joint"), py::arg("profile"), py::arg("coord") = 0, py::arg("name") = py::none(),
          "Prescribe coordinate `coord` of `joint` by a profile [rad or m over t in s] "
          "(armdyn.profiles.*, a number, or a Python callable t -> (y, yd, ydd): accepted but "
          "slow, it runs Python at every evaluation): a rheonomic constraint whose multiplier is "
          "the drive's effort (SimulationResult.drive_forces). `name` defaults to the joint's. "
          "Returns the drive index; ModelError on an unknown joint or coordinate, or a bad "
          "profile.")
      .def(
          "add_body_force",
          [](ModelBuilder& b, const StrArg& body_, const ArrayLike& force, const ArrayLike& torque,
             const OptArrayLike& point, const OptProfileLike& profile) {
            const std::string body = str_arg(body_, "ModelBuilder.add_body_force", "body");
            const std::string who = "load on body '" + body + "'";
            Vec3 pt;
            Profile pr;
            if (!point.is_none()) pt = to_vec3(point, who + ": point");
            if (!profile.is_none()) pr = to_profile(profile, who + ": profile");
            b.add_body_load(body, to_vec3(force, who + ": force"),
                            to_vec3(torque, who + ": torque"), point.is_none() ? nullptr : &pt,
                            profile.is_none() ? nullptr : &pr);
          },
          py::arg("body"), py::arg("force") = py::make_tuple(0.0, 0.0, 0.0),
          py::arg("torque") = py::make_tuple(0.0, 0.0, 0.0), py::arg("point") = py::none(),
          py::arg("profile") = py::none(),
          "Force [N] at a point (world coordinates at assembly; default the CoM) and torque "
          "[N m], both in world axes, optionally scaled by a profile.")
      .def(
          "add_spring_damper",
          [](ModelBuilder& b, const StrArg& n_, const StrArg& ba_, const ArrayLike& pa,
             const StrArg& bb_, const ArrayLike& pb, const FloatArg& k, const FloatArg& c,
             const OptFloat& rest) {
            const char* fn = "ModelBuilder.add_spring_damper";
            const std::string n = str_arg(n_, fn, "name"), ba = str_arg(ba_, fn, "body_a"),
                              bb = str_arg(bb_, fn, "body_b");
            const double kv = float_arg(k, fn, "stiffness"), cv = float_arg(c, fn, "damping");
            const double rv = opt_float_arg(rest, fn, "rest_length", -1.0);
            if (!rest.is_none() && rv < 0.0)
              throw ModelError(msg(fn, ": rest_length must be >= 0 or None, got ", rv));
            const std::string who = "spring-damper '" + n + "'";
            b.add_spring_damper(n, ba, to_vec3(pa, who + ": point_a"), bb,
                                to_vec3(pb, who + ": point_b"), kv, cv, rv);
          },
          py::arg("name"), py::arg("body_a"), py::arg("point_a"), py::arg("body_b"),
          py::arg("point_b"), py::arg("stiffness"), py::arg("damping") = 0.0,
          py::arg("rest_length") = py::none(),
          "Point-to-point spring-damper `name` between point_a (3,) of body_a and point_b (3,) of "
          "body_b (world coordinates at assembly [m]; a body may be 'ground'): force "
          "stiffness [N/m] * (length - rest_length) + damping [N s/m] * length rate along the "
          "line; rest_length [m] defaults to the assembly distance. ModelError on an unknown "
          "body, coincident points, non-finite input, negative stiffness or damping.")
      .def(
          "add_joint_spring_damper",
          [](ModelBuilder& b, const StrArg& joint, const FloatArg& k, const FloatArg& c,
             const FloatArg& rest, const IntArg& coord) {
            const char* fn = "ModelBuilder.add_joint_spring_damper";
            b.add_joint_spring_damper(str_arg(joint, fn, "joint"), float_arg(k, fn, "stiffness"),
                                      float_arg(c, fn, "damping"), float_arg(rest, fn, "rest"),
                                      int_arg(coord, fn, "coord"));
          },
          py::arg("joint"), py::arg("stiffness") = 0.0, py::arg("damping") = 0.0,
          py::arg("rest") = 0.0, py::arg("coord") = 0,
          "Spring-damper on coordinate `coord` of `joint`: tau = -stiffness (q - rest) - "
          "damping qdot, stiffness [N m/rad or N/m], damping [N m s/rad or N s/m], rest [rad "
          "or m]. ModelError on an unknown joint or coordinate, negative stiffness/damping.")
      .def(
          "add_joint_friction",
          [](ModelBuilder& b, const StrArg& joint, const FloatArg& viscous, const FloatArg& coulomb,
             const FloatArg& smoothing_velocity, const IntArg& coord) {
            const char* fn = "ModelBuilder.add_joint_friction";
            b.add_joint_friction(str_arg(joint, fn, "joint"), float_arg(viscous, fn, "viscous"),
                                 float_arg(coulomb, fn, "coulomb"),
                                 float_arg(smoothing_velocity, fn, "smoothing_velocity"),
                                 int_arg(coord, fn, "coord"));
          },
          py::arg("joint"), py::arg("viscous") = 0.0, py::arg("coulomb") = 0.0,
          py::arg("smoothing_velocity") = 1e-3, py::arg("coord") = 0,
          "Joint friction: tau = -viscous * qdot - coulomb * tanh(qdot / smoothing_velocity).")
      .def(
          "add_gear",
          [](ModelBuilder& b, const StrArg& name, const StrArg& ja, const StrArg& jb,
             const FloatArg& ra, const FloatArg& rb) {
            const char* fn = "ModelBuilder.add_gear";
            b.add_gear(str_arg(name, fn, "name"), str_arg(ja, fn, "joint_a"),
                       str_arg(jb, fn, "joint_b"), float_arg(ra, fn, "r_a"),
                       float_arg(rb, fn, "r_b"));
          },
          py::arg("name"), py::arg("joint_a"), py::arg("joint_b"), py::arg("r_a"), py::arg("r_b"),
          "Ideal gear (no backlash) between two revolute joints: the rolling constraint "
          "r_a q_a + r_b q_b = 0 (external mesh, multi-turn angles).")
      .def(
          "add_coupling",
          [](ModelBuilder& b, const StrArg& name, const StrArg& follower, const StrArg& leader,
             const FloatArg& multiplier, const FloatArg& offset) {
            const char* fn = "ModelBuilder.add_coupling";
            b.add_coupling(str_arg(name, fn, "name"), str_arg(follower, fn, "follower"),
                           str_arg(leader, fn, "leader"), float_arg(multiplier, fn, "multiplier"),
                           float_arg(offset, fn, "offset"));
          },
          py::arg("name"), py::arg("follower"), py::arg("leader"), py::arg("multiplier"),
          py::arg("offset") = 0.0,
          "Coupling q_follower = multiplier * q_leader + offset [rad or m] between two revolute "
          "(continuous) or two prismatic joints (URDF <mimic>): one constraint row; the "
          "follower becomes a dependent coordinate, and forward_dynamics, inverse_dynamics, "
          "mass_matrix, state_from_joints and simulate(q0=...) take the independent ones "
          "(model.coord_names). Chains allowed; cycles, a follower coupled twice, joints of "
          "different types and a zero or non-finite multiplier are refused (ModelError).")
      .def(
          "add_actuator",
          [](ModelBuilder& b, const StrArg& joint_, const FloatArg& gear_ratio,
             const FloatArg& rotor_inertia, const FloatArg& efficiency,
             const FloatArg& friction_viscous, const FloatArg& friction_coulomb,
             const OptMotor& motor, const BoolArg& gyroscopic, const OptFloat& friction_smoothing) {
            const char* fn = "ModelBuilder.add_actuator";
            const std::string joint = str_arg(joint_, fn, "joint");
            const double n = float_arg(gear_ratio, fn, "gear_ratio");
            const double j = float_arg(rotor_inertia, fn, "rotor_inertia");
            const double eff = float_arg(efficiency, fn, "efficiency");
            const double fv = float_arg(friction_viscous, fn, "friction_viscous");
            const double fc = float_arg(friction_coulomb, fn, "friction_coulomb");
            const bool gyro = bool_arg(gyroscopic, fn, "gyroscopic");
            MotorSpec spec;
            const MotorSpec* mp = nullptr;
            if (!motor.is_none()) {
              if (!py::isinstance<MotorSpec>(motor))
                throw ModelError(msg(fn, " on joint '", joint,
                                     "': motor must be an armdyn.Motor or None, got ",
                                     shown(motor)));
              spec = motor.cast<MotorSpec>();
              mp = &spec;
            }
            const double vs = opt_float_arg(friction_smoothing, fn, "friction_smoothing", 0.0);
            if (!friction_smoothing.is_none() && !(vs > 0.0))
              throw ModelError(msg("add_actuator on joint '", joint,
                                   "': friction_smoothing must be positive, got ", vs));
            b.add_actuator(joint, n, j, eff, fv, fc, mp, gyro, vs);
          },
          py::arg("joint"), py::arg("gear_ratio"), py::arg("rotor_inertia"),
          py::arg("efficiency") = 1.0, py::arg("friction_viscous") = 0.0,
          py::arg("friction_coulomb") = 0.0, py::arg("motor") = py::none(),
          py::arg("gyroscopic") = false, py::arg("friction_smoothing") = py::none(),
          "A gearbox and motor rotor on a revolute (continuous) or prismatic joint. "
          "gear_ratio N = rotor speed / joint speed (negative reverses the rotor; rad/m for a "
          "prismatic joint, a ball screw); rotor_inertia J [kg m^2] about the rotor axis; "
          "efficiency in (0, 1] (stored for the motor-side maths, not in the dynamics); "
          "friction_viscous [N m s/rad] and friction_coulomb [N m] on the motor side "
          "(reflected as N^2 b and |N| c), Coulomb smoothed by tanh(omega / friction_smoothing), "
          "friction_smoothing [rad/s, motor side] default 1e-3 |N|; motor: an armdyn.Motor or "
          "None. Adds a body, a revolute joint and a coupling (zero mass, thin-disc inertia) "
          "along the joint axis through its origin: by default (gyroscopic=False) "
          "'<joint>_armature' on ground, axial inertia N^2 J, turning with the joint (at qdot: "
          "the gear-reduced model, Pinocchio's armature N^2 J exactly); with gyroscopic=True "
          "'<joint>_rotor' on the joint's parent body, axial inertia J, turning at N qdot "
          "relative to it (the rotor's full kinetic energy, with its carrier's rotation). "
          "ModelError, builder unchanged, on an unknown joint, a joint not "
          "revolute or prismatic, a second actuator, gear_ratio zero or not finite, "
          "rotor_inertia < 0, efficiency outside (0, 1], negative frictions.")
      .def(
          "add_gear_pair",
          [](ModelBuilder& b, const StrArg& name, const StrArg& ja, const StrArg& jb,
             const FloatArg& ra, const FloatArg& rb, const FloatArg& backlash,
             const FloatArg& stiffness, const FloatArg& exponent, const FloatArg& hc_damping) {
            const char* fn = "ModelBuilder.add_gear_pair";
            b.add_gear_pair(
                str_arg(name, fn, "name"), str_arg(ja, fn, "joint_a"), str_arg(jb, fn, "joint_b"),
                float_arg(ra, fn, "r_a"), float_arg(rb, fn, "r_b"),
                float_arg(backlash, fn, "backlash"), float_arg(stiffness, fn, "stiffness"),
                float_arg(exponent, fn, "exponent"), float_arg(hc_damping, fn, "hc_damping"));
          },
          py::arg("name"), py::arg("joint_a"), py::arg("joint_b"), py::arg("r_a"), py::arg("r_b"),
          py::arg("backlash") = 0.0, py::arg("stiffness") = 1e8, py::arg("exponent") = 1.5,
          py::arg("hc_damping") = 0.0,
          "Gear pair with backlash between two revolute joints (external mesh): mesh "
          "displacement s = r_a q_a + r_b q_b, dead zone |s| <= backlash/2, Hunt-Crossley "
          "contact force F = k d^n (1 + hc_damping d') >= 0 beyond it. Contact onset and "
          "separation are located as events (result.events).")
      .def(
          "add_motor",
          [](ModelBuilder& b, const StrArg& joint_, const ProfileLike& reference,
             const FloatArg& kp_, const FloatArg& kd_, const FloatArg& torque_limit_,
             const OptProfileLike& feedforward, const IntArg& coord_, const FloatArg& ki_) {
            const char* fn = "ModelBuilder.add_motor";
            const std::string joint = str_arg(joint_, fn, "joint");
            const double kp = float_arg(kp_, fn, "kp"), kd = float_arg(kd_, fn, "kd");
            const double torque_limit = float_arg(torque_limit_, fn, "torque_limit");
            const int coord = int_arg(coord_, fn, "coord");
            const double ki = float_arg(ki_, fn, "ki");
            const std::string who = "add_motor '" + joint + "'";
            const Profile ref = to_profile(reference, who + ": reference");
            if (feedforward.is_none()) {
              b.add_motor(joint, ref, kp, kd, torque_limit, nullptr, coord, ki);
            } else {
              const Profile ff = to_profile(feedforward, who + ": feedforward");
              b.add_motor(joint, ref, kp, kd, torque_limit, &ff, coord, ki);
            }
          },
          py::arg("joint"), py::arg("reference"), py::arg("kp"), py::arg("kd"),
          py::arg("torque_limit") = 1e300, py::arg("feedforward") = py::none(),
          py::arg("coord") = 0, py::arg("ki") = 0.0,
          "PD or PID motor on a joint coordinate: tau = clamp(kp (q_ref - q) + kd (qd_ref - qd) "
          "+ ki z, +-torque_limit) + feedforward(t), z the integral of q_ref - q (an auxiliary "
          "state, not integrated while saturated); the reference is a profile (armdyn.profiles.*, "
          "a "
          "number, or a callable).")
      .def(
          "add_joint_torque",
          [](ModelBuilder& b, const StrArg& joint_, const ProfileLike& profile,
             const IntArg& coord) {
            const char* fn = "ModelBuilder.add_joint_torque";
            const std::string joint = str_arg(joint_, fn, "joint");
            const int k = int_arg(coord, fn, "coord");
            b.add_joint_torque(joint, to_profile(profile, "joint torque on '" + joint + "'"), k);
          },
          py::arg("joint"), py::arg("profile"), py::arg("coord") = 0,
          "Apply a torque [N m] (revolute) or force [N] (prismatic) on coordinate `coord` of "
          "`joint`, given by a profile of t [s] (armdyn.profiles.*, a number, or a callable t "
          "-> (y, yd, ydd)): acts on the child about/along the joint axis and the opposite on "
          "the parent; reported in SimulationResult.joint_torques. ModelError on an unknown "
          "joint or coordinate, or a bad profile.")
      .def(
          "finalize",
          [cast_model](const ModelBuilder& b, const BoolArg& mass_weighted) {
            FinalizeOptions o;
            o.mass_weighted_assembly =
                bool_arg(mass_weighted, "ModelBuilder.finalize", "mass_weighted_assembly");
            // Ctrl-C: the long parts of a large model's analysis check for signals
            Poll poll = python_poll();
            ScopedThreadPoll scope(&poll);
            ModelPtr m = b.finalize(o);
            for (const std::string& w : m->warnings)
              if (PyErr_WarnEx(PyExc_UserWarning, ("armdyn: " + w).c_str(), 1) != 0)
                throw py::error_already_set();
            return cast_model(m);
          },
          py::arg("mass_weighted_assembly") = true,
          "Validate, analyse topology and rank, assemble; returns an immutable Model.")
      .def_property_readonly(
          "body_names",
          [](const ModelBuilder& b) {
            std::vector<std::string> r;
            for (const auto& x : b.draft().bodies) r.push_back(x.name);
            return r;
          },
          "Names of the bodies added so far, in definition order (for urdf_builder: the "
          "URDF's links as the loader added them).")
      .def_property_readonly(
          "joint_names",
          [](const ModelBuilder& b) {
            std::vector<std::string> r;
            for (const auto& x : b.draft().joints) r.push_back(x.name);
            return r;
          },
          "Names of the joints added so far, in definition order (for urdf_builder: the URDF's "
          "joints as the loader added them, actuator rotors and free bases included).")
      .def_property_readonly(
          "frame_names",
          [](const ModelBuilder& b) {
            std::vector<std::string> r;
            for (const auto& x : b.draft().frames) r.push_back(x.name);
            return r;
          },
          "Names of the named frames added so far (add_frame; for urdf_builder its links), in "
          "definition order.");

  m.attr("URDF_MAX_BYTES") = kUrdfMaxBytes;
  m.attr("URDF_MAX_ATTRIBUTES") = kUrdfMaxAttributes;
  m.attr("URDF_COULOMB_SMOOTHING") = kUrdfCoulombSmoothing;
  m.def(
      "urdf_builder",
      [](const StrArg& src_, const BoolArg& fixed_base_, const ArrayLike& g,
         const BoolArg& physical_inertia_, const BoolArg& mimic_) {
        const char* fn = "urdf_builder";
        // bytes pass as they are (the loader checks names are UTF-8)
        if (!py::isinstance<py::bytes>(src_) && !py::isinstance<py::str>(src_))
          throw ModelError(msg(fn, ": path_or_xml must be a str or bytes, got ", shown(src_)));
        const std::string src = py::isinstance<py::bytes>(src_) ? src_.cast<std::string>()
                                                                : str_arg(src_, fn, "path_or_xml");
        const bool fixed_base = bool_arg(fixed_base_, fn, "fixed_base");
        const bool physical_inertia = bool_arg(physical_inertia_, fn, "physical_inertia");
        const bool mimic = bool_arg(mimic_, fn, "mimic");
        const Vec3 gravity = to_vec3(g, "gravity");
        // Ctrl-C: the loader's loops over the links and joints check for signals
        Poll poll = python_poll();
        ScopedThreadPoll scope(&poll);
        try {
          return urdf_builder(src, fixed_base, gravity, physical_inertia, mimic);
        } catch (const UrdfError& e) {
          // the loader escapes what it quotes; this keeps any message valid UTF-8 regardless
          const std::string text = e.what();
          throw UrdfError(
              py::bytes(text).attr("decode")("utf-8", "backslashreplace").cast<std::string>());
        }
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
