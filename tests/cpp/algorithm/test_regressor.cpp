// SPDX-License-Identifier: BSD-3-Clause
// The dynamic-parameter regressors (armdyn/algorithm/regressor.hpp) from C++: Y pi equals rnea
// and h . pi the energy of the Cartesian state, on a spatial arm (revolute and prismatic joints,
// gravity off the axes) with a gyroscopic and a gear-reduced actuator, joint friction and a
// coupling, and on the same arm on a floating base; the row-major and matrix outputs agree; no
// heap allocation after the first call on a Data.
#include <atomic>
#include <cstdlib>

#include "alloc_counter.hpp"
#include "armdyn/algorithm/energy.hpp"
#include "armdyn/algorithm/regressor.hpp"
#include "armdyn/algorithm/rnea.hpp"
#include "armdyn/builder/builder.hpp"
#include "armdyn/math/quaternion.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

namespace {

// the spatial arm with rotors, friction and a coupling (roll = 0.7 yaw + 0.1)
ModelPtr actuated_arm() {
  ModelBuilder b = armdyn_test::spatial_arm_builder();
  b.add_actuator("pitch", 30.0, 1e-4, 1.0, 0.0, 0.0, nullptr, true);
  b.add_actuator("reach", 200.0, 2e-5);
  b.add_joint_friction("reach", 0.4, 0.2, 0.01);
  b.add_joint_friction("yaw", 0.1, 0.3, 0.02);
  b.add_coupling("roll_follows_yaw", "roll", "yaw", 0.7, 0.1);
  return b.finalize();
}

// the spatial arm's links on a floating base (a free joint instead of the yaw hinge), with a
// gyroscopic rotor
ModelPtr floating_arm() {
  ModelBuilder b(Vec3(0.3, -0.2, -9.81));
  Mat3 i1;
  i1 << 0.05, 0.004, -0.002, 0.004, 0.06, 0.003, -0.002, 0.003, 0.03;
  b.add_body("base", 3.0, i1, Vec3(0.0, 0.02, 0.2), quat_exp(Vec3(0.1, -0.3, 0.2)));
  b.add_body("upper", 2.0, 0.4 * i1, Vec3(0.2, 0.05, 0.45), quat_exp(Vec3(-0.4, 0.2, 0.5)));
  b.add_body("slide", 0.8, 0.2 * i1, Vec3(0.45, 0.1, 0.5), armdyn_test::kIdentityQuat);
  b.add_free("float", "base");
  b.add_revolute("pitch", "base", "upper", Vec3(0.0, 0.03, 0.4), Vec3(0.1, 1, 0).normalized());
  b.add_prismatic("reach", "upper", "slide", Vec3(0.4, 0.08, 0.5), Vec3(1, 0.1, 0).normalized());
  // a gyroscopic rotor on the floating base: its column's rows on the free joint too
  b.add_actuator("pitch", 25.0, 3e-4, 1.0, 0.0, 0.0, nullptr, true);
  return b.finalize();
}

struct State {
  VecX q, qd, qdd;
};

State state(const Model& m, double phase) {
  const int nq = m.independent.nq(), nv = m.independent.nv();
  State s{VecX(nq), VecX(nv), VecX(nv)};
  for (int k = 0; k < nq; ++k) s.q[k] = std::sin(1.3 * k + phase);
  for (int f = 0; f < m.n_free; ++f) s.q.segment<4>(7 * f + 3).normalize();
  for (int k = 0; k < nv; ++k) {
    s.qd[k] = 0.5 - 0.23 * k + phase;
    s.qdd[k] = -0.4 + 0.31 * k - phase;
  }
  return s;
}

void check_regressor(const Model& m) {
  Data d(m), ref(m);
  const VecX pi = dynamic_parameters(m);
  MatX Y;
  for (double phase : {0.0, 0.7, -1.9}) {
    const State s = state(m, phase);
    joint_torque_regressor(m, d, s.q, s.qd, s.qdd, Y);
    CHECK(Y.rows() == d.ni && Y.cols() == pi.size());
    const VecX tau = rnea(m, ref, s.q, s.qd, s.qdd);
    CHECK_MAT_NEAR(VecX(Y * pi), tau, 1e-12 * std::max(1.0, tau.cwiseAbs().maxCoeff()));
    // the row-major output: the same numbers
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> R(Y.rows(), Y.cols());
    R.setConstant(7.0);  // every entry written
    joint_torque_regressor_into(m, d, s.q, s.qd, s.qdd, R.data());
    CHECK(MatX(R) == Y);
    // the energy of the Cartesian state
    VecX h, u, v;
    energy_regressor(m, d, s.q, s.qd, h);
    state_from_independent(m, s.q, s.qd, u, v, "test");
    double ke = 0.0, pe = 0.0;
    energy(m, ref, u.data(), v.data(), ke, pe);
    CHECK_NEAR(h.dot(pi), ke + pe, 1e-12 * (std::abs(ke) + std::abs(pe)));
  }
}

}  // namespace

