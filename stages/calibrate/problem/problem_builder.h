#ifndef TILTCAL_STAGES_CALIBRATE_PROBLEM_PROBLEM_BUILDER_H_
#define TILTCAL_STAGES_CALIBRATE_PROBLEM_PROBLEM_BUILDER_H_

// The ceres::Problem of the spline calibration (docs/design.md §6, §7, §13):
// parameter blocks of a CalibrationState with their manifolds, gauge, the
// bound on tau, and the residuals (all analytic, fixed-size rows):
//   gyro  (gyro_cost_function.h):  one row per IMU sample, weight
//         1/ImuNoiseParams.gyro_sigma_radps;
//   accel (accel_cost_function.h): one row per IMU sample, weight
//         1/ImuNoiseParams.accel_sigma_mps2;
//   lidar (point_to_plane_cost_function.h): one row per associated point,
//         weight 1/LidarResidualParams.sigma_m, Cauchy loss of scale
//         LidarResidualParams.cauchy_scale per row (in units of the weighted
//         residual, i.e. of sigma_m; 0 = none);
//   the rows of one kind with the same parameter blocks (the same knot
//   window, bias segment) form one residual block (stacked_cost_function.h),
//   the Cauchy loss folded into each LiDAR row;
//   more residual sets (the ground residuals, ground_residuals.h) through
//   AddExtraResiduals, which only adds residual blocks on the state's pointers.
//
// Gauge (world frame a, 6 DoF): with fix_first_knots, rotation knot 0 and
// position knot 0 are held constant (used by the IMU-only initial fits).
// The main solve instead lets the fixed surfel planes of the map (built in a)
// pin the world frame, as holding knot 0 there couples the gauge to physically
// unobservable directions (on a plane: translation along the rotation axis)
// and fakes information on them. Either way the result is re-expressed
// afterwards so that C_ab(t0) = 1 and r_a^{ba}(t0) = 0 exactly
// (ReexpressInFirstImuFrame).
//
// Gyro and accelerometer biases: one block per segment of the state; with
// more than one, a random-walk prior between consecutive segments
// (ImuNoiseParams gyro_bias_random_walk_radps2_sqrthz,
// accel_bias_random_walk_mps3_sqrthz; 0 = untied).
//
// IMU intrinsics (docs/design.md §6): the gyro and accelerometer triad
// errors E_g, E_a (calibration_state.h) are in every IMU row; their
// upper triangles are held at zero by a ceres::SubsetManifold. Held constant
// unless estimate_imu_intrinsics; then each has a prior at zero
// (triad_errors_prior_cost_function.h, counted in prior_residuals).
//
// Optional prior on r_b^{lb} (translation_prior_sigma_m > 0): one residual
// (r_b^{lb} - r_prior) / sigma (3), or, with a unit translation_prior_axis_b,
// only its component along that axis, a^T (r_b^{lb} - r_prior) / sigma (the
// motion's principal rotation axis: the direction planar motion cannot
// observe, while in-plane directions are left to the data). Counted in
// ProblemCounts::prior_residuals.
//
// Time offset: tau is held (interval_manifold.h) in
//   [max(C - B, tau_bin - S), min(C + B, tau_bin + S)],
// C = time_offset_center_s, B = time_offset_bound_s (|tau - C| <= B
// overall), S = time_offset_step_bound_s
// (how far tau may move from the value tau_bin that chose the frozen knot
// windows of the LiDAR residuals in this build). The problem is rebuilt (and
// the windows re-chosen) at every outer iteration.
//
// Clock drift (time_offset_drift.h): with estimate_clock_rate the state's
// clock_rate rho is a block of the problem, held in
//   [max(-R, rho_bin - S / H), min(R, rho_bin + S / H)]
// (R = clock_rate_max_ppm * 1e-6, H = clock_rate_half_length_s, the largest |t - t_ref|),
// and every residual that uses tau is wrapped in
// DriftingTimeOffsetCostFunction (rho appended as its last block), the LiDAR
// ones here, the ground ones by their adder (ClockRateInProblem). Without
// it, rho is not in the problem and stays at its value (0).
//
// The object owns the manifolds and the shared loss (Ceres does not), and the
// Problem; it must outlive any evaluation of the Problem (the covariance).

