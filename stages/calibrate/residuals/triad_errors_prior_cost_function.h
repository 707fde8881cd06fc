#ifndef TILTCAL_STAGES_CALIBRATE_RESIDUALS_TRIAD_ERRORS_PRIOR_COST_FUNCTION_H_
#define TILTCAL_STAGES_CALIBRATE_RESIDUALS_TRIAD_ERRORS_PRIOR_COST_FUNCTION_H_

// Prior of an IMU triad's errors E (common/imu/triad_errors.h) at zero, an
// ideal triad:
//   r_ij = E_ij / sigma_ij        (9, dimensionless)
// sigma_ii = the scale prior (a fraction), sigma_ij (i != j) = the
// misalignment prior (rad): the datasheet's tolerances of a consumer IMU.
//
// Parameter block: E, 9 doubles row-major. Entries held by a manifold (the
// accelerometer's upper triangle) stay at zero and cost nothing.

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

namespace tiltcal::calibrate {

class TriadErrorsPriorCostFunction final : public ceres::SizedCostFunction<9, 9> {
 public:
  TriadErrorsPriorCostFunction(double scale_sigma, double misalignment_sigma_rad) {
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        inv_sigma_[3 * i + j] = 1.0 / (i == j ? scale_sigma : misalignment_sigma_rad);
      }
    }
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    for (int k = 0; k < 9; ++k) residuals[k] = inv_sigma_[k] * parameters[0][k];
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 9, 9, Eigen::RowMajor>> j(jacobians[0]);
      j = inv_sigma_.asDiagonal();
    }
    return true;
  }

 private:
  Eigen::Matrix<double, 9, 1> inv_sigma_;
};

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_RESIDUALS_TRIAD_ERRORS_PRIOR_COST_FUNCTION_H_
