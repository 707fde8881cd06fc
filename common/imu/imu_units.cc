#include "common/imu/imu_units.h"

#include <algorithm>
#include <cmath>

namespace tiltcal::imu {

namespace {

bool WithinBand(double value, double expected, const UnitBand& band) {
  return value >= band.min_ratio * expected && value <= band.max_ratio * expected;
}

// The value at `percentile` (0–100) of `values`: the element of rank
// round(percentile/100 · (n − 1)) in increasing order; 0 when empty.
double Percentile(std::vector<double> values, double percentile) {
  if (values.empty()) return 0.0;
  const double fraction = std::clamp(percentile, 0.0, 100.0) / 100.0;
  const auto at =
      values.begin() + std::lround(fraction * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), at, values.end());
  return *at;
}

// Indices of the static intervals' samples, in time order.
std::vector<size_t> StaticSampleIndices(size_t num_samples,
                                        const std::vector<StaticInterval>& static_intervals) {
  std::vector<size_t> indices;
  for (const StaticInterval& interval : static_intervals) {
    for (size_t i = interval.begin_index; i < interval.end_index && i < num_samples; ++i) {
      indices.push_back(i);
    }
  }
  return indices;
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
                                  const std::vector<StaticInterval>& static_intervals,
                                  const UnitBand& band) {
  AccelUnitEvidence evidence;
  std::vector<double> norms;
  for (size_t i : StaticSampleIndices(samples.size(), static_intervals)) {
    norms.push_back(samples[i].linear_acceleration_mps2.norm());
  }
  evidence.from_static_samples = !norms.empty();
  if (norms.empty()) {
    for (const ImuReading& sample : samples) {
      norms.push_back(sample.linear_acceleration_mps2.norm());
    }
  }
  evidence.num_samples = norms.size();
  evidence.median_norm = Percentile(std::move(norms), 50.0);
  if (evidence.num_samples == 0) return evidence;
  if (WithinBand(evidence.median_norm, kStandardGravityMps2, band)) {
    evidence.unit = AccelUnit::kMetresPerSecond2;
  } else if (WithinBand(evidence.median_norm, 1.0, band)) {
    evidence.unit = AccelUnit::kStandardGravity;
  }
  return evidence;
}

GyroRateEvidence DetectGyroUnitFromRates(const std::vector<ImuReading>& samples,
                                         double percentile, double max_vehicle_turn_rate_radps) {
  GyroRateEvidence evidence;
  evidence.percentile = percentile;
  std::vector<double> rates;
  rates.reserve(samples.size());
  for (const ImuReading& sample : samples) rates.push_back(sample.angular_velocity_radps.norm());
  evidence.rate_at_percentile = Percentile(std::move(rates), percentile);
  if (evidence.rate_at_percentile <= max_vehicle_turn_rate_radps) {
    evidence.unit = GyroUnit::kRadiansPerSecond;
  } else if (evidence.rate_at_percentile * kRadiansPerDegree <= max_vehicle_turn_rate_radps) {
    evidence.unit = GyroUnit::kDegreesPerSecond;
  }
  return evidence;
}

std::optional<GyroUnit> GyroUnitFromScale(double gyro_over_reference, const UnitBand& band) {
  if (WithinBand(gyro_over_reference, 1.0, band)) return GyroUnit::kRadiansPerSecond;
  if (WithinBand(gyro_over_reference, 1.0 / kRadiansPerDegree, band)) {
    return GyroUnit::kDegreesPerSecond;
  }
  return std::nullopt;
}

RestForce MeanRestForce(const std::vector<ImuReading>& samples,
                        const std::vector<StaticInterval>& static_intervals) {
  RestForce rest;
  for (size_t i : StaticSampleIndices(samples.size(), static_intervals)) {
    rest.mean += samples[i].linear_acceleration_mps2;
    ++rest.num_samples;
  }
  rest.from_static_samples = rest.num_samples > 0;
  if (!rest.from_static_samples) {
    for (const ImuReading& sample : samples) rest.mean += sample.linear_acceleration_mps2;
    rest.num_samples = samples.size();
  }
  if (rest.num_samples > 0) rest.mean /= static_cast<double>(rest.num_samples);
  return rest;
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
