#ifndef TILTCAL_STAGES_CALIBRATE_PROBLEM_CALIBRATION_STATE_H_
#define TILTCAL_STAGES_CALIBRATE_PROBLEM_CALIBRATION_STATE_H_

// The estimated quantities of the calibrator (docs/design.md §5, §6), stored
// as the parameter blocks of the ceres::Problem. Every pointer handed to Ceres points
// into this struct (or into the SplineTrajectory it owns), so the struct must
// not move while a Problem refers to it.
//
// Frames: IMU b, LiDAR l, world a = the IMU frame at the first IMU sample.
// Times: double seconds relative to the first IMU stamp (IMU clock). A LiDAR
// time t_l happened at IMU time t = t_l + tau(t_l), with the linear clock
// drift tau(t_l) = tau0 + rho (t_l - t_ref) (TimeOffsetAt; rho = 0: one tau).
//
// Blocks (all owned here) and their manifolds, as set by the problem builder
// (problem_builder.h) BEFORE any residual is added:
//   trajectory.rotation_knot(i)  4 doubles (x, y, z, w), C_ab at knot i,
//                                spline::RightQuaternionManifold;
//   trajectory.position_knot(i)  3 doubles, r_a^{ba} at knot i, m;
//   imu_from_lidar_rotation      4 doubles (x, y, z, w), C_bl,
//                                spline::RightQuaternionManifold;
//   imu_from_lidar_translation   3 doubles, r_b^{lb}, m;
//   time_offset_s                1 double, tau, s, bounded (lower/upper bound
//                                set on the block); with a clock drift, tau0:
//                                tau at time_reference_s;
//   clock_rate                   1 double, rho, dimensionless (ppm * 1e-6),
//                                bounded; in the problem only when the drift
//                                is estimated (time_offset_drift.h), else 0;
//   gravity_direction            3 doubles, unit vector n_g in a pointing DOWN
//                                (g_a = gravity_norm_mps2 * n_g),
//                                ceres::SphereManifold<3>;
//   gyro_bias.values[i]          3 doubles, b_g over segment i, rad/s;
//   accel_bias.values[i]         3 doubles, b_a over segment i, m/s^2.
//   gyro_triad_errors            9 doubles, E_g row-major, and
//   accel_triad_errors           9 doubles, E_a row-major: the triads' scale
//                                and axis errors (common/imu/triad_errors.h);
//                                held constant (at zero unless a caller set
//                                them) when the IMU intrinsics are not
//                                estimated; E_a's upper entries always at 0
//                                (ceres::SubsetManifold).
//                                Both biases are piecewise constant in time
//                                (bias_segments.h): a real IMU's biases
//                                wander: a constant b_a would bend the
//                                trajectory and the yaw of C_bl, a constant
//                                b_g the rotation spline away from the
//                                LiDAR's; one segment for the whole sequence
//                                when the segment length is 0.
// Gauge (C_ab(t0) = 1, r_a^{ba}(t0) = 0; docs/design.md §6): the builder holds the
// first knots constant (see problem_builder.h).
//
// Residuals that use the time offset pick their knot window from the CURRENT
// tau when they are added (TimeWindow below) and keep it frozen; u may then
// leave [0, 1) by at most time_offset_bound / dt while tau moves (see
// point_to_plane_cost_function.h). The problem is rebuilt, and the windows
// re-chosen, at every outer iteration.
//
// Code that adds more residuals (e.g. the ground residuals,
// ground_residuals.h) only calls problem->AddResidualBlock with these
// pointers; it must not add the blocks itself, change their manifolds or
// bounds, or hold the pointers beyond the life of the Problem.

#include <array>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/spline/knot_grid.h"
#include "common/spline/spline_trajectory.h"
#include "stages/calibrate/problem/bias_segments.h"

namespace tiltcal::calibrate {

struct CalibrationState {
  explicit CalibrationState(const spline::UniformKnotGrid& grid) : trajectory(grid) {}
  CalibrationState(const CalibrationState&) = default;
  CalibrationState& operator=(const CalibrationState&) = default;

  spline::SplineTrajectory trajectory;
  double imu_from_lidar_rotation[4] = {0.0, 0.0, 0.0, 1.0};  // C_bl (x, y, z, w)
  double imu_from_lidar_translation[3] = {0.0, 0.0, 0.0};    // r_b^{lb}, m
  double time_offset_s[1] = {0.0};                           // tau (tau0), s
  double clock_rate[1] = {0.0};                              // rho, dimensionless
  // t_ref of the drift: LiDAR clock, s from the first IMU stamp.
  double time_reference_s = 0.0;
  double gravity_direction[3] = {0.0, 0.0, -1.0};            // n_g, unit, frame a, down
  double gravity_norm_mps2 = 9.81;                           // |g_a|, fixed
  BiasSegments gyro_bias;   // b_g, rad/s
  BiasSegments accel_bias;  // b_a, m/s^2
  std::array<double, 9> gyro_triad_errors{};   // E_g (measured = (I + E_g) true)
  std::array<double, 9> accel_triad_errors{};  // E_a, lower triangular

