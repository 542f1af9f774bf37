// SPDX-License-Identifier: BSD-3-Clause
// Data: every buffer one evaluation of a model writes, made once from the model and reused, so
// that the algorithms of armdyn/algorithm/ (free functions of (const Model&, Data&, ...)) allocate
// nothing per call. One Data per thread: a Model is shared read-only, a Data is not.
#pragma once

#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "armdyn/integrate/integrators.hpp"
#include "armdyn/kernels/articulated_sweep.hpp"
#include "armdyn/kernels/constraint_rows.hpp"
#include "armdyn/kernels/jets.hpp"
#include "armdyn/kernels/joint_space.hpp"
#include "armdyn/kernels/kkt_factor.hpp"
#include "armdyn/kernels/tree_sweep.hpp"
#include "armdyn/model/model.hpp"

namespace armdyn {

struct ParameterLayout;  // algorithm/regressor.hpp
struct LoopWork;         // algorithm/loop_coordinates.hpp

/// Counters of the Cartesian pipeline over a Data's life (a simulation reports them).
struct PipelineStats {
  long position_projections = 0;  ///< position corrections that needed a factorisation
  long newton_iterations = 0;
  long velocity_projections = 0;
  long kkt_solves = 0;
  long factorizations = 0;
  long articulated_solves = 0;  ///< of kkt_solves: by the articulated-body recursion
  /// body_accelerations evaluations where the constraint Jacobian had lower rank than at
  /// assembly (a singular configuration); the first one is described in singular_note.
  long singular_evaluations = 0;
  std::string singular_note;
  /// body_accelerations evaluations solved in augmented form (KktSolver::accelerations_augmented)
  /// because of light bodies or a range-space solve whose constraint residual showed lost
  /// accuracy; why, in augmented_note
  long augmented_solves = 0;
  std::string augmented_note;
};

class Data {
 public:
  /// Sizes every buffer for m. The Data may be used only with this model (checked by
  /// check_data, which the public algorithms call).
  explicit Data(const Model& m);
  ~Data();
  Data(const Data&) = delete;
  Data& operator=(const Data&) = delete;

  const Model* model;  ///< the model the buffers are sized for (identity only, not owned)
  int n = 0;           ///< joint-space degrees of freedom: len(qd) (model.nv_joint)
  int nq = 0;          ///< len(q) (model.nq_joint: 7 per floating base where n has 6)
  int nco = 0;  ///< joint coordinates of Model::coords (n without the floating bases' 6 each)
  /// the independent joint-space sizes (Model::independent): len(q) and len(qd) a coupled
  /// model's public joint-space functions take (nq and n without couplings)
  int niq = 0, ni = 0;

  // --- kinematics: joint_space_kinematics, load_kinematics (shared by the joint-space and the
  // Cartesian algorithms; each loads it before use) ---
  std::vector<BodyKin> kin;  ///< per body: pose and velocity
  // --- forces (body_forces, coordinate_forces, cartesian_forces) ---
  VecX eta;        ///< (nv) applied and gyroscopic forces on the bodies
  VecX coord_tau;  ///< (nco) joint-coordinate forces and gear contact forces (coordinate_forces)
  /// add_force_element_derivatives (algorithm/force_derivatives.hpp), sized by its first call:
  /// per degree of freedom its world twist (angular; velocity of the origin); per entry of a
  /// body's chain or of a spring-damper's two chains: the degree of freedom, its joint's level
  /// (1 at the body), and the terms of algorithm/force_derivatives.cpp (dd, fa, tc, g, dT)
  struct ForceDerivScratch {
    std::vector<Vec6> twist;
    std::vector<int> dofs, level;
    std::vector<Vec3> dd, fa, tc;
    VecX g, dT;
  } force_deriv;
  // --- recursive Newton-Euler (rnea) ---
  RneWork rne;
  VecX tau;  ///< (n) the last rnea's joint torques/forces
  // --- composite-rigid-body algorithm (crba) ---
  std::vector<int> joint_of_body;  ///< per body: the joint it is the child of (-1: none)
  /// A subtree's spatial inertia about the world origin: mass m, first moment h = m c, and
  /// rotational inertia I about the origin; momentum (I w + h x v_O, m v_O - h x w).
  struct Composite {
    double m = 0.0;
    Vec3 h = Vec3::Zero();
    Mat3 I = Mat3::Zero();
  };
  std::vector<Composite> ic;  ///< per body: its subtree's spatial inertia
  std::vector<Vec6> s;        ///< per coordinate: its motion (angular; velocity of origin)
  MatX M;                     ///< (n, n) joint-space mass matrix
  // --- articulated-body algorithm (aba) ---
  struct AbaWork {
    std::vector<Mat6> IA;         ///< per body: its subtree's articulated inertia (about its CoM)
    std::vector<Vec6> pA, v, a;   ///< per body: bias force, spatial velocity, acceleration
    std::vector<Vec6> U, c;       ///< per coordinate: I^A s and the velocity product v_p x s qd
    std::vector<double> Dinv, u;  ///< per coordinate: 1 / (s^T I^A s) and tau - s^T p^A
  } aba;
  // --- forward dynamics ---
  VecX rhs, qdd, zero;
  MatX L;  ///< (n, n) Cholesky factor of M in its lower triangle (math/cholesky.hpp)
  /// TreeDynamics with ideal gears: M T, the reduced T^T M T and its factor, scratch (sized by
  /// the first TreeDynamics on this Data)
  struct TreeScratch {
    MatX MT, Mr, Lr;
    VecX y, w, res, gear_delta;
  } tree;

