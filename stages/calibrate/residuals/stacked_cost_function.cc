#include "stages/calibrate/residuals/stacked_cost_function.h"

#include <glog/logging.h>

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <utility>

namespace tiltcal::calibrate {
namespace {

using RowMajorMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// phi(s) and phi'(s) of the folded loss (stacked_cost_function.h). Where the
// loss is nearly quadratic (s |rho''| < 1e-5 rho'), rho(s) / s and
// rho'(s) s - rho(s) cancel to rounding noise (rho itself is then inexact,
// e.g. Cauchy's log(1 + s / b^2)), so they come from the expansion about s,
// rho(0) = 0: rho(s) = rho'(s) s - rho''(s) s^2 / 2 + O(s^3), which gives
// phi^2 = rho' - rho'' s / 2 and phi' = rho'' / (4 phi) (the threshold
// balances the two errors: ~1e-11 relative in phi for Cauchy).
void FoldedLoss(const ceres::LossFunction& loss, double s, double* phi, double* dphi_ds) {
  double rho[3];
  loss.Evaluate(s, rho);
  if (s * std::abs(rho[2]) < 1e-5 * rho[1]) {
    *phi = std::sqrt(rho[1] - 0.5 * rho[2] * s);
    *dphi_ds = *phi > 0.0 ? rho[2] / (4.0 * *phi) : 0.0;
    return;
  }
  *phi = std::sqrt(rho[0] / s);
  *dphi_ds = *phi > 0.0 ? (rho[1] * s - rho[0]) / (2.0 * s * s * *phi) : 0.0;
}

}  // namespace

StackedCostFunction::StackedCostFunction(std::vector<std::unique_ptr<ceres::CostFunction>> rows,
                                         const ceres::LossFunction* row_loss)
    : rows_(std::move(rows)), row_loss_(row_loss) {
  *mutable_parameter_block_sizes() = rows_.front()->parameter_block_sizes();
  CHECK_LE(parameter_block_sizes().size(), kMaxParameterBlocks);
  for (const int32_t size : parameter_block_sizes()) CHECK_LE(size, kMaxBlockSize);
  int total = 0;
  row_offsets_.reserve(rows_.size());
  for (const std::unique_ptr<ceres::CostFunction>& row : rows_) {
    row_offsets_.push_back(total);
    total += row->num_residuals();
  }
  set_num_residuals(total);
}

bool StackedCostFunction::EvaluateRows(double const* const* parameters, double* residuals) const {
  for (std::size_t i = 0; i < rows_.size(); ++i) {
    if (!rows_[i]->Evaluate(parameters, residuals + row_offsets_[i], nullptr)) return false;
  }
  return true;
}

bool StackedCostFunction::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  const std::vector<int32_t>& sizes = parameter_block_sizes();
  // Row i writes its Jacobian rows in place: row-major blocks stack by rows.
  std::array<double*, kMaxParameterBlocks> row_jacobians;
  const std::size_t num_jacobians = jacobians != nullptr ? sizes.size() : 0;
  for (std::size_t i = 0; i < rows_.size(); ++i) {
    const int offset = row_offsets_[i];
    const int m = rows_[i]->num_residuals();
    double* r = residuals + offset;
    for (std::size_t k = 0; k < num_jacobians; ++k) {
      row_jacobians[k] = jacobians[k] != nullptr ? jacobians[k] + offset * sizes[k] : nullptr;
    }
    if (!rows_[i]->Evaluate(parameters, r, jacobians != nullptr ? row_jacobians.data() : nullptr)) {
      return false;
    }
    if (row_loss_ == nullptr) continue;
    Eigen::Map<Eigen::VectorXd> ri(r, m);
    double phi = 1.0;
    double dphi_ds = 0.0;
    FoldedLoss(*row_loss_, ri.squaredNorm(), &phi, &dphi_ds);
    for (std::size_t k = 0; k < num_jacobians; ++k) {
      if (row_jacobians[k] == nullptr) continue;
      Eigen::Map<RowMajorMatrixXd> j(row_jacobians[k], m, sizes[k]);
      // J~ = phi J + 2 phi' r (r^T J)
      const Eigen::Matrix<double, 1, Eigen::Dynamic, Eigen::RowMajor, 1, kMaxBlockSize> rt_j =
          ri.transpose() * j;
      j *= phi;
      j.noalias() += (2.0 * dphi_ds) * ri * rt_j;
    }
    ri *= phi;
  }
  return true;
}

void StackedResidualAdder::Add(ceres::CostFunction* row, std::vector<double*> parameter_blocks) {
  auto [it, inserted] = group_of_.try_emplace(parameter_blocks, groups_.size());
  if (inserted) groups_.push_back(Group{std::move(parameter_blocks), {}});
  groups_[it->second].rows.emplace_back(row);
}

int StackedResidualAdder::Flush(ceres::Problem* problem) {
  const int added = static_cast<int>(groups_.size());
  for (Group& g : groups_) {
    problem->AddResidualBlock(new StackedCostFunction(std::move(g.rows), row_loss_), nullptr,
                              g.parameter_blocks.data(),
                              static_cast<int>(g.parameter_blocks.size()));
  }
  groups_.clear();
  group_of_.clear();
  return added;
}

}  // namespace tiltcal::calibrate
