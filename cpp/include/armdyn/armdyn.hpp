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

// In layer order (docs/development.md, "Layers"): each folder includes only those above it.

// errors, interruption and math
#include "armdyn/errors.hpp"
#include "armdyn/math/angles.hpp"
#include "armdyn/math/quaternion.hpp"
#include "armdyn/math/types.hpp"
#include "armdyn/poll.hpp"

// the integrators (ODE interface, DOPRI5, DOP853, RK4, TR-BDF2; the Integrator enum)
#include "armdyn/integrate/integrators.hpp"

// the model description
#include "armdyn/model/model.hpp"
#include "armdyn/model/profile.hpp"
#include "armdyn/model/properties.hpp"

// the kernels under the algorithms: jets, constraint rows, KKT factor, block-sparse Schur,
// tree sweep, and the joint-space kinematics and Newton-Euler sweep
#include "armdyn/kernels/joint_space.hpp"

// the per-evaluation workspace
#include "armdyn/data.hpp"

// joint-space algorithms: forces, recursive Newton-Euler, CRBA, forward/inverse dynamics, tree
// dynamics with gears, driven inverse dynamics, frame poses and Jacobians
#include "armdyn/algorithm/crba.hpp"
#include "armdyn/algorithm/derivatives.hpp"
#include "armdyn/algorithm/driven_inverse_dynamics.hpp"
#include "armdyn/algorithm/dynamics.hpp"
#include "armdyn/algorithm/forces.hpp"
#include "armdyn/algorithm/frames.hpp"
#include "armdyn/algorithm/regressor.hpp"
#include "armdyn/algorithm/rnea.hpp"
#include "armdyn/algorithm/tree_dynamics.hpp"

// the Cartesian pipeline on the bodies' state (u, v): kinematics, constraints, forces
// (cartesian_forces), KKT (body_accelerations), projection, reactions, energy
#include "armdyn/algorithm/constraints.hpp"
#include "armdyn/algorithm/energy.hpp"
#include "armdyn/algorithm/kinematics.hpp"
#include "armdyn/algorithm/kkt.hpp"
#include "armdyn/algorithm/projection.hpp"
#include "armdyn/algorithm/reactions.hpp"

// building a model: the builder (finalize: topology, assembly, rank analysis), its summary,
// and the welded form simulate() integrates
#include "armdyn/builder/builder.hpp"
#include "armdyn/builder/summary.hpp"
#include "armdyn/builder/weld.hpp"

// whole runs
#include "armdyn/simulate/batch.hpp"
#include "armdyn/simulate/simulate.hpp"

// validators independent of the Cartesian path
#include "armdyn/validate/validators.hpp"

// URDF import, model bytes, payloads, models of identified parameters
#include "armdyn/io/model_copy.hpp"
#include "armdyn/io/parameter_model.hpp"
#include "armdyn/io/payload.hpp"
#include "armdyn/io/serialize.hpp"
#include "armdyn/io/urdf.hpp"
