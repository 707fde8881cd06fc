#ifndef TILTCAL_BAG_ROS2_MESSAGES_H_
#define TILTCAL_BAG_ROS2_MESSAGES_H_

// The ROS 2 layouts of sensor_msgs/msg/Imu and sensor_msgs/msg/PointCloud2,
// decoded from CDR (cdr_reader.h) into the structs the ROS 1 decoder fills
// (bag/sensor_messages.h). They differ from ROS 1 in the header only:
// std_msgs/Header has no seq, and its stamp is builtin_interfaces/Time
// (i32 sec, u32 nanosec). A negative sec (before 1970) is an error. Every
// read is bounds-checked; a message that runs short is an error naming the
// field (the caller adds file, topic and index).

#include <cstddef>
#include <cstdint>

#include "bag/sensor_messages.h"
#include "common/status.h"

namespace tiltcal::ros2 {

inline constexpr char kImuType[] = "sensor_msgs/msg/Imu";
inline constexpr char kPointCloud2Type[] = "sensor_msgs/msg/PointCloud2";

// The serialization of the messages in rosbag2 and MCAP ("cdr").
inline constexpr char kCdrEncoding[] = "cdr";

Status DecodeImu(const uint8_t* data, size_t size, bag::ImuMessage* imu);
// `cloud->data` points into `data`. `cloud` may be reused between calls.
Status DecodePointCloud2(const uint8_t* data, size_t size, bag::PointCloud2View* cloud);

}  // namespace tiltcal::ros2

#endif  // TILTCAL_BAG_ROS2_MESSAGES_H_
