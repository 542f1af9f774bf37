// SPDX-License-Identifier: BSD-3-Clause
// Whole runs (armdyn/simulate/simulate.hpp): a pendulum's energy is conserved and its angle
// follows an independent RK4 integration of I_O phi'' = -m g L sin(phi); a prismatic body
// falls as g t^2 / 2; the Cartesian and joint-space formulations agree; a run on a reused Data
// equals a run on a new one, bit for bit.
#include <cmath>
#include <string>

#include "armdyn/builder/builder.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/simulate/simulate.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

namespace {

/// phi(t) of the pendulum from (phi0, 0) by classical RK4 with a fine step (the reference).
double pendulum_reference(const armdyn_test::Pendulum& p, double t_end) {
  const int n = 20000;
  const double h = t_end / n;
  double x = p.phi0, w = 0.0;
  for (int k = 0; k < n; ++k) {
    const double k1x = w, k1w = p.phidd(x);
    const double k2x = w + 0.5 * h * k1w, k2w = p.phidd(x + 0.5 * h * k1x);
    const double k3x = w + 0.5 * h * k2w, k3w = p.phidd(x + 0.5 * h * k2x);
    const double k4x = w + h * k3w, k4w = p.phidd(x + h * k3x);
    x += h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
    w += h / 6 * (k1w + 2 * k2w + 2 * k3w + k4w);
  }
  return x;
}

}  // namespace

TEST_CASE(pendulum_angle_and_energy) {
  armdyn_test::Pendulum p;
  p.phi0 = 1.2;
  const ModelPtr m = p.model();
  const double t_end = 2.0;
  for (const Coordinates coords : {Coordinates::Cartesian, Coordinates::Joint}) {
    SimOptions opt;
    opt.integrator = Integrator::Dop853;
    opt.step.rtol = 1e-11;
    opt.step.atol = 1e-12;
    opt.step.output_dt = 0.1;
    opt.coordinates = coords;
    const SimResult r = simulate(*m, t_end, opt, m->u0, m->v0);
    CHECK(r.error.empty());
    CHECK(r.n == 21);
    CHECK_NEAR(r.t.back(), t_end, 1e-12);
    CHECK_NEAR(p.phi0 + r.q.back(), pendulum_reference(p, t_end), 1e-8);
    const double e0 = r.kinetic_energy[0] + r.potential_energy[0];
    CHECK_NEAR(e0, -p.m * p.g * p.L * std::cos(p.phi0), 1e-12);  // V = m g z, at rest
    for (long k = 0; k < r.n; ++k) {
      CHECK_NEAR(r.kinetic_energy[k] + r.potential_energy[k], e0, 1e-8);
      // T = 1/2 I_O phi'^2
      CHECK_NEAR(r.kinetic_energy[k], 0.5 * p.io() * r.qd[k] * r.qd[k], 1e-12);
      CHECK(r.position_residual[k] < 1e-10);
    }
  }
}

TEST_CASE(prismatic_body_falls_at_g) {
  ModelBuilder b(Vec3(0, 0, -9.81));
  b.add_body("block", 2.0, Vec3(0.1, 0.1, 0.1).asDiagonal(), Vec3(0, 0, 5),
             armdyn_test::kIdentityQuat);
  b.add_prismatic("rail", "ground", "block", Vec3(0, 0, 5), Vec3::UnitZ());
  const ModelPtr m = b.finalize();
  SimOptions opt;
  opt.integrator = Integrator::Rk4;
  opt.step.dt = 0.01;
  opt.step.output_dt = 0.25;
  const SimResult r = simulate(*m, 1.0, opt, m->u0, m->v0);
  CHECK(r.n == 5);
  for (long k = 0; k < r.n; ++k) {
    const double t = r.t[k];
    CHECK_NEAR(r.q[k], -0.5 * 9.81 * t * t, 1e-12);
    CHECK_NEAR(r.qd[k], -9.81 * t, 1e-12);
    CHECK_NEAR(r.u[7 * k + 2], 5.0 - 0.5 * 9.81 * t * t, 1e-12);
    // the rail carries no load along itself; across it nothing (gravity is along the rail)
    CHECK_NEAR(r.qdd[k], -9.81, 1e-12);
  }
  CHECK(r.integrator == "rk4");
}

