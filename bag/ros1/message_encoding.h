#ifndef TILTCAL_BAG_ROS1_MESSAGE_ENCODING_H_
#define TILTCAL_BAG_ROS1_MESSAGE_ENCODING_H_

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "bag/ros1/messages.h"

namespace tiltcal::ros1 {

// Encoding of sensor_msgs/Imu, sensor_msgs/PointCloud2, the Livox CustomMsg
// and tf2_msgs/TFMessage into the ROS1 wire
// format (little-endian, no padding; string = u32 length + bytes; T[] = u32
// count + elements; T[N] = N elements), and the connection data a bag
// records for them. The decoding side is messages.h.

struct MessageType {
  const char* type;        // "sensor_msgs/Imu"
  const char* md5sum;      // ROS1 MD5 of the definition
  const char* definition;  // full text as in a bag's connection record
};
const MessageType& ImuMessageType();
const MessageType& PointCloud2MessageType();
// livox_ros_driver/CustomMsg (its CustomPoint as dependency).
const MessageType& LivoxCustomMsgMessageType();
// tf2_msgs/TFMessage (geometry_msgs/TransformStamped and its dependencies).
const MessageType& TfMessageType();

// std_msgs/Header: seq, stamp (u32 sec, u32 nsec), frame_id.
// Returns false when stamp_ns is not representable as ROS time.
bool AppendHeader(std::string* out, uint32_t seq, int64_t stamp_ns, const std::string& frame_id);

// sensor_msgs/Imu without orientation (orientation_covariance[0] = −1),
// with diagonal covariances of the given variances.
bool SerializeImu(uint32_t seq, int64_t stamp_ns, const std::string& frame_id,
                  const Eigen::Vector3d& angular_velocity_radps,
                  const Eigen::Vector3d& linear_acceleration_mps2, double gyro_variance,
                  double accel_variance, std::string* out);

// sensor_msgs/PointCloud2 with `data` = height * row_step bytes.
bool SerializePointCloud2(uint32_t seq, int64_t stamp_ns, const std::string& frame_id,
                          uint32_t height, uint32_t width, const std::vector<PointField>& fields,
                          uint32_t point_step, const std::string& data, bool is_dense,
                          std::string* out);

// livox_ros_driver/CustomMsg: header.stamp = timebase (as the driver), the
// points as given (point_num = points.size()).
bool SerializeLivoxCustomMsg(uint32_t seq, int64_t timebase_ns, const std::string& frame_id,
                             uint8_t lidar_id, const std::vector<LivoxPoint>& points,
                             std::string* out);

// tf2_msgs/TFMessage with the transforms as given.
void SerializeTfMessage(const TfMessage& msg, std::string* out);

}  // namespace tiltcal::ros1

#endif  // TILTCAL_BAG_ROS1_MESSAGE_ENCODING_H_
