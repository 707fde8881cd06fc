#ifndef TILTCAL_STAGES_SIMULATE_ROS1_MESSAGES_H_
#define TILTCAL_STAGES_SIMULATE_ROS1_MESSAGES_H_

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace tiltcal::simulate {

// ROS1 wire format (little-endian, no padding; string = u32 length + bytes;
// T[] = u32 count + elements; T[N] = N elements) of the two messages the
// simulator writes.

struct RosMessageType {
  const char* type;        // "sensor_msgs/Imu"
  const char* md5sum;      // ROS1 MD5 of the definition
  const char* definition;  // full text as in a bag's connection record
};
const RosMessageType& ImuMessageType();
const RosMessageType& PointCloud2MessageType();

// std_msgs/Header: seq, stamp (u32 sec, u32 nsec), frame_id.
// Returns false when stamp_ns is not representable as ROS time.
bool AppendHeader(std::string* out, uint32_t seq, int64_t stamp_ns, const std::string& frame_id);

// sensor_msgs/Imu without orientation (orientation_covariance[0] = −1),
// with diagonal covariances of the given variances.
bool SerializeImu(uint32_t seq, int64_t stamp_ns, const std::string& frame_id,
                  const Eigen::Vector3d& angular_velocity_radps,
                  const Eigen::Vector3d& linear_acceleration_mps2, double gyro_variance,
                  double accel_variance, std::string* out);

// sensor_msgs/PointField.
struct PointField {
  std::string name;
  uint32_t offset;
  uint8_t datatype;  // 1 INT8 … 7 FLOAT32, 8 FLOAT64
  uint32_t count;
};
enum PointFieldType : uint8_t {
  kInt8 = 1, kUint8 = 2, kInt16 = 3, kUint16 = 4, kInt32 = 5, kUint32 = 6, kFloat32 = 7,
  kFloat64 = 8
};

// sensor_msgs/PointCloud2 with `data` = height * row_step bytes.
bool SerializePointCloud2(uint32_t seq, int64_t stamp_ns, const std::string& frame_id,
                          uint32_t height, uint32_t width, const std::vector<PointField>& fields,
                          uint32_t point_step, const std::string& data, bool is_dense,
                          std::string* out);

}  // namespace tiltcal::simulate

#endif  // TILTCAL_STAGES_SIMULATE_ROS1_MESSAGES_H_
