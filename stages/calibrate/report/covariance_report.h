#ifndef TILTCAL_STAGES_CALIBRATE_REPORT_COVARIANCE_REPORT_H_
#define TILTCAL_STAGES_CALIBRATE_REPORT_COVARIANCE_REPORT_H_

// Covariance of the calibration (C_bl, r_b^{lb}, tau) from the final
// Jacobian, and the observability report (docs/design.md §11).
//
// Covariance: the marginal covariance (marginal_covariance.h: the Schur
// complement of J^T J, robust loss applied, linear in the sequence's length)
// of the blocks C_bl, r_b^{lb}, tau in the TANGENT space, 7x7 in the order
//   (delta_C [3, rad], delta_r [3, m], delta_tau [1, s])
// with the right perturbation C_bl <- C_bl Exp(delta_C): delta_C is a
// rotation vector in the LiDAR frame l. Residuals are weighted by 1/sigma, so
// this is (J^T J)^{-1} of the weighted problem with everything else
// (trajectory, gravity, biases) marginalised.
//
// Observability: the marginal information of each group is eigen-decomposed
// separately (mixing rad, m and s in one decomposition would depend on units):
// rotation 3x3 (sigma in deg, directions in l then reported in b),
// translation 3x3 (sigma in m, frame b) and tau (s). A direction is weak when
// its sigma exceeds the threshold of its group. Each is named by its angle to
// the principal rotation axis of the motion (the dominant eigenvector of
// sum omega omega^T of the bias-corrected gyro, frame b): for a ground
// vehicle on a plane, translation along that axis (vertical) is the weak one
// without ground residuals.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <ceres/problem.h>

#include <Eigen/Core>

#include "common/imu/imu_reading.h"
#include "common/status.h"
#include "stages/calibrate/problem/calibration_state.h"
#include "stages/calibrate/report/residual_type.h"
#include "stages/calibrate/report/variance_components.h"
#include "tiltcal/proto/calibrate_params.pb.h"
#include "tiltcal/proto/calibration.pb.h"

