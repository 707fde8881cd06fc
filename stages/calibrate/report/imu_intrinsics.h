#ifndef TILTCAL_STAGES_CALIBRATE_REPORT_IMU_INTRINSICS_H_
#define TILTCAL_STAGES_CALIBRATE_REPORT_IMU_INTRINSICS_H_

// The IMU's intrinsics in the solve (docs/design.md §6, "IMU intrinsics"):
// whether the data show them (a score test at a solution with them held),
// and their report. The triad errors E_g, E_a themselves are blocks of the
// state (calibration_state.h) in every IMU row (gyro_cost_function.h,
// accel_cost_function.h), with priors (problem_builder.h).
//
// Score test of E_g = E_a = 0 (both held constant in the problem): with J
// the weighted Jacobian of all residuals with respect to the 12 free entries
// (the 6 lower-triangular ones of E_g, then of E_a), r the weighted
// residuals, P the
// priors' information (diag 1 / sigma^2 of the prior) and sigma0^2 the
// variance factor of the solution (covariance_report.h),
//   g = J^T r,   H = J^T J + P,   chi2 = g^T H^-1 g / sigma0^2,
// about chi-square with 12 degrees of freedom when the IMU is ideal. The
// other parameters are held in J, not marginalised: their information only
// lowers the statistic, so the test is conservative. -H^-1 g is the one-step
// estimate of the errors (what the residuals point to).

#include <array>
#include <string>
#include <vector>

#include <ceres/problem.h>

#include <Eigen/Core>

#include "common/status.h"
#include "stages/calibrate/problem/calibration_state.h"
#include "tiltcal/proto/calibrate_params.pb.h"
#include "tiltcal/proto/calibration.pb.h"

namespace tiltcal::calibrate {

struct ImuIntrinsicsScore {
  double chi2 = 0.0;  // divided by sigma0^2
  int dof = 0;
  double sigma0_squared = 1.0;
  // The one-step estimate, 9 doubles each (upper triangles 0).
  std::array<double, 9> gyro_triad_errors{};
  std::array<double, 9> accel_triad_errors{};
};

// The test above on the problem's current state; the error blocks must
// be in the problem and held constant, and are held again afterwards.
Status ScoreTestImuIntrinsics(ceres::Problem* problem, CalibrationState* state,
                              const proto::ImuIntrinsicsParams& params, int num_threads,
                              ImuIntrinsicsScore* score);

// One triad's report from its errors E and the covariance of its free
// entries (tangent, in row-major order of the entries `free`; empty: not
// estimated, sigmas 0).
proto::ImuTriadEstimate DescribeTriad(const std::array<double, 9>& errors,
                                      const std::vector<int>& free,
                                      const Eigen::MatrixXd& covariance);

// The entries of the estimated errors whose sigma (from the
// covariance of ComputeExtrinsicCovariance, kFreeIntrinsicEntries square) is above
// params.undetermined_sigma_fraction of their prior, named e.g.
// "gyroscope z scale", "accelerometer y axis towards x".
std::vector<std::string> UndeterminedIntrinsics(const Eigen::MatrixXd& covariance,
                                                const proto::ImuIntrinsicsParams& params);

// The free entries of E_g and E_a in the problem's tangent order.
const std::vector<int>& GyroErrorEntries();
const std::vector<int>& AccelErrorEntries();

// The sigma of the prior of entry (i, j) of a triad's errors: scale on the
// diagonal (fraction), misalignment off it (rad).
double IntrinsicPriorSigma(int row, int col, const proto::ImuIntrinsicsParams& params);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_REPORT_IMU_INTRINSICS_H_
