// libFuzzer harness: any bytes as a ROS 1 bag. Opens it (index or salvage
// scan), reads every message in time order and decodes the IMU and
// PointCloud2 messages. Every outcome must be a Status, never a crash, a
// sanitizer report or unbounded work.
#include <cstddef>
#include <cstdint>

#include "bag/ros1/bag_reader.h"
#include "bag/ros1/messages.h"
#include "fuzz/fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  tiltcal::fuzz::FuzzInputFile file(data, size);
  if (!file.ok()) return 0;
  tiltcal::ros1::BagReader reader;
  if (!reader.Open(file.path()).ok()) return 0;
  tiltcal::ros1::ReadOptions options;
  options.chunk_cache_size = 2;
  tiltcal::ros1::ImuMessage imu;
  tiltcal::ros1::PointCloud2View cloud;
  (void)reader.ReadMessages(options, [&](const tiltcal::ros1::MessageView& m) {
    if (m.connection->type == tiltcal::ros1::kImuType) {
      (void)tiltcal::ros1::DecodeImu(m.data, m.size, &imu);
    } else if (m.connection->type == tiltcal::ros1::kPointCloud2Type) {
      (void)tiltcal::ros1::DecodePointCloud2(m.data, m.size, &cloud);
    }
    return tiltcal::Status::Ok();
  });
  return 0;
}
