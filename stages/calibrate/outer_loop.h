#ifndef TILTCAL_STAGES_CALIBRATE_OUTER_LOOP_H_
#define TILTCAL_STAGES_CALIBRATE_OUTER_LOOP_H_

// The calibration's outer loop (docs/design.md §7): rounds of surfel map and
// association with the current state, problem build and LM solve until the
// extrinsic settles, the IMU intrinsics' score test between rounds
// (imu_intrinsics.h), and a final round on a denser sample when asked
// (OuterLoopParams.final_association).

#include <cstddef>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include <ceres/solver.h>

#include <Eigen/Core>

#include "common/status.h"
#include "stages/calibrate/calibrate.h"
#include "stages/calibrate/problem/calibration_state.h"
#include "stages/calibrate/problem/problem_builder.h"
#include "stages/calibrate/report/imu_intrinsics.h"
#include "tiltcal/proto/calibrate_params.pb.h"
#include "tiltcal/proto/calibration.pb.h"

namespace tiltcal::calibrate {

// The outer iterations' running totals and the last round's problem.
struct OuterLoop {
  std::unique_ptr<CalibrationProblem> problem;
  // The last round drawn with AssociationParams `association`, kept when the
  // final round (OuterLoopParams.final_association) solves a denser sample:
  // the variance factor, the residual statistics and the intrinsics' score
  // test read it at the final estimate (ReportProblem); the final problem's
  // residuals are down-weighted (dense_sample_weight.h), so their RMS says
  // nothing of the noise.
  std::unique_ptr<CalibrationProblem> sample_problem;
  ceres::Solver::Summary summary;
  std::vector<LidarPointResidual> lidar;
  double map_s = 0, assoc_s = 0, build_s = 0, solve_s = 0, solve_cpu_s = 0;
  int total_iterations = 0;
  double first_initial_cost = -1.0;
  bool converged = false;
  std::string termination;
  int rounds = 0;
  // The trust-region radius the last solve ended with (0: no solve yet).
  double last_trust_region_radius = 0.0;
  // How far the last round moved C_bl (deg), r_b^{lb} (m) and tau (s).
  double moved_deg = 0.0, moved_m = 0.0, moved_s = 0.0;
  // The last score test of the IMU intrinsics (imu_intrinsics.h), the
  // round after which it ran (0: none) and whether it found them.
  ImuIntrinsicsScore intrinsics_score;
  int intrinsics_score_round = 0;
  bool intrinsics_found = false;
  // The last round moved the extrinsic by less than the OuterLoopParams
  // stop thresholds (from the second round on).
  bool settled = false;
};

// The problem the covariance and the verdict read (see OuterLoop).
CalibrationProblem* ReportProblem(const OuterLoop& loop);

// What every outer round uses and does not change.
struct OuterLoopSetup {
  const CalibrateInputs& inputs;
  const proto::CalibrateParams& params;
  const ExtraResidualAdder& ground_adder;
  ProblemOptions problem_options;
  ceres::Solver::Options solver_options;
  // Motion's principal rotation axis (unit, frame b) and whether the distance
  // residual observes the translation along it.
  Eigen::Vector3d axis_b;
  bool translation_along_axis_observed;
};

// The rounds with OuterLoopParams.association until the extrinsic settles
// or OuterLoopParams.iterations are done (one more after the score test
// finds the IMU intrinsics, which are then estimated: setup's
// problem_options), the final denser round when asked, and the score test
// at the end when the intrinsics are OFF.
Status RunOuterLoop(OuterLoopSetup* setup, CalibrationState* state, OuterLoop* loop,
                    std::ostream* log);

// Timings, problem size and solver report of the outer loop.
void FillSolverReport(const OuterLoop& loop, proto::CalibrationResult* result);

// The IMU intrinsics' report: estimated values with the sigmas of their
// marginal covariance (12x12, may be empty), or the score test's one-step
// values.
void FillImuIntrinsics(const proto::ImuIntrinsicsParams& params, const OuterLoop& loop,
                       bool estimated, const CalibrationState& state,
                       const Eigen::MatrixXd& covariance, proto::CalibrationResult* result);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_OUTER_LOOP_H_
