#ifndef TILTCAL_STAGES_CALIBRATE_RESIDUALS_DRIFTING_TIME_OFFSET_COST_FUNCTION_H_
#define TILTCAL_STAGES_CALIBRATE_RESIDUALS_DRIFTING_TIME_OFFSET_COST_FUNCTION_H_

// A residual that uses the time offset tau, with tau drifting linearly
// (time_offset_drift.h, docs/design.md §5):
//   tau(t) = tau0 + rho (t - t_ref)
// t: the residual's LiDAR stamp (a point's t_j, a scan's t_k), s from the
// first IMU stamp on the LiDAR clock; t_ref: the reference time of the state
// (CalibrationState::time_reference_s, the middle of the scans' stamps);
// tau0, s: the time offset block; rho: the clock-rate block (1 double,
// d tau / d t, dimensionless; the LiDAR clock's rate against the IMU's is
// -rho), so that a LiDAR stamp t happened at IMU time t + tau(t).
//
// Wraps an inner cost function whose block tau_block is tau (the
// point-to-plane and the ground residuals, block 10 and 6): the inner
// function is evaluated with tau replaced by tau(t), and one block is
// appended, rho:
//   r(x, tau0, rho) = r_inner(x, tau0 + rho (t - t_ref))
//   dr/dtau0 = dr_inner/dtau,   dr/drho = (t - t_ref) dr_inner/dtau.
// The inner Jacobians of every other block are the inner function's at
// tau(t). The inner cost's frozen knot window must have been chosen with
// tau(t) (CalibrationState::TimeWindow does).
//
// Owns the inner cost function.

#include <memory>

#include <ceres/cost_function.h>

namespace tiltcal::calibrate {

class DriftingTimeOffsetCostFunction final : public ceres::CostFunction {
 public:
  // inner: owned; its block tau_block has size 1; at most kMaxResiduals
  // residuals and kMaxBlocks blocks. time_from_reference_s: t - t_ref, s.
  DriftingTimeOffsetCostFunction(ceres::CostFunction* inner, int tau_block,
                                 double time_from_reference_s);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  const ceres::CostFunction& inner() const { return *inner_; }
  double time_from_reference_s() const { return time_from_reference_s_; }

  // The residual rows of the calibrator have at most 3 residuals (flat
  // ground) and at most 11 blocks.
  static constexpr int kMaxResiduals = 8;
  static constexpr int kMaxBlocks = 15;

 private:
  std::unique_ptr<ceres::CostFunction> inner_;
  int tau_block_;
  double time_from_reference_s_;
};

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_RESIDUALS_DRIFTING_TIME_OFFSET_COST_FUNCTION_H_
