#ifndef TILTCAL_STAGES_CALIBRATE_INIT_INITIALISATION_H_
#define TILTCAL_STAGES_CALIBRATE_INIT_INITIALISATION_H_

// Initial values of the calibration state that survive planar motion
// (docs/design.md §9), in this order:
//  1. gyro bias and g_a from the static start or the first seconds
//     (common/imu/imu_initialisation.h); accelerometer bias 0;
//  2. rotation spline C_ab(t): knots from the integrated gyro
//     (knot i at t0 + (i - 1) dt), then an LM fit to the gyro residuals with
//     the bias held (rotation knot 0 held: gauge);
//  3. LiDAR odometry (lidar_odometry.h, GICP or NDT) on scans deskewed with
//     that rotation spline and the rig's C_bl (tau = 0), giving T_{l0 lk};
//  3b. coarse tau over +-InitParams.coarse_time_offset_window_s from the
//     angular speeds of gyro and odometry (coarse_time_offset.h), with the
//     gyro/LiDAR rate scale checked (a gyro in deg/s is an error); an
//     untrusted peak leaves tau at 0 (InitialisationReport::coarse says
//     why). No trusted peak, a scale out of bounds or gyro speeds above
//     max_plausible_gyro_speed_radps (99th percentile): the same on an
//     odometry without the gyro (a gyro in another unit misleads the
//     deskew and the prior), then the scale check. A coarse tau beyond
//     time_offset_bound_s (or the gyro-free case) reruns the odometry at
//     that tau. Scans whose sweep at t_l + tau is outside the IMU span are
//     counted (dropped_scans_outside_imu) and take no further part;
//  4. extrinsic: the rig's measured (C_bl, r_b^{lb}) (the paper's protocol);
//     hand-eye rotation (hand_eye_rotation.h) replaces C_bl only when its
//     excitation measure says the motion is rich enough; otherwise (planar
//     motion) the rig's C_bl is only tilted so that the LiDAR's principal
//     rotation axis maps onto the IMU's (AlignRotationAxes: fixes the two
//     tilt angles, keeps the rig's angle about the axis). A rig C_bl whose
//     mapped axis is more than max_axis_alignment_deg off, without hand-eye
//     excitation, is an error (rig_rotation_check.h);
//  4b. tau by a grid search of the odometry's scan-to-scan rotations
//     against the gyro spline within +-time_offset_bound_s of the coarse tau
//     (SearchTimeOffset);
//  4c. the rotation spline refitted to the gyro and the odometry's
//     orientations carried to b (RefineRotationSpline), so that its heading
//     follows the LiDAR instead of the integrated gyro bias error;
//  4d. the starting C_bl checked about the motion's axis by the
//     accelerations (rig_rotation_check.h): a yaw error beyond
//     max_rig_rotation_error_deg is an error;
//  5. position spline r_a^{ba}(t) and the lever arm r_b^{lb}: the odometry
//     gives the LiDAR positions at the scan times (scan k at IMU time
//     t_k + tau; the LiDAR at the first registered scan f as origin),
//       p_l(t_k) = C_ab(t_f) C_bl r_{l0}^{lk l0} = r_a^{ba}(t_k) + C_ab(t_k) r_b^{lb},
//     fitted by LM together with the accelerometer residuals (rotation held;
//     gravity direction, accelerometer bias and r_b^{lb} free, the latter
//     with a prior at the rig's value).
// The odometry registers every LidarOdometryParams.scan_step-th scan. The
// initialisation reads these CalibrateParams: init, imu_noise,
// static_detection, odometry, hand_eye, scans (the odometry's range crop),
// gravity_norm_mps2, time_offset_bound_s (the tau search range around the
// coarse tau),
// extrinsic_translation_prior_sigma_m and num_threads.

#include <optional>
#include <vector>

#include "common/imu/imu_initialisation.h"
#include "common/imu/imu_reading.h"
#include "common/io/eigen_proto.h"
#include "common/status.h"
#include "stages/calibrate/init/coarse_time_offset.h"
#include "stages/calibrate/init/hand_eye_rotation.h"
#include "stages/calibrate/init/rig_rotation_check.h"
#include "stages/calibrate/odometry/lidar_odometry.h"
#include "stages/calibrate/problem/calibration_state.h"
#include "stages/calibrate/problem/lidar_scans.h"
#include "tiltcal/proto/calibrate_params.pb.h"

