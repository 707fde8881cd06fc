// libFuzzer harness: any bytes as a CDR-serialized ROS 2 message, decoded as
// sensor_msgs/msg/Imu and as sensor_msgs/msg/PointCloud2. Every outcome must
// be a Status; a decoded cloud's data must lie inside the input.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "bag/ros2/messages.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  tiltcal::bag::ImuMessage imu;
  (void)tiltcal::ros2::DecodeImu(data, size, &imu);
  tiltcal::bag::PointCloud2View cloud;
  if (tiltcal::ros2::DecodePointCloud2(data, size, &cloud).ok()) {
    const bool inside = cloud.data_size == 0 ||
                        (cloud.data >= data && cloud.data_size <= size &&
                         static_cast<size_t>(cloud.data - data) <= size - cloud.data_size);
    if (!inside) std::abort();  // a view past the message
  }
  return 0;
}
