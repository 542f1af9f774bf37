// SPDX-License-Identifier: BSD-3-Clause
// Engine: the per-model workspace that runs the pipeline
//   (u, v, t) -> body kinematics -> constraints (f, zeta, xi) -> forces (eta) -> KKT -> vdot, delta
// and the topological projection of (u, v) onto f = 0 and zeta v = rhs. All buffers are sized
// once in the constructor; nothing is allocated per evaluation.
#pragma once

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "armdyn/math/angles.hpp"
#include "armdyn/solver/kkt.hpp"
#include "armdyn/solver/tree_sweep.hpp"

namespace armdyn {

struct ProjectionStats {
  long position_projections = 0;  ///< position corrections that needed a factorisation
  long newton_iterations = 0;
  long velocity_projections = 0;
};

class Engine {
 public:
  explicit Engine(const Model& m);
  Engine(const Engine&) = delete;  // ce_ points into this engine's jet cache
  Engine& operator=(const Engine&) = delete;

  /// Rows taking part: all (joints + drives) by default, or joints only (joint-space calls).
  void set_include_drives(bool on) { nrows_ = on ? m_.nc : m_.nc_joint; }
  int nrows() const { return nrows_; }
  /// Auxiliary states z (model.n_aux: integral terms of PI motors) used by forces(); nullptr:
  /// all zero. aux_rates() gives their rates at the loaded state.
  void set_aux(const double* z) { aux_ = z; }
  void aux_rates(double t, double* zdot) const;
  /// Optional joint-space generalised forces (n_coords), added to eta; nullptr for none.
  void set_joint_torques(const double* tau) {
    tau_ = tau;
    tau_jets_.resize(tau ? m_.coords.size() : 0);
  }
  /// With joint torques set: the jets (rate, Jacobian, bias; no value) of every joint
  /// coordinate at the state of the last forces() call.
  const std::vector<ScalarJet>& torque_jets() const { return tau_jets_; }
  /// false: forces() leaves out the joint-coordinate forces and gear pairs (a joint-space
  /// caller adds them to its generalised forces directly, from unwrapped coordinates).
  void set_coordinate_forces(bool on) { coord_forces_ = on; }

  /// Kinematics of (u, v); v may be nullptr (at rest).
  void load(const double* u, const double* v);
  /// eta at the loaded state: gravity, gyroscopic, loads, springs, coordinate forces.
  /// @throws SolverError naming the body when a force is not finite.
  void forces(double t);
  /// Forward dynamics: vdot (nv) and multipliers (stored, see delta()).
  /// reuse_factor: the last projection factored A at this very u with the mass metric.
  /// A fully driven tree (square zeta) takes the O(n) sweep instead of the KKT factorisation
  /// (swept() is then true), unless a block is singular.
  void dynamics(double t, const double* u, const double* v, double* vdot,
                bool reuse_factor = false);
  /// dynamics() at the state already in the kinematic cache (load(), or kin_in() filled by the
  /// caller).
  void dynamics_loaded(double t, double* vdot, bool reuse_factor = false);
  /// The kinematic cache, for callers that build the body states themselves (joint-space
  /// forward and inverse dynamics: poses and velocities straight from the joint coordinates).
  std::vector<BodyKin>& kin_in() {
    jets_.reset();
    return kin_;
  }
  /// u' = S(u) v: xdot and 1/2 e (x) [0, omega].
  void udot(const double* u, const double* v, double* ud) const;
  /// Project u onto f(u, t) = 0 (minimum-norm Newton in metric W, quaternions renormalised) and
  /// v onto zeta v = rhs. Leaves A factored at the final u.
  /// @throws SolverError when the position iteration does not converge.
  void project(double t, double* u, double* v, Metric metric);
  /// ||f||_inf and ||zeta v - rhs||_inf over the active rows at (u, v, t).
  void residuals(double t, const double* u, const double* v, double& rf, double& rv);
  /// The same from the last constraint evaluation (at the loaded u and t), for velocities v.
  void loaded_residuals(const double* v, double& rf, double& rv);
  /// Kinetic and potential (gravity + springs) energy.
  void energy(const double* u, const double* v, double& ke, double& pe);
  /// Reaction on joint j's child at the joint point, in the child's joint frame, from the
  /// multipliers of the last dynamics() call (kinematics must still be loaded).
  void joint_reaction(int j, Vec3& force, Vec3& torque) const;

  /// Unwrapped value of a tracked angle coordinate (gears) from its raw (wrapped) value,
  /// continuous with the value at the last projection.
  double tracked(int coord, double raw) const {
    return track_ref_[coord] + wrap_angle(raw - track_ref_[coord]);
  }
  /// Gear mesh displacement s, rate and penetration |s| - backlash/2 at the loaded state.
  void gear_mesh(int g, double& s, double& sd, double& penetration) const;
  /// After a failure: when the constraint Jacobian at (u, v, t) is nearly singular (scaled
  /// pivots below threshold), a sentence naming the nearly dependent rows; otherwise empty.
  std::string diagnose_singularity(double t, const double* u, const double* v,
                                   double threshold = 1e-7);
  /// Set the tracked angles' references from the loaded state (after each projection).
  void commit_tracking();
  const VecX& tracking() const { return track_ref_; }
  void set_tracking(const Eigen::Ref<const VecX>& ref) { track_ref_ = ref; }

  const VecX& delta() const { return delta_; }
  /// Set the multipliers (all rows) that joint_reaction() reports.
  void set_multipliers(const VecX& delta) { delta_ = delta; }
  const VecX& eta() const { return eta_; }
  const ConstraintEval& constraints() const { return ce_; }
  ConstraintEval& constraints() { return ce_; }
  const std::vector<BodyKin>& kin() const { return kin_; }
  KktSolver& kkt() { return kkt_; }
  const KktSolver& kkt() const { return kkt_; }
  /// The last dynamics() solved the square system by the tree sweep (kkt() was not used).
  bool swept() const { return swept_; }
  const Model& model() const { return m_; }
  ProjectionStats pstats;
  long kkt_solves = 0, factorizations = 0;
  /// dynamics evaluations where the constraint Jacobian had lower rank than at assembly
  /// (a singular configuration); the first one is described in singular_note.
  long singular_evaluations = 0;
  std::string singular_note;

 private:
  void scatter(const Row12& g, int pa, int pb);
  void coordinate_forces(double t);  // joint-coordinate forces and gear pairs into eta_
  const Model& m_;
  std::vector<BodyKin> kin_;
  ConstraintEval ce_;
  KktSolver kkt_;
  VecX eta_, delta_, tmp_nv_, tmp_nc_, mu_;
  VecX vd_;
  VecX track_ref_;        // unwrapped reference of tracked angle coordinates (by coordinate index)
  VecX cq_, cqd_, ctau_;  // coordinate values, rates and generalised forces of the force laws
  const double* tau_ = nullptr;
  std::vector<ScalarJet> tau_jets_;
  mutable CoordJetCache jets_;  // coordinate jets at the loaded state
  const double* aux_ = nullptr;
  int nrows_ = 0;
  double tol_f_ = 1e-13;
  TreeSweep sweep_;
  bool swept_ = false;
  bool coord_forces_ = true;
};

}  // namespace armdyn
