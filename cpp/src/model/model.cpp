// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/model/model.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "armdyn/errors.hpp"
#include "armdyn/math/angles.hpp"

namespace armdyn {

const char* joint_type_name(JointType t) {
  switch (t) {
    case JointType::Revolute:
      return "revolute";
    case JointType::Prismatic:
      return "prismatic";
    case JointType::Spherical:
      return "spherical";
    case JointType::Fixed:
      return "fixed";
    case JointType::Cylindrical:
      return "cylindrical";
    case JointType::Universal:
      return "universal";
    case JointType::Free:
      return "free";
    case JointType::Inline:
      return "inline";
    case JointType::Distance:
      return "distance";
  }
  return "?";
}

int Model::find_body(const std::string& name) const {
  if (name == "ground") return kGround;
  auto it = body_index.find(name);
  if (it == body_index.end()) throw ModelError(msg("unknown body '", name, "'"));
  return it->second;
}

int Model::find_joint(const std::string& name) const {
  auto it = joint_index.find(name);
  if (it == joint_index.end()) throw ModelError(msg("unknown joint '", name, "'"));
  return it->second;
}

int Model::find_frame(const std::string& name) const {
  auto it = frame_index.find(name);
  if (it != frame_index.end()) return it->second;
  // the known names in model order, at most a few of them
  constexpr size_t kShown = 10;
  std::string known;
  for (size_t k = 0; k < frames.size() && k < kShown; ++k)
    known += (k ? ", '" : "'") + frames[k].name + "'";
  if (frames.size() > kShown) known += msg(", ... (", frames.size() - kShown, " more)");
  if (frames.empty()) known = "none";
  throw ModelError(msg("unknown frame '", name, "' (known: ", known, ")"));
}

std::string Model::row_name(int row) const {
  for (const Joint& j : joints) {
    const int r = joint_rows(j.type);
    if (row >= j.row0 && row < j.row0 + r) {
      const int k = row - j.row0;
      const char* what = "position";
      switch (j.type) {
        case JointType::Revolute:
        case JointType::Universal:
        case JointType::Fixed:
        case JointType::Spherical:
          what = k < 3 ? "position" : "rotation";
          break;
        case JointType::Prismatic:
          what = k < 3 ? "rotation" : "position";
          break;
        case JointType::Cylindrical:
          what = k < 2 ? "rotation" : "position";
          break;
        default:
          break;
      }
      return msg("joint '", j.name, "' row ", k, " (", what, ")");
    }
  }
  for (const GearConstraint& g : gear_constraints)
    if (row == g.row) return msg(g.coupling ? "coupling '" : "gear '", g.name, "'");
  for (const Drive& d : drives)
    if (d.row == row) return msg("drive '", d.name, "'");
  return msg("row ", row);
}

std::string Model::joint_path_reason(bool ignore_drives) const {
  if (!joint_tree)
    return joint_space_reason.empty() ? "the model is not a tree" : joint_space_reason;
  if (!drives.empty() && !ignore_drives)
    return "drive '" + drives[0].name +
           "' prescribes a coordinate (the joint-space path has no driving rows)";
  return {};
}

void IndependentCoords::expand_q(const double* q, double* q_full) const {
  for (int i = 0; i < lead_q; ++i) q_full[i] = q[i];
  const int nf = static_cast<int>(source.size());
  for (int c = 0; c < nf; ++c) q_full[lead_q + c] = scale[c] * q[lead_q + source[c]] + shift[c];
}

void IndependentCoords::expand_v(const double* x, double* x_full) const {
  for (int i = 0; i < lead_v; ++i) x_full[i] = x[i];
  const int nf = static_cast<int>(source.size());
  for (int c = 0; c < nf; ++c) x_full[lead_v + c] = scale[c] * x[lead_v + source[c]];
}

void IndependentCoords::reduce(const double* f_full, double* f) const {
  for (int i = 0; i < lead_v; ++i) f[i] = f_full[i];
  for (int k = 0; k < n; ++k) f[lead_v + k] = 0.0;
  const int nf = static_cast<int>(source.size());
  for (int c = 0; c < nf; ++c) f[lead_v + source[c]] += scale[c] * f_full[lead_v + c];
}

void IndependentCoords::reduce(const MatX& M, MatX& Mr) const {
  // G = blockdiag(I (lead_v), G_coords): entry i of the full vector is s(i) x[r(i)]
  const int nf = lead_v + static_cast<int>(source.size());
  auto r = [&](int i) { return i < lead_v ? i : lead_v + source[i - lead_v]; };
  auto s = [&](int i) { return i < lead_v ? 1.0 : scale[i - lead_v]; };
  Mr.setZero();
  for (int j = 0; j < nf; ++j) {
    const int rj = r(j);
    const double sj = s(j);
    for (int i = 0; i < nf; ++i) Mr(r(i), rj) += s(i) * M(i, j) * sj;
  }
}

void IndependentCoords::align(const std::vector<Coord>& coords, double* coord_q) const {
  const int nf = static_cast<int>(source.size());
  for (int c = 0; c < nf; ++c) {
    // (a loop model's dependent coordinates, source -1, follow no independent one)
    if (source[c] < 0 || full[source[c]] == c || !coords[c].angular) continue;
    const double want = scale[c] * coord_q[full[source[c]]] + shift[c];
    coord_q[c] = want + wrap_angle(coord_q[c] - want);
  }
}

const std::array<MotorSpec::Field, MotorSpec::kNumFields>& MotorSpec::fields() {
  static const std::array<Field, kNumFields> f = {{
      {"torque_constant", &MotorSpec::torque_constant},
      {"resistance", &MotorSpec::resistance},
      {"voltage", &MotorSpec::voltage},
      {"no_load_speed", &MotorSpec::no_load_speed},
      {"continuous_torque", &MotorSpec::continuous_torque},
      {"peak_torque", &MotorSpec::peak_torque},
      {"max_speed", &MotorSpec::max_speed},
      {"thermal_resistance", &MotorSpec::thermal_resistance},
      {"thermal_time_constant", &MotorSpec::thermal_time_constant},
      {"rotor_inertia", &MotorSpec::rotor_inertia},
      {"mass", &MotorSpec::mass},
      {"thermal_resistance_winding", &MotorSpec::thermal_resistance_winding},
      {"thermal_resistance_housing", &MotorSpec::thermal_resistance_housing},
      {"thermal_time_constant_winding", &MotorSpec::thermal_time_constant_winding},
      {"thermal_time_constant_housing", &MotorSpec::thermal_time_constant_housing},
      {"max_winding_temperature", &MotorSpec::max_winding_temperature},
      {"brake_torque", &MotorSpec::brake_torque},
  }};
  return f;
}

// every double member is listed in fields() (a member added without it changes the size)
static_assert(sizeof(MotorSpec) == sizeof(std::string) + MotorSpec::kNumFields * sizeof(double),
              "MotorSpec: list every datasheet field in MotorSpec::fields() and kNumFields");

void MotorSpec::validate(const std::string& who) const {
  for (const auto& [n, p] : fields()) {
    const double v = this->*p;
    if (std::isnan(v)) continue;  // not given
    if (!std::isfinite(v) || !(v > 0))
      throw ModelError(msg(who, ": ", n, " must be finite and > 0 (or not given), got ", v));
  }
}

bool MotorSpec::operator==(const MotorSpec& o) const {
  if (name != o.name) return false;
  for (const auto& [n, p] : fields()) {
    const double a = this->*p, b = o.*p;
    if (!(a == b || (std::isnan(a) && std::isnan(b)))) return false;
  }
  return true;
}

}  // namespace armdyn