  // Splits b_g and b_a into segments of gyro_segment_s and accel_segment_s
  // over the spline (0 = one segment), each at its current mean. Call before
  // a Problem refers to the state.
  Status SetBiasSegments(double gyro_segment_s, double accel_segment_s) {
    const double t0 = trajectory.grid().t0_s();
    const double duration = trajectory.grid().end_s() - t0;
    TILTCAL_RETURN_IF_ERROR(
        gyro_bias.Split(t0, duration, gyro_segment_s, "imu_noise.gyro_bias_segment_s"));
    return accel_bias.Split(t0, duration, accel_segment_s, "imu_noise.accel_bias_segment_s");
  }
  // Every parameter block of b_g and b_a (3 doubles each).
  std::vector<double*> BiasBlocks() {
    std::vector<double*> blocks;
    for (BiasSegments* bias : {&gyro_bias, &accel_bias}) {
      for (std::array<double, 3>& b : bias->values) blocks.push_back(b.data());
    }
    return blocks;
  }

  // Convenience accessors (copies).
  Eigen::Quaterniond ImuFromLidarRotation() const {
    return Eigen::Quaterniond(imu_from_lidar_rotation[3], imu_from_lidar_rotation[0],
                              imu_from_lidar_rotation[1], imu_from_lidar_rotation[2])
        .normalized();
  }
  Eigen::Vector3d ImuFromLidarTranslation() const {
    return Eigen::Vector3d(imu_from_lidar_translation[0], imu_from_lidar_translation[1],
                           imu_from_lidar_translation[2]);
  }
  // g_a = |g| n_g, m/s^2, frame a.
  Eigen::Vector3d GravityInWorld() const {
    return gravity_norm_mps2 *
           Eigen::Vector3d(gravity_direction[0], gravity_direction[1], gravity_direction[2])
               .normalized();
  }
  // Means of b_g and b_a over their segments.
  Eigen::Vector3d GyroBias() const { return gyro_bias.Mean(); }
  Eigen::Vector3d AccelBias() const { return accel_bias.Mean(); }

  void SetImuFromLidarRotation(const Eigen::Quaterniond& q) {
    const Eigen::Quaterniond n = q.normalized();
    imu_from_lidar_rotation[0] = n.x();
    imu_from_lidar_rotation[1] = n.y();
    imu_from_lidar_rotation[2] = n.z();
    imu_from_lidar_rotation[3] = n.w();
  }
  void SetImuFromLidarTranslation(const Eigen::Vector3d& r) {
    for (int i = 0; i < 3; ++i) imu_from_lidar_translation[i] = r[i];
  }
  // Sets n_g = g_a / |g_a| (the norm stays gravity_norm_mps2).
  void SetGravityDirection(const Eigen::Vector3d& gravity_in_world) {
    const Eigen::Vector3d n = gravity_in_world.normalized();
    for (int i = 0; i < 3; ++i) gravity_direction[i] = n[i];
  }
  // Set every segment of b_g or b_a to b.
  void SetGyroBias(const Eigen::Vector3d& b) { gyro_bias.SetAll(b); }
  void SetAccelBias(const Eigen::Vector3d& b) { accel_bias.SetAll(b); }

  // tau at LiDAR time t_lidar_s (s from the first IMU stamp, LiDAR clock):
  //   tau(t) = tau0 + rho (t - t_ref),
  // exactly tau0 when rho is 0 (the single-tau path is unchanged bit for bit).
  double TimeOffsetAt(double t_lidar_s) const {
    if (clock_rate[0] == 0.0) return time_offset_s[0];
    return time_offset_s[0] + clock_rate[0] * (t_lidar_s - time_reference_s);
  }

  // The frozen knot window of a residual at LiDAR time t_lidar_s, chosen with
  // the current tau: Locate(t_lidar_s + tau(t_lidar_s)). Returns false when
  // that time is outside the spline (the residual is then skipped).
  bool TimeWindow(double t_lidar_s, spline::KnotWindow* window) const {
    return trajectory.grid().Locate(t_lidar_s + TimeOffsetAt(t_lidar_s), window);
  }
};

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_PROBLEM_CALIBRATION_STATE_H_
