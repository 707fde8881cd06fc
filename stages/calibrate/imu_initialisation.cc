#include "stages/calibrate/imu_initialisation.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace tiltcal::calibrate {
namespace {

// Exp: rotation vector (rad) -> unit quaternion (local; first-order series
// below 1e-10 rad).
Eigen::Quaterniond ExpQ(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  if (theta < 1e-10) {
    return Eigen::Quaterniond(1.0, 0.5 * phi.x(), 0.5 * phi.y(), 0.5 * phi.z()).normalized();
  }
  return Eigen::Quaterniond(Eigen::AngleAxisd(theta, phi / theta));
}

// First index with time >= t.
std::size_t LowerIndex(const std::vector<ImuReading>& samples, double t) {
  return static_cast<std::size_t>(
      std::lower_bound(samples.begin(), samples.end(), t,
                       [](const ImuReading& s, double value) { return s.time_s < value; }) -
      samples.begin());
}

// Mean and per-axis standard deviation over samples [begin, end).
struct WindowStats {
  Eigen::Vector3d gyro_mean, gyro_std, accel_mean, accel_std;
};

WindowStats ComputeStats(const std::vector<ImuReading>& samples, std::size_t begin, std::size_t end) {
  WindowStats s;
  const double n = static_cast<double>(end - begin);
  s.gyro_mean.setZero();
  s.accel_mean.setZero();
  for (std::size_t i = begin; i < end; ++i) {
    s.gyro_mean += samples[i].angular_velocity_radps;
    s.accel_mean += samples[i].linear_acceleration_mps2;
  }
  s.gyro_mean /= n;
  s.accel_mean /= n;
  Eigen::Vector3d gyro_var = Eigen::Vector3d::Zero(), accel_var = Eigen::Vector3d::Zero();
  for (std::size_t i = begin; i < end; ++i) {
    gyro_var += (samples[i].angular_velocity_radps - s.gyro_mean).cwiseAbs2();
    accel_var += (samples[i].linear_acceleration_mps2 - s.accel_mean).cwiseAbs2();
  }
  s.gyro_std = (gyro_var / n).cwiseSqrt();
  s.accel_std = (accel_var / n).cwiseSqrt();
  return s;
}

}  // namespace

Status ValidateImuReadings(const std::vector<ImuReading>& samples) {
  if (samples.empty()) return Status::Error("no IMU samples");
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const ImuReading& s = samples[i];
    if (!std::isfinite(s.time_s) || !s.angular_velocity_radps.allFinite() ||
        !s.linear_acceleration_mps2.allFinite()) {
      return Status::Error("IMU sample " + std::to_string(i) + ": non-finite value");
    }
    if (i > 0 && !(s.time_s > samples[i - 1].time_s)) {
      return Status::Error("IMU sample " + std::to_string(i) + ": time " + std::to_string(s.time_s) +
                           " s does not increase");
    }
  }
  return Status::Ok();
}

StaticInterval DetectStaticStart(const std::vector<ImuReading>& samples,
                                 const StaticDetectionOptions& options) {
  StaticInterval result;
  if (samples.size() < 2 || !(options.window_s > 0.0) || !(options.hop_s > 0.0)) return result;
  const double t0 = samples.front().time_s;
  const double t_last = samples.back().time_s;
  double static_end = t0;
  bool any_static = false;
  for (int k = 0;; ++k) {
    const double begin_t = t0 + k * options.hop_s;
    const double end_t = begin_t + options.window_s;
    if (end_t > t_last + 1e-12) break;
    const std::size_t begin = LowerIndex(samples, begin_t);
    const std::size_t end = LowerIndex(samples, end_t);
    if (end < begin + 2) break;  // too sparse to judge
    const WindowStats s = ComputeStats(samples, begin, end);
    const bool is_static = s.gyro_std.maxCoeff() <= options.max_gyro_std_radps &&
                           s.accel_std.maxCoeff() <= options.max_accel_std_mps2 &&
                           s.gyro_mean.norm() <= options.max_gyro_mean_radps;
    if (!is_static) break;
    any_static = true;
    static_end = end_t;
  }
  if (!any_static || static_end - t0 < options.min_duration_s) return result;
  result.found = true;
  result.begin_s = t0;
  result.end_s = static_end;
  result.begin_index = 0;
  result.end_index = LowerIndex(samples, static_end);
  return result;
}