namespace tiltcal::calibrate {

struct InitialisationReport {
  imu::ImuInitialisation imu;
  HandEyeResult hand_eye;
  bool rotation_from_hand_eye = false;
  // The odometry whose poses the initialisation used (the last run): its
  // scans, those registered (scan 0 not counted), and the registered scans
  // whose registration quality was measured (VOXEL_ICP always; GICP / NDT
  // with odometry.registration_quality) with the means of their
  // LidarOdometryPose::fitness_rms_m (m) and inlier_fraction.
  int odometry_scans = 0;
  int odometry_registered = 0;
  int odometry_quality_scans = 0;
  double odometry_mean_fitness_m = 0.0;
  double odometry_mean_inlier_fraction = 0.0;
  double gyro_fit_rms = 0.0;      // RMS weighted gyro residual after the fit
  double rotation_refit_rms = 0.0;  // RMS weighted residual of step 4c
  double position_fit_rms = 0.0;  // RMS weighted residual of the position fit
  bool axis_alignment_applied = false;
  double axis_alignment_deg = 0.0;  // correction of the rig's C_bl by the axis alignment
  double time_offset_init_s = 0.0;  // tau after the grid search (step 4b), s
  // Step 3b: the wide-window alignment, and the centre of the tau searches
  // and of the solve's tau bound (the coarse tau when trusted, else 0), s.
  CoarseTimeOffset coarse;
  double time_offset_center_s = 0.0;
  bool odometry_rerun = false;  // the odometry was run again at the coarse tau
  // The gyro-aided odometry gave no trusted peak or a rate scale out of
  // bounds, so tau and the scale were measured on an odometry without the
  // gyro (raw scans, no rotation prior).
  bool odometry_without_gyro = false;
  int dropped_scans_outside_imu = 0;
  // Steps 4 and 4d: the rig's C_bl against the motion, and how far the
  // starting C_bl is from the rig's, deg.
  double rig_axis_disagreement_deg = 0.0;
  double rig_rotation_correction_deg = 0.0;
  AccelerationCheck acceleration_check;
  // How much the motion turned (the hand-eye rotation pairs).
  TurningAmount turning;
  // Principal rotation axis of the (bias-corrected) gyro, frame b, and the
  // share of sum omega omega^T along it (covariance_report.h).
  Eigen::Vector3d rotation_axis_b = Eigen::Vector3d::UnitZ();
  double rotation_axis_fraction = 0.0;
  double imu_seconds = 0.0;
  double rotation_fit_seconds = 0.0;
  double odometry_seconds = 0.0;
  double position_fit_seconds = 0.0;
};

// A state whose spline grid covers the IMU samples (knot spacing and bias
// segments from the params, |g_a| = gravity_norm_mps2). Errors: fewer than
// 10 samples, a span beyond spline.max_duration_s.
Status MakeStateOverImu(const std::vector<imu::ImuReading>& imu_samples,
                        const proto::CalibrateParams& params,
                        std::optional<CalibrationState>* state);

// Steps 1 and 2 alone: gyro bias, g_a (accelerometer bias 0, tau 0), the
// motion's principal rotation axis and the rotation spline fitted to the
// gyro, into *state and the matching fields of *report.
Status InitialiseImuAndRotationSpline(const std::vector<imu::ImuReading>& imu_samples,
                                      const proto::CalibrateParams& params,
                                      CalibrationState* state, InitialisationReport* report);

// Fills *state (whose grid covers the IMU samples) from the IMU samples
// (times relative to the first sample), the raw scans and the rig's
// measured extrinsic.
Status InitialiseState(const std::vector<imu::ImuReading>& imu_samples,
                       const std::vector<LidarScan>& scans, const Rigid3d& measured_imu_from_lidar,
                       const proto::CalibrateParams& params, CalibrationState* state,
                       InitialisationReport* report);

// Rotation-axis alignment for planar motion: with a_b, a_l the principal
// axes (dominant eigenvectors of sum phi phi^T, phi = Log of the relative
// rotations, signs matched by their correlation) of the IMU and LiDAR
// relative rotations, returns R * C_bl with R the smallest rotation taking
// C_bl a_l to a_b. Fixes the two tilt angles of C_bl; the angle about the
// axis stays the rig's.
Eigen::Quaterniond AlignRotationAxes(const std::vector<RotationPair>& pairs,
                                     const Eigen::Quaterniond& imu_from_lidar);

// Tau near center_s: minimises sum_k |Log(C_ab(t_k+tau)^T C_ab(t_{k+1}+tau))
// - C_bl Log(C_{l0 lk}^T C_{l0 l(k+1)})|^2 over consecutive scans on a grid
// of step_s over center_s + [-bound_s, bound_s], refined by a parabola.
double SearchTimeOffset(const CalibrationState& state, const std::vector<double>& scan_times_s,
                        const std::vector<Eigen::Quaterniond>& lidar_rotations, double center_s,
                        double bound_s, double step_s);

// Step 2 alone: knots from the integrated gyro (bias = state's b_g), then the
// gyro-only LM fit. Returns the RMS weighted gyro residual.
double FitRotationSplineToGyro(const std::vector<imu::ImuReading>& imu_samples,
                               const proto::CalibrateParams& params, CalibrationState* state);

// Step 4c alone: LM fit of the rotation knots (from their current values) to
// the gyro and to orientations C_ab at IMU times (OrientationSampleCostFunction,
// sigma InitParams.odometry_rotation_sigma_deg). Returns the RMS weighted
// residual.
double RefineRotationSpline(const std::vector<double>& times_s,
                            const std::vector<Eigen::Quaterniond>& orientations_a_from_b,
                            const std::vector<imu::ImuReading>& imu_samples,
                            const proto::CalibrateParams& params, CalibrationState* state);

// Step 5 alone: position knots, r_b^{lb}, g_a and b_a from LiDAR positions
// p_l(t) in a at IMU times and the accelerometer, rotation knots held
// (knots first interpolated linearly from p_l - C_ab r_b^{lb}); position
// samples of sigma InitParams.odometry_position_sigma_m; r_b^{lb} free with a
// prior of sigma CalibrateParams.extrinsic_translation_prior_sigma_m at its
// current value along translation_prior_axis_b (unit, frame b; zero:
// isotropic), held when that sigma is 0. Returns the RMS weighted residual.
double FitPositionSpline(const std::vector<double>& times_s,
                         const std::vector<Eigen::Vector3d>& lidar_positions_a,
                         const std::vector<imu::ImuReading>& imu_samples,
                         const proto::CalibrateParams& params,
                         const Eigen::Vector3d& translation_prior_axis_b, CalibrationState* state);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_INIT_INITIALISATION_H_
