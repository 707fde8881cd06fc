// libFuzzer harness: any bytes as an MCAP file. Opens it (summary or data
// section scan), reads every message in log-time order (chunks stored, lz4
// or zstd, through the reader's chunk cache) and decodes the IMU and
// PointCloud2 messages. Every outcome must be a Status, never a crash, a
// sanitizer report or unbounded work.
#include <cstddef>
#include <cstdint>

#include "bag/mcap/mcap_reader.h"
#include "bag/ros2/messages.h"
#include "fuzz/fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  tiltcal::fuzz::FuzzInputFile file(data, size);
  if (!file.ok()) return 0;
  tiltcal::mcap::McapReader reader;
  if (!reader.Open(file.path()).ok()) return 0;
  tiltcal::bag::ImuMessage imu;
  tiltcal::bag::PointCloud2View cloud;
  (void)reader.ReadMessages({}, [&](const tiltcal::bag::Message& m) {
    if (m.encoding != tiltcal::bag::Encoding::kCdr) return tiltcal::Status::Ok();
    if (reader.TopicType(*m.topic) == tiltcal::ros2::kImuType) {
      (void)tiltcal::ros2::DecodeImu(m.data, m.size, &imu);
    } else {
      (void)tiltcal::ros2::DecodePointCloud2(m.data, m.size, &cloud);
    }
    return tiltcal::Status::Ok();
  });
  return 0;
}
