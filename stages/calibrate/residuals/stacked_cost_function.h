#ifndef TILTCAL_STAGES_CALIBRATE_RESIDUALS_STACKED_COST_FUNCTION_H_
#define TILTCAL_STAGES_CALIBRATE_RESIDUALS_STACKED_COST_FUNCTION_H_

// Residuals that share every parameter block, evaluated as one Ceres residual
// block (docs/design.md §13, "Stacked residual blocks"). Rows i = 1..n, each
// a cost function with m_i residuals r_i(x) and Jacobians J_ik:
//   r = [r~_1; ...; r~_n],   J_k = [J~_1k; ...; J~_nk]   (row-major, so row
// i's block of J_k is contiguous and is written in place by row i).
// Without a loss, r~_i = r_i and J~_ik = J_ik. With a per-row robust loss
// rho (ceres::LossFunction on s_i = |r_i|^2) the loss is folded into the
// residual so that Ceres' cost 1/2 |r|^2 is exactly 1/2 sum_i rho(s_i):
//   r~_i  = phi(s_i) r_i,                     phi(s) = sqrt(rho(s) / s),
//   J~_ik = phi(s_i) J_ik + 2 phi'(s_i) r_i r_i^T J_ik,
//   phi'(s) = (rho'(s) s - rho(s)) / (2 s^2 phi(s))
// (phi(0) = sqrt(rho'(0)); the second term vanishes with r_i). The minimum
// is the one of the per-row loss; the Gauss-Newton model is the one of the
// folded residual (docs/design.md §13).
//
// Why: Ceres' cost per residual block (its J^T J product terms, one per
// pair of parameter blocks of each residual block, their symbolic set-up per
// solve, and the per-block evaluation bookkeeping) dominated the solve when
// every IMU sample and LiDAR point was its own block.

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/problem.h>

#include <map>
#include <memory>
#include <vector>

namespace tiltcal::calibrate {

class StackedCostFunction final : public ceres::CostFunction {
 public:
  // The calibrator's residuals have at most 11 parameter blocks of at most
  // 4 doubles.
  static constexpr std::size_t kMaxParameterBlocks = 16;
  static constexpr int kMaxBlockSize = 16;

  // rows: non-empty, every row with the same parameter block sizes.
  // row_loss: applied per row (not owned; may be null; must outlive this).
  StackedCostFunction(std::vector<std::unique_ptr<ceres::CostFunction>> rows,
                      const ceres::LossFunction* row_loss);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  // The rows' own residuals r_i, without the loss (residual statistics).
  bool EvaluateRows(double const* const* parameters, double* residuals) const;

  int num_rows() const { return static_cast<int>(rows_.size()); }
  const ceres::CostFunction& row(int i) const { return *rows_[static_cast<std::size_t>(i)]; }

 private:
  std::vector<std::unique_ptr<ceres::CostFunction>> rows_;
  std::vector<int> row_offsets_;  // first residual of row i
  const ceres::LossFunction* row_loss_;
};

// Groups residual rows by their parameter blocks and adds each group to a
// problem as one StackedCostFunction: Add() collects, Flush() adds. Rows with
// the same parameter block list (same pointers, same order) end up in one
// block, in the order they were given.
class StackedResidualAdder {
 public:
  explicit StackedResidualAdder(const ceres::LossFunction* row_loss) : row_loss_(row_loss) {}

  void Add(ceres::CostFunction* row, std::vector<double*> parameter_blocks);
  // Adds every group to `problem` (which takes ownership of the cost
  // functions); returns the number of residual blocks added.
  int Flush(ceres::Problem* problem);

 private:
  struct Group {
    std::vector<double*> parameter_blocks;
    std::vector<std::unique_ptr<ceres::CostFunction>> rows;
  };
  const ceres::LossFunction* row_loss_;
  std::vector<Group> groups_;
  std::map<std::vector<double*>, std::size_t> group_of_;  // into groups_
};

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_RESIDUALS_STACKED_COST_FUNCTION_H_
