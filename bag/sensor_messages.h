#ifndef TILTCAL_BAG_SENSOR_MESSAGES_H_
#define TILTCAL_BAG_SENSOR_MESSAGES_H_

// The in-memory form of the sensor messages decode reads, whatever the bag
// format: std_msgs/Header, sensor_msgs/Imu, sensor_msgs/PointCloud2 and
// PointField, the Livox CustomMsg and tf2_msgs/TFMessage. ROS 1
// (bag/ros1/messages.h, the ROS 1 wire format) and ROS 2
// (bag/ros2/messages.h, CDR) decode into these same structs, so the decode
// stage's sinks do not know which format a message came from.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace tiltcal::bag {

// A stamp: seconds and nanoseconds since the epoch. ROS 1 time is u32 sec +
// u32 nsec; ROS 2 builtin_interfaces/Time is i32 sec + u32 nanosec, and its
// decoder rejects negative seconds, so both fit here.
struct RosTime {
  uint32_t sec = 0;
  uint32_t nsec = 0;
};
// sec * 1e9 + nsec. nsec >= 1e9 (not normalized) is accepted as it adds up.
inline int64_t RosTimeToNs(RosTime t) {
  return static_cast<int64_t>(t.sec) * 1000000000 + static_cast<int64_t>(t.nsec);
}

// std_msgs/Header. `seq` exists in ROS 1 only (0 from ROS 2).
struct Header {
  uint32_t seq = 0;
  RosTime stamp;
  std::string frame_id;
};

// sensor_msgs/Imu.
struct ImuMessage {
  Header header;
  double orientation[4] = {};  // x, y, z, w
  double orientation_covariance[9] = {};
  double angular_velocity[3] = {};  // rad/s
  double angular_velocity_covariance[9] = {};
  double linear_acceleration[3] = {};  // m/s^2
  double linear_acceleration_covariance[9] = {};
};

// sensor_msgs/PointField datatypes.
enum PointFieldType : uint8_t {
  kInt8 = 1,
  kUint8 = 2,
  kInt16 = 3,
  kUint16 = 4,
  kInt32 = 5,
  kUint32 = 6,
  kFloat32 = 7,
  kFloat64 = 8,
};
// Bytes of one value of `datatype`; 0 for an unknown type.
size_t PointFieldTypeSize(uint8_t datatype);
// "FLOAT32", ...; "type N" for unknown codes.
std::string PointFieldTypeName(uint8_t datatype);

struct PointField {
  std::string name;
  uint32_t offset = 0;
  uint8_t datatype = 0;
  uint32_t count = 0;
};

// sensor_msgs/PointCloud2. `data` points into the serialized message (no
// copy): valid as long as it is.
struct PointCloud2View {
  Header header;
  uint32_t height = 0;
  uint32_t width = 0;
  std::vector<PointField> fields;
  bool is_bigendian = false;
  uint32_t point_step = 0;
  uint32_t row_step = 0;
  const uint8_t* data = nullptr;
  uint32_t data_size = 0;
  bool is_dense = false;
};


// One point of a Livox CustomMsg (livox_ros_driver/CustomPoint, identical in
// livox_ros_driver2 and livox_interfaces).
struct LivoxPoint {
  uint32_t offset_time = 0;  // ns after the message's timebase
  float x = 0, y = 0, z = 0;  // m, LiDAR frame
  uint8_t reflectivity = 0;   // 0..255
  // Livox point tag (Livox SDK, "tag information"): bits 0-1 noise judged
  // from the spatial position (00 none, 01 high, 10 moderate, 11 low
  // confidence that the point is noise: rain, fog, dust), bits 2-3 noise
  // judged from the intensity (same coding), bits 4-5 the return number,
  // bits 6-7 reserved.
  uint8_t tag = 0;
  uint8_t line = 0;  // laser (line) number: 0-5 Avia, 0-3 Mid-360
};

// livox_ros_driver/CustomMsg, livox_ros_driver2 CustomMsg (ROS 1 and ROS 2),
// livox_interfaces/msg/CustomMsg: the same fields in the same order.
struct LivoxCustomMessage {
  Header header;
  uint64_t timebase = 0;   // ns, the time of the first point (sensor or synchronised clock)
  uint32_t point_num = 0;  // the driver's count; the decoders require it to equal points.size()
  uint8_t lidar_id = 0;
  uint8_t rsvd[3] = {};
  std::vector<LivoxPoint> points;
};

// geometry_msgs/TransformStamped: the pose of frame `child_frame_id` in
// frame `header.frame_id` (the parent): p_parent = R(rotation) p_child +
// translation, translation in metres resolved in the parent.
struct TransformStamped {
  Header header;
  std::string child_frame_id;
  double translation[3] = {};        // x, y, z
  double rotation[4] = {0, 0, 0, 1};  // x, y, z, w (as on the wire)
};

// tf2_msgs/TFMessage (ROS 1 also tf/tfMessage, the same layout): the
// messages of /tf and /tf_static.
struct TfMessage {
  std::vector<TransformStamped> transforms;
};
// The topic of the static transforms, as tf2 names it.
inline constexpr char kTfStaticTopic[] = "/tf_static";

}  // namespace tiltcal::bag

#endif  // TILTCAL_BAG_SENSOR_MESSAGES_H_
