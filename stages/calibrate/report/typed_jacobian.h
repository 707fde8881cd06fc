#ifndef TILTCAL_STAGES_CALIBRATE_REPORT_TYPED_JACOBIAN_H_
#define TILTCAL_STAGES_CALIBRATE_REPORT_TYPED_JACOBIAN_H_

// The Jacobian of every residual block of a calibration problem (robust loss
// applied, residuals weighted by their sigma) in the columns of the given
// parameter blocks, with each row's residual type (residual_type.h) and per
// type the weighted square sum 2F_k (ceres' cost with the robust loss, times
// 2) at the current parameters.

#include <array>
#include <vector>

#include <ceres/problem.h>

#include <Eigen/SparseCore>

#include "common/status.h"
#include "stages/calibrate/report/residual_type.h"

namespace tiltcal::calibrate {

struct TypedJacobian {
  Eigen::SparseMatrix<double, Eigen::RowMajor> jacobian;
  std::vector<int> row_type;  // ResidualType of each row
  std::array<double, kNumResidualTypes> square_sum{};
};

Status EvaluateTypedJacobian(ceres::Problem* problem, const std::vector<double*>& parameter_blocks,
                             int num_threads, TypedJacobian* out);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_REPORT_TYPED_JACOBIAN_H_
