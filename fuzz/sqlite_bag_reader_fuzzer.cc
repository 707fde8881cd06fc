// libFuzzer harness: any bytes as a rosbag2 .db3 file (libsqlite3 opens it
// read-only and immutable; a named file in /dev/shm, fuzz_input_file.h). Opens it (topics, counts, time range), reads
// every message in record-time order and decodes the IMU and PointCloud2
// messages. Every outcome must be a Status, never a crash or a sanitizer
// report in the reader.
#include <cstddef>
#include <cstdint>

#include "bag/ros2/messages.h"
#include "bag/ros2/sqlite_bag_reader.h"
#include "fuzz/fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  tiltcal::fuzz::FuzzInputNamedFile file(data, size, ".db3");
  if (!file.ok()) return 0;
  tiltcal::ros2::SqliteBagReader reader;
  if (!reader.Open(file.path()).ok()) return 0;
  tiltcal::bag::ImuMessage imu;
  tiltcal::bag::PointCloud2View cloud;
  (void)reader.ReadMessages({}, [&](const tiltcal::bag::Message& m) {
    if (reader.TopicType(*m.topic) == tiltcal::ros2::kImuType) {
      (void)tiltcal::ros2::DecodeImu(m.data, m.size, &imu);
    } else {
      (void)tiltcal::ros2::DecodePointCloud2(m.data, m.size, &cloud);
    }
    return tiltcal::Status::Ok();
  });
  return 0;
}
