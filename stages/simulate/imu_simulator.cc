#include "stages/simulate/imu_simulator.h"

#include <algorithm>
#include <cmath>

#include "bag/ros1/message_encoding.h"
#include "common/imu/imu_units.h"
#include "common/io/eigen_proto.h"

namespace tiltcal::simulate {
namespace {

// The units the IMU messages are published in (SimFaultParams).
imu::AccelUnit PublishedAccelUnit(const proto::SimFaultParams& faults) {
  return faults.imu_accel_unit() == proto::SimFaultParams::G ? imu::AccelUnit::kStandardGravity
                                                             : imu::AccelUnit::kMetresPerSecond2;
}
imu::GyroUnit PublishedGyroUnit(const proto::SimFaultParams& faults) {
  return faults.imu_gyro_unit() == proto::SimFaultParams::DEGPS
             ? imu::GyroUnit::kDegreesPerSecond
             : imu::GyroUnit::kRadiansPerSecond;
}

}  // namespace

ImuSimulator::ImuSimulator(const proto::SimulateParams& params, const Scenario& scenario)
    : params_(params.imu()),
      scenario_(scenario),
      schedule_(MakeImuSchedule(scenario.num_imu_samples, params_.rate_hz(),
                                scenario.imu_start_stamp_ns, params.faults(), params.seed())),
      rng_(params.seed(), kImuNoiseStream),
      rate_(params_.rate_hz()),
      gyro_sigma_(params_.gyro_noise_density_radps_sqrthz() * std::sqrt(rate_)),
      accel_sigma_(params_.accel_noise_density_mps2_sqrthz() * std::sqrt(rate_)),
      gyro_walk_(params_.gyro_bias_random_walk_radps2_sqrthz() / std::sqrt(rate_)),
      accel_walk_(params_.accel_bias_random_walk_mps3_sqrthz() / std::sqrt(rate_)),
      gyro_published_per_si_(1.0 / imu::ToSiFactor(PublishedGyroUnit(params.faults()))),
      accel_published_per_si_(1.0 / imu::ToSiFactor(PublishedAccelUnit(params.faults()))),
      gyro_bias_(ToEigen(params_.gyro_bias_radps())),
      accel_bias_(ToEigen(params_.accel_bias_mps2())),
      last_gyro_bias_(gyro_bias_),
      last_accel_bias_(accel_bias_),
      vibration_(params.faults().imu_vibration(), params.seed()) {
  DrawImuIntrinsics(params.faults(), params.seed(), &gyro_errors_, &accel_errors_);
  gyro_from_true_ = gyro_errors_.MeasuredFromTrue();
  accel_from_true_ = accel_errors_.MeasuredFromTrue();
}

Status ImuSimulator::WriteUpTo(int64_t stamp_ns, uint32_t connection, ros1::BagWriter* writer) {
  while (next_ < scenario_.num_imu_samples && schedule_.stamp_ns[next_] <= stamp_ns) {
    TILTCAL_RETURN_IF_ERROR(SimulateSample(next_++, connection, writer));
  }
  return Status::Ok();
}

Eigen::Vector3d ImuSimulator::Gaussian3() {
  const double x = rng_.Gaussian(), y = rng_.Gaussian(), z = rng_.Gaussian();
  return Eigen::Vector3d(x, y, z);
}

Status ImuSimulator::SimulateSample(int i, uint32_t connection, ros1::BagWriter* writer) {
  const int64_t rel_ns = NominalImuStampNs(0, rate_, i);
  const double t = rel_ns * 1e-9;
  const ImuState s = scenario_.trajectory->Evaluate(t);
  max_yaw_rate_ = std::max(max_yaw_rate_, std::abs(s.yaw_rate_radps));
  // What the triads feel (frame b): the motion plus the vibration; then
  // what they read: K · that (imu_intrinsics.h), plus bias and noise.
  Eigen::Vector3d omega_felt = s.angular_velocity_b;
  Eigen::Vector3d force_felt =
      s.world_from_imu.transpose() * (s.acceleration_w - scenario_.gravity_w);
  vibration_.Add(t, s.moving_rate, &omega_felt, &force_felt);
  if (!gyro_errors_.IsIdentity()) omega_felt = gyro_from_true_ * omega_felt;
  if (!accel_errors_.IsIdentity()) force_felt = accel_from_true_ * force_felt;
  const Eigen::Vector3d omega = omega_felt + gyro_bias_ + gyro_sigma_ * Gaussian3();
  const Eigen::Vector3d force = force_felt + accel_bias_ + accel_sigma_ * Gaussian3();
  last_gyro_bias_ = gyro_bias_;
  last_accel_bias_ = accel_bias_;
  gyro_bias_ += gyro_walk_ * Gaussian3();
  accel_bias_ += accel_walk_ * Gaussian3();
  if (!schedule_.kept[i]) return Status::Ok();
  const int64_t stamp_ns = schedule_.stamp_ns[i];
  const double gyro_sigma = gyro_sigma_ * gyro_published_per_si_;
  const double accel_sigma = accel_sigma_ * accel_published_per_si_;
  if (!ros1::SerializeImu(static_cast<uint32_t>(i), stamp_ns, params_.frame_id(),
                          omega * gyro_published_per_si_, force * accel_published_per_si_,
                          gyro_sigma * gyro_sigma, accel_sigma * accel_sigma, &message_)) {
    return Status::Error("IMU stamp of sample " + std::to_string(i) + " is not a ROS time");
  }
  return writer->Write(connection, stamp_ns, message_);
}

}  // namespace tiltcal::simulate
