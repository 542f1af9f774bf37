// SPDX-License-Identifier: BSD-3-Clause
// A finalized model with other dynamic parameters (identification: an identified parameter vector
// pi turned back into a model). The model's description is taken as a builder's draft (the bytes
// of armdyn/io/serialize.hpp), each body's mass, centre of mass and inertia, each coordinate's
// friction and rotor inertia are set from pi, and the draft is finalized again as the original
// was: every cache that depends on the masses (assembly, KKT plans, the welded model, the mass
// matrix's definiteness check) is derived afresh.
#pragma once

#include "armdyn/model/model.hpp"

namespace armdyn {

/// `m` with dynamic parameters `pi` (ParameterLayout's order, armdyn/algorithm/regressor.hpp):
/// dynamic_parameters() of the result equals pi (to round-off), but for the offsets, which are
/// measurement biases, not dynamics (ignored), and the result's inverse dynamics equals
/// joint_torque_regressor(m, ...) * pi. `m` is unchanged.
///  - Bodies: (m, m c, I_o) about the parameter frame -> the body's mass, centre of mass c and
///    inertia about c (body axes). An armdyn body's frame has its origin at the centre of mass,
///    so the body frame moves by the centre of mass's shift (axes kept) and every point held in
///    it moves the other way (joint points, named frames, spring points, loads, Body::position):
///    the geometry is unchanged. A massless body (m = 0, first moment 0) keeps its frame. A body
///    without a frame of its name (its parameter frame was its body frame: a builder's model)
///    gets one, at its old body frame (old centre of mass, body axes), so that the result's
///    parameters are about the same frames as pi.
///  - Friction fv, fc of an independent coordinate: every friction source reflected onto it (its
///    own, its followers', the actuators' motor-side) scaled by the ratio to pi's value (their
///    smoothing velocities kept: the regressor's column is then exact); a coordinate without
///    viscous or Coulomb friction gets it on its own joint (Coulomb smoothing
///    kRegressorCoulombSmoothing, the regressor's column for it).
///  - Ia: the actuators' rotor inertias J scaled the same way (N^2 J summed equals Ia; all on the
///    first actuator when their sum is 0), the rotor bodies' thin-disc inertias updated; a
///    coordinate without actuator and Ia > 0 gets one: add_actuator(joint, gear_ratio 1,
///    rotor_inertia Ia) (a gear-reduced armature: tau += Ia qdd).
/// physical_inertia: true, each body's 10 numbers must be physically consistent (pseudo-inertia
/// positive semidefinite: m >= 0 and the inertia about the centre of mass positive semidefinite
/// with the triangle inequality); false, the inertia about the centre of mass only positive
/// semidefinite (ModelBuilder::set_physical_inertia(false): published or identified sets that
/// violate the triangle inequality). Either way m >= 0, a zero mass has a zero first moment,
/// fv, fc, Ia >= 0.
/// @throws ModelError naming the culprit (the pi entry by dynamic_parameter_names, the body,
///   the coordinate) on a pi of the wrong length, a non-finite entry, a parameter set the model
///   cannot hold (above), a model dynamic_parameter_layout refuses, a model holding a profile
///   made from a Python function (it cannot be copied), or a result that does not finalize.
ModelPtr model_with_dynamic_parameters(const Model& m, const VecX& pi,
                                       bool physical_inertia = true);

}  // namespace armdyn
