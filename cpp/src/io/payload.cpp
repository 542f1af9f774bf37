// SPDX-License-Identifier: BSD-3-Clause
// Model::with_payloads (armdyn/io/payload.hpp).
#include "armdyn/io/payload.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include "armdyn/builder/builder.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/io/model_copy.hpp"
#include "armdyn/math/quaternion.hpp"

namespace armdyn {

namespace {

/// Where a payload goes: the body it is welded to and the pose of `at` in world at the build
/// pose (the builder's inputs are world coordinates at the build pose).
struct Mount {
  std::string body;  ///< the body's name ("ground" for the world)
  Vec3 origin = Vec3::Zero();
  Mat3 axes = Mat3::Identity();  ///< at's axes as columns in world
};

Mount resolve_mount(const Model& d, const std::string& at, const std::string& who) {
  Mount mt;
  int body = kGround;
  Vec3 point = Vec3::Zero();  // in the body frame (relative to its centre of mass)
  Mat3 rot = Mat3::Identity();
  if (auto f = d.frame_index.find(at); f != d.frame_index.end()) {
    const NamedFrame& fr = d.frames[f->second];
    body = fr.body;
    point = fr.point;
    rot = fr.rotation;
  } else if (auto b = d.body_index.find(at); b != d.body_index.end()) {
    body = b->second;
  } else if (auto j = d.joint_index.find(at); j != d.joint_index.end()) {
    // a joint: its point and joint frame on the parent's side
    const Joint& jt = d.joints[j->second];
    body = jt.parent;
    point = jt.point_parent;
    rot = jt.frame_parent;
  } else if (at != "ground") {
    throw ModelError(
        msg(who, ": at '", at, "' is neither a frame, a body nor a joint of the model"));
  }
  mt.body = d.body_name(body);
  if (body == kGround) {
    mt.origin = point;
    mt.axes = rot;
  } else {
    const Body& bd = d.bodies[body];
    const Mat3 R = quat_to_rot(bd.orientation);
    mt.origin = bd.position + R * point;
    mt.axes = R * rot;
  }
  return mt;
}

void check_name_free(const Model& d, const std::string& name, const std::string& who) {
  if (name.empty()) throw ModelError(msg(who, ": name must not be empty"));
  const std::string joint = name + "_mount";
  std::string taken;
  if (name == "ground")
    taken = "is reserved";
  else if (d.body_index.count(name))
    taken = "is taken by a body of the model";
  else if (d.frame_index.count(name))
    taken = "is taken by a frame of the model";
  else if (d.joint_index.count(joint))
    taken = msg("is taken: the model has a joint '", joint, "'");
  if (!taken.empty())
    throw ModelError(msg(who, ": name '", name, "' ", taken, " (a payload adds body and frame '",
                         name, "' and joint '", joint, "'; give it another name)"));
}

void check_numbers(const Payload& p, const std::string& who) {
  if (!std::isfinite(p.mass) || !(p.mass >= 0.0))
    throw ModelError(msg(who, ": mass must be finite and >= 0, got ", p.mass));
  if (!p.com.allFinite())
    throw ModelError(msg(who, ": com must be finite, got (", p.com.transpose(), ")"));
  if (!p.inertia.allFinite()) throw ModelError(msg(who, ": inertia must be finite"));
  const double scale = p.inertia.cwiseAbs().maxCoeff();
  if ((p.inertia - p.inertia.transpose()).cwiseAbs().maxCoeff() > 1e-9 * std::max(scale, 1e-300))
    throw ModelError(msg(who, ": inertia is not symmetric"));
  const InertiaCheck ic = check_inertia(0.5 * (p.inertia + p.inertia.transpose()), true);
  if (!ic.problem.empty())
    throw ModelError(
        msg(who, ": inertia ", ic.problem, " (principal moments ", ic.moments.transpose(), ")"));
}

/// Add payload `p` to the builder, its checks first (the builder is with_payloads' own copy:
/// the model is unchanged whatever throws).
void add_payload(ModelBuilder& b, const Payload& p, const std::string& who) {
  const Model& d = b.draft();
  check_numbers(p, who);
  check_name_free(d, p.name, who);
  const Mount mt = resolve_mount(d, p.at, who);
  const Vec3 com = mt.origin + mt.axes * p.com;
  const Vec4 orientation = rot_to_quat(mt.axes);
  try {
    b.add_body(p.name, p.mass, p.inertia, com, orientation);
  } catch (const ModelError& e) {
    // the builder names "body '<name>': <field> ..."; the payload's inertia is the argument
    throw ModelError(msg(who, ": ", e.what()));
  }
  b.add_fixed(p.name + "_mount", mt.body, p.name, mt.origin);
  b.add_frame(p.name, p.name, com, orientation);
}

}  // namespace

ModelPtr with_payloads(const Model& m, const std::vector<Payload>& payloads,
                       const std::string& fn) {
  std::vector<std::string> notes;
  Model draft = model_draft(m, fn, notes, "; add the payload with the ModelBuilder instead");
  ModelBuilder b(std::move(draft), true);
  for (std::size_t k = 0; k < payloads.size(); ++k) {
    const std::string who =
        fn == "with_payload" ? fn : msg(fn, ": payloads[", k, "] '", payloads[k].name, "'");
    add_payload(b, payloads[k], who);
  }
  return finalize_like(b, m, std::move(notes), fn, "the payload");
}

}  // namespace armdyn
