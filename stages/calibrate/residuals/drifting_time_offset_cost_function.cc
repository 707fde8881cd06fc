#include "stages/calibrate/residuals/drifting_time_offset_cost_function.h"

#include <array>
#include <vector>

#include <glog/logging.h>

namespace tiltcal::calibrate {

DriftingTimeOffsetCostFunction::DriftingTimeOffsetCostFunction(ceres::CostFunction* inner,
                                                               int tau_block,
                                                               double time_from_reference_s)
    : inner_(inner), tau_block_(tau_block), time_from_reference_s_(time_from_reference_s) {
  const std::vector<int32_t>& sizes = inner_->parameter_block_sizes();
  CHECK(tau_block_ >= 0 && tau_block_ < static_cast<int>(sizes.size()) &&
        sizes[static_cast<size_t>(tau_block_)] == 1);
  CHECK_LE(static_cast<int>(sizes.size()), kMaxBlocks);
  CHECK_LE(inner_->num_residuals(), kMaxResiduals);
  set_num_residuals(inner_->num_residuals());
  *mutable_parameter_block_sizes() = sizes;
  mutable_parameter_block_sizes()->push_back(1);  // rho
}

bool DriftingTimeOffsetCostFunction::Evaluate(double const* const* parameters, double* residuals,
                                              double** jacobians) const {
  const int n = static_cast<int>(inner_->parameter_block_sizes().size());
  // tau(t) = tau0 + rho (t - t_ref).
  const double tau = parameters[tau_block_][0] + parameters[n][0] * time_from_reference_s_;
  std::array<const double*, kMaxBlocks> inner_parameters{};
  for (int i = 0; i < n; ++i) inner_parameters[static_cast<size_t>(i)] = parameters[i];
  inner_parameters[static_cast<size_t>(tau_block_)] = &tau;
  if (jacobians == nullptr) return inner_->Evaluate(inner_parameters.data(), residuals, nullptr);

  // dr/dtau is needed for rho even when tau0's Jacobian is not asked for.
  std::array<double*, kMaxBlocks> inner_jacobians{};
  for (int i = 0; i < n; ++i) inner_jacobians[static_cast<size_t>(i)] = jacobians[i];
  std::array<double, kMaxResiduals> d_r_d_tau{};
  double*& tau_jacobian = inner_jacobians[static_cast<size_t>(tau_block_)];
  if (tau_jacobian == nullptr && jacobians[n] != nullptr) tau_jacobian = d_r_d_tau.data();
  if (!inner_->Evaluate(inner_parameters.data(), residuals, inner_jacobians.data())) return false;
  if (jacobians[n] != nullptr) {
    for (int k = 0; k < num_residuals(); ++k) {
      jacobians[n][k] = time_from_reference_s_ * tau_jacobian[k];
    }
  }
  return true;
}

}  // namespace tiltcal::calibrate
