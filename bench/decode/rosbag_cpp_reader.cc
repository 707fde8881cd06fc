// Anchor of the decode benchmark: reads a ROS1 bag with the C++ rosbag library
// of ros_comm (Debian librosbag-storage-dev) the way a ROS user would —
// rosbag::View over all messages in time order, MessageInstance::instantiate
// into sensor_msgs::PointCloud2 / sensor_msgs::Imu — and touches every point's
// x, y, z (FLOAT32, metres) and time (FLOAT32, s relative to header.stamp),
// summing them so the compiler cannot drop the work. Field offsets come from
// the cloud's PointField table (the Velodyne layout has `time` at the
// unaligned offset 18), values are read with memcpy.
//
// Usage: rosbag_cpp_reader BAG
// Prints one line: messages, clouds, points, imu messages, checksums, wall s.
// Not part of the project build: see bench/decode/CMakeLists.txt.

#include <chrono>
#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/PointField.h>

namespace {

// Byte offset of FLOAT32 field `name`, or -1.
int Float32FieldOffset(const sensor_msgs::PointCloud2& cloud, const char* name) {
  for (const sensor_msgs::PointField& field : cloud.fields) {
    if (field.name == name && field.datatype == sensor_msgs::PointField::FLOAT32) {
      return static_cast<int>(field.offset);
    }
  }
  return -1;
}

inline float LoadFloat(const uint8_t* p) {
  float value;
  std::memcpy(&value, p, sizeof(value));
  return value;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s BAG\n", argv[0]);
    return 2;
  }
  const auto start = std::chrono::steady_clock::now();
  uint64_t num_messages = 0, num_clouds = 0, num_points = 0, num_imu = 0;
  double sum_xyz = 0.0, sum_time_s = 0.0, sum_imu = 0.0;
  try {
    rosbag::Bag bag;
    bag.open(argv[1], rosbag::bagmode::Read);
    rosbag::View view(bag);  // all connections, ordered by record time
    for (const rosbag::MessageInstance& message : view) {
      ++num_messages;
      if (sensor_msgs::PointCloud2::ConstPtr cloud =
              message.instantiate<sensor_msgs::PointCloud2>()) {
        const int ox = Float32FieldOffset(*cloud, "x");
        const int oy = Float32FieldOffset(*cloud, "y");
        const int oz = Float32FieldOffset(*cloud, "z");
        const int ot = Float32FieldOffset(*cloud, "time");
        if (ox < 0 || oy < 0 || oz < 0 || ot < 0 || cloud->is_bigendian) {
          std::fprintf(stderr, "%s: cloud %" PRIu64 " lacks FLOAT32 x, y, z, time\n", argv[1],
                       num_clouds);
          return 1;
        }
        const uint32_t step = cloud->point_step;
        if (static_cast<uint64_t>(cloud->row_step) * cloud->height > cloud->data.size() ||
            static_cast<uint64_t>(step) * cloud->width > cloud->row_step) {
          std::fprintf(stderr, "%s: cloud %" PRIu64 ": data shorter than its size\n", argv[1],
                       num_clouds);
          return 1;
        }
        for (uint32_t row = 0; row < cloud->height; ++row) {
          const uint8_t* p = cloud->data.data() + static_cast<size_t>(row) * cloud->row_step;
          for (uint32_t col = 0; col < cloud->width; ++col, p += step) {
            sum_xyz += static_cast<double>(LoadFloat(p + ox)) + LoadFloat(p + oy) + LoadFloat(p + oz);
            sum_time_s += LoadFloat(p + ot);
          }
        }
        num_points += static_cast<uint64_t>(cloud->width) * cloud->height;
        ++num_clouds;
      } else if (sensor_msgs::Imu::ConstPtr imu = message.instantiate<sensor_msgs::Imu>()) {
        sum_imu += imu->angular_velocity.x + imu->angular_velocity.y + imu->angular_velocity.z +
                   imu->linear_acceleration.x + imu->linear_acceleration.y +
                   imu->linear_acceleration.z;
        ++num_imu;
      }
    }
    bag.close();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", argv[1], e.what());
    return 1;
  }
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("rosbag_cpp_reader: messages=%" PRIu64 " clouds=%" PRIu64 " points=%" PRIu64
              " imu=%" PRIu64 " sum_xyz=%.6e sum_time_s=%.6e sum_imu=%.6e wall_s=%.3f\n",
              num_messages, num_clouds, num_points, num_imu, sum_xyz, sum_time_s, sum_imu,
              wall_s);
  return 0;
}
