#ifndef TILTCAL_TESTS_BAG_ROS1_ROSBAG_ORACLE_H_
#define TILTCAL_TESTS_BAG_ROS1_ROSBAG_ORACLE_H_

#include <cstdint>
#include <string>
#include <vector>

namespace tiltcal::ros1::testing {

// What the real ROS library (tests/oracle/read_sim_bag.py, run with Debian's
// /usr/bin/python3) found in a bag.
struct DumpedField {
  std::string name;
  uint32_t offset = 0, datatype = 0, count = 0;
};
struct DumpedMessage {
  std::string topic, type, frame_id;
  int64_t record_ns = 0, stamp_ns = 0;
  uint32_t seq = 0, crc32 = 0, size = 0;
  // sensor_msgs/Imu
  double imu[9] = {};  // wx wy wz ax ay az gyro_var accel_var orientation_cov0
  // sensor_msgs/PointCloud2
  int cloud_index = -1;
  uint32_t height = 0, width = 0, point_step = 0, row_step = 0;
  bool is_dense = false, is_bigendian = false;
  std::vector<DumpedField> fields;
  std::vector<std::vector<double>> points;  // only for the requested clouds
};
struct BagDump {
  std::string compression;
  std::vector<DumpedMessage> messages;
  std::vector<const DumpedMessage*> Topic(const std::string& topic) const;
};

// Runs the oracle on `bag` (writes `dump_path`), dumping the points of the
// clouds in `cloud_indices`, and parses its output. Returns false with the
// oracle's output in *error on failure.
bool DumpBagWithRosbag(const std::string& bag, const std::string& dump_path,
                       const std::vector<int>& cloud_indices, BagDump* dump, std::string* error);

// CRC-32 (IEEE 802.3, as zlib.crc32) of bytes.
uint32_t Crc32(const void* data, size_t size);

}  // namespace tiltcal::ros1::testing

#endif  // TILTCAL_TESTS_BAG_ROS1_ROSBAG_ORACLE_H_
