// SPDX-License-Identifier: BSD-3-Clause
// Poll: the cancellation and progress hook of a long C++ loop (the integrators, the kinematic
// path, batches of inverse dynamics). The loop calls poll(t, t_end) once per iteration; that is
// a counter increment, and every `stride` calls a steady-clock read; every `interval` seconds of
// wall time the callback runs with the loop's progress (t of t_end), and the cancel flag is read
// at each clock read. Either may stop the loop by throwing Interrupted (the callback: any
// exception, which propagates out of the loop unchanged). The stride adapts so that the clock is
// read a few times per interval, whatever an iteration costs.
//
// One Poll per thread and loop (it keeps its own clock); threads of one batch share a callback
// only if it is thread-safe, and share a std::atomic<bool> cancel flag that one of them (or the
// caller's thread) sets.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>

#include "armdyn/errors.hpp"

namespace armdyn {

class Poll {
 public:
  using Callback = std::function<void(double t, double t_end)>;
  using Clock = std::chrono::steady_clock;

  Poll() = default;
  /// callback: called every `interval` seconds of wall time (may be empty); cancel: a flag
  /// another thread sets to stop the loop (may be null).
  explicit Poll(Callback callback, double interval = 0.005,
                const std::atomic<bool>* cancel = nullptr)
      : callback_(std::move(callback)), cancel_(cancel), interval_(interval) {}

  /// Restart the clock (a loop's start; the first callback comes one interval later).
  void start() {
    last_ = read_ = Clock::now();
    count_ = 0;
    stride_ = 1;
  }

  /// Called once per iteration of a loop at time t of t_end.
  void operator()(double t, double t_end) {
    if (++count_ < stride_) return;
    due(t, t_end);
  }

 private:
  void due(double t, double t_end) {
    count_ = 0;
    if (cancel_ && cancel_->load(std::memory_order_relaxed)) throw Interrupted("run cancelled");
    const Clock::time_point now = Clock::now();
    // a few clock reads per interval: the stride doubles while they come more often than
    // 8 per interval and halves when one comes later than half an interval
    const double since_read = std::chrono::duration<double>(now - read_).count();
    read_ = now;
    if (since_read < interval_ / 8) {
      if (stride_ < kMaxStride) stride_ *= 2;
    } else if (since_read > interval_ / 2 && stride_ > 1) {
      stride_ /= 2;
    }
    if (std::chrono::duration<double>(now - last_).count() < interval_) return;
    last_ = now;
    if (callback_) callback_(t, t_end);
  }

  static constexpr long kMaxStride = 1024;
  Callback callback_;
  const std::atomic<bool>* cancel_ = nullptr;
  double interval_ = 0.005;
  Clock::time_point last_ = Clock::now(), read_ = last_;
  long count_ = 0, stride_ = 1;
};

/// The poll of the calling thread's long call that has no loop options of its own (finalize on
/// a large model, the URDF reader): set by ScopedThreadPoll, read by poll_point(); null: none.
inline Poll*& thread_poll() {
  static thread_local Poll* poll = nullptr;
  return poll;
}

/// One unit of work of such a call: the thread's poll, if any, may stop it (its exception).
inline void poll_point() {
  if (Poll* p = thread_poll()) (*p)(0.0, 0.0);
}

/// Sets the thread's poll for a scope (and restores the previous one).
class ScopedThreadPoll {
 public:
  explicit ScopedThreadPoll(Poll* poll) : previous_(thread_poll()) {
    thread_poll() = poll;
    if (poll) poll->start();
  }
  ~ScopedThreadPoll() { thread_poll() = previous_; }
  ScopedThreadPoll(const ScopedThreadPoll&) = delete;
  ScopedThreadPoll& operator=(const ScopedThreadPoll&) = delete;

 private:
  Poll* previous_;
};

}  // namespace armdyn
