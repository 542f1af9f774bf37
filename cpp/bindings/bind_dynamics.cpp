// SPDX-License-Identifier: BSD-3-Clause
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>

#include "armdyn/algorithm/energy.hpp"
#include "armdyn/algorithm/forces.hpp"
#include "armdyn/algorithm/kinematics.hpp"
#include "armdyn/algorithm/kkt.hpp"
#include "armdyn/data.hpp"
#include "armdyn/kernels/joint_space.hpp"
#include "armdyn/simulate/simulate.hpp"
#include "common.hpp"

namespace armdyn {

namespace py = pybind11;
using namespace py_helpers;

namespace {

Metric metric_of(const std::string& s) {
  if (s == "mass") return Metric::Mass;
  if (s == "unweighted") return Metric::Identity;
  throw ModelError(msg("projection must be 'mass' or 'unweighted', got '", s, "'"));
}

void check_state(const Model& md, const VecX& u, const VecX& v, const char* fn) {
  if (!u.allFinite()) throw ModelError(msg(fn, ": u contains NaN or inf"));
  if (!v.allFinite()) throw ModelError(msg(fn, ": v contains NaN or inf"));
  for (int i = 0; i < md.nb; ++i)
    if (!(u.segment<4>(7 * i + 3).norm() > 0))
      throw ModelError(msg(fn, ": zero Euler parameters for body '", md.bodies[i].name, "'"));
}

py::dict result_dict(const Model& md, const SimResult& r) {
  const py::ssize_t n = r.n, nj = static_cast<py::ssize_t>(md.joints.size());
  py::dict d;
  d["t"] = to_numpy(r.t.data(), {n});
  d["u"] = to_numpy(r.u.data(), {n, md.nq});
  d["v"] = to_numpy(r.v.data(), {n, md.nv});
  d["q"] = to_numpy(r.q.data(), {n, static_cast<py::ssize_t>(md.nq_joint)});
  d["qd"] = to_numpy(r.qd.data(), {n, static_cast<py::ssize_t>(md.nv_joint)});
  d["qdd"] = to_numpy(r.qdd.data(), {n, static_cast<py::ssize_t>(md.nv_joint)});
  d["drive_forces"] =
      to_numpy(r.drive_forces.data(), {n, static_cast<py::ssize_t>(md.drives.size())});
  d["joint_torques"] = to_numpy(r.joint_torques.data(), {n, static_cast<py::ssize_t>(md.nv_joint)});
  d["reaction_forces"] = to_numpy(r.reaction_forces.data(), {n, nj, 3});
  d["reaction_torques"] = to_numpy(r.reaction_torques.data(), {n, nj, 3});
  {
    const py::ssize_t ng = static_cast<py::ssize_t>(md.gears.size() + md.gear_constraints.size());
    py::dict gf;
    std::vector<std::string> names;
    for (const auto& g : md.gears) names.push_back(g.name);
    for (const auto& g : md.gear_constraints) names.push_back(g.name);
    gf["names"] = names;
    gf["force"] = to_numpy(r.gear_forces.data(), {n, ng});
    d["gear_forces"] = gf;
  }
  {
    py::dict lf;
    lf["names"] = r.limit_joints;
    lf["force"] =
        to_numpy(r.limit_forces.data(), {n, static_cast<py::ssize_t>(r.limit_joints.size())});
    d["limit_forces"] = lf;
  }
  d["position_residual"] = to_numpy(r.position_residual.data(), {n});
  d["velocity_residual"] = to_numpy(r.velocity_residual.data(), {n});
  d["kinetic_energy"] = to_numpy(r.kinetic_energy.data(), {n});
  d["potential_energy"] = to_numpy(r.potential_energy.data(), {n});
  py::dict s;
  s["steps"] = r.stats.steps;
  s["rejected"] = r.stats.rejected;
  s["rhs_evals"] = r.stats.rhs_evals;
  s["kkt_solves"] = r.kkt_solves;
  s["factorizations"] = r.factorizations;
  s["position_projections"] = r.position_projections;
  s["newton_iterations"] = r.newton_iterations;
  s["seconds"] = r.cpu_seconds;
  s["jacobians"] = r.stats.jacobians;
  s["lu_factorizations"] = r.stats.lu_factorizations;
  s["newton_iterations_implicit"] = r.stats.newton_iterations;
  s["newton_failures"] = r.stats.newton_failures;
  s["events"] = r.stats.events;
  s["singular_evaluations"] = r.singular_evaluations;
  s["singular_note"] = r.singular_note;
  s["augmented_solves"] = r.augmented_solves;
  s["augmented_note"] = r.augmented_note;
  s["integrator"] = r.integrator;
  s["integrator_reason"] = r.integrator_reason;
  s["solver_bodies"] = r.solver_bodies;
  s["solver_rows"] = r.solver_rows;
  s["formulation"] = r.formulation;
  d["stats"] = s;
  py::dict ev;
  ev["t"] = to_numpy(r.event_t.data(), {static_cast<py::ssize_t>(r.event_t.size())});
  std::vector<std::string> names;
  for (int i : r.event_index) names.push_back(md.gears[i].name);
  ev["gear"] = names;
  std::vector<bool> onset;
  for (int dir : r.event_direction) onset.push_back(dir > 0);
  ev["onset"] = onset;
  {
    py::dict lim;
    lim["t"] = to_numpy(r.limit_event_t.data(), {static_cast<py::ssize_t>(r.limit_event_t.size())});
    lim["joint"] = r.limit_event_joint;
    std::vector<std::string> side, kind;
    static const char* kinds[] = {"rest", "bounce", "release"};
    for (int sd : r.limit_event_side) side.emplace_back(sd > 0 ? "lower" : "upper");
    for (int k : r.limit_event_kind) kind.emplace_back(kinds[k]);
    lim["side"] = side;
    lim["kind"] = kind;
    ev["limits"] = lim;
  }
  d["events"] = ev;
  d["error"] = r.error;
  return d;
}

/// The Python exceptions that stopped a run, for armdyn.simulate to raise: "interrupt" (to
/// raise as itself, with .result) and "cause" (a SolverError's __cause__), or None.
void add_run_exception(const SimResult& r, py::dict& d) {
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

SimOptions sim_options(const std::string& integrator, double rtol, double atol, double dt,
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
  o.projection = metric_of(projection);
  return o;
}

/// The full joint-space q a run starts its multi-turn tracking from, of the independent q0 (a
/// coupled model's followers set by their couplings).
VecX expanded_q_start(const Model& md, const VecX& qi) {
  if (qi.size() != md.independent.nq())
    throw ModelError(msg("q0 must have ", md.independent.nq(), " entries, got ", qi.size()));
  VecX q(md.nq_joint);
  md.independent.expand_q(qi.data(), q.data());
  return q;
}

}  // namespace

void bind_dynamics(py::module_& m) {
  // The simulate options common to _simulate and _rollout (armdyn.simulation._sim_args builds
  // the Python side of both).
#define ARMDYN_SIM_OPTION_ARGS                                                          \
  integrator, rtol, atol, dt, output_dt, projection, max_steps, max_step, merge_welded, \
      coordinates, limits, restitution
  m.def(
      "_simulate",
      [](const Model& md, double t_end, const std::string& integrator, double rtol, double atol,
         double dt, double output_dt, const OptArrayLike& u0, const OptArrayLike& v0,
         const std::string& projection, long max_steps, double max_step, bool merge_welded,
         const std::string& coordinates, const OptArrayLike& q_start, bool limits,
         double restitution, const OptProgress& progress) {
        // armdyn.simulate answers a model with no bodies itself (nothing to integrate)
        if (md.nb == 0)
          throw ModelError("_simulate: the model has no bodies (use armdyn.simulate)");
        SimulateGuard guard("simulate");
        SimOptions o = sim_options(ARMDYN_SIM_OPTION_ARGS);
        if (!q_start.is_none())
          o.q_start = expanded_q_start(md, to_vec(q_start, "q0", md.independent.nq()));
        const VecX u = u0.is_none() ? md.u0 : to_vec(u0, "u0", md.nq);
        const VecX v = v0.is_none() ? md.v0 : to_vec(v0, "v0", md.nv);
        Poll poll = python_poll(&progress);
        o.step.poll = &poll;
        SimResult r;
        {
          py::gil_scoped_release release;
          r = simulate(md, t_end, o, u, v);
        }
        py::dict d = result_dict(md, r);
        add_run_exception(r, d);
        return d;
      },
      py::arg("model"), py::arg("t_end"), py::arg("integrator"), py::arg("rtol"), py::arg("atol"),
      py::arg("dt"), py::arg("output_dt"), py::arg("u0"), py::arg("v0"), py::arg("projection"),
      py::arg("max_steps"), py::arg("max_step") = 0.0, py::arg("merge_welded") = true,
      py::arg("coordinates") = "cartesian", py::arg("q_start") = py::none(),
      py::arg("limits") = true, py::arg("restitution") = 0.0, py::arg("progress") = py::none());

  m.def(
      "_output_row_bytes",
      [](const Model& md) {
        // the columns finish() (simulate.cpp) sizes per output time; limit forces: at most one
        // per joint
        const size_t nj = md.joints.size();
        const size_t cols = 1 + static_cast<size_t>(md.nq + md.nv + md.nq_joint) +
                            3 * static_cast<size_t>(md.nv_joint) + md.drives.size() + 6 * nj + 4 +
                            md.gears.size() + md.gear_constraints.size() + nj;
        return cols * sizeof(double);
      },
      py::arg("model"),
      "Bytes of one output time of simulate (every table's row, the limit forces counted for "
      "every joint): the bound armdyn.simulate checks an output_dt run against.");

  m.def(
      "_rollout",
      [](const Model& md, double t_end, const std::string& integrator, double rtol, double atol,
         double dt, double output_dt, const py::array_t<double, py::array::c_style>& u0,
         const py::array_t<double, py::array::c_style>& v0, const std::string& projection,
         long max_steps, double max_step, bool merge_welded, const std::string& coordinates,
         const OptArrayLike& q_start, bool limits, double restitution,
         std::vector<std::string> errors, int threads, const OptProgress& progress) {
        if (md.nb == 0) throw ModelError("_rollout: the model has no bodies (use armdyn.rollout)");
        const SimOptions base = sim_options(ARMDYN_SIM_OPTION_ARGS);
        if (u0.ndim() != 2 || u0.shape(1) != md.nq)
          throw ModelError(
              msg("rollout: u0 must have shape (n_runs, ", md.nq, "), got ", shape_str(u0)));
        const long n = static_cast<long>(u0.shape(0));
        if (v0.ndim() != 2 || v0.shape(0) != n || v0.shape(1) != md.nv)
          throw ModelError(
              msg("rollout: v0 must have shape (", n, ", ", md.nv, "), got ", shape_str(v0)));
        if (static_cast<long>(errors.size()) != n)
          throw ModelError(msg("rollout: ", errors.size(), " error entries for ", n, " runs"));
        if (threads < 1) throw ModelError(msg("rollout: threads must be >= 1, got ", threads));
        std::vector<VecX> us(n), vs(n), qs;
        for (long k = 0; k < n; ++k) {
          us[k] = Eigen::Map<const VecX>(u0.data(k, 0), md.nq);
          vs[k] = Eigen::Map<const VecX>(v0.data(k, 0), md.nv);
        }
        if (!q_start.is_none()) {
          const auto q = q_start.cast<py::array_t<double, py::array::c_style>>();
          const long nqi = md.independent.nq();
          if (q.ndim() != 2 || q.shape(0) != n || q.shape(1) != nqi)
            throw ModelError(
                msg("rollout: q0 must have shape (", n, ", ", nqi, "), got ", shape_str(q)));
          qs.resize(n);
          for (long k = 0; k < n; ++k)
            if (errors[k].empty())
              qs[k] = expanded_q_start(md, Eigen::Map<const VecX>(q.data(k, 0), nqi));
        }
        std::vector<SimResult> results(n);
        const int nt = static_cast<int>(std::min<long>(threads, std::max<long>(n, 1)));
        // the batch: a work queue (an atomic index) over nt threads, one Data per thread; the
        // caller's thread waits, checking for signals (Ctrl-C) every 20 ms
        std::atomic<long> next{0}, done{0};
        std::atomic<bool> stop{false};
        auto last_report = std::chrono::steady_clock::now();
        std::mutex mutex;
        std::condition_variable finished;
        int running = nt;
        py::object interrupt = py::none();
        {
          py::gil_scoped_release release;
          auto work = [&] {
            std::unique_ptr<Data> d;
            // cancellation: between runs, and inside a run by the stepping loops' poll, which
            // checks `stop` every few milliseconds (the run then ends with its outputs so far)
            Poll poll(Poll::Callback(), 0.005, &stop);
            SimOptions o = base;
            o.step.poll = &poll;
            while (!stop.load(std::memory_order_relaxed)) {
              const long k = next.fetch_add(1);
              if (k >= n) break;
              if (!errors[k].empty()) continue;
              try {
                if (!d) d = std::make_unique<Data>(md);
                if (!qs.empty()) o.q_start = qs[k];
                results[k] = simulate(md, *d, t_end, o, us[k], vs[k]);
              } catch (const SolverError& e) {
                errors[k] = e.what();
                d.reset();  // a run cut short by an exception: the next one starts afresh
              } catch (const std::exception& e) {
                errors[k] = e.what();
                d.reset();
              }
              done.fetch_add(1, std::memory_order_relaxed);
            }
            std::lock_guard<std::mutex> lock(mutex);
            if (--running == 0) finished.notify_all();
          };
          std::vector<std::thread> pool;
          pool.reserve(nt);
          try {
            for (int i = 0; i < nt; ++i) pool.emplace_back(work);
          } catch (...) {
            // could not start a thread: the started ones finish the queue
            std::lock_guard<std::mutex> lock(mutex);
            running -= nt - static_cast<int>(pool.size());
          }
          std::unique_lock<std::mutex> lock(mutex);
          while (running > 0) {
            if (finished.wait_for(lock, std::chrono::milliseconds(20),
                                  [&] { return running == 0; }))
              break;
            if (!stop.load()) {
              lock.unlock();
              {
                py::gil_scoped_acquire gil;
                if (PyErr_CheckSignals() != 0) {
                  stop = true;
                  py::error_already_set e;  // fetches (and clears) the handler's exception
                  interrupt = e.value();
                } else if (!progress.is_none()) {
                  // the runs finished so far, every 0.1 s; an exception stops the batch
                  const auto now = std::chrono::steady_clock::now();
                  if (std::chrono::duration<double>(now - last_report).count() >= 0.1) {
                    last_report = now;
                    try {
                      progress(done.load(), n);
                    } catch (py::error_already_set& e) {
                      stop = true;
                      interrupt = e.value();
                    }
                  }
                }
              }
              lock.lock();
            }
          }
          lock.unlock();
          for (auto& t : pool) t.join();
        }
        py::list out;
        for (long k = 0; k < n; ++k) {
          SimResult& r = results[k];
          if (r.error.empty() && !errors[k].empty()) r.error = errors[k];
          if (r.error.empty() && stop && r.t.empty() && r.n == 0)
            r.error = "interrupted before the run started";
          out.append(result_dict(md, r));
        }
        return py::make_tuple(out, interrupt);
      },
      py::arg("model"), py::arg("t_end"), py::arg("integrator"), py::arg("rtol"), py::arg("atol"),
      py::arg("dt"), py::arg("output_dt"), py::arg("u0"), py::arg("v0"), py::arg("projection"),
      py::arg("max_steps"), py::arg("max_step"), py::arg("merge_welded"), py::arg("coordinates"),
      py::arg("q_start"), py::arg("limits"), py::arg("restitution"), py::arg("errors"),
      py::arg("threads"), py::arg("progress") = py::none(),
      "Runs of simulate from each row of u0/v0 (q_start: the joint-space q0 rows, or None) on "
      "`threads` C++ threads, the GIL released; (list of result dicts, the interrupting "
      "exception or None). A run whose `errors` entry is non-empty is not run; a run that "
      "raises has its message in its dict's 'error'.");
#undef ARMDYN_SIM_OPTION_ARGS

  m.def(
      "state_from_joints",
      [](const Model& md, const ArrayLike& q, const OptArrayLike& qd) {
        require_joint_space(md, "state_from_joints", true);
        const IndependentCoords& ic = md.independent;
        const long nq = ic.nq(), n = ic.nv();
        const VecX qi = to_vec(q, "q", nq),
                   qdi = qd.is_none() ? VecX::Zero(n) : to_vec(qd, "qd", n);
        check_joint_vector(qi, nq, "state_from_joints", "q");
        check_joint_vector(qdi, n, "state_from_joints", "qd");
        VecX qf(md.nq_joint), qdf(md.nv_joint), u, v;
        ic.expand_q(qi.data(), qf.data());
        ic.expand_v(qdi.data(), qdf.data());
        state_from_joints(md, qf, qdf, u, v);
        return py::make_tuple(to_numpy(u), to_numpy(v));
      },
      py::arg("model"), py::arg("q"), py::arg("qd") = py::none(),
      "Cartesian state (u, v) of a joint-space tree model from joint-space q (n_coords) and qd "
      "(n_dofs; default zero): a coupled model's independent coordinates, the followers set by "
      "their couplings. Returns (u (nq,), v (nv,)) float64 arrays: per body CoM [m] and unit "
      "Euler parameters; CoM velocity [m/s, world] and angular velocity [rad/s, body]. "
      "ModelError on a model without a joint space or wrong shapes.");

  m.def(
      "joint_coordinates",
      [](const Model& md, const ArrayLike& u, const ArrayLike& v) {
        VecX q, qd;
        joint_coordinates(md, to_vec(u, "u", md.nq), to_vec(v, "v", md.nv), q, qd);
        const IndependentCoords& ic = md.independent;
        VecX qi(ic.nq()), qdi(ic.nv());
        qi.head(ic.lead_q) = q.head(ic.lead_q);
        qdi.head(ic.lead_v) = qd.head(ic.lead_v);
        for (int k = 0; k < ic.n; ++k) {
          qi[ic.lead_q + k] = q[ic.lead_q + ic.full[k]];
          qdi[ic.lead_v + k] = qd[ic.lead_v + ic.full[k]];
        }
        return py::make_tuple(to_numpy(qi), to_numpy(qdi));
      },
      py::arg("model"), py::arg("u"), py::arg("v"),
      "Joint-space q (n_coords: floating bases' poses, then joint coordinates with angles in "
      "(-pi, pi]) and qd (n_dofs) at the Cartesian state (u, v): a coupled model's independent "
      "coordinates, as state_from_joints takes.");

  m.def(
      "evaluate_constraints",
      [](const Model& md, const ArrayLike& u, const ArrayLike& v, double t) {
        const VecX uu = to_vec(u, "u", md.nq), vv = to_vec(v, "v", md.nv);
        check_state(md, uu, vv, "evaluate_constraints");
        std::vector<BodyKin> kin;
        body_kinematics(md, uu.data(), vv.data(), kin);
        ConstraintEval ce;
        ce.init(md);
        eval_constraints(md, kin, t, true, ce);
        py::dict d;
        d["f"] = to_numpy(ce.f);
        d["zeta"] = to_numpy(dense_zeta(md, ce));
        d["xi"] = to_numpy(ce.xi);
        d["rhs"] = to_numpy(ce.rhs);
        return d;
      },
      py::arg("model"), py::arg("u"), py::arg("v"), py::arg("t") = 0.0,
      "The constraints at the Cartesian state u (nq,), v (nv,) and time t [s]: a dict of float64 "
      "arrays f (nc,) (the residuals, [m or rad]), zeta (nc, nv) (the Jacobian), xi (nc,) and "
      "rhs (nc,), with zeta v = rhs and zeta v' = -xi. ModelError on wrong shapes.");

  m.def(
      "body_accelerations",
      [](const Model& md, const ArrayLike& u, const ArrayLike& v, double t) {
        const VecX uu = to_vec(u, "u", md.nq), vv = to_vec(v, "v", md.nv);
        check_state(md, uu, vv, "body_accelerations");
        Data d(md);
        VecX vd(md.nv);
        body_accelerations(md, d, t, uu.data(), vv.data(), vd.data());
        return py::make_tuple(to_numpy(vd), to_numpy(d.delta));
      },
      py::arg("model"), py::arg("u"), py::arg("v"), py::arg("t") = 0.0,
      "Solve the KKT system at the Cartesian state u (nq,), v (nv,) and time t [s]: returns "
      "(v' (nv,) the bodies' accelerations [m/s^2, rad/s^2], delta (nc,) the Lagrange "
      "multipliers [N, N m]). ModelError on wrong shapes, SolverError on a singular system.");

  m.def(
      "body_mass_matrix",
      [](const Model& md) {
        MatX g = MatX::Zero(md.nv, md.nv);
        for (int i = 0; i < md.nb; ++i) {
          g.block<3, 3>(6 * i, 6 * i) = md.bodies[i].mass * Mat3::Identity();
          g.block<3, 3>(6 * i + 3, 6 * i + 3) = md.bodies[i].inertia;
        }
        return to_numpy(g);
      },
      py::arg("model"),
      "The constant Cartesian mass matrix Gamma = blockdiag(m_i I3, J_i) (nv, nv) [kg, kg m^2] "
      "of the bodies (J_i about the CoM in body axes).");

  m.def(
      "body_forces",
      [](const Model& md, const ArrayLike& u, const ArrayLike& v, double t) {
        const VecX uu = to_vec(u, "u", md.nq), vv = to_vec(v, "v", md.nv);
        check_state(md, uu, vv, "body_forces");
        Data d(md);
        load_kinematics(md, d, uu.data(), vv.data());
        cartesian_forces(md, d, t);
        return to_numpy(d.eta);
      },
      py::arg("model"), py::arg("u"), py::arg("v"), py::arg("t") = 0.0,
      "The applied Cartesian forces eta (nv,) at the state u (nq,), v (nv,) and time t [s]: per "
      "body the force [N, world] and torque [N m, body axes] of gravity, the gyroscopic -w x Jw, "
      "loads, springs and joint forces. ModelError on wrong shapes.");

  m.def(
      "energy",
      [](const Model& md, const ArrayLike& u, const ArrayLike& v) {
        const VecX uu = to_vec(u, "u", md.nq), vv = to_vec(v, "v", md.nv);
        Data d(md);
        double ke, pe;
        energy(md, d, uu.data(), vv.data(), ke, pe);
        return py::make_tuple(ke, pe);
      },
      py::arg("model"), py::arg("u"), py::arg("v"),
      "(kinetic, potential) energy [J] at the Cartesian state u (nq,), v (nv,); the potential "
      "includes gravity and springs. ModelError on wrong shapes.");
}

}  // namespace armdyn
