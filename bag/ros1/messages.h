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
#include "common/status.h"

namespace tiltcal::ros1 {

inline constexpr char kImuType[] = "sensor_msgs/Imu";
inline constexpr char kPointCloud2Type[] = "sensor_msgs/PointCloud2";

// std_msgs/Header: seq u32, stamp time, frame_id string.
struct Header {
  uint32_t seq = 0;
  RosTime stamp;
  std::string frame_id;
};

// sensor_msgs/Imu (md5 6a62c6daae103f4ff57a132d6f95cec2); 312 + |frame_id| bytes.
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

// sensor_msgs/PointCloud2 (md5 1158d486dd51d683ce2f1be655c3c181). `data`
// points into the serialized message (no copy): valid as long as it is.
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

// Decodes a whole message; trailing bytes after the last field are an error
// (the record holds another type). `cloud` may be reused between calls.
Status DecodeImu(const uint8_t* data, size_t size, ImuMessage* imu);
Status DecodePointCloud2(const uint8_t* data, size_t size, PointCloud2View* cloud);

}  // namespace tiltcal::ros1

#endif  // TILTCAL_BAG_ROS1_MESSAGES_H_