#include <functional>
#include <memory>
#include <vector>

#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/solver.h>
#include <ceres/sphere_manifold.h>

#include <Eigen/Core>

#include "common/imu/imu_reading.h"
#include "common/spline/quaternion_manifold.h"
#include "common/status.h"
#include "stages/calibrate/problem/calibration_state.h"
#include "stages/calibrate/residuals/interval_manifold.h"
#include "tiltcal/proto/calibrate_params.pb.h"

namespace tiltcal::calibrate {

// One associated LiDAR point: raw point (frame l) at LiDAR time t_j and the
// surfel plane n^T p_a + d = 0 of the map in frame a.
struct LidarPointResidual {
  double time_s = 0.0;  // t_j, LiDAR clock, s from the first IMU stamp
  Eigen::Vector3d point_lidar_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d plane_normal = Eigen::Vector3d::UnitZ();
  double plane_offset_m = 0.0;
};

// What one build estimates and its bounds; the noise comes from the params
// messages given to the constructor.
struct ProblemOptions {
  // B and S of the tau bound above (CalibrateParams.time_offset_bound_s,
  // OuterLoopParams.time_offset_step_bound_s), s.
  double time_offset_bound_s = 0.0;
  double time_offset_step_bound_s = 0.0;
  // C: the bound B is around C (|tau - C| <= B), the initialisation's coarse
  // tau, s.
  double time_offset_center_s = 0.0;
  // Which calibration blocks are free (constant otherwise).
  bool estimate_extrinsic = true;
  bool estimate_time_offset = true;
  bool estimate_gravity = true;
  bool estimate_biases = true;
  bool estimate_imu_intrinsics = false;
  // rho, its bound R (ppm) and H of the step bound (s); see above.
  bool estimate_clock_rate = false;
  double clock_rate_max_ppm = 0.0;
  double clock_rate_half_length_s = 0.0;
  // Prior rho ~ N(clock_rate_prior, clock_rate_prior_sigma^2) (sigma 0 = none;
  // time_offset_drift.h), counted in prior_residuals.
  double clock_rate_prior = 0.0;
  double clock_rate_prior_sigma = 0.0;
  // Prior sigmas of the triad errors when they are estimated: scale (a
  // fraction) and misalignment (rad).
  double intrinsics_scale_prior_sigma = 0.0;
  double intrinsics_misalignment_prior_sigma_rad = 0.0;
  // Gauge by holding rotation knot 0 and position knot 0 (see above). Off
  // when fixed map planes already pin the world frame.
  bool fix_first_knots = true;
  // Prior r_b^{lb} ~ N(translation_prior_m, sigma^2 I) (sigma 0 = none), or
  // only along translation_prior_axis_b when that is non-zero (unit, frame b).
  Eigen::Vector3d translation_prior_m = Eigen::Vector3d::Zero();
  double translation_prior_sigma_m = 0.0;
  Eigen::Vector3d translation_prior_axis_b = Eigen::Vector3d::Zero();
};

// Counts of what a build added.
struct ProblemCounts {
  int knots = 0;
  int gyro_residuals = 0;
  int accel_residuals = 0;
  int lidar_residuals = 0;
  int lidar_skipped = 0;  // outside the spline
  int ground_residuals = 0;
  int prior_residuals = 0;
  int free_parameters = 0;  // tangent dimension of the non-constant blocks
};

// Adds residual blocks (e.g. the ground residuals) to `problem` on the
// state's blocks; returns the number of residual blocks added in *num_added.
using ExtraResidualAdder =
    std::function<Status(CalibrationState* state, ceres::Problem* problem, int* num_added)>;

class CalibrationProblem {
 public:
  // Adds all blocks of *state (which must outlive this object) with their
  // manifolds, the gauge and the tau bounds. tau is clamped into its bounds.
  CalibrationProblem(CalibrationState* state, const proto::ImuNoiseParams& imu_noise,
                     const proto::LidarResidualParams& lidar, const ProblemOptions& options);
  CalibrationProblem(const CalibrationProblem&) = delete;
  CalibrationProblem& operator=(const CalibrationProblem&) = delete;

