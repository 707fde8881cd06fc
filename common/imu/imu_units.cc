#include "common/imu/imu_units.h"

#include <algorithm>

namespace tiltcal::imu {

namespace {

// Accepted band around an expected magnitude, as factors.
constexpr double kBandLow = 0.8;
constexpr double kBandHigh = 1.25;

bool WithinBand(double value, double expected) {
  return value >= kBandLow * expected && value <= kBandHigh * expected;
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<long>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

double ToSiFactor(AccelUnit unit) {
  return unit == AccelUnit::kStandardGravity ? kStandardGravityMps2 : 1.0;
}

double ToSiFactor(GyroUnit unit) {
  return unit == GyroUnit::kDegreesPerSecond ? kRadiansPerDegree : 1.0;
}

std::string UnitName(AccelUnit unit) {
  return unit == AccelUnit::kStandardGravity ? "g" : "m/s²";
}

std::string UnitName(GyroUnit unit) {
  return unit == GyroUnit::kDegreesPerSecond ? "deg/s" : "rad/s";
}

AccelUnitEvidence DetectAccelUnit(const std::vector<ImuReading>& samples,
                                  const std::vector<StaticInterval>& static_intervals) {
  AccelUnitEvidence evidence;
  std::vector<double> norms;
  for (const StaticInterval& interval : static_intervals) {
    for (size_t i = interval.begin_index; i < interval.end_index && i < samples.size(); ++i) {
      norms.push_back(samples[i].linear_acceleration_mps2.norm());
    }
  }
  evidence.from_static_samples = !norms.empty();
  if (norms.empty()) {
    for (const ImuReading& sample : samples) {
      norms.push_back(sample.linear_acceleration_mps2.norm());
    }
  }
  evidence.median_norm = Median(std::move(norms));
  if (WithinBand(evidence.median_norm, kStandardGravityMps2)) {
    evidence.unit = AccelUnit::kMetresPerSecond2;
  } else if (WithinBand(evidence.median_norm, 1.0)) {
    evidence.unit = AccelUnit::kStandardGravity;
  }
  return evidence;
}

std::optional<GyroUnit> GyroUnitFromScale(double gyro_over_reference) {
  if (WithinBand(gyro_over_reference, 1.0)) return GyroUnit::kRadiansPerSecond;
  if (WithinBand(gyro_over_reference, 1.0 / kRadiansPerDegree)) return GyroUnit::kDegreesPerSecond;
  return std::nullopt;
}

void ConvertToSi(AccelUnit accel, GyroUnit gyro, std::vector<ImuReading>* samples) {
  const double accel_factor = ToSiFactor(accel);
  const double gyro_factor = ToSiFactor(gyro);
  for (ImuReading& sample : *samples) {
    sample.linear_acceleration_mps2 *= accel_factor;
    sample.angular_velocity_radps *= gyro_factor;
  }
}

}  // namespace tiltcal::imu
