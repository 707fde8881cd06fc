#include "stages/calibrate/report/typed_jacobian.h"

#include <algorithm>
#include <cmath>

#include <ceres/crs_matrix.h>

#include "stages/calibrate/residuals/stacked_cost_function.h"

namespace tiltcal::calibrate {

Status EvaluateTypedJacobian(ceres::Problem* problem, const std::vector<double*>& parameter_blocks,
                             int num_threads, TypedJacobian* out) {
  ceres::Problem::EvaluateOptions options;
  options.parameter_blocks = parameter_blocks;
  problem->GetResidualBlocks(&options.residual_blocks);
  options.apply_loss_function = true;
  options.num_threads = std::max(1, num_threads);
  out->row_group.clear();
  out->row_component.clear();
  out->square_sum.fill(0.0);
  for (const ceres::ResidualBlockId id : options.residual_blocks) {
    const ceres::CostFunction* cost_function = problem->GetCostFunctionForResidualBlock(id);
    const VarianceGroup group = VarianceGroupOf(cost_function);
    const int rows = cost_function->num_residuals();
    out->row_group.insert(out->row_group.end(), static_cast<size_t>(rows), group);
    const auto* stacked = dynamic_cast<const StackedCostFunction*>(cost_function);
    const int measurement_rows = stacked != nullptr ? stacked->row(0).num_residuals() : rows;
    for (int i = 0; i < rows; ++i) out->row_component.push_back(i % measurement_rows);
    double cost = 0.0;
    if (!problem->EvaluateResidualBlock(id, true, &cost, nullptr, nullptr) ||
        !std::isfinite(cost)) {
      return Status::Error("the residuals could not be evaluated");
    }
    out->square_sum[group] += 2.0 * cost;
  }
  std::vector<double> residuals;
  ceres::CRSMatrix crs;
  if (!problem->Evaluate(options, nullptr, &residuals, nullptr, &crs)) {
    return Status::Error("the residuals could not be evaluated");
  }
  out->residuals = Eigen::Map<const Eigen::VectorXd>(residuals.data(),
                                                     static_cast<Eigen::Index>(residuals.size()));
  out->jacobian = Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor>>(
      crs.num_rows, crs.num_cols, static_cast<Eigen::Index>(crs.values.size()), crs.rows.data(),
      crs.cols.data(), crs.values.data());
  return Status::Ok();
}

}  // namespace tiltcal::calibrate
