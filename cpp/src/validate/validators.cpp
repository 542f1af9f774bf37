// SPDX-License-Identifier: BSD-3-Clause
#include "armdyn/validate/validators.hpp"

#include <unsupported/Eigen/AutoDiff>

#include "armdyn/algorithm/forces.hpp"
#include "armdyn/errors.hpp"
#include "joint_fk.hpp"

namespace armdyn {

namespace {

using AD = Eigen::AutoDiffScalar<VecX>;
using ADVec = Eigen::Matrix<AD, Eigen::Dynamic, 1>;
using ADMat = Eigen::Matrix<AD, Eigen::Dynamic, Eigen::Dynamic>;
using ADV3 = Eigen::Matrix<AD, 3, 1>;
using ADM3 = Eigen::Matrix<AD, 3, 3>;

void check(const VecX& x, long n, const char* name) {
  if (x.size() != n)
    throw ModelError(msg("LagrangeValidator: ", name, " has length ", x.size(), ", expected ", n));
  if (!x.allFinite()) throw ModelError(msg("LagrangeValidator: ", name, " contains NaN or inf"));
}

AD constant(double v, int n) { return AD(v, VecX::Zero(n)); }

}  // namespace

LagrangeValidator::LagrangeValidator(std::shared_ptr<const Model> m, bool rotational_inertia)
    : m_(std::move(m)), rot_(rotational_inertia) {
  if (!m_) throw ModelError("LagrangeValidator: no model");
  require_joint_space(*m_, "LagrangeValidator", true);
  for (const CoordForce& cf : m_->coord_forces)
    if (cf.aux >= 0)
      throw ModelError(msg("LagrangeValidator: ", cf.name,
                           " has an integral term (ki > 0), a state outside the joint "
                           "coordinates; validate the model without it"));
}

namespace {
// the chart coordinates of joint_fk at q (joint-space sizes): the coordinates' values, and zero
// for the floating bases' charts (about the pose in q itself)
VecX chart_of(const Model& m, const VecX& q) {
  VecX x = VecX::Zero(m.nv_joint);
  const int nc = static_cast<int>(m.coords.size());
  x.tail(nc) = q.tail(nc);
  return x;
}
}  // namespace

bool LagrangeValidator::coupled() const {
  const IndependentCoords& ic = m_->independent;
  return !ic.source.empty() && !ic.identity();
}
long LagrangeValidator::nq() const { return coupled() ? m_->independent.nq() : m_->nq_joint; }
long LagrangeValidator::nv() const { return coupled() ? m_->independent.nv() : m_->nv_joint; }

MatX LagrangeValidator::mass_matrix(const VecX& q) const {
  if (!coupled()) return full_mass_matrix(q);
  const IndependentCoords& ic = m_->independent;
  check(q, ic.nq(), "q");
  VecX qf(m_->nq_joint);
  ic.expand_q(q.data(), qf.data());
  MatX Mr(ic.nv(), ic.nv());
  ic.reduce(full_mass_matrix(qf), Mr);
  return Mr;
}

VecX LagrangeValidator::torques(const VecX& q, const VecX& qd, const VecX& qdd, double t) const {
  if (!coupled()) return full_torques(q, qd, qdd, t);
  // the couplings' rows are linear in q: G qd and G qdd are the full rates and accelerations
  const IndependentCoords& ic = m_->independent;
  check(q, ic.nq(), "q");
  check(qd, ic.nv(), "qd");
  check(qdd, ic.nv(), "qdd");
  VecX qf(m_->nq_joint), qdf(m_->nv_joint), qddf(m_->nv_joint), tau(ic.nv());
  ic.expand_q(q.data(), qf.data());
  ic.expand_v(qd.data(), qdf.data());
  ic.expand_v(qdd.data(), qddf.data());
  ic.reduce(full_torques(qf, qdf, qddf, t).data(), tau.data());
  return tau;
}

MatX LagrangeValidator::full_mass_matrix(const VecX& q) const {
  const Model& m = *m_;
  const int n = m.nv_joint;
  check(q, m.nq_joint, "q");
  check_base_quaternions(m, q, "LagrangeValidator");
  JointFk<double> fk;
  joint_fk<double>(m, chart_of(m, q), fk, true, q.data());
  MatX M = MatX::Zero(n, n);
  for (int i = 0; i < m.nb; ++i) {
    const Body& b = m.bodies[i];
    M.noalias() += b.mass * fk.Jv[i].transpose() * fk.Jv[i];
    if (rot_) {
      const Mat3 Iw = fk.R[i] * b.inertia * fk.R[i].transpose();
      M.noalias() += fk.Jw[i].transpose() * Iw * fk.Jw[i];
    }
  }
  return M;
}

VecX LagrangeValidator::full_torques(const VecX& q, const VecX& qd, const VecX& qdd_in,
                                     double t) const {
  const Model& m = *m_;
  const int n = m.nv_joint, F = m.n_free;
  check(q, m.nq_joint, "q");
  check(qd, n, "qd");
  check(qdd_in, n, "qdd");
  check_base_quaternions(m, q, "LagrangeValidator");
  if (!std::isfinite(t)) throw ModelError("LagrangeValidator: t is not finite");
  // kinematics with derivatives with respect to every coordinate (a floating base's chart
  // about its pose in q: chart rates (v, w); chart accelerations (v' + w x v, w'), joint_fk)
  const VecX x = chart_of(m, q);
  VecX qdd = qdd_in;
  for (const Joint& j : m.joints) {
    if (j.type != JointType::Free) continue;
    const Vec3 v = qd.segment<3>(j.dof0), w = qd.segment<3>(j.dof0 + 3);
    qdd.segment<3>(j.dof0) += w.cross(v);
  }
  ADVec qa(n);
  for (int k = 0; k < n; ++k) qa[k] = AD(x[k], n, k);
  JointFk<AD> fk;
  joint_fk<AD>(m, qa, fk, true, q.data());
  ADMat M = ADMat::Constant(n, n, constant(0.0, n));
  AD V = constant(0.0, n);
  const ADV3 g = m.gravity.cast<AD>();
  for (int i = 0; i < m.nb; ++i) {
    const Body& b = m.bodies[i];
    const AD mass = constant(b.mass, n);
    M += mass * (fk.Jv[i].transpose() * fk.Jv[i]);
    if (rot_) {
      const ADM3 Iw = fk.R[i] * b.inertia.cast<AD>() * fk.R[i].transpose();
      M += fk.Jw[i].transpose() * (Iw * fk.Jw[i]);
    }
    V -= mass * g.dot(fk.x[i]);
  }
  VecX Q = VecX::Zero(n);
  // point-to-point spring-dampers: potential 1/2 k (L - L0)^2, damping force -c Ldot on L
  for (const SpringDamper& sd : m.springs) {
    auto point = [&](int body, const Vec3& p) -> ADV3 {
      if (body == kGround) return p.cast<AD>();
      return fk.x[body] + fk.R[body] * p.cast<AD>();
    };
    const AD L = (point(sd.body_b, sd.point_b) - point(sd.body_a, sd.point_a)).norm();
    const AD e = L - constant(sd.rest_length, n);
    V += constant(0.5 * sd.stiffness, n) * e * e;
    const VecX dL = L.derivatives();
    Q -= sd.damping * dL.dot(qd) * dL;
  }
  // joint springs, dampers, friction and inputs on the coordinates
  // (the coordinates follow the floating bases' blocks: 7 entries each in q, 6 in qd and Q)
  const double* qc = q.data() + 7 * F;
  const double* qdc = qd.data() + 6 * F;
  double* Qc = Q.data() + 6 * F;
  for (const CoordForce& cf : m.coord_forces)
    Qc[cf.coord] +=
        coord_force_value(cf, m.coords[cf.coord].angular, qc[cf.coord], qdc[cf.coord], t);
  // gear pairs (q are unwrapped here)
  for (int gi = 0; gi < static_cast<int>(m.gears.size()); ++gi) {
    double s, sd, pen;
    gear_mesh(m, gi, qc, qdc, s, sd, pen);
    add_gear_torques(m.gears[gi], gear_mesh_force(m.gears[gi], s, sd), Qc);
  }
  // body loads: world force at a body point and world torque
  for (const BodyLoad& l : m.body_loads) {
    const double s = l.has_profile ? l.profile.eval(t).y : 1.0;
    Eigen::Matrix<double, 3, Eigen::Dynamic> Jv(3, n), Jw(3, n);
    for (int k = 0; k < n; ++k)
      for (int r = 0; r < 3; ++r) {
        Jv(r, k) = fk.Jv[l.body](r, k).value();
        Jw(r, k) = fk.Jw[l.body](r, k).value();
      }
    Mat3 R;
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 3; ++c) R(a, c) = fk.R[l.body](a, c).value();
    const Vec3 F = s * l.force, T = s * l.torque;
    Q += Jv.transpose() * F + Jw.transpose() * (T + (R * l.point).cross(F));
  }
  // Euler-Lagrange: M qdd + Mdot qd - 1/2 d(qd^T M qd)/dq + dV/dq = tau + Q
  VecX tau = -Q;
  for (int i = 0; i < n; ++i) {
    double row = 0.0;
    for (int j = 0; j < n; ++j) {
      const AD& Mij = M(i, j);
      row += Mij.value() * qdd[j];
      if (Mij.derivatives().size() == n) {
        row += Mij.derivatives().dot(qd) * qd[j];
        tau -= 0.5 * qd[i] * qd[j] * Mij.derivatives();
      }
    }
    tau[i] += row;
  }
  if (V.derivatives().size() == n) tau += V.derivatives();
  return tau;
}