GyroIntegrator::GyroIntegrator(const std::vector<ImuReading>& samples,
                               const Eigen::Vector3d& gyro_bias_radps) {
  times_.reserve(samples.size());
  rates_.reserve(samples.size());
  rotations_.reserve(samples.size());
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const Eigen::Vector3d w = samples[k].angular_velocity_radps - gyro_bias_radps;
    if (k > 0) {
      const double dt = samples[k].time_s - times_.back();
      q = (q * ExpQ(0.5 * (rates_.back() + w) * dt)).normalized();
    }
    times_.push_back(samples[k].time_s);
    rates_.push_back(w);
    rotations_.push_back(q);
  }
}

Eigen::Quaterniond GyroIntegrator::Rotation(double time_s) const {
  if (times_.empty()) return Eigen::Quaterniond::Identity();
  if (time_s <= times_.front()) {
    return (rotations_.front() * ExpQ(rates_.front() * (time_s - times_.front()))).normalized();
  }
  if (time_s >= times_.back()) {
    return (rotations_.back() * ExpQ(rates_.back() * (time_s - times_.back()))).normalized();
  }
  const std::size_t k1 = static_cast<std::size_t>(
      std::upper_bound(times_.begin(), times_.end(), time_s) - times_.begin());
  const std::size_t k = k1 - 1;
  const double dt = times_[k1] - times_[k];
  const double s = time_s - times_[k];
  const Eigen::Vector3d w_mid = rates_[k] + (rates_[k1] - rates_[k]) * (0.5 * s / dt);
  return (rotations_[k] * ExpQ(w_mid * s)).normalized();
}

Eigen::Quaterniond GyroIntegrator::RelativeRotation(double t1_s, double t2_s) const {
  return (Rotation(t1_s).conjugate() * Rotation(t2_s)).normalized();
}

Status InitialiseImu(const std::vector<ImuReading>& samples,
                     const ImuInitialisationOptions& options, ImuInitialisation* out) {
  TILTCAL_RETURN_IF_ERROR(ValidateImuReadings(samples));
  *out = ImuInitialisation();
  out->static_start = DetectStaticStart(samples, options.static_detection);

  std::size_t begin = 0, end = 0;
  if (out->static_start.found) {
    out->from_static_start = true;
    begin = out->static_start.begin_index;
    end = out->static_start.end_index;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::size_t i = begin; i < end; ++i) sum += samples[i].angular_velocity_radps;
    out->gyro_bias_radps = sum / static_cast<double>(end - begin);
  } else {
    begin = 0;
    end = std::max<std::size_t>(LowerIndex(samples, samples.front().time_s + options.fallback_window_s), 1);
  }

  // Rotation-compensated specific-force mean in a: at rest (or on average
  // over a window with zero mean acceleration) it equals -g_a.
  const GyroIntegrator integrator(samples, out->gyro_bias_radps);
  Eigen::Vector3d mean_f = Eigen::Vector3d::Zero();
  for (std::size_t i = begin; i < end; ++i) {
    mean_f += integrator.Rotation(samples[i].time_s) * samples[i].linear_acceleration_mps2;
  }
  mean_f /= static_cast<double>(end - begin);
  const double norm = mean_f.norm();
  if (!(norm > 1e-6)) {
    return Status::Error("IMU samples " + std::to_string(begin) + ".." + std::to_string(end - 1) +
                         ": mean specific force is zero; cannot find gravity");
  }
  out->gravity_in_world_mps2 = -options.gravity_norm_mps2 * mean_f / norm;
  out->accel_norm_mismatch_mps2 = norm - options.gravity_norm_mps2;
  out->averaging_begin_s = samples[begin].time_s;
  out->averaging_end_s = samples[end - 1].time_s;
  out->num_samples_averaged = static_cast<int>(end - begin);
  return Status::Ok();
}

}  // namespace tiltcal::calibrate
