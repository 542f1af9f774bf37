// SPDX-License-Identifier: BSD-3-Clause
// Data: every buffer one evaluation of a model writes, made once from the model and reused, so
// that the algorithms of armdyn/algorithm/ (free functions of (const Model&, Data&, ...)) allocate
// nothing per call. One Data per thread: a Model is shared read-only, a Data is not.
#pragma once

#include <memory>
#include <vector>

#include "armdyn/analysis/joint_space.hpp"
#include "armdyn/model/model.hpp"
#include "armdyn/solver/kinematics.hpp"

namespace armdyn {

class Engine;

class Data {
 public:
  /// Sizes every buffer for m. The Data may be used only with this model (checked by
  /// check_data, which the public algorithms call).
  explicit Data(const Model& m);
  ~Data();
  Data(const Data&) = delete;
  Data& operator=(const Data&) = delete;

  const Model* model;  ///< the model the buffers are sized for (identity only, not owned)
  int n = 0;           ///< joint coordinates

  // --- kinematics (forward_kinematics) ---
  std::vector<BodyKin> kin;  ///< per body: pose and velocity
  // --- forces (body_forces, coordinate_forces) ---
  VecX eta;        ///< (nv) applied and gyroscopic forces on the bodies
  VecX coord_tau;  ///< (n) joint-coordinate forces and gear contact forces
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
  // --- forward dynamics ---
  VecX rhs, qdd, zero;
  MatX L;  ///< (n, n) Cholesky factor of M in its lower triangle (math/cholesky.hpp)
  // --- the Cartesian (KKT) path: made on first use ---
  std::unique_ptr<Engine> engine;  ///< forward dynamics through the Cartesian KKT system
  VecX vd, tau_in;                 ///< (nv) accelerations; (n) torques seen by the engine
  std::unique_ptr<Model> driven;   ///< inverse dynamics: the model with every coordinate driven
  std::unique_ptr<Engine> driven_engine;
  VecX drive_ref;  ///< (3 n) drive values (q, qd, qdd) of driven_engine
};

/// Throws ModelError when data was not made for m.
void check_data(const Model& m, const Data& d, const char* fn);

}  // namespace armdyn