  // One gyro and one accel block per sample inside the spline. Times are IMU
  // clock seconds (the grid's clock).
  void AddImuResiduals(const std::vector<imu::ImuReading>& samples, bool gyro, bool accel);
  // Knot windows chosen with the current tau (frozen for this build).
  void AddLidarResiduals(const std::vector<LidarPointResidual>& points);
  Status AddExtraResiduals(const ExtraResidualAdder& adder);

  // Holds the rotation and position knots constant (e.g. for a gyro-only or
  // position-only fit).
  void SetRotationKnotsConstant();
  void SetPositionKnotsConstant();
  // Takes the blocks that no residual uses out of the solve (so the solver
  // does not see parameters without information), keeping the state's
  // values: unused knots are held constant, unused calibration blocks
  // removed. Call after the last Add*; extra residual sets must only use
  // knots that the other residuals use (knot use is tracked by the Add*
  // calls).
  void RemoveUnusedKnots();

  ceres::Problem* problem() { return problem_.get(); }
  const ProblemCounts& counts();
  double time_offset_lower_s() const { return tau_lower_; }
  double time_offset_upper_s() const { return tau_upper_; }
  // rho's bounds of this build (both 0 when rho is not estimated).
  double clock_rate_lower() const { return rho_lower_; }
  double clock_rate_upper() const { return rho_upper_; }

 private:
  // The steps of the constructor, in this order (Ceres orders the blocks by
  // insertion): every block of the state with its manifold and the gauge;
  // tau's bounds; rho with its bounds and prior; the extrinsic and gravity
  // held when not estimated; the biases held or tied by their random walk;
  // the IMU intrinsics held or given their prior; the translation's prior.
  void AddStateBlocks();
  void BoundTimeOffset();
  void AddClockRate();
  void HoldOrTieBiases();
  void HoldOrPriorImuIntrinsics();
  void AddTranslationPrior();
  void MarkKnots(int first_knot, bool position);

  CalibrationState* state_;
  proto::ImuNoiseParams imu_noise_;
  proto::LidarResidualParams lidar_;
  ProblemOptions options_;
  spline::RightQuaternionManifold quaternion_manifold_;
  ceres::SphereManifold<3> sphere_manifold_;
  // E_g, E_a lower triangular: entries (0, 1), (0, 2), (1, 2) held.
  ceres::SubsetManifold lower_triangular_manifold_{9, {1, 2, 5}};
  std::unique_ptr<IntervalManifold> time_offset_manifold_;  // tau in its bounds
  std::unique_ptr<IntervalManifold> clock_rate_manifold_;   // rho in its bounds
  std::unique_ptr<ceres::LossFunction> lidar_loss_;
  std::unique_ptr<ceres::Problem> problem_;
  ProblemCounts counts_;
  double tau_lower_ = 0.0;
  double tau_upper_ = 0.0;
  double rho_lower_ = 0.0;
  double rho_upper_ = 0.0;
  std::vector<char> rotation_used_;
  std::vector<char> position_used_;
};

// What the params set of one LM solve.
struct SolverSettings {
  int max_iterations = 1;
  int num_threads = 1;
  double function_tolerance = 0.0;          // 0: Ceres' default
  double initial_trust_region_radius = 0.0;  // 0: Ceres' default
};

// Whether the state's clock rate rho is a block of `problem` (the drift is
// estimated): residual adders then wrap their tau residuals
// (DriftingTimeOffsetCostFunction).
bool ClockRateInProblem(const CalibrationState& state, const ceres::Problem& problem);

// Solver settings of the calibrator: LM, SPARSE_NORMAL_CHOLESKY (no Schur
// solvers) and the given settings.
ceres::Solver::Options MakeSolverOptions(const SolverSettings& settings);

// Re-expresses the state in the gauge C_ab(t0) = 1, r_a^{ba}(t0) = 0 with
// t0 = grid start: with G = C_ab(t0)^T and p0 = r_a^{ba}(t0), every rotation
// knot R_i <- G R_i, position knot p_i <- G (p_i - p0), n_g <- G n_g. The
// extrinsic, tau and the biases do not change.
void ReexpressInFirstImuFrame(CalibrationState* state);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_PROBLEM_PROBLEM_BUILDER_H_
