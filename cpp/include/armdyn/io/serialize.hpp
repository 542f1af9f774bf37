// SPDX-License-Identifier: BSD-3-Clause
// A Model (finalized, or a builder's draft) as bytes and back (pickling, copies, a model sent to
// worker processes). The bytes hold the model's description -- what the builder's add_* calls
// made: bodies, joints, frames, drives, loads, force elements, gears, couplings, actuators,
// notes -- and, for a finalized model, its finalize options and KKT path choice; doubles bit for
// bit. They do not hold what finalize derives (sizes, rows, coordinates, topology, the assembled
// state, the rank analysis): loading checks every value of the description as the builder checks
// its input (each count against the bytes left before anything is allocated, each index against
// the tables read so far, names, enums, finiteness, unit quaternions, rotation matrices, positive
// semidefinite inertias, coupling chains), then finalizes it again by the builder's own path, so
// no byte string loads as a model the builder could not have made. The copy is the model
// finalize makes from that description: bit for bit the original on the same armdyn build.
// The format is private to armdyn: it starts with a magic tag and a format version, checked on
// load; this armdyn writes version 3 and reads 2 and 3 (2 lacks the motor datasheet fields after
// the first nine of MotorSpec::fields(): they load as not given). The derived caches (KKT plans,
// the welded model) are built again on first use.
#pragma once

#include <string>

#include "armdyn/model/model.hpp"

namespace armdyn {

/// The bytes of finalized model `m`. @throws ModelError naming the element when a profile is a
/// user function (a Python callable cannot be stored).
std::string serialize_model(const Model& m);
/// The model serialize_model() stored, finalized again from its checked description.
/// @throws ModelError naming the field on bytes that are not such a model (wrong tag, other
/// format version or kind, truncated, out-of-range or inconsistent data, a description the
/// builder would refuse or that does not finalize). Nothing is left half-built.
Model deserialize_model(const std::string& bytes);

/// The bytes of a builder's draft (ModelBuilder::draft()). @throws as serialize_model.
std::string serialize_draft(const Model& draft);
/// The draft serialize_draft() stored, checked as deserialize_model checks a model's
/// description (a draft for ModelBuilder(Model, bool)). @throws ModelError naming the field.
Model deserialize_draft(const std::string& bytes);

}  // namespace armdyn