TEST_CASE(y_pi_equals_rnea_with_rotors_friction_and_a_coupling) {
  const ModelPtr mp = actuated_arm();
  CHECK(mp->independent.nv() == 3);  // yaw, pitch, reach; roll follows yaw
  check_regressor(*mp);
}

TEST_CASE(y_pi_equals_rnea_on_a_floating_base) {
  const ModelPtr mp = floating_arm();
  CHECK(mp->n_free == 1 && mp->independent.nv() == 8 && mp->actuators.size() == 1);
  check_regressor(*mp);
}

TEST_CASE(the_layout_is_kept_with_the_model) {
  const ModelPtr mp = actuated_arm();
  const ParameterLayout& a = cached_parameter_layout(*mp);
  CHECK(&a == &cached_parameter_layout(*mp));
  CHECK(a.n_params == dynamic_parameter_layout(*mp).n_params);
  CHECK(a.rotors.size() == 1);  // the gyroscopic rotor; the gear-reduced one is Ia qdd
  Data d(*mp);
  MatX Y;
  const State s = state(*mp, 0.2);
  joint_torque_regressor(*mp, d, s.q, s.qd, s.qdd, Y);
  CHECK(d.parameter_layout == &a);
}

TEST_CASE(refused_calls_leave_the_output_as_it_was) {
  const ModelPtr mp = actuated_arm();
  Data d(*mp);
  State s = state(*mp, 0.4);
  MatX Y = MatX::Constant(2, 2, 5.0);
  s.qdd[1] = std::nan("");
  CHECK_THROWS(joint_torque_regressor(*mp, d, s.q, s.qd, s.qdd, Y), ModelError);
  CHECK(Y.rows() == 2 && Y.cols() == 2 && Y(1, 1) == 5.0);
  ModelBuilder b = armdyn_test::spatial_arm_builder();
  b.add_joint_spring_damper("pitch", 10.0, 0.1, 0.0);
  const ModelPtr springy = b.finalize();
  Data ds(*springy);
  const State t = state(*springy, 0.1);
  CHECK_THROWS(joint_torque_regressor(*springy, ds, t.q, t.qd, t.qdd, Y), ModelError);
  CHECK(ds.parameter_layout == nullptr);
}

TEST_CASE(regressors_allocate_nothing_after_the_first_call) {
  for (const ModelPtr& mp : {actuated_arm(), floating_arm()}) {
    const Model& m = *mp;
    Data d(m);
    const State s = state(m, 0.3);
    MatX Y;
    VecX h;
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> R;
    joint_torque_regressor(m, d, s.q, s.qd, s.qdd, Y);
    energy_regressor(m, d, s.q, s.qd, h);
    R.resize(Y.rows(), Y.cols());
    VecX hr(h.size());
    const long before = g_allocations.load();
    for (int i = 0; i < 3; ++i) {
      joint_torque_regressor(m, d, s.q, s.qd, s.qdd, Y);
      joint_torque_regressor_into(m, d, s.q, s.qd, s.qdd, R.data());
      energy_regressor(m, d, s.q, s.qd, h);
      energy_regressor_into(m, d, s.q, s.qd, hr.data());
    }
    CHECK(g_allocations.load() == before);
  }
}

ARMDYN_TEST_MAIN()
