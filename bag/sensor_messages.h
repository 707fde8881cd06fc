#ifndef TILTCAL_BAG_SENSOR_MESSAGES_H_
#define TILTCAL_BAG_SENSOR_MESSAGES_H_

// The in-memory form of the sensor messages decode reads, whatever the bag
// format: std_msgs/Header, sensor_msgs/Imu, sensor_msgs/PointCloud2 and
// PointField. ROS 1 (bag/ros1/messages.h, the ROS 1 wire format) and ROS 2
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

}  // namespace tiltcal::bag

#endif  // TILTCAL_BAG_SENSOR_MESSAGES_H_