  // --- the Cartesian pipeline on the bodies' state (u, v): algorithm/kinematics (load),
  // constraints, forces (cartesian_forces), kkt (body_accelerations), projection, reactions,
  // energy ---
  // settings of the calls that follow, set by the caller:
  int nrows = 0;  ///< rows taking part: model.nc (joints and drives, the default) or nc_joint
  const double* aux = nullptr;  ///< auxiliary states z (model.n_aux); nullptr: all zero
  /// Joint-space generalised forces (n: the floating bases' wrenches, then the coordinates')
  /// added to eta by cartesian_forces; nullptr: none.
  const double* joint_torques = nullptr;
  /// With joint_torques: the joint-space q and qd (sizes nq_joint, nv_joint) of the loaded
  /// state, which was placed from them (so it is on every joint's manifold). The
  /// joint-coordinate forces and gear pairs then read them instead of the coordinates' jets (no
  /// angles from atan2), and revolute coordinates take their closed-form jets
  /// (revolute_jet_on_manifold); nullptr: from the jets.
  const double* joint_q = nullptr;
  const double* joint_qd = nullptr;
  /// false: cartesian_forces leaves out the joint-coordinate forces and gear pairs (a
  /// joint-space caller adds them to its generalised forces directly).
  bool with_coordinate_forces = true;
  /// false: body_accelerations may leave delta as it was where that saves work (the articulated
  /// sweep: a forward-dynamics call reads the accelerations only).
  bool multipliers = true;
  // buffers:
  ConstraintEval ce;             ///< f, zeta, rhs, xi at the loaded state
  std::vector<int> joint_block;  ///< per joint: its row block in ce.blocks (-1: no rows)
  CoordJetCache jets;            ///< coordinate jets at the loaded state (ce.coord_cache)
  VecX track_ref;  ///< (nco) unwrapped reference of the angle coordinates (ce.track_ref)
  /// Angle tracking along a run in time (simulate sets track_by_rates): the last commit's
  /// references, the angles' rates there and its time. project() at time t then first moves
  /// track_ref on by rate * (t - t_commit), so the turn of an angle that moved more than half a
  /// turn since the last projection (a fast rotor, a long step of a high-order integrator) is
  /// taken from its rate, not from the nearest branch. Only while track_ref is still the
  /// commit's (anything that sets track_ref otherwise falls back to the nearest branch).
  struct TrackCommit {
    VecX ref, rate;
    double t = std::numeric_limits<double>::quiet_NaN();
  };
  bool track_by_rates = false;
  TrackCommit track_commit;
  std::vector<ScalarJet> tau_jets;  ///< (nco) with joint_torques: each coordinate's jet (no value)
  VecX cq, cqd;                     ///< (nco) the coordinates the force laws read, from the jets
  KktSolver kkt;                    ///< the factor of the KKT system's Schur complement
  TreeSweep sweep;                  ///< the O(n) solve of a fully driven tree
  ArticulatedSweep artic;           ///< the O(n) solve of a tree's KKT system (not fully driven)
  bool swept = false;               ///< the last body_accelerations took the sweep (kkt not used)
  /// the range-space solve lost accuracy once on this Data (its constraint residual): every later
  /// body_accelerations takes the augmented solve (reset_pipeline clears it)
  bool augmented = false;
  /// the model's light bodies (light_bodies(model), looked up once here, not per evaluation)
  const LightBodies* light = nullptr;
  VecX delta;                        ///< (nc) multipliers of the last body_accelerations
  VecX vd_work, tmp_nv, tmp_nc, mu;  ///< (nv, nv, nc, nc) scratch
  double tol_f = 1e-13;              ///< position residual accepted by project without a correction
  PipelineStats stats;

  // --- whole runs (simulate/simulate) and driven solves (algorithm/driven_inverse_dynamics) ---
  IntegratorWork integrator;  ///< the integrators' stages and scratch
  /// a run's output: the state y, (u, v), the accelerations vd and joint accelerations qdd
  struct RunScratch {
    VecX y, u, v, vd, qdd;
  } run;
  /// DrivenSolver: the drive values, the predictor, the saved state and tracking
  struct DrivenScratch {
    VecX qc, qdc, ud, u_save, v_save, u_pred, track_save;
    TreeFkWork fk;
  } driven_solve;
  /// a run of the welded model (builder/weld.hpp) evaluates on this Data of it (made on first
  /// use); this Data then holds the full model's outputs
  std::unique_ptr<Data> welded_data;

