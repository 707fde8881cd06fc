#include "common/spline/so3_spline.h"

#include <Eigen/Geometry>

#include "common/geometry/so3.h"
#include "common/spline/cubic_basis.h"

namespace tiltcal::spline {

using geometry::Hat;

void EvaluateSo3Spline(const double* const knots[4], double u, double inv_dt, int outputs,
                       So3SplineSample* sample) {
  const bool want_rot_jac = (outputs & kSo3RotationJacobian) != 0;
  const bool want_vel_jac = (outputs & kSo3AngularVelocityJacobian) != 0;
  const bool want_rot = want_rot_jac || want_vel_jac || (outputs & kSo3Rotation) != 0;
  const bool want_acc = (outputs & kSo3AngularAcceleration) != 0;
  const bool want_vel = want_acc || want_vel_jac || (outputs & kSo3AngularVelocity) != 0;
  const bool want_jac = want_rot_jac || want_vel_jac;

  const CubicBasis basis = CumulativeCubicBasis(u, inv_dt);

  // Knot deltas d_j (index 1..3) and the factors E_j = Exp(lambda_j d_j)
  // (A_j = E_j^T), with Jr(lambda_j d_j) when Jacobians are requested.
  Eigen::Vector3d d[4];
  Eigen::Matrix3d e[4];
  Eigen::Matrix3d jr_scaled[4];
  for (int j = 1; j < 4; ++j) {
    const Eigen::Map<const Eigen::Quaterniond> q_a(knots[j - 1]);
    const Eigen::Map<const Eigen::Quaterniond> q_b(knots[j]);
    d[j] = geometry::LogQuaternion(Eigen::Quaterniond(q_a.conjugate() * q_b));
    const Eigen::Vector3d phi = basis.value[j] * d[j];
    if (want_jac) {
      geometry::ExpMatrixAndRightJacobian(phi, &e[j], &jr_scaled[j]);
    } else {
      e[j] = geometry::ExpMatrix(phi);
    }
  }

  // Suffix products T_j = E_{j+1} ... E_3 (T_3 = I).
  Eigen::Matrix3d t[4];
  t[3].setIdentity();
  for (int j = 2; j >= 0; --j) t[j] = e[j + 1] * t[j + 1];

  if (want_rot) {
    const Eigen::Map<const Eigen::Quaterniond> q0(knots[0]);
    sample->rotation = q0.toRotationMatrix() * t[0];
  }

  // Recursions for omega and alpha; w_prev[j] = w^{j-1}.
  Eigen::Vector3d w_prev[4];
  if (want_vel) {
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    Eigen::Vector3d a = Eigen::Vector3d::Zero();
    for (int j = 1; j < 4; ++j) {
      w_prev[j] = w;
      const Eigen::Vector3d vd = basis.d1[j] * d[j];
      w = e[j].transpose() * w + vd;
      if (want_acc) a = e[j].transpose() * a + basis.d2[j] * d[j] + w.cross(vd);
    }
    sample->angular_velocity = w;
    if (want_acc) sample->angular_acceleration = a;
  }

  if (!want_jac) return;

  // d d_j / d delta_{s+j-1} = -Jl^{-1}(d_j) = -Jr^{-1}(d_j)^T,
  // d d_j / d delta_{s+j}   = +Jr^{-1}(d_j).
  Eigen::Matrix3d jr_inv[4];
  for (int j = 1; j < 4; ++j) jr_inv[j] = geometry::RightJacobianInverse(d[j]);

  if (want_rot_jac) {
    // d eps / d d_j = T_j^T lambda_j Jr(lambda_j d_j);  d eps / d delta_0 (direct) = T_0^T.
    Eigen::Matrix3d v[4];
    for (int j = 1; j < 4; ++j) v[j] = basis.value[j] * t[j].transpose() * jr_scaled[j];
    auto& jac = sample->rotation_jacobian;
    jac[0] = t[0].transpose() - v[1] * jr_inv[1].transpose();
    jac[1] = v[1] * jr_inv[1] - v[2] * jr_inv[2].transpose();
    jac[2] = v[2] * jr_inv[2] - v[3] * jr_inv[3].transpose();
    jac[3] = v[3] * jr_inv[3];
  }

  if (want_vel_jac) {
    // d omega / d d_j = T_j^T (lambda_j A_j [w^{j-1}]_x Jr(-lambda_j d_j) + lambda'_j I),
    // with A_j = E_j^T and Jr(-x) = Jr(x)^T. w^0 = 0 so the first term vanishes for j = 1.
    Eigen::Matrix3d wj[4];
    for (int j = 1; j < 4; ++j) {
      Eigen::Matrix3d inner = basis.d1[j] * Eigen::Matrix3d::Identity();
      if (j > 1) {
        inner.noalias() +=
            basis.value[j] * e[j].transpose() * Hat(w_prev[j]) * jr_scaled[j].transpose();
      }
      wj[j].noalias() = t[j].transpose() * inner;
    }
    auto& jac = sample->angular_velocity_jacobian;
    jac[0] = -wj[1] * jr_inv[1].transpose();
    jac[1] = wj[1] * jr_inv[1] - wj[2] * jr_inv[2].transpose();
    jac[2] = wj[2] * jr_inv[2] - wj[3] * jr_inv[3].transpose();
    jac[3] = wj[3] * jr_inv[3];
  }
}

}  // namespace tiltcal::spline
