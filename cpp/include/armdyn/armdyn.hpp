// SPDX-License-Identifier: BSD-3-Clause
// armdyn: the supported C++ API in one include. Link armdyn::core (find_package(armdyn)).
//
//   armdyn::ModelBuilder b;                   // bodies, joints, drives, force elements
//   armdyn::ModelPtr model = b.finalize();    // the immutable Model, assembled
//   armdyn::Data data(*model);                // every per-evaluation buffer
//   armdyn::forward_dynamics(*model, data, q, qd, tau);   // qdd
//   armdyn::inverse_dynamics(*model, data, q, qd, qdd);   // tau
//   armdyn::crba(*model, data, q);                        // M(q)
//   armdyn::SimResult r = armdyn::simulate(*model, t_end, options, model->u0, model->v0);
#pragma once

// errors and math
#include "armdyn/errors.hpp"
#include "armdyn/math/angles.hpp"
#include "armdyn/math/quaternion.hpp"
#include "armdyn/math/types.hpp"

// the model description and its per-evaluation workspace
#include "armdyn/data.hpp"
#include "armdyn/model/model.hpp"
#include "armdyn/model/profile.hpp"

// building a model: the builder (finalize: topology, assembly, rank analysis), its summary,
// and the welded form simulate() integrates
#include "armdyn/builder/builder.hpp"
#include "armdyn/builder/summary.hpp"
#include "armdyn/builder/weld.hpp"

// joint-space algorithms: forces, recursive Newton-Euler, CRBA, forward/inverse dynamics, frame
// poses and Jacobians
#include "armdyn/algorithm/crba.hpp"
#include "armdyn/algorithm/dynamics.hpp"
#include "armdyn/algorithm/forces.hpp"
#include "armdyn/algorithm/frames.hpp"
#include "armdyn/algorithm/rnea.hpp"

// the Cartesian pipeline on the bodies' state (u, v): kinematics, constraints, forces
// (cartesian_forces), KKT (body_accelerations), projection, reactions, energy
#include "armdyn/algorithm/constraints.hpp"
#include "armdyn/algorithm/energy.hpp"
#include "armdyn/algorithm/kinematics.hpp"
#include "armdyn/algorithm/kkt.hpp"
#include "armdyn/algorithm/projection.hpp"
#include "armdyn/algorithm/reactions.hpp"

// URDF import
#include "armdyn/io/urdf.hpp"

// the integrators (the kernels under the pipeline -- jets, constraint rows, KKT factor, tree
// sweep -- are in armdyn/solver/)
#include "armdyn/solver/integrators.hpp"

// driven inverse dynamics, joint-space state, tree dynamics with gears, whole runs
#include "armdyn/analysis/inverse_dynamics.hpp"
#include "armdyn/analysis/joint_space.hpp"
#include "armdyn/analysis/simulate.hpp"
#include "armdyn/analysis/tree_dynamics.hpp"

// validators independent of the Cartesian path
#include "armdyn/validate/validators.hpp"