TEST_CASE(option_names_and_bad_options) {
  CHECK(integrator_from_name("dop853") == Integrator::Dop853);
  CHECK(std::string(integrator_name(Integrator::Trbdf2)) == "trbdf2");
  CHECK(coordinates_from_name("joint") == Coordinates::Joint);
  CHECK_THROWS(integrator_from_name("euler"), ModelError);
  CHECK_THROWS(coordinates_from_name("polar"), ModelError);
  const ModelPtr m = armdyn_test::Pendulum().model();
  SimOptions rk4;
  rk4.integrator = Integrator::Rk4;  // without a step
  CHECK_THROWS(simulate(*m, 1.0, rk4, m->u0, m->v0), ModelError);
  SimOptions ok;
  CHECK_THROWS(simulate(*m, 1.0, ok, VecX::Zero(3), m->v0), ModelError);
  CHECK_THROWS(simulate(*m, -1.0, ok, m->u0, m->v0), ModelError);
}

TEST_CASE(runs_on_a_reused_data_equal_runs_on_a_new_one) {
  // the two-link arm with a welded tool, a PI motor (an auxiliary state) and a driven variant:
  // every kind of run (welded Cartesian, joint space, RK4, TR-BDF2, kinematic) on one Data,
  // each equal to the same run on a new Data, whatever ran before on the reused one
  ModelBuilder b = armdyn_test::TwoLink().builder();
  b.add_body("tool", 0.4, Vec3(1e-3, 2e-3, 3e-3).asDiagonal(), Vec3(1.1, 0.0, 0.05),
             quat_exp(Vec3(0.3, -0.2, 0.1)));
  b.add_fixed("tool_mount", "link2", "tool", Vec3(1.0, 0, 0));
  b.add_motor("elbow", Profile::sine(0.5, 1.0, 0.0, 0.0), 20.0, 1.0, 1e300, nullptr, 0, 5.0);
  const ModelPtr m = b.finalize();
  ModelBuilder bd = armdyn_test::TwoLink().builder();
  bd.add_drive("shoulder", Profile::sine(0.8, 0.7, 0.0, 0.0));
  bd.add_drive("elbow", Profile::cubic(0.0, 1.2, 0.0, 1.0));
  const ModelPtr driven = bd.finalize();
  auto run = [](const Model& model, Data* d, Integrator integ, Coordinates coords,
                bool merge = true) {
    SimOptions o;
    o.integrator = integ;
    o.coordinates = coords;
    o.merge_welded = merge;
    o.step.rtol = 1e-9;
    o.step.atol = 1e-10;
    o.step.dt = integ == Integrator::Rk4 ? 1e-3 : 0.0;
    o.step.output_dt = 0.05;
    return d ? simulate(model, *d, 0.6, o, model.u0, model.v0)
             : simulate(model, 0.6, o, model.u0, model.v0);
  };
  auto same = [](const SimResult& a, const SimResult& b) {
    return a.n == b.n && a.t == b.t && a.u == b.u && a.v == b.v && a.q == b.q &&
           a.reaction_forces == b.reaction_forces && a.drive_forces == b.drive_forces &&
           a.kinetic_energy == b.kinetic_energy && a.stats.steps == b.stats.steps &&
           a.kkt_solves == b.kkt_solves && a.position_projections == b.position_projections &&
           a.error.empty() && b.error.empty();
  };
  Data d(*m);
  const std::pair<Integrator, Coordinates> kinds[] = {
      {Integrator::Dopri5, Coordinates::Cartesian}, {Integrator::Dop853, Coordinates::Joint},
      {Integrator::Rk4, Coordinates::Cartesian},    {Integrator::Trbdf2, Coordinates::Joint},
      {Integrator::Dopri5, Coordinates::Cartesian}, {Integrator::Dopri5, Coordinates::Joint}};
  for (const auto& [integ, coords] : kinds) {
    const SimResult fresh = run(*m, nullptr, integ, coords);
    CHECK(fresh.n == 13 && fresh.solver_bodies == 2);  // the tool welded to link 2
    CHECK(same(run(*m, &d, integ, coords), fresh));
  }
  // unwelded after welded on the same Data
  CHECK(same(run(*m, &d, Integrator::Dopri5, Coordinates::Cartesian, false),
             run(*m, nullptr, Integrator::Dopri5, Coordinates::Cartesian, false)));
  Data dd(*driven);
  for (int k = 0; k < 2; ++k)
    CHECK(same(run(*driven, &dd, Integrator::Default, Coordinates::Cartesian),
               run(*driven, nullptr, Integrator::Default, Coordinates::Cartesian)));
  CHECK_THROWS(run(*driven, &d, Integrator::Default, Coordinates::Cartesian), ModelError);
}

ARMDYN_TEST_MAIN()
