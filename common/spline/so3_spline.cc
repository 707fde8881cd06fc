#include "common/spline/so3_spline.h"

#include <Eigen/Geometry>

#include "common/geometry/so3.h"
#include "common/spline/cubic_basis.h"

namespace tiltcal::spline {

using geometry::Hat;

namespace {

// The terms of the knot intervals j = 1..3 (index 0 unused but for t[0]).
struct KnotTerms {
  Eigen::Vector3d d[4];          // knot deltas d_j
  Eigen::Matrix3d e[4];          // E_j = Exp(lambda_j d_j) (A_j = E_j^T)
  Eigen::Matrix3d jr_scaled[4];  // Jr(lambda_j d_j), when Jacobians are requested
  Eigen::Matrix3d t[4];          // suffix products T_j = E_{j+1} ... E_3 (T_3 = I)
  Eigen::Vector3d w_prev[4];     // w^{j-1} of the angular velocity recursion
  Eigen::Matrix3d jr_inv[4];     // Jr^{-1}(d_j), when Jacobians are requested
};

// Knot deltas d_j (index 1..3) and the factors E_j = Exp(lambda_j d_j), with
// Jr(lambda_j d_j) when `want_jac`; then the suffix products T_j.
void KnotFactors(const double* const knots[4], const CubicBasis& basis, bool want_jac,
                 KnotTerms* k) {
  for (int j = 1; j < 4; ++j) {
    const Eigen::Map<const Eigen::Quaterniond> q_a(knots[j - 1]);
    const Eigen::Map<const Eigen::Quaterniond> q_b(knots[j]);
    k->d[j] = geometry::LogQuaternion(Eigen::Quaterniond(q_a.conjugate() * q_b));
    const Eigen::Vector3d phi = basis.value[j] * k->d[j];
    if (want_jac) {
      geometry::ExpMatrixAndRightJacobian(phi, &k->e[j], &k->jr_scaled[j]);
    } else {
      k->e[j] = geometry::ExpMatrix(phi);
    }
  }
  k->t[3].setIdentity();
  for (int j = 2; j >= 0; --j) k->t[j] = k->e[j + 1] * k->t[j + 1];
}

// Recursions for omega and alpha (alpha when `want_acc`); keeps w^{j-1} in
// k->w_prev[j].
void AngularVelocityRecursion(const CubicBasis& basis, bool want_acc, KnotTerms* k,
                              So3SplineSample* sample) {
  Eigen::Vector3d w = Eigen::Vector3d::Zero();
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  for (int j = 1; j < 4; ++j) {
    k->w_prev[j] = w;
    const Eigen::Vector3d vd = basis.d1[j] * k->d[j];
    w = k->e[j].transpose() * w + vd;
    if (want_acc) a = k->e[j].transpose() * a + basis.d2[j] * k->d[j] + w.cross(vd);
  }
  sample->angular_velocity = w;
  if (want_acc) sample->angular_acceleration = a;
}

// d eps / d d_j = T_j^T lambda_j Jr(lambda_j d_j);  d eps / d delta_0 (direct) = T_0^T.
void RotationJacobian(const CubicBasis& basis, const KnotTerms& k, So3SplineSample* sample) {
  Eigen::Matrix3d v[4];
  for (int j = 1; j < 4; ++j) v[j] = basis.value[j] * k.t[j].transpose() * k.jr_scaled[j];
  auto& jac = sample->rotation_jacobian;
  jac[0] = k.t[0].transpose() - v[1] * k.jr_inv[1].transpose();
  jac[1] = v[1] * k.jr_inv[1] - v[2] * k.jr_inv[2].transpose();
  jac[2] = v[2] * k.jr_inv[2] - v[3] * k.jr_inv[3].transpose();
  jac[3] = v[3] * k.jr_inv[3];
}

// d omega / d d_j = T_j^T (lambda_j A_j [w^{j-1}]_x Jr(-lambda_j d_j) + lambda'_j I),
// with A_j = E_j^T and Jr(-x) = Jr(x)^T. w^0 = 0 so the first term vanishes for j = 1.
void AngularVelocityJacobian(const CubicBasis& basis, const KnotTerms& k,
                             So3SplineSample* sample) {
  Eigen::Matrix3d wj[4];
  for (int j = 1; j < 4; ++j) {
    Eigen::Matrix3d inner = basis.d1[j] * Eigen::Matrix3d::Identity();
    if (j > 1) {
      inner.noalias() +=
          basis.value[j] * k.e[j].transpose() * Hat(k.w_prev[j]) * k.jr_scaled[j].transpose();
    }
    wj[j].noalias() = k.t[j].transpose() * inner;
  }
  auto& jac = sample->angular_velocity_jacobian;
  jac[0] = -wj[1] * k.jr_inv[1].transpose();
  jac[1] = wj[1] * k.jr_inv[1] - wj[2] * k.jr_inv[2].transpose();
  jac[2] = wj[2] * k.jr_inv[2] - wj[3] * k.jr_inv[3].transpose();
  jac[3] = wj[3] * k.jr_inv[3];
}

}  // namespace

void EvaluateSo3Spline(const double* const knots[4], double u, double inv_dt, int outputs,
                       So3SplineSample* sample) {
  const bool want_rot_jac = (outputs & kSo3RotationJacobian) != 0;
  const bool want_vel_jac = (outputs & kSo3AngularVelocityJacobian) != 0;
  const bool want_rot = want_rot_jac || want_vel_jac || (outputs & kSo3Rotation) != 0;
  const bool want_acc = (outputs & kSo3AngularAcceleration) != 0;
  const bool want_vel = want_acc || want_vel_jac || (outputs & kSo3AngularVelocity) != 0;
  const bool want_jac = want_rot_jac || want_vel_jac;

  const CubicBasis basis = CumulativeCubicBasis(u, inv_dt);
  KnotTerms k;
  KnotFactors(knots, basis, want_jac, &k);
  if (want_rot) {
    const Eigen::Map<const Eigen::Quaterniond> q0(knots[0]);
    sample->rotation = q0.toRotationMatrix() * k.t[0];
  }
  if (want_vel) AngularVelocityRecursion(basis, want_acc, &k, sample);
  if (!want_jac) return;

  // d d_j / d delta_{s+j-1} = -Jl^{-1}(d_j) = -Jr^{-1}(d_j)^T,
  // d d_j / d delta_{s+j}   = +Jr^{-1}(d_j).
  for (int j = 1; j < 4; ++j) k.jr_inv[j] = geometry::RightJacobianInverse(k.d[j]);
  if (want_rot_jac) RotationJacobian(basis, k, sample);
  if (want_vel_jac) AngularVelocityJacobian(basis, k, sample);
}

}  // namespace tiltcal::spline