  /// the public joint-space functions on a coupled model: the full coordinates (n) expanded
  /// from the independent ones, and the reduced results (ni)
  struct Coupled {
    VecX q, qd, qdd, tau_full;  ///< (nq; n)
    VecX tau, qdd_out, rhs;     ///< (ni)
    MatX M, L;                  ///< (ni, ni)
  } coupled;

  // --- the public Cartesian forward and inverse dynamics (algorithm/dynamics) ---
  VecX vd, tau_in;                    ///< (nv) accelerations; (n) the joint torques of the call
  std::unique_ptr<Model> driven;      ///< inverse dynamics: the model with every coordinate driven
  std::unique_ptr<Data> driven_data;  ///< made on first use, for *driven
  VecX drive_ref;                     ///< (3 n) drive values (q, qd, qdd) of driven_data
  /// the joint-level functions of a model with loops (Model::loop_coordinates): the driven
  /// model, its Data and the last solved state (branch continuity), made on first use (shared_ptr:
  /// its deleter is made with it, so this layer needs not see the type)
  std::shared_ptr<LoopWork> loop;

  // --- joint reactions along a joint-space motion (algorithm/reactions) ---
  /// the joints joint_reactions sweeps (tree_sweep), made on its first call
  std::vector<std::pair<int, int>> reaction_sweep;
  bool reaction_sweep_made = false;

  // --- first-order derivatives of the dynamics (algorithm/derivatives), sized on first use
  // (ensure_derivatives: quadratic in the coordinates, never per call) ---
  struct Derivatives {
    /// per body: its subtree's spatial inertia about the reference point o, and the angular
    /// block Bc and linear momentum Lc of the inertia's velocity variation B (B u = Y (u x V) +
    /// u x* Y V + V x* Y u = (Bc u_w, -2 Lc x u_w): its other blocks vanish)
    std::vector<Composite> Yc;
    std::vector<Mat3> Bc;
    std::vector<Vec3> Lc;
    /// per body: spatial velocity, acceleration (gravity offset) and the subtree's Newton-Euler
    /// wrench (gravity and gyroscopic terms, no force elements)
    std::vector<Vec6> V, A, Fc;
    /// per degree of freedom (n): its motion S, the parent's terms u = V_p x S, w = A_p x S +
    /// V_p x u, a = (V_p + V_c) x S; the subtree's Yc S and Bc^T S; the subtree wrench's
    /// derivatives along q (without and with S x* Fc) and along qd
    std::vector<Vec6> S, u, w, av, YS, BS, dFq, dFqx, dFv;
    /// per body, forward derivatives (the passes run at qdd = 0, then qdd added): the
    /// acceleration qdd adds, and the sum of YS qdd over the degrees of freedom below the body
    std::vector<Vec6> dA, dH;
    MatX dq, dqd;  ///< (n, n) the rigid-body derivatives of tau_full, then the force elements'
    /// the public results (ni, ni): dtau/dq and dtau/dqd; forward: dqdd/dq, dqdd/dqd, M^-1
    MatX tau_q, tau_qd, qdd_q, qdd_qd, qdd_tau;
    VecX qdd_full, qdd;  ///< (n) the forward derivatives' accelerations (full), (ni) independent
    /// per degree of freedom: the one it moves on (the previous of its joint's, else the last of
    /// the nearest ancestor joint's; -1: none); tree_sparse when each is below its child's
    /// index, so that M = L^T D L factors without fill-in (Featherstone's LTDL)
    std::vector<int> dof_parent;
    bool tree_sparse = false;
    /// the factor, by rows: dof k's ancestor dofs anc[anc0[k] .. anc0[k + 1]) (nearest first),
    /// L's entries lval at the same places, D and 1 / D (n)
    std::vector<int> anc0, anc;
    std::vector<double> lval;
    VecX ltd, ltd_inv;
    /// (n, 3n) row-major: [M^-1, -M^-1 dtau/dq, -M^-1 dtau/dqd] as the factor's solves make them
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> solves;
    bool sized = false;
  } deriv;

  // --- the dynamic-parameter regressors (algorithm/regressor) ---
  /// the model's parameter layout (cached_parameter_layout), looked up by the first regressor
  /// call on this Data (a model the regressor refuses leaves it nullptr)
  const ParameterLayout* parameter_layout = nullptr;

  // --- named frames (algorithm/frames) ---
  Mat4 frame_pose = Mat4::Identity();  ///< the last frame pose [R p; 0 1]
  Mat6X frame_jacobian;                ///< (6, n) the last joint-space frame Jacobian
  Mat6X frame_jacobian_independent;    ///< (6, ni) ... of a coupled model: J G
  MatX frame_jacobian_v;               ///< (6, nv) the last Cartesian frame Jacobian
};

/// Return the settings and learnt state of d's Cartesian pipeline to those of a new Data (the
/// rows, auxiliary states, joint torques, tracked angles, counters and the KKT solver's sticky
/// regularisation): a run on a reused Data then gives the same result, bit for bit.
void reset_pipeline(Data& d);

/// Throws ModelError when data was not made for m.
void check_data(const Model& m, const Data& d, const char* fn);

}  // namespace armdyn
