#include "stages/calibrate/residuals/bias_random_walk_cost_function.h"

#include <cmath>

namespace tiltcal::calibrate {

BiasRandomWalkCostFunction::BiasRandomWalkCostFunction(double sigma_rw, double dt_s)
    : inv_sigma_(1.0 / (sigma_rw * std::sqrt(dt_s))) {}

bool BiasRandomWalkCostFunction::Evaluate(double const* const* parameters, double* residuals,
                                          double** jacobians) const {
  for (int i = 0; i < 3; ++i) residuals[i] = (parameters[1][i] - parameters[0][i]) * inv_sigma_;
  if (jacobians == nullptr) return true;
  for (int block = 0; block < 2; ++block) {
    if (jacobians[block] == nullptr) continue;
    const double sign = block == 0 ? -inv_sigma_ : inv_sigma_;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) jacobians[block][3 * r + c] = r == c ? sign : 0.0;
    }
  }
  return true;
}

}  // namespace tiltcal::calibrate
