#ifndef TILTCAL_TESTS_STAGES_DECODE_VEHICLE_BAG_H_
#define TILTCAL_TESTS_STAGES_DECODE_VEHICLE_BAG_H_

// A small ROS1 bag of a ground vehicle for the decode stage's unit and clock
// tests (written with bag/ros1's BagWriter): /imu/data at 200 Hz that stands
// still for 2 s and then turns (up to 0.6 rad/s about z) from a level, z-up
// start, and /points at 10 Hz (64 points on a ring, Velodyne layout with a
// per-point `time`). Its IMU values can be published in other units or with
// the other sign, and its LiDAR stamps on another clock, as drivers do; it
// can carry static transforms on /tf_static. IMU frame "imu_link", LiDAR
// frame "lidar".

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "bag/ros1/bag_writer.h"
#include "bag/ros1/message_encoding.h"
#include "tests/common/imu/synthetic_imu.h"

namespace tiltcal::testing {

struct VehicleBagOptions {
  double duration_s = 12.0;
  // Published value = SI value × scale: 1/9.80665 publishes g, −1 a
  // sign-flipped accelerometer, 180/π deg/s.
  double accel_scale = 1.0;
  double gyro_scale = 1.0;
  // Added to the LiDAR header stamps (not to the record times): a LiDAR that
  // stamps on another clock than the IMU.
  int64_t lidar_stamp_offset_ns = 0;
  // The LiDAR's clock runs this fast against the IMU's and the recorder's:
  // its header stamps gain t · ppm · 1e-6 over the bag (t since its start).
  double lidar_clock_drift_ppm = 0.0;
  // IMU message `far_future_imu_index` (>= 0) stamped at the last second
  // uint32 can hold (2^32 − 1 s, in 2106); zero_stamps: every header stamp 0
  // (a driver that never sets them).
  int far_future_imu_index = -1;
  bool zero_stamps = false;
  // IMU message `corrupt_imu_index` (>= 0) publishes corrupt_accel_mps2 as
  // its x specific force and corrupt_gyro_radps as its x angular velocity
  // (before the scales), e.g. 1e300: a record no IMU can produce.
  int corrupt_imu_index = -1;
  double corrupt_accel_mps2 = 0.0;
  double corrupt_gyro_radps = 0.0;
  // Messages on /tf_static (tf2_msgs/TFMessage), recorded 1 ms apart from
  // the bag's start, before the first IMU message.
  std::vector<bag::TfMessage> tf_static;
};

inline constexpr int64_t kVehicleBagStartNs = 1700000000000000000LL;
inline constexpr int64_t kVehicleBagImuLatencyNs = 1000000;     // record − stamp, IMU
inline constexpr int64_t kVehicleBagLidarLatencyNs = 20000000;  // record − true time, LiDAR

// The IMU readings of the bag in SI (time_s from the first sample).
inline std::vector<imu::ImuReading> VehicleBagImu(double duration_s) {
  const auto omega = [](double t) {
    return t < 2.0 ? Eigen::Vector3d::Zero()
                   : Eigen::Vector3d(0.03 * std::sin(1.3 * t), 0.02 * std::cos(0.9 * t),
                                     0.6 * std::sin(0.8 * (t - 2.0)));
  };
  return imu::testing::SyntheticImu(200.0, duration_s, omega, Eigen::Quaterniond::Identity(),
                                    Eigen::Vector3d(0, 0, -9.81),
                                    Eigen::Vector3d(0.002, -0.001, 0.003), 0.002, 0.03, nullptr);
}

// Writes the bag at `path`; false when a message cannot be written.
inline bool WriteVehicleBag(const std::string& path, const VehicleBagOptions& options) {
  ros1::BagWriter writer;
  if (!writer.Open(path, ros1::ChunkCompression::kNone, 256 * 1024).ok()) return false;
  const ros1::MessageType& imu_type = ros1::ImuMessageType();
  const ros1::MessageType& cloud_type = ros1::PointCloud2MessageType();
  const uint32_t imu_connection =
      writer.AddConnection("/imu/data", imu_type.type, imu_type.md5sum, imu_type.definition);
  const uint32_t cloud_connection = writer.AddConnection(
      "/points", cloud_type.type, cloud_type.md5sum, cloud_type.definition);
  struct Message {
    int64_t record_ns;
    uint32_t connection;
    std::string bytes;
  };
  std::vector<Message> messages;
  if (!options.tf_static.empty()) {
    const ros1::MessageType& tf_type = ros1::TfMessageType();
    const uint32_t tf_connection =
        writer.AddConnection(bag::kTfStaticTopic, tf_type.type, tf_type.md5sum, tf_type.definition);
    for (size_t i = 0; i < options.tf_static.size(); ++i) {
      Message m{kVehicleBagStartNs - 100000000 + static_cast<int64_t>(i) * 1000000, tf_connection,
                ""};
      ros1::SerializeTfMessage(options.tf_static[i], &m.bytes);
      messages.push_back(std::move(m));
    }
  }
  const std::vector<imu::ImuReading> readings = VehicleBagImu(options.duration_s);
  for (size_t i = 0; i < readings.size(); ++i) {
    const int64_t stamp_ns = kVehicleBagStartNs + std::llround(readings[i].time_s * 1e9);
    Message m{stamp_ns + kVehicleBagImuLatencyNs, imu_connection, ""};
    int64_t published_ns = options.zero_stamps ? 0 : stamp_ns;
    if (static_cast<int>(i) == options.far_future_imu_index) published_ns = 4294967295LL * 1000000000;
    imu::ImuReading reading = readings[i];
    if (static_cast<int>(i) == options.corrupt_imu_index) {
      reading.linear_acceleration_mps2.x() = options.corrupt_accel_mps2;
      reading.angular_velocity_radps.x() = options.corrupt_gyro_radps;
    }
    if (!ros1::SerializeImu(static_cast<uint32_t>(i), published_ns, "imu_link",
                            reading.angular_velocity_radps * options.gyro_scale,
                            reading.linear_acceleration_mps2 * options.accel_scale, 1e-6,
                            1e-4, &m.bytes)) {
      return false;
    }
    messages.push_back(std::move(m));
  }
  // x, y, z, intensity float32; ring uint16; time float32 (s after the stamp).
  const std::vector<ros1::PointField> fields = {
      {"x", 0, ros1::kFloat32, 1},         {"y", 4, ros1::kFloat32, 1},
      {"z", 8, ros1::kFloat32, 1},         {"intensity", 12, ros1::kFloat32, 1},
      {"ring", 16, ros1::kUint16, 1},      {"time", 18, ros1::kFloat32, 1}};
  constexpr uint32_t kPointStep = 22;
  constexpr int kPoints = 64;
  for (int k = 0; 0.1 * k + 0.1 <= options.duration_s; ++k) {
    const int64_t true_ns = kVehicleBagStartNs + k * 100000000LL;
    std::string data(kPoints * kPointStep, '\0');
    for (int p = 0; p < kPoints; ++p) {
      const double azimuth = 2.0 * M_PI * p / kPoints;
      const float values[4] = {static_cast<float>(10.0 * std::cos(azimuth)),
                               static_cast<float>(10.0 * std::sin(azimuth)), -0.5f, 1.0f};
      const uint16_t ring = static_cast<uint16_t>(p % 16);
      const float time_s = static_cast<float>(0.1 * p / kPoints);
      char* point = &data[p * kPointStep];
      std::copy_n(reinterpret_cast<const char*>(values), 16, point);
      std::copy_n(reinterpret_cast<const char*>(&ring), 2, point + 16);
      std::copy_n(reinterpret_cast<const char*>(&time_s), 4, point + 18);
    }
    Message m{true_ns + kVehicleBagLidarLatencyNs, cloud_connection, ""};
    if (!ros1::SerializePointCloud2(static_cast<uint32_t>(k),
                                    options.zero_stamps
                                        ? 0
                                        : true_ns + options.lidar_stamp_offset_ns +
                                              std::llround(static_cast<double>(
                                                               true_ns - kVehicleBagStartNs) *
                                                           options.lidar_clock_drift_ppm * 1e-6),
                                    "lidar", 1, kPoints,
                                    fields, kPointStep, data, true, &m.bytes)) {
      return false;
    }
    messages.push_back(std::move(m));
  }
  std::stable_sort(messages.begin(), messages.end(),
                   [](const Message& a, const Message& b) { return a.record_ns < b.record_ns; });
  for (const Message& m : messages) {
    if (!writer.Write(m.connection, m.record_ns, m.bytes).ok()) return false;
  }
  return writer.Close().ok();
}

}  // namespace tiltcal::testing

#endif  // TILTCAL_TESTS_STAGES_DECODE_VEHICLE_BAG_H_
