#ifndef TILTCAL_COMMON_IMU_IMU_UNITS_H_
#define TILTCAL_COMMON_IMU_IMU_UNITS_H_

#include <optional>
#include <string>
#include <vector>

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

// What the specific force says about the accelerometer's unit. On a ground
// vehicle |f_m| stays near |g| (its own accelerations are a fraction of g),
// so the median norm is about 9.81 in m/s² and about 1 in g. When the
// sequence has static intervals only their samples are used.
struct AccelUnitEvidence {
  double median_norm = 0.0;  // median |f_m|, in the published unit
  bool from_static_samples = false;
  // m/s² when median_norm is within [0.8, 1.25]·g_n, g within [0.8, 1.25];
  // nothing otherwise (a scale no driver uses, or a broken sensor).
  std::optional<AccelUnit> unit;
};
AccelUnitEvidence DetectAccelUnit(const std::vector<ImuReading>& samples,
                                  const std::vector<StaticInterval>& static_intervals);

// The gyro unit a measured scale gyro/reference (AngularSpeedAlignment::scale
// against the LiDAR odometry in rad/s) points to: rad/s within [0.8, 1.25],
// deg/s within [0.8, 1.25]·180/π, nothing otherwise.
std::optional<GyroUnit> GyroUnitFromScale(double gyro_over_reference);

// Readings converted to SI: ω·ToSiFactor(gyro), f·ToSiFactor(accel).
void ConvertToSi(AccelUnit accel, GyroUnit gyro, std::vector<ImuReading>* samples);

}  // namespace tiltcal::imu

#endif  // TILTCAL_COMMON_IMU_IMU_UNITS_H_
