#ifndef TILTCAL_BAG_ROS2_MESSAGES_H_
#define TILTCAL_BAG_ROS2_MESSAGES_H_

// The ROS 2 layouts of sensor_msgs/msg/Imu, sensor_msgs/msg/PointCloud2 and
// the Livox CustomMsg,
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
// Livox CustomMsg of livox_ros_driver2 and of livox_ros2_driver (livox_interfaces).
inline constexpr char kLivox2CustomMsgType[] = "livox_ros_driver2/msg/CustomMsg";
inline constexpr char kLivoxInterfacesCustomMsgType[] = "livox_interfaces/msg/CustomMsg";

inline constexpr char kTfMessageType[] = "tf2_msgs/msg/TFMessage";

// The serialization of the messages in rosbag2 and MCAP ("cdr").
inline constexpr char kCdrEncoding[] = "cdr";

Status DecodeImu(const uint8_t* data, size_t size, bag::ImuMessage* imu);
// `cloud->data` points into `data`. `cloud` may be reused between calls.
Status DecodePointCloud2(const uint8_t* data, size_t size, bag::PointCloud2View* cloud);
// Livox CustomMsg (fields as bag::LivoxCustomMessage; in CDR timebase is
// 8-byte aligned and every CustomPoint starts 4-byte aligned). point_num
// differing from the array's length is an error. `msg->points` may be reused.
Status DecodeLivoxCustomMsg(const uint8_t* data, size_t size, bag::LivoxCustomMessage* msg);

// tf2_msgs/msg/TFMessage: a sequence of geometry_msgs/msg/TransformStamped
// (header, string child_frame_id, f64 translation x y z, f64 rotation
// x y z w; the doubles 8-byte aligned). `msg->transforms` may be reused.
Status DecodeTfMessage(const uint8_t* data, size_t size, bag::TfMessage* msg);

}  // namespace tiltcal::ros2

#endif  // TILTCAL_BAG_ROS2_MESSAGES_H_
