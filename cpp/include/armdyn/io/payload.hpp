// SPDX-License-Identifier: BSD-3-Clause
// A finalized model with payloads added: each a rigid body welded to a named frame or a body of
// the model (Python Model.with_payload / with_payloads). The model's description is taken as a
// builder's draft (the bytes of armdyn/io/serialize.hpp: the one definition of what a draft
// holds), the payloads are added by the builder's own add_body / add_fixed / add_frame (their
// checks), and the result is finalized as the original was (same options, same KKT path).
#pragma once

#include <string>
#include <vector>

#include "armdyn/model/model.hpp"

namespace armdyn {

/// One payload: a rigid body of `mass` [kg] with its centre of mass at `com` [m] and inertia
/// `inertia` [kg m^2] (about the centre of mass), both in the axes of `at` and from its origin.
/// `at` names a frame of the model (Model::frames); else a body (its centre of mass and axes)
/// or "ground"; else a joint (its point and joint frame on the parent's side, z the joint axis;
/// welded to the parent). The first kind that has the name wins (a URDF link is a frame, the
/// link frame, and a body).
struct Payload {
  std::string at;
  double mass = 0.0;
  Vec3 com = Vec3::Zero();
  Mat3 inertia = Mat3::Zero();
  std::string name = "payload";
};

/// `m` with each payload added: a body `name` (axes those of `at`) welded to at's body by a
/// fixed joint `<name>_mount` (reactions reported at at's origin) and a frame `name` at the
/// payload's centre of mass (its axes). `m` is unchanged. `fn` names the caller in messages
/// ("with_payload", "with_payloads").
/// @throws ModelError naming the payload and the culprit on an unknown `at`, a name already
///   taken (a body, joint or frame of the model, or another payload), a negative or non-finite
///   mass, a non-finite com, a non-symmetric or non-physical inertia (positive semidefinite and
///   the triangle inequality), a model that does not finalize with the payloads, or a model
///   holding a profile made from a Python function (it cannot be copied).
ModelPtr with_payloads(const Model& m, const std::vector<Payload>& payloads,
                       const std::string& fn = "with_payloads");

}  // namespace armdyn
