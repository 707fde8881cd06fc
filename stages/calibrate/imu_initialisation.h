#ifndef TILTCAL_STAGES_CALIBRATE_IMU_INITIALISATION_H_
#define TILTCAL_STAGES_CALIBRATE_IMU_INITIALISATION_H_

// IMU-only initial values for the calibrator (issue 5 item 4): static-start
// detection, gyro bias, gravity direction in the world frame, and gyro
// integration giving C_ab(t).
//
// Frames and models (DESIGN §5): IMU b, world a = the IMU frame at the FIRST
// IMU sample, so C_ab(t_first) = 1. Measurements
//   w_m = w_b(t) + b_g + n,      f_m = C_ab(t)^T (rdd_a(t) - g_a) + b_a + n.
// At rest rdd_a = 0, so f_m = -C_ab^T g_a + b_a and g_a = -C_ab f_m (b_a = 0).
//
// Accelerometer bias: from one static attitude only the component of b_a
// along gravity would show (as |mean f| != |g|); its other components are
// indistinguishable from a gravity direction change. It is therefore set to
// zero here, and the norm mismatch is reported for diagnosis only.

#include <cstddef>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/status.h"

namespace tiltcal::calibrate {

// One IMU sample in the IMU frame b. time_s: seconds relative to the
// sequence start (IMU clock).
struct ImuReading {
  double time_s = 0.0;
  Eigen::Vector3d angular_velocity_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d linear_acceleration_mps2 = Eigen::Vector3d::Zero();  // specific force
};

struct StaticDetectionOptions {
  double window_s = 0.5;              // length of one test window, s
  double hop_s = 0.1;                 // window step, s (resolution of the end time)
  double max_gyro_std_radps = 0.01;   // per-axis standard deviation bound, rad/s
  double max_accel_std_mps2 = 0.05;   // per-axis standard deviation bound, m/s^2
  double max_gyro_mean_radps = 0.05;  // |mean gyro| bound (rules out steady turning), rad/s
  double min_duration_s = 1.0;        // shorter static starts are not used
};

// [begin_s, end_s] and the samples [begin_index, end_index) of the static start.
struct StaticInterval {
  bool found = false;
  double begin_s = 0.0;
  double end_s = 0.0;
  std::size_t begin_index = 0;
  std::size_t end_index = 0;
};

// Longest run of consecutive static windows starting at the first sample.
// Window k covers [t0 + k hop, t0 + k hop + window); it is static when every
// axis of gyro and accel has a standard deviation below the bounds and the
// mean gyro norm is below max_gyro_mean_radps. The start ends at the end of
// the last static window before the first moving one. `found` is false when
// that run is shorter than min_duration_s (or the first window moves).
// Samples must be sorted by time (see ValidateImuReadings).
StaticInterval DetectStaticStart(const std::vector<ImuReading>& samples,
                                 const StaticDetectionOptions& options);

// Error when empty, non-finite or not strictly increasing in time; the message
// names the sample index ("IMU sample 12: ...").
Status ValidateImuReadings(const std::vector<ImuReading>& samples);

// C_ab(t) by integrating the bias-corrected gyro: with w_k = w_m,k - b_g and
// dt = t_{k+1} - t_k,
//   C_ab(t_{k+1}) = C_ab(t_k) Exp(0.5 (w_k + w_{k+1}) dt)
// (midpoint of the linearly interpolated rate), and inside an interval
//   C_ab(t_k + s) = C_ab(t_k) Exp(w(t_k + s/2) s),  w linear in time,
// which reproduces the step rule at s = dt. Before the first / after the last
// sample the rotation is extrapolated at the first / last rate.
class GyroIntegrator {
 public:
  GyroIntegrator() = default;
  // Samples must be valid (ValidateImuReadings).
  GyroIntegrator(const std::vector<ImuReading>& samples, const Eigen::Vector3d& gyro_bias_radps);

  // C_ab(t) as a unit quaternion (maps b at time t to a).
  Eigen::Quaterniond Rotation(double time_s) const;
  // C_{b(t1) b(t2)} = C_ab(t1)^T C_ab(t2).
  Eigen::Quaterniond RelativeRotation(double t1_s, double t2_s) const;

  double begin_s() const { return times_.empty() ? 0.0 : times_.front(); }
  double end_s() const { return times_.empty() ? 0.0 : times_.back(); }
  bool empty() const { return times_.empty(); }

 private:
  std::vector<double> times_;
  std::vector<Eigen::Vector3d> rates_;          // bias-corrected, rad/s
  std::vector<Eigen::Quaterniond> rotations_;   // C_ab(t_k)
};

struct ImuInitialisationOptions {
  StaticDetectionOptions static_detection;
  double gravity_norm_mps2 = 9.81;  // |g_a|
  // Without a static start, g_a comes from the first this-many seconds.
  double fallback_window_s = 2.0;
};

struct ImuInitialisation {
  StaticInterval static_start;
  // True when the values below come from a static start.
  bool from_static_start = false;
  // Mean gyro over the static start; zero (unobserved) without one.
  Eigen::Vector3d gyro_bias_radps = Eigen::Vector3d::Zero();
  // Always zero: not observable from one static attitude (see file comment).
  Eigen::Vector3d accel_bias_mps2 = Eigen::Vector3d::Zero();
  // g_a = -|g| normalise(mean_i C_ab(t_i) f_i) over the averaging window.
  Eigen::Vector3d gravity_in_world_mps2 = Eigen::Vector3d::Zero();
  // |mean_i C_ab(t_i) f_i| - |g| over the window, m/s^2 (bias/scale hint).
  double accel_norm_mismatch_mps2 = 0.0;
  double averaging_begin_s = 0.0;
  double averaging_end_s = 0.0;
  int num_samples_averaged = 0;
};

// Gyro bias and gravity from the static start, or from the first
// fallback_window_s seconds (rotation-compensated with the integrated gyro,
// zero bias) when there is none.
Status InitialiseImu(const std::vector<ImuReading>& samples,
                     const ImuInitialisationOptions& options, ImuInitialisation* out);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_IMU_INITIALISATION_H_
