#include "stages/calibrate/report/imu_static_noise.h"

#include <Eigen/Core>

namespace tiltcal::calibrate {
namespace {

// sum_i |x_i - mean|^2 / (3 (n - 1)) of the vectors x.
double PooledAxisVariance(const std::vector<Eigen::Vector3d>& x) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& v : x) mean += v;
  mean /= static_cast<double>(x.size());
  double sum = 0.0;
  for (const Eigen::Vector3d& v : x) sum += (v - mean).squaredNorm();
  return sum / (3.0 * static_cast<double>(x.size() - 1));
}

}  // namespace

ImuStaticNoise MeasureImuStaticNoise(const std::vector<imu::ImuReading>& readings, double begin_s,
                                     double end_s, double gyro_sigma_radps,
                                     double accel_sigma_mps2, double low_pass_correlation) {
  ImuStaticNoise out;
  std::vector<Eigen::Vector3d> gyro;
  std::vector<Eigen::Vector3d> accel;
  for (const imu::ImuReading& r : readings) {
    if (r.time_s < begin_s || r.time_s > end_s) continue;
    gyro.push_back(r.angular_velocity_radps);
    accel.push_back(r.linear_acceleration_mps2);
  }
  out.samples = static_cast<int>(gyro.size());
  if (out.samples < kMinStaticNoiseSamples || !(gyro_sigma_radps > 0.0) ||
      !(accel_sigma_mps2 > 0.0)) {
    return out;
  }
  out.gyro_factor =
      PooledAxisVariance(gyro) / (gyro_sigma_radps * gyro_sigma_radps) * low_pass_correlation;
  out.accel_factor =
      PooledAxisVariance(accel) / (accel_sigma_mps2 * accel_sigma_mps2) * low_pass_correlation;
  return out;
}

}  // namespace tiltcal::calibrate
