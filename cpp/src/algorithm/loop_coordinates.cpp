// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/algorithm/loop_coordinates.hpp"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <map>
#include <utility>

#include "armdyn/algorithm/constraints.hpp"
#include "armdyn/algorithm/frames.hpp"
#include "armdyn/algorithm/kinematics.hpp"
#include "armdyn/algorithm/kkt.hpp"
#include "armdyn/algorithm/projection.hpp"
#include "armdyn/algorithm/reactions.hpp"
#include "armdyn/algorithm/rnea.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/kernels/constraint_rows.hpp"
#include "armdyn/kernels/jets.hpp"
#include "armdyn/math/angles.hpp"

namespace armdyn {

namespace {

// --- the choice of the independent coordinates (finalize) ----------------------------------

// The velocity rows of the joint coordinates at the assembled state, restricted to the null
// space of the joint rows: row c is coordinate c's rate per unit of each free motion
// (nco x mobility), and each coordinate's full row norm (to judge a restricted row's size).
struct CoordRows {
  MatX P;
  VecX scale;
};

CoordRows coordinate_rows(const Model& m) {
  std::vector<BodyKin> kin;
  body_kinematics(m, m.u0.data(), nullptr, kin);
  ConstraintEval ce;
  ce.init(m);
  eval_constraints(m, kin, 0.0, false, ce);
  const MatX z = dense_zeta(m, ce).topRows(m.nc_joint);
  MatX N;  // (nv, mobility): an orthonormal basis of the null space of the joint rows
  if (m.nc_joint == 0) {
    N = MatX::Identity(m.nv, m.nv);
  } else {
    Eigen::ColPivHouseholderQR<MatX> qr(z.transpose());
    qr.setThreshold(1e-6);
    const MatX Q = qr.householderQ();
    N = Q.rightCols(m.nv - static_cast<int>(qr.rank()));
  }
  const int nco = static_cast<int>(m.coords.size());
  CoordRows r{MatX::Zero(nco, N.cols()), VecX::Zero(nco)};
  for (int c = 0; c < nco; ++c) {
    const ScalarJet s = coord_jet(m, kin, c);
    const Joint& j = m.joints[m.coords[c].joint];
    Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(m.nv);
    if (j.parent != kGround) row.segment<6>(6 * j.parent) += s.J.segment<6>(0);
    if (j.child != kGround) row.segment<6>(6 * j.child) += s.J.segment<6>(6);
    r.P.row(c) = row * N;
    r.scale[c] = row.norm();
  }
  return r;
}

// Greedy pivoted independence test: add() takes a coordinate when its restricted row is
// independent of those taken (its component off their span above 1e-6 of its full row)
struct Independence {
  const CoordRows& rows;
  MatX basis;  // (mobility, taken) orthonormal
  int taken = 0;
  explicit Independence(const CoordRows& r) : rows(r), basis(r.P.cols(), r.P.cols()) {}
  bool add(int c) {
    if (taken >= basis.cols()) return false;
    VecX p = rows.P.row(c).transpose();
    for (int pass = 0; pass < 2; ++pass)  // twice: Gram-Schmidt to round-off
      for (int k = 0; k < taken; ++k) p -= basis.col(k).dot(p) * basis.col(k);
    const double n = p.norm();
    if (!(n > 1e-6 * std::max(rows.scale[c], 1e-300))) return false;
    basis.col(taken++) = p / n;
    return true;
  }
};

bool has_ideal_gear(const Model& m) {
  for (const GearConstraint& g : m.gear_constraints)
    if (!g.coupling) return true;
  return false;
}

std::string name_list(const Model& m, const std::vector<int>& coords) {
  std::string s;
  for (int c : coords) s += (s.empty() ? "'" : ", '") + m.coords[c].name + "'";
  return s.empty() ? std::string("none") : s;
}

// the user's choice, validated in the order given
std::vector<int> requested_coordinates(const Model& m, const CoordRows& rows) {
  constexpr const char* fn = "finalize: set_independent_coordinates";
  std::map<std::string, int> index;
  for (size_t c = 0; c < m.coords.size(); ++c) index[m.coords[c].name] = static_cast<int>(c);
  std::vector<int> chosen;
  for (const std::string& name : m.independent_request) {
    const auto it = index.find(name);
    if (it == index.end()) {
      std::string known;
      for (const Coord& c : m.coords) known += (known.empty() ? "'" : ", '") + c.name + "'";
      throw ModelError(
          msg(fn, ": unknown joint coordinate '", name, "' (joint_coord_names: ", known, ")"));
    }
    if (std::find(chosen.begin(), chosen.end(), it->second) != chosen.end())
      throw ModelError(msg(fn, ": coordinate '", name, "' given twice"));
    chosen.push_back(it->second);
  }
  if (static_cast<int>(chosen.size()) != m.mobility)
    throw ModelError(msg(fn, ": ", chosen.size(), " coordinate(s) given, the model's mobility is ",
                         m.mobility, " (give exactly that many)"));
  Independence ind(rows);
  for (size_t k = 0; k < chosen.size(); ++k)
    if (!ind.add(chosen[k]))
      throw ModelError(msg(fn, ": coordinate '", m.coords[chosen[k]].name,
                           "' is not independent of ",
                           name_list(m, std::vector<int>(chosen.begin(), chosen.begin() + k)),
                           " at the assembled configuration (the loop constraints determine it)"));
  return chosen;
}

// armdyn's default: the coordinates in model order (couplings' followers last), each taken
// when independent of those taken before
std::vector<int> default_coordinates(const Model& m, const CoordRows& rows) {
  std::vector<char> follower(m.coords.size(), 0);
  for (const GearConstraint& g : m.gear_constraints)
    if (g.coupling) follower[g.coord_a] = 1;
  Independence ind(rows);
  std::vector<int> chosen;
  for (const int pass : {0, 1})
    for (size_t c = 0; c < m.coords.size(); ++c)
      if (follower[c] == pass && ind.add(static_cast<int>(c)))
        chosen.push_back(static_cast<int>(c));
  return chosen;
}

// Model::independent of the chosen coordinates: each coupling follower of a chosen coordinate
// (an actuator's rotor) resolved through its chain, every other coordinate dependent (-1)
void set_independent(Model& m, const std::vector<int>& chosen) {
  IndependentCoords& ic = m.independent;
  const int nf = static_cast<int>(m.coords.size());
  ic = IndependentCoords();
  ic.n = static_cast<int>(chosen.size());
  ic.full = chosen;
  ic.source.assign(nf, -1);
  ic.scale.assign(nf, 1.0);
  ic.shift.assign(nf, 0.0);
  for (int k = 0; k < ic.n; ++k) ic.source[chosen[k]] = k;
  std::vector<const GearConstraint*> follows(nf, nullptr);
  for (const GearConstraint& g : m.gear_constraints)
    if (g.coupling) follows[g.coord_a] = &g;
  for (int c = 0; c < nf; ++c) {
    if (ic.source[c] >= 0) continue;
    double scale = 1.0, shift = 0.0;
    int k = c;
    for (int steps = 0; follows[k] && ic.source[k] < 0 && steps <= nf; ++steps) {
      shift += scale * follows[k]->offset;
      scale *= follows[k]->multiplier();
      k = follows[k]->coord_b;
    }
    if (k == c || ic.source[k] < 0) continue;
    ic.source[c] = ic.source[k];
    ic.scale[c] = scale;
    ic.shift[c] = shift;
  }
}

}  // namespace

void choose_loop_coordinates(Model& m) {
  m.loop_coordinates = false;
  // a tree without ideal gears has independent joint coordinates (a coupling's follower is
  // dependent by construction); a fixed-base tree with ideal gears takes the loop functions (the
  // gear rows are constraint rows like loop closures), simulated in joint space over all its
  // coordinates by TreeDynamics
  if (m.is_tree && !(has_ideal_gear(m) && m.n_free == 0)) {
    if (!m.independent_request.empty())
      throw ModelError(
          msg("finalize: set_independent_coordinates applies to models with closed loops or ideal "
              "gears (fixed base); this model ",
              has_ideal_gear(m) ? "has a floating base" : "is a tree without ideal gears",
              " (its joint coordinates are independent; a coupling's follower is dependent by "
              "construction)"));
    if (has_ideal_gear(m))
      m.joint_space_reason +=
          " (and a floating base: the joint-level functions take ideal gears on fixed-base "
          "trees only; use simulate and the Cartesian functions)";
    return;
  }
  if (m.n_free > 0) {
    if (!m.independent_request.empty())
      throw ModelError(
          "finalize: set_independent_coordinates: a model with closed loops and a floating base "
          "has no joint-level functions (use simulate and the Cartesian functions)");
    m.joint_space_reason +=
        " (and a floating base: the joint-level functions of loop models "
        "take fixed-base models only)";
    return;
  }
  const CoordRows rows = coordinate_rows(m);
  const std::vector<int> chosen =
      m.independent_request.empty() ? default_coordinates(m, rows) : requested_coordinates(m, rows);
  if (static_cast<int>(chosen.size()) < m.mobility) {
    m.joint_space_reason +=
        msg(": its mobility is ", m.mobility, " but only ", chosen.size(),
            " joint coordinate(s) are independent (", name_list(m, chosen),
            "); the other freedoms have no joint coordinate (a body spinning between ball "
            "joints, a free or spherical joint in the loop), so the joint-level functions do not "
            "apply (use simulate, driven_inverse_dynamics and the Cartesian functions)");
    return;
  }
  set_independent(m, chosen);
  m.loop_coordinates = true;
  m.joint_space_reason +=
      msg(" (forward_dynamics, inverse_dynamics, mass_matrix, state_from_joints, "
          "joint_reactions, frame_pose and frame_jacobian take its independent coordinates ",
          name_list(m, chosen), ")");
}

// --- the state at the independent coordinates ------------------------------------------------

namespace {

// LoopWork::linear: from each independent coordinate along the gear and coupling rows
// (r_a q_a + r_b q_b = offset, couplings as the same row), each coordinate reached once; false
// when the model has other closures, a cycle of rows, or a tree of rows without (or with two)
// independent coordinates
bool linear_gear_map(const Model& m, LoopWork& w) {
  if (!m.is_tree || !m.joint_tree || m.n_free > 0) return false;
  const int nco = static_cast<int>(m.coords.size());
  std::vector<std::vector<const GearConstraint*>> rows_of(nco);
  for (const GearConstraint& g : m.gear_constraints) {
    if (!(g.r_a != 0.0 && g.r_b != 0.0) || g.coord_a == g.coord_b) return false;
    rows_of[g.coord_a].push_back(&g);
    rows_of[g.coord_b].push_back(&g);
  }
  const IndependentCoords& ic = m.independent;
  w.lin_source.assign(nco, -1);
  w.lin_scale.assign(nco, 0.0);
  w.lin_shift.assign(nco, 0.0);
  std::vector<const GearConstraint*> via(nco, nullptr);  // the row each was reached by
  std::vector<int> queue;
  for (int k = 0; k < ic.n; ++k) {
    const int c0 = ic.full[k];
    if (w.lin_source[c0] >= 0) return false;  // two independent coordinates in one tree
    w.lin_source[c0] = k;
    w.lin_scale[c0] = 1.0;
    queue.assign(1, c0);
    for (size_t i = 0; i < queue.size(); ++i) {
      const int c = queue[i];
      for (const GearConstraint* g : rows_of[c]) {
        if (g == via[c]) continue;
        const bool from_a = g->coord_a == c;
        const int o = from_a ? g->coord_b : g->coord_a;
        if (w.lin_source[o] >= 0) return false;  // a cycle of rows
        // q_o = (offset - r_c q_c) / r_o
        const double r_c = from_a ? g->r_a : g->r_b, r_o = from_a ? g->r_b : g->r_a;
        w.lin_source[o] = k;
        w.lin_scale[o] = -r_c / r_o * w.lin_scale[c];
        w.lin_shift[o] = (g->offset - r_c * w.lin_shift[c]) / r_o;
        via[o] = g;
        queue.push_back(o);
      }
    }
  }
  for (int c = 0; c < nco; ++c)
    if (w.lin_source[c] < 0) return false;
  return true;
}

}  // namespace

LoopWork::LoopWork(const Model& m) {
  const IndependentCoords& ic = m.independent;
  const int n = ic.n;
  auto dr = std::make_unique<Model>(m);
  dr->drives.clear();
  dr->drive_index.clear();
  for (int k = 0; k < n; ++k) {
    const Coord& c = dr->coords[ic.full[k]];
    Drive x;
    x.name = c.name;
    x.joint = c.joint;
    x.coord = c.sub;
    x.profile = Profile::constant(0.0);
    x.row = dr->nc_joint + k;
    dr->drive_index[x.name] = k;
    dr->drives.push_back(x);
  }
  dr->nc = dr->nc_joint + n;
  dr->rank_all = dr->rank_joint + n;
  dr->mobility_driven = dr->mobility - n;
  // (the copy plans its KKT factorisation afresh, for the new drive rows: kkt_plans)
  driven = std::move(dr);
  dd = std::make_unique<Data>(*driven);
  ref = VecX::Zero(3 * n);
  dd->ce.drive_ref = ref.data();
  // positions to round-off (one Newton step past the pipeline's 1e-13): the results then do not
  // depend on the state Newton started from (the Data's history)
  dd->tol_f = 1e-15 * std::max(1.0, m.length_scale);
  for (VecX* x : {&u, &u_start, &u_save, &u_pred, &u_step, &ud}) *x = VecX::Zero(m.nq);
  for (VecX* x : {&v, &vd, &v_start, &v_save, &zero_v}) *x = VecX::Zero(m.nv);
  for (VecX* x : {&q_last, &q_from, &dq, &out, &qs, &unit, &zero_n}) *x = VecX::Zero(n);
  track_start = track_save = VecX::Zero(static_cast<long>(m.coords.size()));
  tau_full = VecX::Zero(m.nv_joint);
  T = MatX::Zero(m.nv, n);
  GT = MatX::Zero(m.nv, n);
  M = MatX::Zero(n, n);
  J = Mat6X::Zero(6, n);
  linear = linear_gear_map(m, *this);
  q_full = qd_full = qdd_full = VecX::Zero(static_cast<long>(m.coords.size()));
}

namespace {

LoopWork& loop_work(const Model& m, Data& d) {
  if (!d.loop) d.loop = std::make_shared<LoopWork>(m);
  return *d.loop;
}

// sizes and finiteness of the inputs (x: qd, qdd or tau; nullptr: none)
void check_loop_inputs(const Model& m, const Data& d, Eigen::Ref<const VecX> q,
                       std::initializer_list<std::pair<const char*, Eigen::Ref<const VecX>>> xs,
                       double t, const char* fn) {
  check_data(m, d, fn);
  const long n = m.independent.n;
  check_joint_vector(q, n, fn, "q");
  for (const auto& [name, x] : xs) check_joint_vector(x, n, fn, name);
  if (!std::isfinite(t)) throw ModelError(msg(fn, ": t is not finite"));
}

// per body max(|dx| / length scale, rotation angle), max over bodies
double distance(const Model& m, const VecX& a, const VecX& b) {
  double d = 0.0;
  for (int i = 0; i < m.nb; ++i) {
    const double dx = (a.segment<3>(7 * i) - b.segment<3>(7 * i)).norm() / m.length_scale;
    const double c = std::min(1.0, std::abs(a.segment<4>(7 * i + 3).dot(b.segment<4>(7 * i + 3))));
    d = std::max({d, dx, 2.0 * std::acos(c)});
  }
  return d;
}

void set_ref(LoopWork& w, const VecX& q, Eigen::Ref<const VecX> qd, double qdd_scale,
             const double* qdd) {
  for (long k = 0; k < q.size(); ++k) {
    w.ref[3 * k] = q[k];
    w.ref[3 * k + 1] = qd[k];
    w.ref[3 * k + 2] = qdd ? qdd_scale * qdd[k] : 0.0;
  }
}

// The independent coordinates of the solved state u (angles as the tracking left them)
void coordinates_of(const Model& m, LoopWork& w, VecX& q) {
  const IndependentCoords& ic = m.independent;
  Data& dd = *w.dd;
  load_kinematics(*w.driven, dd, w.u.data(), nullptr);
  for (int k = 0; k < ic.n; ++k) {
    const int c = ic.full[k];
    const double raw = coord_value(m, dd.kin, c);
    q[k] = m.coords[c].angular ? tracked(dd, c, raw) : raw;
  }
}

// The largest motion of a body per unit of the path parameter along the tangent v (per body
// max(|CoM velocity| / length scale, |angular velocity|)) [rad]
double tangent_size(const Model& m, const VecX& v) {
  double r = 0.0;
  for (int i = 0; i < m.nb; ++i)
    r = std::max({r, v.segment<3>(6 * i).norm() / m.length_scale, v.segment<3>(6 * i + 3).norm()});
  return r;
}

// The longest step of the continuation: at most this rotation of a body per step [rad] (so the
// tracked angles, gear rows included, keep their turns)
constexpr double kMaxStep = 0.5;

// one step of the continuation from the state at q_from + s dq to q_from + s1 dq: the predictor
// along the path's tangent, then Newton; an empty string on success. `too_long` (> 0) when the
// step would move a body more than kMaxStep: the factor it is too long by (nothing solved)
std::string path_step(LoopWork& w, double t, double s, double s1, VecX& qs, double& too_long) {
  const Model& dm = *w.driven;
  Data& dd = *w.dd;
  too_long = 0.0;
  // the tangent at s: the velocity problem with the rates dq
  qs = w.q_from + s * w.dq;
  set_ref(w, qs, w.dq, 0.0, nullptr);
  project(dm, dd, t, w.u.data(), w.v.data(), Metric::Mass);
  const double size = tangent_size(dm, w.v) * (s1 - s);
  if (size > kMaxStep) {
    too_long = size / kMaxStep;
    return "";
  }
  udot(dm, w.u.data(), w.v.data(), w.ud.data());
  w.u_pred = w.u + (s1 - s) * w.ud;
  w.u_save = w.u;
  w.u = w.u_pred;
  qs = w.q_from + s1 * w.dq;
  set_ref(w, qs, w.dq, 0.0, nullptr);
  try {
    project(dm, dd, t, w.u.data(), w.v.data(), Metric::Mass);
  } catch (const SolverError& err) {
    return err.what();
  }
  if (const int bad = flipped_joint(dm, dd.kin); bad >= 0)
    return msg("the position problem converged to a flipped configuration of joint '",
               dm.joints[bad].name, "'");
  // Newton must stay on the branch it was predicted on
  if (distance(dm, w.u, w.u_pred) > std::max(0.25 * distance(dm, w.u_pred, w.u_save), 1e-3))
    return "the position correction is large against the predicted motion (another assembly "
           "branch, or a singular configuration on the way)";
  return "";
}

std::string coordinate_values(const Model& m, Eigen::Ref<const VecX> q) {
  std::string s;
  for (long k = 0; k < q.size(); ++k)
    s += msg(k ? ", " : "", m.coords[m.independent.full[k]].name, " = ", q[k]);
  return s;
}

// The singular configuration's message when the driven rows lost rank at the loaded state
std::string singular_note(LoopWork& w) {
  const KktSolver& kkt = w.dd->kkt;
  if (!(kkt.used_pseudo_inverse() && kkt.rank() < w.driven->rank_all)) return "";
  return msg(
      "the independent coordinates do not determine the configuration there (a singular "
      "configuration: the prescribed and joint rows have rank ",
      kkt.rank(), " instead of ", w.driven->rank_all,
      "; dependent rows: ", dependent_row_names(*w.driven, *w.dd), ")");
}

// LoopWork::linear: every coordinate's q, qd (and qdd, when given) from the independent ones;
// a ModelError naming the coordinate that overflows
void expand_linear(const Model& m, LoopWork& w, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                   const double* qdd, const char* fn) {
  const int nco = static_cast<int>(m.coords.size());
  for (int c = 0; c < nco; ++c) {
    const int k = w.lin_source[c];
    const double s = w.lin_scale[c];
    w.q_full[c] = s * q[k] + w.lin_shift[c];
    w.qd_full[c] = s * qd[k];
    if (qdd) w.qdd_full[c] = s * qdd[k];
    if (!std::isfinite(w.q_full[c]) || !std::isfinite(w.qd_full[c]) ||
        (qdd && !std::isfinite(w.qdd_full[c])))
      throw ModelError(msg(fn, ": joint coordinate '", m.coords[c].name, "' (", s,
                           " times independent coordinate '", m.coords[m.independent.full[k]].name,
                           "' through the gear and coupling rows) overflows at q = ", q[k],
                           ", qd = ", qd[k], qdd ? msg(", qdd = ", qdd[k]) : std::string(),
                           " (scale the inputs down)"));
  }
}

// LoopWork::linear: the state (w.u, w.v) at (q, qd) placed by the tree's kinematics at the
// coordinates the rows give (their turns exact), the driven Data's angle references those
// coordinates and its KKT factor marked stale (the pose changed without a projection)
void place_linear(const Model& m, LoopWork& w, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                  const char* fn) {
  const int nco = static_cast<int>(m.coords.size());
  expand_linear(m, w, q, qd, nullptr, fn);
  joint_space_kinematics(m, w.q_full, w.qd_full, w.kin);
  cartesian_state(m, w.kin, w.u.data(), w.v.data());
  if (!w.v.allFinite())
    throw ModelError(msg(fn, ": the bodies' velocities overflow at the rates qd = (",
                         coordinate_values(m, qd), ") (scale the inputs down)"));
  Data& dd = *w.dd;
  for (int c = 0; c < nco; ++c)
    if (m.coords[c].angular) dd.track_ref[c] = w.q_full[c];
  dd.kkt.mark_stale();
  dd.artic.mark_stale();
  w.q_last = q;
  w.have = true;
}

// The state (w.u, w.v) at (q, qd), by continuation from the Data's last state; restores it and
// throws SolverError on failure
void solve_state(const Model& m, Data& d, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                 double t, const char* fn) {
  LoopWork& w = loop_work(m, d);
  Data& dd = *w.dd;
  const IndependentCoords& ic = m.independent;
  if (w.linear) {
    place_linear(m, w, q, qd, fn);
    return;
  }
  if (!w.have) {
    w.u = m.u0;
    w.v.setZero();
    dd.track_ref.setZero();
    load_kinematics(*w.driven, dd, w.u.data(), nullptr);
    commit_tracking(*w.driven, dd);
    coordinates_of(m, w, w.q_last);
    w.have = true;
  }
  w.u_start = w.u;
  w.v_start = w.v;
  w.track_start = dd.track_ref;
  w.q_from = w.q_last;
  // an ideal gear's coordinates keep their turns (a turn of a gear is not a turn of its mate):
  // the path goes the whole way; without gears a loop's angles are taken modulo a turn
  const bool turns = has_ideal_gear(m);
  for (int k = 0; k < ic.n; ++k) {
    const double diff = q[k] - w.q_from[k];
    w.dq[k] = m.coords[ic.full[k]].angular && !turns ? wrap_angle(diff) : diff;
  }
  std::string failure;
  double s = 0.0, h = 1.0, h_len = 1.0;  // h_len: the step the length cap allowed
  VecX& qs = w.qs;
  while (s < 1.0 && ic.n > 0 && w.dq.cwiseAbs().maxCoeff() > 0.0) {
    const double s1 = std::min(s + h, 1.0);
    w.track_save = dd.track_ref;
    w.u_step = w.u;
    double too_long = 0.0;
    failure = path_step(w, t, s, s1, qs, too_long);
    if (failure.empty() && too_long == 0.0) {
      s = s1;
      continue;
    }
    w.u = w.u_step;
    dd.track_ref = w.track_save;
    if (too_long > 0.0) {  // shorter steps, not a failure
      h = h_len = 0.9 * (s1 - s) / too_long;
      continue;
    }
    h *= 0.5;
    if (h < h_len / 1024) break;
  }
  try {
    if (failure.empty()) {
      set_ref(w, q, qd, 0.0, nullptr);
      project(*w.driven, dd, t, w.u.data(), w.v.data(), Metric::Mass);
      failure = singular_note(w);
    }
  } catch (const SolverError& err) {
    failure = err.what();
  }
  if (!failure.empty()) {
    std::string note = singular_note(w);
    if (note == failure) note.clear();
    w.u = w.u_start;
    w.v = w.v_start;
    dd.track_ref = w.track_start;
    throw SolverError(msg(fn, ": no configuration at the independent coordinates (",
                          coordinate_values(m, q), ") reached from the last one (",
                          coordinate_values(m, w.q_last), "): ", failure, note.empty() ? "" : "; ",
                          note));
  }
  w.q_last = q;
}

// The velocity map T = dv/dqd at the solved position (column k: the velocities of unit rate of
// independent coordinate k), by the driven velocity problem
void velocity_map(const Model& m, LoopWork& w, Eigen::Ref<const VecX> q, double t) {
  const int n = m.independent.n;
  VecX& unit = w.unit;
  if (w.linear) {
    // the tree's velocities at the rates the rows give one unit of coordinate k
    for (int k = 0; k < n; ++k) {
      for (int c = 0; c < static_cast<int>(m.coords.size()); ++c)
        w.qd_full[c] = w.lin_source[c] == k ? w.lin_scale[c] : 0.0;
      joint_space_kinematics(m, w.q_full, w.qd_full, w.kin);
      cartesian_state(m, w.kin, w.u_save.data(), w.zero_v.data());
      w.T.col(k) = w.zero_v;
    }
    return;
  }
  for (int k = 0; k < n; ++k) {
    unit.setZero();
    unit[k] = 1.0;
    for (int i = 0; i < n; ++i) {
      w.ref[3 * i] = q[i];
      w.ref[3 * i + 1] = unit[i];
      w.ref[3 * i + 2] = 0.0;
    }
    w.zero_v = w.v;
    project(*w.driven, *w.dd, t, w.u.data(), w.zero_v.data(), Metric::Mass);
    w.T.col(k) = w.zero_v;
  }
}

DynamicsMethod loop_method(DynamicsMethod method, const char* fn) {
  if (method == DynamicsMethod::Auto || method == DynamicsMethod::Cartesian)
    return DynamicsMethod::Cartesian;
  throw ModelError(msg(fn,
                       ": a model with closed loops or ideal gears is evaluated on the Cartesian "
                       "formulation only: method must be 'auto' or 'cartesian'"));
}

}  // namespace

const VecX& loop_forward_dynamics(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                                  Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> tau, double t,
                                  DynamicsMethod method) {
  constexpr const char* fn = "forward_dynamics";
  loop_method(method, fn);
  check_loop_inputs(m, d, q, {{"qd", qd}, {"tau", tau}}, t, fn);
  solve_state(m, d, q, qd, t, fn);
  LoopWork& w = *d.loop;
  const IndependentCoords& ic = m.independent;
  // the KKT system of the joint rows with the torques as loads (forward_dynamics' Cartesian
  // settings, restored on every exit)
  struct Settings {
    Data& d;
    ~Settings() {
      d.joint_torques = nullptr;
      d.nrows = d.model->nc;
    }
  } restore{d};
  w.tau_full.setZero();
  for (int k = 0; k < ic.n; ++k) w.tau_full[ic.full[k]] = tau[k];
  d.nrows = m.nc_joint;
  d.aux = nullptr;
  d.augmented = false;
  d.with_coordinate_forces = true;
  d.joint_torques = w.tau_full.data();
  d.track_ref = w.dd->track_ref;
  load_kinematics(m, d, w.u.data(), w.v.data());
  body_accelerations_loaded(m, d, t, w.vd.data());
  for (int k = 0; k < ic.n; ++k)
    w.out[k] = coord_acceleration(m, d.tau_jets[ic.full[k]], ic.full[k], w.vd);
  return w.out;
}

namespace {

// the driven acceleration problem at the solved state: the multipliers in w.dd
void driven_accelerations(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                          Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> qdd, double t,
                          const char* fn) {
  (void)m;
  LoopWork& w = *d.loop;
  Data& dd = *w.dd;
  for (long k = 0; k < q.size(); ++k) {
    w.ref[3 * k] = q[k];
    w.ref[3 * k + 1] = qd[k];
    w.ref[3 * k + 2] = qdd[k];
  }
  dd.augmented = false;
  body_accelerations(*w.driven, dd, t, w.u.data(), w.v.data(), w.vd.data(), true);
  const std::string note = singular_note(w);
  if (!note.empty()) throw SolverError(msg(fn, ": ", note));
}

}  // namespace

const VecX& loop_inverse_dynamics(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                                  Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> qdd, double t,
                                  DynamicsMethod method) {
  constexpr const char* fn = "inverse_dynamics";
  const bool cartesian = method == DynamicsMethod::Cartesian;
  loop_method(method, fn);
  check_loop_inputs(m, d, q, {{"qd", qd}, {"qdd", qdd}}, t, fn);
  LoopWork& lw = loop_work(m, d);
  if (lw.linear && !cartesian) {
    // every coordinate affine in the independent ones (qdd_c = s_c qdd_k exactly): the
    // Newton-Euler recursion over all coordinates, reduced by the map (the rows' forces do no
    // work along it): tau_k = sum_c s_c tau_c over the coordinates c of k
    expand_linear(m, lw, q, qd, qdd.data(), fn);
    rnea_full(m, d, lw.q_full, lw.qd_full, lw.qdd_full, t);
    lw.out.setZero();
    for (int c = 0; c < static_cast<int>(m.coords.size()); ++c)
      lw.out[lw.lin_source[c]] += lw.lin_scale[c] * d.tau[c];
    return lw.out;
  }
  solve_state(m, d, q, qd, t, fn);
  driven_accelerations(m, d, q, qd, qdd, t, fn);
  LoopWork& w = *d.loop;
  for (int k = 0; k < m.independent.n; ++k) w.out[k] = -w.dd->delta[m.nc_joint + k];
  return w.out;
}

void loop_joint_reactions(const Model& m, Data& d, Eigen::Ref<const VecX> q,
                          Eigen::Ref<const VecX> qd, Eigen::Ref<const VecX> qdd, double t,
                          double* forces, double* torques) {
  constexpr const char* fn = "joint_reactions";
  check_loop_inputs(m, d, q, {{"qd", qd}, {"qdd", qdd}}, t, fn);
  solve_state(m, d, q, qd, t, fn);
  driven_accelerations(m, d, q, qd, qdd, t, fn);
  LoopWork& w = *d.loop;
  for (size_t j = 0; j < m.joints.size(); ++j) {
    Vec3 f, tq;
    joint_reaction(*w.driven, *w.dd, static_cast<int>(j), f, tq);
    for (int i = 0; i < 3; ++i) {
      forces[3 * j + i] = f[i];
      torques[3 * j + i] = tq[i];
    }
  }
}

const MatX& loop_mass_matrix(const Model& m, Data& d, Eigen::Ref<const VecX> q) {
  constexpr const char* fn = "mass_matrix";
  check_loop_inputs(m, d, q, {}, 0.0, fn);
  LoopWork& w = loop_work(m, d);
  solve_state(m, d, q, w.zero_n, 0.0, fn);
  velocity_map(m, w, q, 0.0);
  // Gamma T by bodies (Gamma block diagonal: m I and the inertia per body)
  for (int i = 0; i < m.nb; ++i) {
    w.GT.middleRows<3>(6 * i) = m.bodies[i].mass * w.T.middleRows<3>(6 * i);
    w.GT.middleRows<3>(6 * i + 3).noalias() = m.bodies[i].inertia * w.T.middleRows<3>(6 * i + 3);
  }
  w.M.noalias() = w.T.transpose() * w.GT;
  return w.M;
}

void loop_state(const Model& m, Data& d, Eigen::Ref<const VecX> q, Eigen::Ref<const VecX> qd,
                VecX& u, VecX& v, const char* fn) {
  check_loop_inputs(m, d, q, {{"qd", qd}}, 0.0, fn);
  solve_state(m, d, q, qd, 0.0, fn);
  u = d.loop->u;
  v = d.loop->v;
}

const Mat4& loop_frame_pose(const Model& m, Data& d, Eigen::Ref<const VecX> q, int frame) {
  constexpr const char* fn = "frame_pose";
  check_loop_inputs(m, d, q, {}, 0.0, fn);
  if (frame < 0 || frame >= static_cast<int>(m.frames.size()))
    throw ModelError(msg(fn, ": frame index ", frame, " out of range"));
  LoopWork& w = loop_work(m, d);
  solve_state(m, d, q, w.zero_n, 0.0, fn);
  return frame_pose_cartesian(m, d, w.u, frame);
}

const Mat6X& loop_frame_jacobian(const Model& m, Data& d, Eigen::Ref<const VecX> q, int frame) {
  constexpr const char* fn = "frame_jacobian";
  check_loop_inputs(m, d, q, {}, 0.0, fn);
  if (frame < 0 || frame >= static_cast<int>(m.frames.size()))
    throw ModelError(msg(fn, ": frame index ", frame, " out of range"));
  LoopWork& w = loop_work(m, d);
  solve_state(m, d, q, w.zero_n, 0.0, fn);
  velocity_map(m, w, q, 0.0);
  const MatX& Jv = frame_jacobian_cartesian(m, d, w.u, frame);
  w.J.noalias() = Jv * w.T;
  return w.J;
}

void loop_joint_coordinates(const Model& m, const VecX& u, const VecX& v, VecX& q, VecX& qd) {
  check_joint_vector(u, m.nq, "joint_coordinates", "u");
  check_joint_vector(v, m.nv, "joint_coordinates", "v");
  std::vector<BodyKin> kin;
  body_kinematics(m, u.data(), v.data(), kin);
  const IndependentCoords& ic = m.independent;
  q.resize(ic.n);
  qd.resize(ic.n);
  for (int k = 0; k < ic.n; ++k) {
    const ScalarJet s = coord_jet(m, kin, ic.full[k]);
    q[k] = s.val;
    qd[k] = s.rate;
  }
}

VecX loop_full_coordinates(const Model& m, const VecX& qi) {
  constexpr const char* fn = "simulate: q0";
  Data d(m);
  VecX u, v;
  loop_state(m, d, qi, VecX::Zero(qi.size()), u, v, fn);
  // the angles as the continuation tracked them (a gear's turns: its rows hold in them)
  Data& dd = *d.loop->dd;
  load_kinematics(*d.loop->driven, dd, u.data(), nullptr);
  const int nf = static_cast<int>(m.coords.size());
  VecX q(m.nq_joint);
  for (int c = 0; c < nf; ++c) {
    const double raw = coord_value(m, dd.kin, c);
    q[c] = m.coords[c].angular ? tracked(dd, c, raw) : raw;
  }
  const IndependentCoords& ic = m.independent;
  for (int k = 0; k < ic.n; ++k) q[ic.full[k]] = qi[k];
  ic.align(m.coords, q.data());
  return q;
}

}  // namespace armdyn
