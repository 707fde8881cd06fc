#ifndef TILTCAL_COMMON_IMU_IMU_UNITS_H_
#define TILTCAL_COMMON_IMU_IMU_UNITS_H_

// What an IMU driver publishes: the units of its accelerometer and gyro and
// the sign of its specific force, decided from the readings themselves.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/imu/imu_reading.h"
#include "common/imu/static_detection.h"

namespace tiltcal::imu {

// The units an IMU driver may publish in. ROS' sensor_msgs/Imu says m/s² and
// rad/s; several drivers (the Livox built-in IMU, some INS and Hesai
// drivers) publish the accelerometer in g and the gyro in deg/s.
enum class AccelUnit { kMetresPerSecond2, kStandardGravity };
enum class GyroUnit { kRadiansPerSecond, kDegreesPerSecond };

inline constexpr double kStandardGravityMps2 = 9.80665;
inline constexpr double kRadiansPerDegree = 0.017453292519943295;

// Multiplier that converts a reading in `unit` to SI (m/s², rad/s).
double ToSiFactor(AccelUnit unit);
double ToSiFactor(GyroUnit unit);
std::string UnitName(AccelUnit unit);  // "m/s²", "g"
std::string UnitName(GyroUnit unit);   // "rad/s", "deg/s"

// Accepted band of a measured magnitude around the one a unit predicts:
// measured / predicted within [min_ratio, max_ratio]. With min_ratio >= 0.5
// and max_ratio <= 2 the bands of m/s² and g (and of rad/s and deg/s) never
// overlap, so at most one unit fits.
struct UnitBand {
  double min_ratio = 0.8;
  double max_ratio = 1.25;
};

// What the specific force says about the accelerometer's unit. On a ground
// vehicle |f_m| stays near |g| (its own accelerations are a fraction of g),
// so the median norm is about 9.81 in m/s² and about 1 in g. When the
// sequence has static intervals only their samples are used.
struct AccelUnitEvidence {
  double median_norm = 0.0;  // median |f_m|, in the published unit
  size_t num_samples = 0;    // samples the median is over
  bool from_static_samples = false;
  // m/s² when median_norm / 9.80665 is within `band`, g when median_norm / 1
  // is; nothing otherwise (a scale no driver uses, or a broken sensor).
  std::optional<AccelUnit> unit;
};
AccelUnitEvidence DetectAccelUnit(const std::vector<ImuReading>& samples,
                                  const std::vector<StaticInterval>& static_intervals,
                                  const UnitBand& band = UnitBand());

// What the rates alone say about the gyro's unit. A ground vehicle never
// turns faster than a few rad/s (max_vehicle_turn_rate_radps), so a high
// percentile of |ω_m| above that bound, read as rad/s, means the gyro
// publishes deg/s; above the bound even read as deg/s, neither unit fits.
// At or below the bound rad/s is assumed: a gyro in deg/s on a vehicle that
// never turned faster than that many deg/s reads the same, and only a
// reference rotation (the LiDAR odometry, GyroUnitFromScale) tells the two
// apart.
struct GyroRateEvidence {
  double percentile = 0.0;          // which percentile of |ω_m|, %
  double rate_at_percentile = 0.0;  // |ω_m| at that percentile, published unit
  std::optional<GyroUnit> unit;
};
GyroRateEvidence DetectGyroUnitFromRates(const std::vector<ImuReading>& samples,
                                         double percentile, double max_vehicle_turn_rate_radps);

// The gyro unit a measured scale gyro/reference (AngularSpeedAlignment::scale
// against the LiDAR odometry in rad/s) points to: rad/s when the scale is
// within `band` of 1, deg/s within `band` of 180/π, nothing otherwise.
std::optional<GyroUnit> GyroUnitFromScale(double gyro_over_reference,
                                          const UnitBand& band = UnitBand());

// The mean specific force at rest, in the published unit and frame b: over
// the static intervals' samples, else over all samples. At rest f_m = −g in
// frame b, pointing up; over a drive of a ground vehicle the mean of its own
// accelerations is small against g and its attitude stays near upright, so
// the mean over all samples points up too. A mean that points down means
// the driver publishes −f_m (gravity instead of specific force) or the frame
// the caller compares with is wrong.
struct RestForce {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  size_t num_samples = 0;
  bool from_static_samples = false;
};
RestForce MeanRestForce(const std::vector<ImuReading>& samples,
                        const std::vector<StaticInterval>& static_intervals);

// Readings converted to SI: ω·ToSiFactor(gyro), f·ToSiFactor(accel).
void ConvertToSi(AccelUnit accel, GyroUnit gyro, std::vector<ImuReading>* samples);

}  // namespace tiltcal::imu

#endif  // TILTCAL_COMMON_IMU_IMU_UNITS_H_
