#ifndef TILTCAL_STAGES_CALIBRATE_REPORT_TYPED_JACOBIAN_H_
#define TILTCAL_STAGES_CALIBRATE_REPORT_TYPED_JACOBIAN_H_

// The Jacobian of every residual block of a calibration problem (robust loss
// applied, residuals weighted by their sigma) in the columns of the given
// parameter blocks, with each row's variance group (residual_type.h), its
// residual and its component, and per group the weighted square
// sum 2F_k (ceres' cost with the robust loss, times 2) at the current
// parameters. Rows are in the order the problem holds its residual blocks:
// the order they were added in (the calibration removes none), for the ground
// residuals the scans' order.

#include <array>
#include <vector>

#include <ceres/problem.h>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "common/status.h"
#include "stages/calibrate/report/residual_type.h"

namespace tiltcal::calibrate {

struct TypedJacobian {
  Eigen::SparseMatrix<double, Eigen::RowMajor> jacobian;
  std::vector<int> row_group;        // VarianceGroup of each row
  // The row's index within its measurement: 0..2 for a gyro, accel, flat or
  // up residual (a stacked block's rows in turn), 0 for a dist, incl or
  // LiDAR residual.
  std::vector<int> row_component;
  Eigen::VectorXd residuals;         // weighted, robust loss applied
  std::array<double, kNumVarianceGroups> square_sum{};
};

Status EvaluateTypedJacobian(ceres::Problem* problem, const std::vector<double*>& parameter_blocks,
                             int num_threads, TypedJacobian* out);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_REPORT_TYPED_JACOBIAN_H_
