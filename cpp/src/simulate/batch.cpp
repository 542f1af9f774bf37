// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/simulate/batch.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>

#include "armdyn/data.hpp"
#include "armdyn/errors.hpp"

namespace armdyn {

namespace {

/// The shared state of a batch: the work queue (an atomic index), the count of runs done, the
/// stop flag, and the count of threads still running (under `mutex`).
struct BatchQueue {
  std::atomic<long> next{0}, done{0};
  std::atomic<bool> stop{false};
  std::mutex mutex;
  std::condition_variable finished;
  int running = 0;
};

/// One thread's share: runs taken from the queue until it is empty or the batch stops.
void work_through(const Model& m, double t_end, const SimOptions& base, BatchRuns& runs,
                  std::vector<SimResult>& results, BatchQueue& q) {
  const long n = static_cast<long>(runs.u0.size());
  std::unique_ptr<Data> d;
  // cancellation: between runs, and inside a run by the stepping loops' poll, which checks
  // `stop` every few milliseconds (the run then ends with its outputs so far)
  Poll poll(Poll::Callback(), 0.005, &q.stop);
  SimOptions o = base;
  o.step.poll = &poll;
  while (!q.stop.load(std::memory_order_relaxed)) {
    const long k = q.next.fetch_add(1);
    if (k >= n) break;
    if (!runs.errors[k].empty()) continue;
    try {
      if (!d) d = std::make_unique<Data>(m);
      if (!runs.q_start.empty()) o.q_start = runs.q_start[k];
      results[k] = simulate(m, *d, t_end, o, runs.u0[k], runs.v0[k]);
    } catch (const std::exception& e) {
      runs.errors[k] = e.what();
      d.reset();  // a run cut short by an exception: the next one starts afresh
    }
    q.done.fetch_add(1, std::memory_order_relaxed);
  }
  std::lock_guard<std::mutex> lock(q.mutex);
  if (--q.running == 0) q.finished.notify_all();
}

/// The calling thread: waits for the pool, calling wait(done) every 20 ms until it stops the
/// batch.
void wait_for_pool(BatchQueue& q, const BatchWait& wait) {
  std::unique_lock<std::mutex> lock(q.mutex);
  while (q.running > 0) {
    if (q.finished.wait_for(lock, std::chrono::milliseconds(20), [&] { return q.running == 0; }))
      break;
    if (!q.stop.load()) {
      lock.unlock();
      if (wait && wait(q.done.load())) q.stop = true;
      lock.lock();
    }
  }
}

void check_runs(const BatchRuns& runs, int threads) {
  const size_t n = runs.u0.size();
  if (runs.v0.size() != n)
    throw ModelError(msg("rollout: ", runs.v0.size(), " v0 rows for ", n, " runs"));
  if (runs.errors.size() != n)
    throw ModelError(msg("rollout: ", runs.errors.size(), " error entries for ", n, " runs"));
  if (threads < 1) throw ModelError(msg("rollout: threads must be >= 1, got ", threads));
  if (!runs.q_start.empty() && runs.q_start.size() != n)
    throw ModelError(msg("rollout: ", runs.q_start.size(), " q0 rows for ", n, " runs"));
}

}  // namespace

std::vector<SimResult> simulate_batch(const Model& m, double t_end, const SimOptions& opt,
                                      BatchRuns runs, int threads, const BatchWait& wait) {
  check_runs(runs, threads);
  const long n = static_cast<long>(runs.u0.size());
  for (long k = 0; k < static_cast<long>(runs.q_start.size()); ++k)
    if (runs.errors[k].empty()) {
      // a loop or geared model's start solved alone: a run that does not assemble fails alone
      try {
        runs.q_start[k] = q_start_from_independent(m, runs.q_start[k]);
      } catch (const SolverError& e) {
        runs.errors[k] = e.what();
      }
    }
  std::vector<SimResult> results(n);
  const int nt = static_cast<int>(std::min<long>(threads, std::max<long>(n, 1)));
  BatchQueue q;
  q.running = nt;
  std::vector<std::thread> pool;
  pool.reserve(nt);
  try {
    for (int i = 0; i < nt; ++i)
      pool.emplace_back([&] { work_through(m, t_end, opt, runs, results, q); });
  } catch (...) {
    // could not start a thread: the started ones finish the queue
    std::lock_guard<std::mutex> lock(q.mutex);
    q.running -= nt - static_cast<int>(pool.size());
  }
  wait_for_pool(q, wait);
  for (auto& t : pool) t.join();
  for (long k = 0; k < n; ++k) {
    SimResult& r = results[k];
    if (r.error.empty() && !runs.errors[k].empty()) r.error = runs.errors[k];
    if (r.error.empty() && q.stop && r.t.empty() && r.n == 0)
      r.error = "interrupted before the run started";
  }
  return results;
}

}  // namespace armdyn