namespace tiltcal::calibrate {

using Matrix7d = Eigen::Matrix<double, 7, 7>;

// Principal rotation axis of the motion in the IMU frame b (unit; sign with
// a non-negative largest component) and the fraction of sum |omega|^2 about
// it (1 = rotation about one axis only).
struct MotionAxis {
  Eigen::Vector3d axis_b = Eigen::Vector3d::UnitZ();
  double fraction = 0.0;
};
MotionAxis PrincipalRotationAxis(const std::vector<imu::ImuReading>& samples,
                                 const Eigen::Vector3d& gyro_bias_radps);

// Fills *covariance (7x7 as above; a block held constant in the problem has
// zero rows and columns). Errors (rank deficiency, failure of the
// factorisation) are returned as Status for the report; they are data, not a
// failure of the stage.
// With intrinsics_covariance and the IMU triad errors free in the problem,
// they are marginalised last as well and their covariance (12x12, tangent:
// E_g's 6 lower-triangular entries row by row, then E_a's)
// is returned there; otherwise it is left empty.
// With clock_rate_row and the clock rate rho free in the problem (the drift
// is estimated, time_offset_drift.h), rho is marginalised last, after the 7,
// and its row of the 8x8 covariance is returned there: cov(rho, .) with the
// 7 above, then var(rho) (rho dimensionless); otherwise it is left empty.
// The 7x7 is the marginal covariance of the 7 either way.
// With group_weights, each variance group's information (residual_type.h)
// is multiplied by its weight (the variance components' w_k,
// variance_components.h).
using VarianceGroupWeights = std::array<double, kNumVarianceGroups>;
Status ComputeExtrinsicCovariance(ceres::Problem* problem, CalibrationState* state,
                                  const proto::ObservabilityParams& params, int num_threads,
                                  Matrix7d* covariance,
                                  Eigen::MatrixXd* intrinsics_covariance = nullptr,
                                  std::vector<double>* clock_rate_row = nullptr,
                                  const VarianceGroupWeights* group_weights = nullptr);

// A-posteriori variance factor of the weighted least-squares problem at its
// current parameters: sigma0^2 = 2 F / (m - n), F the cost with the robust
// loss (ceres' 1/2 sum rho), m the number of residuals, n the tangent size of
// the non-constant parameter blocks. The expected value of sigma0^2 is 1 when
// the residual sigmas are the noise's; the covariance (J^T J)^{-1} computed
// with those sigmas is then scaled by sigma0^2 (docs/design.md §11).
// sigma0_squared is 1 and redundancy <= 0 when m <= n.
struct VarianceFactor {
  double sigma0_squared = 1.0;
  int64_t redundancy = 0;
};
VarianceFactor ComputeVarianceFactor(ceres::Problem* problem);

// What the IMU residuals' variance components need beyond their fit: for
// readings low-passed and thinned (imu_vibration.h), the correlation the
// filter gives them (LowPassCorrelation) and the floors of s_k tau_k, their
// noise measured at rest (imu_static_noise.h; 1 when not measured). Raw
// readings: 1 and no floor (0).
struct ImuResidualNoise {
  double low_pass_correlation = 1.0;
  double gyro_floor = 0.0;
  double accel_floor = 0.0;
};

// Variance components per variance group (residual_type.h,
// variance_components.h) of a problem at its current parameters, indexed by
// VarianceGroup: gyro, accel, lidar and the four ground residuals estimated,
// other (priors, bias random walks) held at 1. The ground's have a floor of
// 1 (their errors are the ground planes', shared by many residuals: their
// fit says nothing of the vertical's error). Errors that stay correlated
// along the sequence divide the information by their tau
// (error_correlation.h, with params.correlation_batches batches; 0: none
// estimated): each ground group's, from its residuals in the scans' order
// (rolling ground, a rocking suspension), and, for low-passed readings
// (imu.low_pass_correlation > 1), the gyro's and accelerometer's, at least
// imu.low_pass_correlation, with imu's floors.
Status ComputeVarianceGroupComponents(ceres::Problem* problem, const ImuResidualNoise& imu,
                                      const proto::ObservabilityParams& params, int num_threads,
                                      std::vector<VarianceComponent>* components);

// The covariance with the data's information scaled by 1/sigma0^2 and the
// priors' kept: a prior acts on the extrinsic block only, so the marginal
// information is P^{-1} = S_data + L_prior, and the result is
// ((P^{-1} - L_prior) / sigma0^2 + L_prior)^{-1}. Parameters held constant
// (zero variance, e.g. tau with time_offset_bound_s 0) keep zero rows and
// columns; the rest is computed without them.
Matrix7d ScaleDataInformation(const Matrix7d& covariance, const Matrix7d& prior_information,
                              double sigma0_squared);
// The same for any size (n x n; the 7 and rho when the drift is estimated).
Eigen::MatrixXd ScaleDataInformation(const Eigen::MatrixXd& covariance,
                                     const Eigen::MatrixXd& prior_information,
                                     double sigma0_squared);

// Writes covariance, rotation_sigma_deg, translation_sigma_m,
// time_offset_sigma_s and the observability directions into *result; a
// direction is weak when its sigma exceeds params.weak_rotation_sigma_deg,
// weak_translation_sigma_m or weak_time_offset_sigma_s.
// c_bl: the estimated C_bl (to express rotation directions in b).
void FillCovarianceReport(const Matrix7d& covariance, const Eigen::Matrix3d& c_bl,
                          const MotionAxis& motion, const proto::ObservabilityParams& params,
                          proto::CalibrationResult* result);

// Adds the clock rate's observability entry (its sigma in ppm, the drift's
// over the scans' span, tau's at both ends; direction: 8 values, the 8th
// rho's) when the
// drift report is estimated and has a covariance; weak as report.weak().
void AddClockRateObservability(const proto::TimeOffsetDriftReport& report,
                               const proto::ObservabilityParams& params,
                               proto::CalibrationResult* result);

// "x", "y", "z" of the dominant component and the direction, e.g.
// "(0.01, -0.02, 1.00)".
std::string DescribeDirection(const Eigen::Vector3d& v);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_REPORT_COVARIANCE_REPORT_H_
