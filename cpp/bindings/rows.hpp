// SPDX-License-Identifier: BSD-3-Clause
// The calling conventions of the joint-space functions (bind_algorithm.cpp, bind_frames.cpp): the
// model and workspace arguments (armdyn.Data, or one Data per thread and model), one state (1-D
// arrays) or one state per row (2-D arrays, evaluated in one C++ loop without the GIL, an error
// naming its row), frames by name or index, and row-major copies of the outputs.
#pragma once

#include <pybind11/numpy.h>

#include <initializer_list>
#include <memory>
#include <vector>

#include "armdyn/algorithm/output_check.hpp"
#include "armdyn/data.hpp"
#include "common.hpp"
#include "output_pool.hpp"

namespace armdyn::py_helpers {

using ModelHolder = std::shared_ptr<Model>;

/// armdyn.Data: a workspace with its model kept alive.
struct DataPy {
  explicit DataPy(ModelHolder md) : model(std::move(md)), data(*model) {}
  ModelHolder model;
  Data data;
};

/// The model argument of a dynamics function: an armdyn.Model, else a ModelError naming it.
inline ModelHolder model_of(const ModelArg& model, const char* fn) {
  if (!py::isinstance<Model>(model))
    throw ModelError(msg(fn, ": model must be an armdyn.Model, got ", shown(model)));
  return model.cast<ModelHolder>();
}

/// This thread's workspace for md: the last few models used, the most recent first.
inline Data& cached_data(const ModelHolder& md) {
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

/// The workspace of a call: data (an armdyn.Data of md), or this thread's for md when None.
inline Data& data_for(const ModelHolder& md, const py::object& data, const char* fn) {
  if (!md) throw ModelError(msg(fn, ": no model"));
  if (data.is_none()) return cached_data(md);
  if (!py::isinstance<DataPy>(data))
    throw ModelError(msg(fn, ": data must be an armdyn.Data (or None)"));
  auto* d = data.cast<DataPy*>();
  check_data(*md, d->data, fn);
  return d->data;
}

/// The model and the workspace of a call (model_of, data_for).
struct CallArgs {
  ModelHolder holder;
  Data& data;
  const Model& model() const { return *holder; }
};

inline CallArgs call_args(const ModelArg& model, const py::object& data, const char* fn) {
  ModelHolder md = model_of(model, fn);
  Data& d = data_for(md, data, fn);
  return CallArgs{std::move(md), d};
}

inline bool is_batch(const py::handle& q) {
  return py::isinstance<py::array>(q) && py::reinterpret_borrow<py::array>(q).ndim() == 2;
}

inline double scalar_time(const py::handle& t, const char* fn) {
  if (PyFloat_Check(t.ptr())) return PyFloat_AS_DOUBLE(t.ptr());
  try {
    return t.cast<double>();
  } catch (const py::cast_error&) {
    throw ModelError(msg(fn, ": t must be a number (or one per row of a 2-D q)"));
  }
}

/// A (rows, n) float64 C-contiguous array of a 2-D argument (converted when needed).
inline py::array_t<double> rows_of(const py::handle& obj, const char* fn, const char* name,
                                   long rows, long n) {
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
  py::array_t<double> out = OutputPool::get().array(out_shape);
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

/// f(), its SolverError naming the largest input when that is beyond 1e150 (products of two
/// such numbers overflow: the Cartesian path reports "non-finite accelerations" then); a
/// Python callback's error passes as it is.
template <class F>
decltype(auto) naming_huge_inputs(const char* fn, std::initializer_list<NamedInput> inputs, F&& f) {
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

inline py::array_t<double> vector_out(const VecX& v) {
  py::array_t<double> a(v.size());
  std::copy(v.data(), v.data() + v.size(), a.mutable_data());
  return a;
}

/// A frame argument: its name (str) or its index into model.frame_names (int).
inline int frame_arg(const Model& md, const py::handle& frame, const char* fn) {
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
        check_finite_output(fn, "the result", out.data() + i * size, size,
                            {named_input(qname, qi)});
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
  check_finite_output(fn, "the result", out.data(), size, {named_input(qname, *one)});
  return out;
}

inline void copy_row_major(const Mat4& T, double* out) {
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out[4 * r + c] = T(r, c);
}

template <class M>
void copy_row_major(const M& J, double* out) {
  const long cols = J.cols();
  for (long r = 0; r < J.rows(); ++r)
    for (long c = 0; c < cols; ++c) out[r * cols + c] = J(r, c);
}

/// A (rows, cols) matrix of a 2-D argument, or one row of a 1-D one (cols,).
inline MatX to_mat(const py::handle& obj, const std::string& name, long cols) {
  auto a = as_array(obj, name);
  if (a.ndim() == 1 && a.shape(0) == cols) {
    MatX m(1, cols);
    for (long j = 0; j < cols; ++j) m(0, j) = a.at(j);
    return m;
  }
  if (a.ndim() != 2 || a.shape(1) != cols)
    throw ModelError(msg(name, ": expected shape (n, ", cols, "), got ", shape_str(a)));
  MatX m(a.shape(0), cols);
  for (long i = 0; i < a.shape(0); ++i)
    for (long j = 0; j < cols; ++j) m(i, j) = a.at(i, j);
  return m;
}

/// rows as a float64 array: (rows, cols), or (cols,) when the argument `like` was 1-D.
inline py::array_t<double> rows_out(const MatX& rows, const py::handle& like,
                                    const std::string& name) {
  if (as_array(like, name).ndim() == 1) return to_numpy(VecX(rows.row(0).transpose()));
  return to_numpy(rows);
}

}  // namespace armdyn::py_helpers
