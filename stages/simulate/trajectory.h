#ifndef TILTCAL_STAGES_SIMULATE_TRAJECTORY_H_
#define TILTCAL_STAGES_SIMULATE_TRAJECTORY_H_

#include <Eigen/Core>

namespace tiltcal::simulate {

// Planar motion of a ground vehicle on a tilted plane, in the simulation
// world w (z up, gravity along −z). All quantities are analytic functions of
// time (no numerical differentiation), so the IMU truth is exact.
//
// Plane frame p: C_wp = Ry(pitch) Rx(roll), the plane passes through the
// origin with unit normal n_w = C_wp e_z. The path (u(θ), v(θ)) lives in the
// plane's (x, y); the vehicle frame v has x along the path tangent and z
// along the normal, plus a small roll/pitch vibration about the IMU:
//   C_wv(t) = C_wp Rz(ψ(t)) Rx(φ(t)) Ry(ϑ(t)),   C_wb(t) = C_wv(t) C_vb,
//   r_w^{bw}(t) = C_wp [u, v, d_b]^T   (the IMU stays at height d_b).
// Time: θ(t) = Ω σ(t) where σ(t) is the "moving time": 0 during the static
// start, a quintic ramp of σ' from 0 to 1 over ramp_s, then σ' = 1;
// Ω = 2π / loop period, loop period = arc length / speed.
struct TrajectoryConfig {
  enum class Shape { kFigureEight, kCircle };
  Shape shape = Shape::kFigureEight;
  double length_m = 16.0;
  double width_m = 8.0;
  double speed_mps = 1.0;
  double static_start_s = 0.0;
  double ramp_s = 1.0;
  double vibration_roll_rad = 0.0;
  double vibration_pitch_rad = 0.0;
  double vibration_frequency_hz = 0.0;
  double heading_rad = 0.0;
  // > 0: scale length and width so that the peak yaw rate is this (rad/s).
  double max_yaw_rate_radps = 0.0;
  double ground_roll_rad = 0.0;
  double ground_pitch_rad = 0.0;
  double imu_height_m = 0.5;                           // d_b
  Eigen::Matrix3d vehicle_from_imu = Eigen::Matrix3d::Identity();  // C_vb
};

// Pose and derivatives of the IMU frame b at one time.
struct ImuState {
  Eigen::Matrix3d world_from_imu;  // C_wb
  Eigen::Vector3d position_w;      // r_w^{bw}, m
  Eigen::Vector3d velocity_w;      // m/s
  Eigen::Vector3d acceleration_w;  // m/s², r̈_w
  Eigen::Vector3d angular_velocity_b;  // ω_b, rad/s, resolved in b
  double yaw_rate_radps = 0.0;     // ψ̇ about the plane normal
  double moving_rate = 0.0;        // σ'(t): 0 while static, 1 once moving
};

class PlanarTrajectory {
 public:
  explicit PlanarTrajectory(const TrajectoryConfig& config);

  // Full state at time t (s since the first IMU sample).
  ImuState Evaluate(double t) const;
  // Pose only (cheaper; used per LiDAR firing).
  void Pose(double t, Eigen::Matrix3d* world_from_imu, Eigen::Vector3d* position_w) const;

  const Eigen::Matrix3d& world_from_plane() const { return world_from_plane_; }
  Eigen::Vector3d NormalInWorld() const { return world_from_plane_.col(2); }
  double loop_period_s() const { return loop_period_s_; }
  double arc_length_m() const { return arc_length_m_; }
  // Largest |yaw rate| once moving (after the ramp), rad/s.
  double max_yaw_rate_radps() const { return max_yaw_rate_radps_; }
  // Path size after the yaw-rate scaling.
  double length_m() const { return config_.length_m; }
  double width_m() const { return config_.width_m; }
  // Half extents of the path's bounding box in the plane's (x, y), about 0.
  Eigen::Vector2d PathMin() const { return path_min_; }
  Eigen::Vector2d PathMax() const { return path_max_; }

 private:
  // Path point and its first two derivatives with respect to θ, plane coords.
  void Path(double theta, Eigen::Vector2d* p, Eigen::Vector2d* dp, Eigen::Vector2d* ddp) const;
  // σ(t), σ'(t), σ''(t).
  void MovingTime(double t, double* s, double* ds, double* dds) const;
  // Arc length, bounding box and peak yaw rate for the current size.
  void MeasurePath();

  TrajectoryConfig config_;
  Eigen::Matrix3d world_from_plane_;
  Eigen::Matrix2d heading_rotation_;
  double loop_period_s_ = 1.0;
  double omega_ = 0.0;  // dθ/dσ
  double arc_length_m_ = 0.0;
  double max_yaw_rate_radps_ = 0.0;
  Eigen::Vector2d path_min_, path_max_;
};

}  // namespace tiltcal::simulate

#endif  // TILTCAL_STAGES_SIMULATE_TRAJECTORY_H_
