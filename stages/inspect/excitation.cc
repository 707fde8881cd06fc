#include "stages/inspect/excitation.h"

#include <algorithm>
#include <cmath>

#include "stages/inspect/stamp_statistics.h"

namespace tiltcal::inspect {

std::vector<double> MovingAverage(const std::vector<double>& values, int window) {
  if (window <= 1 || values.empty()) return values;
  const int n = static_cast<int>(values.size());
  const int half = window / 2;
  std::vector<double> prefix(values.size() + 1, 0.0);
  for (int i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + values[i];
  std::vector<double> out(values.size());
  for (int i = 0; i < n; ++i) {
    const int lo = std::max(0, i - half), hi = std::min(n, i + half + 1);
    out[i] = (prefix[hi] - prefix[lo]) / (hi - lo);
  }
  return out;
}

int CountSignChanges(const std::vector<double>& values, double hysteresis) {
  int state = 0, changes = 0;
  for (double v : values) {
    const int sign = v > hysteresis ? 1 : (v < -hysteresis ? -1 : 0);
    if (sign == 0) continue;
    if (state != 0 && sign != state) ++changes;
    state = sign;
  }
  return changes;
}

namespace {

double MaxAbs(const std::vector<double>& values) {
  double m = 0.0;
  for (double v : values) m = std::max(m, std::abs(v));
  return m;
}

}  // namespace

ImuExcitation MeasureImuExcitation(const std::vector<imu::ImuReading>& samples,
                                   const Eigen::Vector3d& gyro_bias_radps,
                                   const Eigen::Vector3d& specific_force_at_rest_mps2,
                                   const ExcitationOptions& options) {
  ImuExcitation e;
  if (samples.size() < 2) return e;
  const Eigen::Vector3d up = specific_force_at_rest_mps2.normalized();
  Eigen::Vector3d lateral = Eigen::Vector3d::UnitY() - up.y() * up;
  // cos 60 deg = 0.5: y within 60 deg of vertical leaves |y_h| < sin 30 deg.
  if (lateral.norm() < 0.5) {
    lateral = Eigen::Vector3d::UnitX() - up.x() * up;
    e.lateral_axis_is_x = true;
  }
  lateral.normalize();
  std::vector<double> yaw_rate, lateral_accel, speed;
  yaw_rate.reserve(samples.size());
  lateral_accel.reserve(samples.size());
  speed.reserve(samples.size());
  for (const imu::ImuReading& s : samples) {
    const Eigen::Vector3d w = s.angular_velocity_radps - gyro_bias_radps;
    yaw_rate.push_back(w.dot(up));
    lateral_accel.push_back(
        (s.linear_acceleration_mps2 - specific_force_at_rest_mps2).dot(lateral));
    speed.push_back(w.norm());
  }
  const double span_s = samples.back().time_s - samples.front().time_s;
  const double rate_hz = span_s > 0.0 ? static_cast<double>(samples.size() - 1) / span_s : 1.0;
  const int window = static_cast<int>(std::lround(options.smoothing_window_s * rate_hz)) | 1;
  yaw_rate = MovingAverage(yaw_rate, window);
  lateral_accel = MovingAverage(lateral_accel, window);
  e.yaw_rate_sign_changes = CountSignChanges(yaw_rate, options.yaw_rate_hysteresis_radps);
  e.lateral_accel_reversals =
      CountSignChanges(lateral_accel, options.lateral_accel_hysteresis_mps2);
  e.max_abs_yaw_rate_radps = MaxAbs(yaw_rate);
  e.max_abs_lateral_accel_mps2 = MaxAbs(lateral_accel);
  e.rotation_speed_p95_radps = Quantile(std::move(speed), 0.95);
  return e;
}

}  // namespace tiltcal::inspect