Vec3 paper_3dof_torques(const Vec3& L, const Vec3& M, double g, const Vec3& th, const Vec3& thd) {
  using std::cos;
  using std::sin;
  const double s12 = sin(th[0] - th[1]), s13 = sin(th[0] - th[2]), s23 = sin(th[1] - th[2]);
  Vec3 T;
  // (9)
  T[0] = L[0] * (M[0] * g * cos(th[0]) + M[1] * g * cos(th[0]) + M[2] * g * cos(th[0]) +
                 L[1] * M[1] * thd[1] * thd[0] * s12 + L[1] * M[2] * thd[1] * thd[0] * s12 +
                 L[2] * M[2] * thd[2] * thd[0] * s13);
  // (10)
  T[1] = L[1] * M[1] * g * cos(th[1]) + L[1] * M[2] * g * cos(th[1]) -
         L[0] * L[1] * M[1] * thd[0] * thd[1] * s12 - L[0] * L[1] * M[2] * thd[0] * thd[1] * s12 +
         L[1] * L[2] * M[2] * thd[1] * thd[2] * s23;
  // (11)
  T[2] = L[2] * M[2] * g * cos(th[2]) - L[0] * L[2] * M[2] * thd[2] * thd[0] * s13 -
         L[1] * L[2] * M[2] * thd[2] * thd[1] * s23;
  return T;
}

