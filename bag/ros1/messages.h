#ifndef TILTCAL_BAG_ROS1_MESSAGES_H_
#define TILTCAL_BAG_ROS1_MESSAGES_H_

// The layouts of sensor_msgs/Imu, sensor_msgs/PointCloud2 and PointField,
// and their decoding from the ROS1 wire format: little-endian, no padding,
// string = u32 length + bytes, T[] = u32 count + elements, T[N] = N
// elements, time = u32 sec + u32 nsec. Encoding: message_encoding.h.
// Every read is bounds-checked; a message that runs past its record is an
// error saying which field did (the caller adds file, topic and index).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "bag/ros1/format.h"
#include "bag/sensor_messages.h"
#include "common/status.h"

namespace tiltcal::ros1 {

inline constexpr char kImuType[] = "sensor_msgs/Imu";
inline constexpr char kPointCloud2Type[] = "sensor_msgs/PointCloud2";
// Livox CustomMsg of livox_ros_driver and of livox_ros_driver2 built for ROS 1.
inline constexpr char kLivoxCustomMsgType[] = "livox_ros_driver/CustomMsg";
inline constexpr char kLivox2CustomMsgType[] = "livox_ros_driver2/CustomMsg";
// The messages of /tf_static (tf2) and of the older tf package: one layout.
inline constexpr char kTfMessageType[] = "tf2_msgs/TFMessage";
inline constexpr char kTfLegacyMessageType[] = "tf/tfMessage";

// The message structs are shared with ROS 2 (bag/sensor_messages.h).
using bag::Header;
using bag::LivoxCustomMessage;
using bag::LivoxPoint;
using bag::ImuMessage;
using bag::TfMessage;
using bag::TransformStamped;
using bag::PointCloud2View;
using bag::PointField;
using bag::PointFieldType;
using bag::PointFieldTypeName;
using bag::PointFieldTypeSize;
using bag::kFloat32;
using bag::kFloat64;
using bag::kInt16;
using bag::kInt32;
using bag::kInt8;
using bag::kUint16;
using bag::kUint32;
using bag::kUint8;

// sensor_msgs/Imu (md5 6a62c6daae103f4ff57a132d6f95cec2) is 312 + |frame_id|
// bytes; sensor_msgs/PointCloud2 has md5 1158d486dd51d683ce2f1be655c3c181.
// Decodes a whole message; trailing bytes after the last field are an error
// (the record holds another type). `cloud` may be reused between calls.
Status DecodeImu(const uint8_t* data, size_t size, ImuMessage* imu);
Status DecodePointCloud2(const uint8_t* data, size_t size, PointCloud2View* cloud);
// Livox CustomMsg: header, u64 timebase, u32 point_num, u8 lidar_id,
// u8[3] rsvd, CustomPoint[] (19 bytes each: u32 offset_time, f32 x y z,
// u8 reflectivity tag line). point_num differing from the array's length is
// an error. `msg->points` may be reused between calls.
Status DecodeLivoxCustomMsg(const uint8_t* data, size_t size, LivoxCustomMessage* msg);

// tf2_msgs/TFMessage (md5 94810edda583a504dfda3829e70d7eec): u32 count,
// then per geometry_msgs/TransformStamped: header, string child_frame_id,
// f64 translation x y z, f64 rotation x y z w. `msg->transforms` may be
// reused between calls.
Status DecodeTfMessage(const uint8_t* data, size_t size, TfMessage* msg);

}  // namespace tiltcal::ros1

#endif  // TILTCAL_BAG_ROS1_MESSAGES_H_
