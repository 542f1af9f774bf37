// SPDX-License-Identifier: BSD-3-Clause
// A batch of runs (armdyn.rollout): simulate() from many initial states on a pool of threads,
// one Data per thread, with the calling thread waiting (and checking for cancellation).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "armdyn/model/model.hpp"
#include "armdyn/simulate/simulate.hpp"

namespace armdyn {

/// The runs of a batch: run k starts from (u0[k], v0[k]), and from the independent joint-space
/// q_start[k] when q_start is not empty (q_start_from_independent); errors[k] non-empty: run k
/// is not run (its result keeps that message as its error).
struct BatchRuns {
  std::vector<VecX> u0, v0, q_start;
  std::vector<std::string> errors;
};

/// Called on the calling thread every 20 ms while the batch runs, with the number of runs
/// finished so far; true stops the batch: runs in flight end at their next poll (every 5 ms,
/// with their outputs so far) and runs not started are not run.
using BatchWait = std::function<bool(long done)>;

/// simulate(m, d, t_end, opt, ...) of every run of `runs` on min(threads, runs) threads (a work
/// queue; a thread that cannot start leaves its share to the others), one Data per thread (made
/// afresh after a run that threw). A run that throws has the exception's message as its error;
/// after a stop, a run not started has the error "interrupted before the run started". The
/// results in run order. opt.step.poll is replaced by each thread's own (the batch's stop).
/// @throws ModelError when runs' sizes disagree, threads < 1, or a q_start row is not
///   model.independent.nq() long.
std::vector<SimResult> simulate_batch(const Model& m, double t_end, const SimOptions& opt,
                                      BatchRuns runs, int threads, const BatchWait& wait);

}  // namespace armdyn
