#include "stages/simulate/trajectory.h"

#include <algorithm>
#include <cmath>

#include "common/geometry/angles.h"
#include "common/geometry/euler_angles.h"

namespace tiltcal::simulate {

namespace {
using geometry::kTwoPi;
// Frequency ratio of the pitch vibration to the roll vibration (incommensurate).
constexpr double kPitchFrequencyRatio = 1.37;
}  // namespace

PlanarTrajectory::PlanarTrajectory(const TrajectoryConfig& config) : config_(config) {
  world_from_plane_ = geometry::RotY(config.ground_pitch_rad) * geometry::RotX(config.ground_roll_rad);
  const double c = std::cos(config.heading_rad), s = std::sin(config.heading_rad);
  heading_rotation_ << c, -s, s, c;
  MeasurePath();
  if (config_.max_yaw_rate_radps > 0.0) {
    // Yaw rate = κ v; scaling the path by f divides κ by f at the same speed.
    const double f = max_yaw_rate_radps_ / config_.max_yaw_rate_radps;
    config_.length_m *= f;
    config_.width_m *= f;
    MeasurePath();
  }
}

void PlanarTrajectory::MeasurePath() {
  // Arc length of one loop (θ from 0 to 2π, midpoint rule), bounding box and
  // peak |dψ/dθ| = |x'y'' − y'x''| / |p'|².
  constexpr int kSteps = 20000;
  double length = 0.0, max_dpsi_dtheta = 0.0;
  path_min_ = Eigen::Vector2d::Constant(1e300);
  path_max_ = Eigen::Vector2d::Constant(-1e300);
  for (int i = 0; i < kSteps; ++i) {
    const double theta = kTwoPi * (i + 0.5) / kSteps;
    Eigen::Vector2d p, dp, ddp;
    Path(theta, &p, &dp, &ddp);
    length += dp.norm() * kTwoPi / kSteps;
    path_min_ = path_min_.cwiseMin(p);
    path_max_ = path_max_.cwiseMax(p);
    max_dpsi_dtheta = std::max(
        max_dpsi_dtheta, std::abs(dp.x() * ddp.y() - dp.y() * ddp.x()) / dp.squaredNorm());
  }
  arc_length_m_ = length;
  loop_period_s_ = length / config_.speed_mps;
  omega_ = kTwoPi / loop_period_s_;
  max_yaw_rate_radps_ = max_dpsi_dtheta * omega_;
}

void PlanarTrajectory::Path(double theta, Eigen::Vector2d* p, Eigen::Vector2d* dp,
                            Eigen::Vector2d* ddp) const {
  const double a = 0.5 * config_.length_m;
  const double st = std::sin(theta), ct = std::cos(theta);
  Eigen::Vector2d q, dq, ddq;
  if (config_.shape == TrajectoryConfig::Shape::kFigureEight) {
    // Lemniscate of Gerono: x = a sin θ, y = w sin θ cos θ = (w/2) sin 2θ.
    const double w = config_.width_m;
    const double s2 = std::sin(2.0 * theta), c2 = std::cos(2.0 * theta);
    q << a * st, 0.5 * w * s2;
    dq << a * ct, w * c2;
    ddq << -a * st, -2.0 * w * s2;
  } else {
    q << a * st, a * (1.0 - ct);
    dq << a * ct, a * st;
    ddq << -a * st, a * ct;
  }
  *p = heading_rotation_ * q;
  *dp = heading_rotation_ * dq;
  *ddp = heading_rotation_ * ddq;
}

void PlanarTrajectory::MovingTime(double t, double* s, double* ds, double* dds) const {
  const double t0 = config_.static_start_s;
  const double tr = config_.ramp_s;
  if (t <= t0) {
    *s = 0.0;
    *ds = 0.0;
    *dds = 0.0;
    return;
  }
  if (t >= t0 + tr) {
    *s = 0.5 * tr + (t - t0 - tr);
    *ds = 1.0;
    *dds = 0.0;
    return;
  }
  // σ' = h(x) = 10x³ − 15x⁴ + 6x⁵, x = (t − t0)/tr; σ = tr (2.5x⁴ − 3x⁵ + x⁶).
  const double x = (t - t0) / tr;
  const double x2 = x * x, x3 = x2 * x, x4 = x3 * x;
  *s = tr * (2.5 * x4 - 3.0 * x4 * x + x4 * x2);
  *ds = 10.0 * x3 - 15.0 * x4 + 6.0 * x4 * x;
  *dds = (30.0 * x2 - 60.0 * x3 + 30.0 * x4) / tr;
}

ImuState PlanarTrajectory::Evaluate(double t) const {
  double sigma, dsigma, ddsigma;
  MovingTime(t, &sigma, &dsigma, &ddsigma);
  const double theta = omega_ * sigma;
  const double dtheta = omega_ * dsigma;
  const double ddtheta = omega_ * ddsigma;
  Eigen::Vector2d p, dp, ddp;
  Path(theta, &p, &dp, &ddp);

  ImuState state;
  // Position, velocity, acceleration in the plane, then in w.
  const Eigen::Vector2d vel = dp * dtheta;
  const Eigen::Vector2d acc = ddp * dtheta * dtheta + dp * ddtheta;
  state.position_w = world_from_plane_ * Eigen::Vector3d(p.x(), p.y(), config_.imu_height_m);
  state.velocity_w = world_from_plane_ * Eigen::Vector3d(vel.x(), vel.y(), 0.0);
  state.acceleration_w = world_from_plane_ * Eigen::Vector3d(acc.x(), acc.y(), 0.0);

  // Heading ψ = atan2(y', x'); ψ̇ = (x'y'' − y'x'') / |p'|² θ̇.
  const double psi = std::atan2(dp.y(), dp.x());
  const double dpsi = (dp.x() * ddp.y() - dp.y() * ddp.x()) / dp.squaredNorm() * dtheta;
  state.yaw_rate_radps = dpsi;
  state.moving_rate = dsigma;

  // Vibration φ = A_r σ' sin(2πf t), ϑ = A_p σ' sin(2π 1.37 f t + 1).
  const double w1 = kTwoPi * config_.vibration_frequency_hz;
  const double w2 = w1 * kPitchFrequencyRatio;
  const double phi = config_.vibration_roll_rad * dsigma * std::sin(w1 * t);
  const double dphi = config_.vibration_roll_rad *
                      (ddsigma * std::sin(w1 * t) + dsigma * w1 * std::cos(w1 * t));
  const double vt = config_.vibration_pitch_rad * dsigma * std::sin(w2 * t + 1.0);
  const double dvt = config_.vibration_pitch_rad *
                     (ddsigma * std::sin(w2 * t + 1.0) + dsigma * w2 * std::cos(w2 * t + 1.0));

  const Eigen::Matrix3d rx = geometry::RotX(phi), ry = geometry::RotY(vt);
  const Eigen::Matrix3d vib = rx * ry;
  state.world_from_imu = world_from_plane_ * geometry::RotZ(psi) * vib * config_.vehicle_from_imu;
  // Body rates: C = A B ⇒ ω(C) = B^T ω(A) + ω(B), for Rz(ψ) · Rx(φ) · Ry(ϑ).
  const Eigen::Vector3d omega_v = vib.transpose() * Eigen::Vector3d(0.0, 0.0, dpsi) +
                                  ry.transpose() * Eigen::Vector3d(dphi, 0.0, 0.0) +
                                  Eigen::Vector3d(0.0, dvt, 0.0);
  state.angular_velocity_b = config_.vehicle_from_imu.transpose() * omega_v;
  return state;
}

void PlanarTrajectory::Pose(double t, Eigen::Matrix3d* world_from_imu,
                            Eigen::Vector3d* position_w) const {
  double sigma, dsigma, ddsigma;
  MovingTime(t, &sigma, &dsigma, &ddsigma);
  const double theta = omega_ * sigma;
  Eigen::Vector2d p, dp, ddp;
  Path(theta, &p, &dp, &ddp);
  *position_w = world_from_plane_ * Eigen::Vector3d(p.x(), p.y(), config_.imu_height_m);
  const double psi = std::atan2(dp.y(), dp.x());
  Eigen::Matrix3d r = world_from_plane_ * geometry::RotZ(psi);
  if (config_.vibration_roll_rad != 0.0 || config_.vibration_pitch_rad != 0.0) {
    const double w1 = kTwoPi * config_.vibration_frequency_hz;
    const double w2 = w1 * kPitchFrequencyRatio;
    const double phi = config_.vibration_roll_rad * dsigma * std::sin(w1 * t);
    const double vt = config_.vibration_pitch_rad * dsigma * std::sin(w2 * t + 1.0);
    r = r * geometry::RotX(phi) * geometry::RotY(vt);
  }
  *world_from_imu = r * config_.vehicle_from_imu;
}

}  // namespace tiltcal::simulate
