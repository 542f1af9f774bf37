// SPDX-License-Identifier: BSD-3-Clause
// Bindings of the joint-space algorithms (armdyn/algorithm/): armdyn.Data, forward_dynamics,
// inverse_dynamics and mass_matrix. One state (1-D arrays) or one state per row (2-D arrays,
// evaluated in one C++ loop without the GIL). Without data=, each thread keeps one Data per
// model, so repeated calls allocate nothing but their output array.
#include <cmath>
#include <initializer_list>
#include <memory>
#include <vector>

#include "armdyn/algorithm/cost_model.hpp"
#include "armdyn/algorithm/crba.hpp"
#include "armdyn/algorithm/dynamics.hpp"
#include "armdyn/algorithm/frames.hpp"
#include "common.hpp"

namespace armdyn {

namespace py = pybind11;
using namespace py_helpers;

namespace {

using ModelHolder = std::shared_ptr<Model>;

/// armdyn.Data: a workspace with its model kept alive.
struct DataPy {
  explicit DataPy(ModelHolder md) : model(std::move(md)), data(*model) {}
  ModelHolder model;
  Data data;
};

/// This thread's workspace for md: the last few models used, the most recent first.
/// The model argument of a dynamics function: an armdyn.Model, else a ModelError naming it.
ModelHolder model_of(const ModelArg& model, const char* fn) {
  if (!py::isinstance<Model>(model))
    throw ModelError(msg(fn, ": model must be an armdyn.Model, got ", shown(model)));
  return model.cast<ModelHolder>();
}

Data& cached_data(const ModelHolder& md) {
  struct Entry {
    const Model* key;
    std::weak_ptr<Model> alive;  // a freed model's address may be reused by another
    std::unique_ptr<Data> data;
  };
  thread_local std::vector<Entry> cache;
  for (size_t i = 0; i < cache.size(); ++i) {
    if (cache[i].key != md.get() || cache[i].alive.expired()) continue;
    if (i > 0) std::swap(cache[0], cache[i]);
    return *cache[0].data;
  }
  constexpr size_t kMaxModels = 8;
  for (size_t i = cache.size(); i-- > 0;)
    if (cache[i].alive.expired()) cache.erase(cache.begin() + static_cast<long>(i));
  if (cache.size() >= kMaxModels) cache.pop_back();
  cache.insert(cache.begin(), Entry{md.get(), md, std::make_unique<Data>(*md)});
  return *cache[0].data;
}

Data& data_for(const ModelHolder& md, const py::object& data, const char* fn) {
  if (!md) throw ModelError(msg(fn, ": no model"));
  if (data.is_none()) return cached_data(md);
  if (!py::isinstance<DataPy>(data))
    throw ModelError(msg(fn, ": data must be an armdyn.Data (or None)"));
  auto* d = data.cast<DataPy*>();
  check_data(*md, d->data, fn);
  return d->data;
}

bool is_batch(const py::handle& q) {
  return py::isinstance<py::array>(q) && py::reinterpret_borrow<py::array>(q).ndim() == 2;
}

double scalar_time(const py::handle& t, const char* fn) {
  if (PyFloat_Check(t.ptr())) return PyFloat_AS_DOUBLE(t.ptr());
  try {
    return t.cast<double>();
  } catch (const py::cast_error&) {
    throw ModelError(msg(fn, ": t must be a number (or one per row of a 2-D q)"));
  }
}

/// A (rows, n) float64 C-contiguous array of a 2-D argument (converted when needed).
py::array_t<double> rows_of(const py::handle& obj, const char* fn, const char* name, long rows,
                            long n) {
  auto a = as_array(obj, msg(fn, ": ", name));
  if (a.ndim() != 2 || a.shape(0) != rows || a.shape(1) != n)
    throw ModelError(
        msg(fn, ": ", name, " must have shape (", rows, ", ", n, "), got ", shape_str(a)));
  return a;
}

/// f(i, q_i, a_i, b_i, t_i, out_i) for every row i of the 2-D arguments q (shape (N, nq)), a, b
/// (shape (N, n)), t a number or one per row; out has shape (N, *out_shape). Runs without the
/// GIL; an error names its row.
template <class Fn>
py::array_t<double> batch(const char* fn, long nq, long n, const py::handle& q, const py::handle& a,
                          const char* an, const py::handle& b, const char* bn, const py::handle& t,
                          std::vector<py::ssize_t> out_shape, Fn&& f) {
  const long rows = static_cast<long>(py::reinterpret_borrow<py::array>(q).shape(0));
  const auto Q = rows_of(q, fn, "q", rows, nq), A = rows_of(a, fn, an, rows, n),
             B = rows_of(b, fn, bn, rows, n);
  VecX ts;
  double t0 = 0.0;
  const bool per_row_t = py::isinstance<py::array>(t) || py::isinstance<py::sequence>(t);
  if (per_row_t)
    ts = to_vec(t, msg(fn, ": t"), rows);
  else
    t0 = scalar_time(t, fn);
  long out_size = 1;
  for (auto s : out_shape) out_size *= static_cast<long>(s);
  out_shape.insert(out_shape.begin(), rows);
  py::array_t<double> out(out_shape);
  const double *qp = Q.data(), *ap = A.data(), *bp = B.data();
  double* op = out.mutable_data();
  Poll poll = python_poll();  // Ctrl-C: KeyboardInterrupt with .result, the rows done
  py::gil_scoped_release nogil;
  poll.start();
  for (long i = 0; i < rows; ++i) {
    using Row = Eigen::Map<const VecX>;
    try {
      poll(static_cast<double>(i), static_cast<double>(rows));
    } catch (PyInterrupted& e) {
      py::gil_scoped_acquire g;
      e.err.value().attr("result") = out[py::slice(0, i, 1)];
      throw;
    }
    try {
      f(Row(qp + i * nq, nq), Row(ap + i * n, n), Row(bp + i * n, n), per_row_t ? ts[i] : t0,
        op + i * out_size);
    } catch (const SolverError& e) {
      std::throw_with_nested(SolverError(msg("row ", i, ": ", e.what())));
    } catch (const ModelError& e) {
      throw ModelError(msg("row ", i, ": ", e.what()));
    }
  }
  return out;
}

/// One input of a call, for finite_out's message.
struct Input {
  const char* name;
  const double* data;
  long size;
};

/// A SolverError when finite inputs gave a non-finite output (the inputs are checked finite
/// before the call): the output's first offending entry and the input entry of largest
/// magnitude, the usual culprit of an overflow. A pass over the output only: no cost when
/// it is finite beyond the scan.
std::string largest_input(std::initializer_list<Input> inputs, double* peak_out = nullptr);

void finite_out(const char* fn, const char* out_name, const double* out, long size,
                std::initializer_list<Input> inputs) {
  long bad = -1;
  for (long i = 0; i < size; ++i)
    if (!std::isfinite(out[i])) {
      bad = i;
      break;
    }
  if (bad < 0) return;
  throw SolverError(msg(fn, ": finite inputs overflow double precision: ", out_name, "[", bad,
                        "] = ", out[bad], largest_input(inputs), " (scale the inputs down)"));
}

/// "; the largest input is tau[1] = 1.7e+308": the input entry of largest magnitude.
std::string largest_input(std::initializer_list<Input> inputs, double* peak_out) {
  const Input* big = nullptr;
  long at = 0;
  double peak = -1.0;
  for (const Input& in : inputs)
    for (long i = 0; i < in.size; ++i)
      if (std::abs(in.data[i]) > peak) {
        peak = std::abs(in.data[i]);
        big = &in;
        at = i;
      }
  if (peak_out) *peak_out = peak;
  return big ? msg("; the largest input is ", big->name, "[", at, "] = ", big->data[at]) : "";
}

/// f(), its SolverError naming the largest input when that is beyond 1e150 (products of two
/// such numbers overflow: the Cartesian path reports "non-finite accelerations" then).
template <class F>
decltype(auto) naming_huge_inputs(const char* fn, std::initializer_list<Input> inputs, F&& f) {
  try {
    return f();
  } catch (const PyCallbackError&) {
    throw;
  } catch (const SolverError& e) {
    double peak = 0.0;
    const std::string culprit = largest_input(inputs, &peak);
    if (!(peak > 1e150)) throw;
    std::throw_with_nested(SolverError(
        msg(fn, ": ", e.what(), culprit, " (beyond 1e150: products overflow; scale it down)")));
  }
}

template <class V>
Input input(const char* name, const V& v) {
  return Input{name, v.data(), static_cast<long>(v.size())};
}

/// q with every floating base's position set to zero (kept in buf): the mass matrix does not
/// depend on where a floating base is, and the CRBA's world-frame products lose precision
/// with the square of its distance from the origin (1e-3 relative at 1e6 m, overflow past
/// 1e154 m). q itself when the model has no floating base.
Eigen::Ref<const VecX> at_origin(const Model& m, Eigen::Ref<const VecX> q, VecX& buf) {
  if (m.n_free == 0) return q;
  buf = q;
  for (int k = 0; k < m.n_free; ++k) buf.segment<3>(7 * k).setZero();
  return buf;
}

py::array_t<double> vector_out(const VecX& v) {
  py::array_t<double> a(v.size());
  std::copy(v.data(), v.data() + v.size(), a.mutable_data());
  return a;
}

/// A frame argument: its name (str) or its index into model.frame_names (int).
int frame_arg(const Model& md, const py::handle& frame, const char* fn) {
  if (py::isinstance<py::str>(frame)) return md.find_frame(str_arg(frame, fn, "frame"));
  // an int, or any integer type (numpy's too), never a bool
  if (PyIndex_Check(frame.ptr()) && !py::isinstance<py::bool_>(frame)) {
    const auto index = py::reinterpret_steal<py::int_>(PyNumber_Index(frame.ptr()));
    if (!index) throw py::error_already_set();
    int overflow = 0;
    const long long k = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
    const long long nf = static_cast<long long>(md.frames.size());
    if (overflow != 0 || k < 0 || k >= nf)
      throw ModelError(msg(fn, ": frame index ", py::str(index).cast<std::string>(),
                           " out of range (the model has ", nf, " frames)"));
    return static_cast<int>(k);
  }
  throw ModelError(msg(fn, ": frame must be a frame name (str) or an index (int), got ",
                       py::str(py::type::of(frame)).cast<std::string>()));
}

/// out (rows, *shape) from f(q_i, out_i) for each row of a 2-D q, or (shape) for a 1-D q; f
/// writes row-major.
template <class Fn>
py::array_t<double> per_state(const char* fn, const char* qname, long n, const py::handle& q,
                              std::vector<py::ssize_t> shape, Fn&& f) {
  long size = 1;
  for (auto s : shape) size *= static_cast<long>(s);
  const auto qa = as_array(q, msg(fn, ": ", qname));  // nested lists too
  if (qa.ndim() == 2) {
    const long rows = static_cast<long>(qa.shape(0));
    const auto Q = rows_of(qa, fn, qname, rows, n);
    shape.insert(shape.begin(), rows);
    py::array_t<double> out(shape);
    for (long i = 0; i < rows; ++i) {
      const Eigen::Map<const VecX> qi(Q.data() + i * n, n);
      try {
        f(qi, out.mutable_data() + i * size);
        finite_out(fn, "the result", out.data() + i * size, size, {input(qname, qi)});
      } catch (const ModelError& e) {
        throw ModelError(msg("row ", i, ": ", e.what()));
      } catch (const SolverError& e) {
        throw SolverError(msg("row ", i, ": ", e.what()));
      }
    }
    return out;
  }
  const VecArg one(qa, msg(fn, ": ", qname).c_str(), n);
  py::array_t<double> out(shape);
  f(*one, out.mutable_data());
  finite_out(fn, "the result", out.data(), size, {input(qname, *one)});
  return out;
}

void copy_row_major(const Mat4& T, double* out) {
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out[4 * r + c] = T(r, c);
}

template <class M>
void copy_row_major(const M& J, double* out) {
  const long cols = J.cols();
  for (long r = 0; r < J.rows(); ++r)
    for (long c = 0; c < cols; ++c) out[r * cols + c] = J(r, c);
}

}  // namespace

void bind_algorithm(py::module_& m) {
  py::class_<DataPy>(m, "Data",
                     "Workspace of one model's evaluations: every buffer forward_dynamics, "
                     "inverse_dynamics and mass_matrix write. One per thread; pass it as data= "
                     "to choose it explicitly (otherwise each thread keeps one per model).")
      .def(py::init([](const ModelArg& model) {
             return std::make_unique<DataPy>(model_of(model, "Data"));
           }),
           py::arg("model"),
           "A workspace for `model` (an armdyn.Model); ModelError if model is None.")
      .def_property_readonly(
          "model", [](const DataPy& d) { return d.model; }, "The model this workspace serves.");

  m.def(
      "forward_dynamics",
      [](const ModelArg& model_, const ArrayLike& q, const ArrayLike& qd, const ArrayLike& tau,
         const FloatOrArray& t, const StrArg& method, const OptData& data) {
        constexpr const char* fn = "forward_dynamics";
        const ModelHolder md = model_of(model_, fn);
        Data& d = data_for(md, data, fn);
        const DynamicsMethod mth = dynamics_method(str_arg(method, fn, "method"), fn);
        const Model& mm = *md;
        if (is_batch(q))
          return batch(fn, d.niq, d.ni, q, qd, "qd", tau, "tau", t, {d.ni},
                       [&](auto qi, auto qdi, auto ti, double tt, double* out) {
                         const auto in = {input("q", qi), input("qd", qdi), input("tau", ti)};
                         const VecX& r = naming_huge_inputs(fn, in, [&]() -> const VecX& {
                           return forward_dynamics(mm, d, qi, qdi, ti, tt, mth);
                         });
                         finite_out(fn, "qdd", r.data(), d.ni, in);
                         std::copy(r.data(), r.data() + d.ni, out);
                       });
        const VecArg qa(q, "q", d.niq), qda(qd, "qd", d.ni), ta(tau, "tau", d.ni);
        const double tt = scalar_time(t, fn);
        const auto in = {input("q", *qa), input("qd", *qda), input("tau", *ta)};
        const VecX& r = naming_huge_inputs(fn, in, [&]() -> const VecX& {
          return forward_dynamics(mm, d, *qa, *qda, *ta, tt, mth);
        });
        finite_out(fn, "qdd", r.data(), d.ni, in);
        return vector_out(r);
      },
      py::arg("model"), py::arg("q"), py::arg("qd"), py::arg("tau"), py::arg("t") = 0.0,
      py::arg("method") = "auto", py::arg("data") = py::none(),
      "Joint accelerations qdd of a tree for joint torques/forces tau at (q, qd) and time t "
      "[s] (q: n_coords, the others n_dofs; a coupled model's independent coordinates, followers "
      "of couplings removed, as Pinocchio's mimic=True models; 2-D: one state per row). method: "
      "'crba' (CRBA mass matrix, "
      "recursive Newton-Euler bias, Cholesky), 'aba' (articulated-body algorithm, O(n)), "
      "'cartesian' (the constrained Newton-Euler KKT system of the bodies), 'joint' (the "
      "cheaper of crba and aba for this model), 'auto' (the cheapest of the three); the choice "
      "comes from a measured cost model (dynamics_cost). The model's force elements act; "
      "drives are ignored.");

  m.def(
      "dynamics_cost",
      [](const ModelArg& model_) {
        const ModelHolder md = model_of(model_, "dynamics_cost");
        const DynamicsCost& c = dynamics_cost(*md);
        auto lower = [](DynamicsMethod x) {
          return x == DynamicsMethod::Aba    ? "aba"
                 : x == DynamicsMethod::Crba ? "crba"
                                             : "cartesian";
        };
        py::dict r;
        r["nb"] = c.nb;
        r["n"] = c.n;
        r["path"] = c.path;
        r["crba_us"] = c.crba;
        r["aba_us"] = c.aba;
        r["cartesian_us"] = c.cartesian;
        r["joint"] = lower(c.joint);
        r["light"] = c.light;
        r["auto"] = lower(c.best);
        r["joint_rhs_us"] = c.joint_rhs;
        r["cartesian_rhs_us"] = c.cartesian_rhs;
        r["simulate"] = c.joint_rhs_cheaper ? "joint" : "cartesian";
        return r;
      },
      py::arg("model"),
      "The measured cost model's prediction for a model (derived once per model): microseconds "
      "per forward_dynamics call by 'crba', 'aba' and 'cartesian', the algorithms method='joint' "
      "and method='auto' take, and the microseconds per right-hand side of simulate in joint "
      "space and in Cartesian coordinates with the formulation coordinates='auto' takes where "
      "both apply.");

  m.def(
      "inverse_dynamics",
      [](const ModelArg& model_, const ArrayLike& q, const ArrayLike& qd, const ArrayLike& qdd,
         const FloatOrArray& t, const StrArg& method, const OptData& data) {
        constexpr const char* fn = "inverse_dynamics";
        const ModelHolder md = model_of(model_, fn);
        Data& d = data_for(md, data, fn);
        const DynamicsMethod mth = dynamics_method(str_arg(method, fn, "method"), fn, false);
        const Model& mm = *md;
        if (is_batch(q))
          return batch(fn, d.niq, d.ni, q, qd, "qd", qdd, "qdd", t, {d.ni},
                       [&](auto qi, auto qdi, auto ai, double tt, double* out) {
                         const VecX& r = inverse_dynamics(mm, d, qi, qdi, ai, tt, mth);
                         finite_out(fn, "tau", r.data(), d.ni,
                                    {input("q", qi), input("qd", qdi), input("qdd", ai)});
                         std::copy(r.data(), r.data() + d.ni, out);
                       });
        const VecArg qa(q, "q", d.niq), qda(qd, "qd", d.ni), aa(qdd, "qdd", d.ni);
        const VecX& r = inverse_dynamics(mm, d, *qa, *qda, *aa, scalar_time(t, fn), mth);
        finite_out(fn, "tau", r.data(), d.ni,
                   {input("q", *qa), input("qd", *qda), input("qdd", *aa)});
        return vector_out(r);
      },
      py::arg("model"), py::arg("q"), py::arg("qd"), py::arg("qdd"), py::arg("t") = 0.0,
      py::arg("method") = "auto", py::arg("data") = py::none(),
      "Joint torques/forces tau realising qdd at (q, qd) and time t [s] (q: n_coords, the others "
      "n_dofs; a coupled model's independent coordinates, tau = G^T tau_full; 2-D: "
      "one state per row): what each joint's actuator applies to its child about/along the "
      "joint axis, gravity and the model's force elements included, drives ignored. method: "
      "'joint' (recursive Newton-Euler), 'cartesian' (every coordinate driven, the drives' KKT "
      "multipliers), 'auto' (joint).");

  m.def(
      "mass_matrix",
      [](const ModelArg& model_, const ArrayLike& q, const OptData& data) {
        constexpr const char* fn = "mass_matrix";
        const ModelHolder md = model_of(model_, fn);
        Data& d = data_for(md, data, fn);
        const Model& mm = *md;
        const long n = d.ni;
        VecX q0;  // q with the floating bases moved to the origin (at_origin)
        // M is symmetric: its column-major storage is also its row-major one
        if (is_batch(q))
          return batch(fn, d.niq, d.niq, q, q, "q", q, "q", py::float_(0.0), {n, n},
                       [&](auto qi, auto, auto, double, double* out) {
                         const MatX& M = crba(mm, d, at_origin(mm, qi, q0));
                         finite_out(fn, "M (column-major)", M.data(), n * n, {input("q", qi)});
                         std::copy(M.data(), M.data() + n * n, out);
                       });
        const VecArg qa(q, "q", d.niq);
        const MatX& M = crba(mm, d, at_origin(mm, *qa, q0));
        finite_out(fn, "M (column-major)", M.data(), n * n, {input("q", *qa)});
        py::array_t<double> a({n, n});
        std::copy(M.data(), M.data() + n * n, a.mutable_data());
        return a;
      },
      py::arg("model"), py::arg("q"), py::arg("data") = py::none(),
      "The joint-space mass matrix M(q) (n_dofs, n_dofs) of a tree, by the "
      "composite-rigid-body algorithm (a coupled model's in its independent coordinates, "
      "G^T M G); 2-D q (one state per row) gives (rows, n, n).");

  m.def(
      "frame_pose",
      [](const ModelArg& model_, const ArrayLike& q, const FrameRef& frame, const OptData& data) {
        constexpr const char* fn = "frame_pose";
        const ModelHolder md = model_of(model_, fn);
        Data& d = data_for(md, data, fn);
        const Model& mm = *md;
        require_joint_space(mm, fn, true);
        const int f = frame_arg(mm, frame, fn);
        return per_state(fn, "q", d.niq, q, {4, 4}, [&](const auto& qi, double* out) {
          copy_row_major(frame_pose(mm, d, qi, f), out);
        });
      },
      py::arg("model"), py::arg("q"), py::arg("frame"), py::arg("data") = py::none(),
      "The world pose of a named frame (a name of model.frame_names or its index) at joint "
      "coordinates q: the 4x4 homogeneous transform [R p; 0 1], R the frame's axes in world "
      "(frame -> world) and p its origin [m]; 2-D q (one state per row) gives (rows, 4, 4).");

  m.def(
      "frame_jacobian",
      [](const ModelArg& model_, const ArrayLike& q, const FrameRef& frame, const OptData& data) {
        constexpr const char* fn = "frame_jacobian";
        const ModelHolder md = model_of(model_, fn);
        Data& d = data_for(md, data, fn);
        const Model& mm = *md;
        require_joint_space(mm, fn, true);
        const int f = frame_arg(mm, frame, fn);
        return per_state(fn, "q", d.niq, q, {6, d.ni}, [&](const auto& qi, double* out) {
          copy_row_major(frame_jacobian(mm, d, qi, f), out);
        });
      },
      py::arg("model"), py::arg("q"), py::arg("frame"), py::arg("data") = py::none(),
      "The Jacobian (6, n_dofs) of a named frame at joint-space q (n_coords): linear rows then "
      "angular rows, world axes, at the frame's origin (Pinocchio's LOCAL_WORLD_ALIGNED), so "
      "that [v; omega] of the frame = J qd (a floating base's six columns first; a coupled "
      "model's independent coordinates, J G). 2-D q gives (rows, 6, n_dofs).");

  m.def(
      "frame_pose_cartesian",
      [](const ModelArg& model_, const ArrayLike& u, const FrameRef& frame, const OptData& data) {
        constexpr const char* fn = "frame_pose_cartesian";
        const ModelHolder md = model_of(model_, fn);
        Data& d = data_for(md, data, fn);
        const Model& mm = *md;
        const int f = frame_arg(mm, frame, fn);
        return per_state(fn, "u", mm.nq, u, {4, 4}, [&](const auto& ui, double* out) {
          copy_row_major(frame_pose_cartesian(mm, d, ui, f), out);
        });
      },
      py::arg("model"), py::arg("u"), py::arg("frame"), py::arg("data") = py::none(),
      "frame_pose from the Cartesian state u (nq; any model, loops included): the 4x4 world "
      "pose of a named frame; 2-D u gives (rows, 4, 4).");

  m.def(
      "frame_jacobian_cartesian",
      [](const ModelArg& model_, const ArrayLike& u, const FrameRef& frame, const OptData& data) {
        constexpr const char* fn = "frame_jacobian_cartesian";
        const ModelHolder md = model_of(model_, fn);
        Data& d = data_for(md, data, fn);
        const Model& mm = *md;
        const int f = frame_arg(mm, frame, fn);
        return per_state(fn, "u", mm.nq, u, {6, mm.nv}, [&](const auto& ui, double* out) {
          copy_row_major(frame_jacobian_cartesian(mm, d, ui, f), out);
        });
      },
      py::arg("model"), py::arg("u"), py::arg("frame"), py::arg("data") = py::none(),
      "The Jacobian (6, nv) of a named frame with respect to the bodies' velocities v of the "
      "Cartesian state (any model): linear rows then angular rows, world axes, at the frame's "
      "origin, so that [v; omega] of the frame = J v. 2-D u gives (rows, 6, nv).");
}

}  // namespace armdyn
