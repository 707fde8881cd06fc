// libFuzzer harness: any bytes as the text of a rosbag2 metadata.yaml. The
// parse must end without a crash or a sanitizer report.
#include <cstddef>
#include <cstdint>
#include <string>

#include "bag/ros2/rosbag2_metadata.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  (void)tiltcal::ros2::ParseRosbag2Metadata(
      std::string(reinterpret_cast<const char*>(data), size));
  return 0;
}
