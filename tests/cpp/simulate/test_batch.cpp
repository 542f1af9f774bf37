// SPDX-License-Identifier: BSD-3-Clause
// A batch of runs (armdyn/simulate/batch.hpp): each run of simulate_batch equals simulate() from
// the same state, bit for bit, whatever the number of threads; runs with an error are skipped;
// a stop from the waiting thread leaves every run either complete or with its error; bad
// arguments are refused. The result's field list (armdyn/simulate/result.hpp): output_row_bytes
// is the size of every table's row.
#include <atomic>
#include <cmath>
#include <string>

#include "armdyn/errors.hpp"
#include "armdyn/simulate/batch.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

namespace {

SimOptions options(double rtol) {
  SimOptions opt;
  opt.integrator = Integrator::Dop853;
  opt.step.rtol = rtol;
  opt.step.atol = rtol;
  opt.step.output_dt = 0.05;
  return opt;
}

/// Runs of the two-link arm from rest at shoulder angles 0.1 k (u0, v0 by simulate's joint start).
BatchRuns arm_runs(const Model& m, int n) {
  BatchRuns runs;
  for (int k = 0; k < n; ++k) {
    VecX q(2), qd = VecX::Zero(2), u, v;
    q << 0.1 * k, -0.05 * k;
    state_from_joints(m, q, qd, u, v);
    runs.u0.push_back(u);
    runs.v0.push_back(v);
    runs.q_start.push_back(q);
  }
  runs.errors.assign(n, "");
  return runs;
}

bool same(const SimResult& a, const SimResult& b) {
  return a.n == b.n && a.t == b.t && a.u == b.u && a.q == b.q && a.qd == b.qd &&
         a.joint_torques == b.joint_torques && a.stats.steps == b.stats.steps &&
         a.kkt_solves == b.kkt_solves && a.error == b.error;
}

}  // namespace

TEST_CASE(batch_runs_equal_single_runs) {
  const ModelPtr m = armdyn_test::TwoLink().model();
  const SimOptions opt = options(1e-9);
  BatchRuns runs = arm_runs(*m, 5);
  runs.errors[3] = "refused before the run";
  for (int threads : {1, 2, 8}) {
    const std::vector<SimResult> rs = simulate_batch(*m, 0.5, opt, runs, threads, nullptr);
    CHECK(rs.size() == 5);
    for (int k = 0; k < 5; ++k) {
      if (k == 3) {
        CHECK(rs[k].error == "refused before the run" && rs[k].n == 0);
        continue;
      }
      SimOptions o = opt;
      o.q_start = runs.q_start[k];  // a tree without couplings: the independent q is q
      const SimResult one = simulate(*m, 0.5, o, runs.u0[k], runs.v0[k]);
      CHECK(one.error.empty() && one.n == 11);
      CHECK(same(rs[k], one));
    }
  }
}

TEST_CASE(a_stop_leaves_runs_complete_or_with_their_error) {
  const ModelPtr m = armdyn_test::TwoLink().model();
  // long, tight runs: the batch is still running at the first wait (20 ms)
  const SimOptions opt = options(1e-13);
  BatchRuns runs = arm_runs(*m, 40);
  std::atomic<int> waits{0};
  const std::vector<SimResult> rs = simulate_batch(*m, 200.0, opt, runs, 1, [&](long) {
    ++waits;
    return true;
  });
  CHECK(waits == 1);
  int stopped = 0;
  for (const SimResult& r : rs) {
    if (r.error.empty()) {
      CHECK(r.n > 0 && std::abs(r.t.back() - 200.0) < 1e-9);
    } else {
      ++stopped;
      CHECK(r.interrupted || r.error == "interrupted before the run started");
    }
  }
  CHECK(stopped > 0);
  CHECK(rs.back().error == "interrupted before the run started");
}

TEST_CASE(bad_batches_are_refused) {
  const ModelPtr m = armdyn_test::TwoLink().model();
  const SimOptions opt = options(1e-6);
  BatchRuns runs = arm_runs(*m, 2);
  CHECK(THROWN_MESSAGE(simulate_batch(*m, 0.1, opt, runs, 0, nullptr), ModelError) ==
        "rollout: threads must be >= 1, got 0");
  BatchRuns short_errors = runs;
  short_errors.errors.pop_back();
  CHECK(THROWN_MESSAGE(simulate_batch(*m, 0.1, opt, short_errors, 1, nullptr), ModelError) ==
        "rollout: 1 error entries for 2 runs");
  BatchRuns long_q = runs;
  long_q.q_start[1] = VecX::Zero(3);
  CHECK(THROWN_MESSAGE(simulate_batch(*m, 0.1, opt, long_q, 1, nullptr), ModelError) ==
        "q0 must have 2 entries, got 3");
}

TEST_CASE(output_row_bytes_is_every_tables_row) {
  const ModelPtr m = armdyn_test::TwoLink().model();
  const SimResult r = simulate(*m, 0.2, options(1e-8), m->u0, m->v0);
  CHECK(r.error.empty() && r.n > 1);
  // every table of the result, counted by hand; limit forces: at most one column per joint
  const size_t nj = m->joints.size();
  const size_t values = r.t.size() + r.u.size() + r.v.size() + r.q.size() + r.qd.size() +
                        r.qdd.size() + r.drive_forces.size() + r.joint_torques.size() +
                        r.reaction_forces.size() + r.reaction_torques.size() +
                        r.position_residual.size() + r.velocity_residual.size() +
                        r.kinetic_energy.size() + r.potential_energy.size() + r.gear_forces.size() +
                        r.limit_forces.size();
  const size_t limit_slack = (nj - r.limit_joints.size()) * static_cast<size_t>(r.n);
  CHECK(output_row_bytes(*m) * static_cast<size_t>(r.n) == (values + limit_slack) * sizeof(double));
  CHECK(std::string(limit_side_name(1)) == "lower" && std::string(limit_side_name(-1)) == "upper");
  CHECK(std::string(limit_event_kind_name(2)) == "release");
}

ARMDYN_TEST_MAIN()