Vec3 paper_5dof_end_effector(double h, double L1, double L2, double L34, const Vec4& th) {
  using std::cos;
  using std::sin;
  const double Y = h + L1 * sin(th[1]) + L2 * sin(th[2]) + L34 * sin(th[3]);   // (22)
  const double lambda = L1 * cos(th[1]) + L2 * cos(th[2]) + L34 * cos(th[3]);  // (23)
  return Vec3(lambda * cos(th[0]), Y, lambda * sin(th[0]));                    // (24), (25)
}

Vec3 end_effector_position(const Model& m, int body, const Vec3& point, const VecX& q) {
  require_joint_space(m, "end_effector_position");
  const long n = m.nq_joint;
  if (q.size() != n)
    throw ModelError(msg("end_effector_position: q has length ", q.size(), ", expected ", n));
  if (!q.allFinite()) throw ModelError("end_effector_position: q contains NaN or inf");
  if (!point.allFinite()) throw ModelError("end_effector_position: point contains NaN or inf");
  if (body == kGround) return point;
  if (body < 0 || body >= m.nb) throw ModelError(msg("end_effector_position: no body ", body));
  check_base_quaternions(m, q, "end_effector_position");
  JointFk<double> fk;
  joint_fk<double>(m, chart_of(m, q), fk, false, q.data());
  return fk.x[body] + fk.R[body] * point;
}

TorqueErrorMetrics torque_error_metrics(const MatX& a, const MatX& ref) {
  if (a.rows() != ref.rows() || a.cols() != ref.cols())
    throw ModelError(msg("torque_error_metrics: shapes differ: (", a.rows(), ", ", a.cols(),
                         ") and (", ref.rows(), ", ", ref.cols(), ")"));
  if (a.rows() == 0) throw ModelError("torque_error_metrics: no samples");
  if (!a.allFinite() || !ref.allFinite())
    throw ModelError("torque_error_metrics: inputs contain NaN or inf");
  TorqueErrorMetrics r;
  const long k = a.cols();
  r.ref_max = ref.cwiseAbs().colwise().maxCoeff().transpose();
  r.percent = MatX(a.rows(), k);
  for (long j = 0; j < k; ++j) {
    if (!(r.ref_max[j] > 0))
      throw ModelError(msg("torque_error_metrics: reference column ", j, " is identically zero"));
    r.percent.col(j) = (a.col(j) - ref.col(j)).cwiseAbs() / r.ref_max[j] * 100.0;  // (26)
  }
  r.rms = (r.percent.array().square().colwise().sum() / static_cast<double>(a.rows()))
              .sqrt()
              .transpose();  // (27)
  r.max = r.percent.cwiseAbs().colwise().maxCoeff().transpose();
  r.average = r.rms.mean();
  return r;
}

MatX LagrangeValidator::torques(const MatX& Q, const MatX& QD, const MatX& QDD,
                                const VecX& t) const {
  if (QD.rows() != Q.rows() || QDD.rows() != Q.rows())
    throw ModelError("LagrangeValidator.torques: q, qd, qdd need the same number of rows");
  MatX out(Q.rows(), nv());
  for (long i = 0; i < Q.rows(); ++i)
    out.row(i) = torques(VecX(Q.row(i).transpose()), VecX(QD.row(i).transpose()),
                         VecX(QDD.row(i).transpose()), t[i])
                     .transpose();
  return out;
}

MatX paper_3dof_torques(const Vec3& L, const Vec3& M, double g, const MatX& theta,
                        const MatX& thetad) {
  if (theta.rows() != thetad.rows())
    throw ModelError("paper_3dof_torques: theta and thetad need the same number of rows");
  MatX out(theta.rows(), 3);
  for (long i = 0; i < theta.rows(); ++i)
    out.row(i) =
        paper_3dof_torques(L, M, g, Vec3(theta.row(i).transpose()), Vec3(thetad.row(i).transpose()))
            .transpose();
  return out;
}

MatX end_effector_positions(const Model& m, int body, const Vec3& point, const MatX& q) {
  MatX out(q.rows(), 3);
  for (long i = 0; i < q.rows(); ++i)
    out.row(i) = end_effector_position(m, body, point, VecX(q.row(i).transpose())).transpose();
  return out;
}

}  // namespace armdyn
