#ifndef TILTCAL_STAGES_CALIBRATE_RESIDUALS_BIAS_RANDOM_WALK_COST_FUNCTION_H_
#define TILTCAL_STAGES_CALIBRATE_RESIDUALS_BIAS_RANDOM_WALK_COST_FUNCTION_H_

// Random-walk prior between two consecutive piecewise-constant bias segments
// b_i, b_{i+1} (3 each, same unit, e.g. m/s^2 for the accelerometer), whose
// centres are dt_s apart:
//   r = (b_{i+1} - b_i) / (sigma_rw * sqrt(dt_s))          (3, dimensionless)
// sigma_rw: the bias random walk (m/s^3/sqrt(Hz) for the accelerometer, i.e.
// the standard deviation of the bias change over one second).
// Parameter blocks: 0 b_i (3), 1 b_{i+1} (3). Jacobians -I/s and +I/s,
// s = sigma_rw sqrt(dt_s).

#include <ceres/sized_cost_function.h>

namespace tiltcal::calibrate {

class BiasRandomWalkCostFunction final : public ceres::SizedCostFunction<3, 3, 3> {
 public:
  BiasRandomWalkCostFunction(double sigma_rw, double dt_s);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  double inv_sigma_;
};

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_RESIDUALS_BIAS_RANDOM_WALK_COST_FUNCTION_H_
