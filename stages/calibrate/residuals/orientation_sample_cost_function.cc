#include "stages/calibrate/residuals/orientation_sample_cost_function.h"

#include "common/geometry/so3.h"
#include "common/spline/so3_spline.h"
#include "stages/calibrate/residuals/jacobian_writer.h"

namespace tiltcal::calibrate {

OrientationSampleCostFunction::OrientationSampleCostFunction(
    const spline::KnotWindow& window, double inv_dt, const Eigen::Quaterniond& measured_a_from_b,
    double sigma_rad)
    : u_(window.u),
      inv_dt_(inv_dt),
      measured_transposed_(measured_a_from_b.normalized().toRotationMatrix().transpose()),
      inv_sigma_(1.0 / sigma_rad) {}

bool OrientationSampleCostFunction::Evaluate(double const* const* parameters, double* residuals,
                                             double** jacobians) const {
  const bool knot_jacobians = KnotJacobiansRequested(jacobians);
  spline::So3SplineSample s;
  spline::EvaluateSo3Spline(
      parameters, u_, inv_dt_,
      spline::kSo3Rotation | (knot_jacobians ? spline::kSo3RotationJacobian : 0), &s);
  const Eigen::Vector3d phi = geometry::LogMatrix(measured_transposed_ * s.rotation);
  Eigen::Map<Eigen::Vector3d> r(residuals);
  r = inv_sigma_ * phi;
  if (!knot_jacobians) return true;
  // Log(M^T R Exp(eps)) = phi + J_r^{-1}(phi) eps + O(eps^2).
  const Eigen::Matrix3d d_eps = inv_sigma_ * geometry::RightJacobianInverse(phi);
  for (int i = 0; i < 4; ++i) {
    if (jacobians[i] == nullptr) continue;
    WriteQuaternionJacobian<3>(d_eps * s.rotation_jacobian[i], parameters[i], jacobians[i]);
  }
  return true;
}

}  // namespace tiltcal::calibrate
