// Anchor of the decode benchmark: reads a ROS1 bag with the C++ rosbag library
// of ros_comm (Debian librosbag-storage-dev) the way a ROS user would —
// rosbag::View over all messages in time order, MessageInstance::instantiate
// into sensor_msgs::PointCloud2 / sensor_msgs::Imu — and touches every point's
// x, y, z (FLOAT32, metres) and time (FLOAT32, s relative to header.stamp),
// summing them so the compiler cannot drop the work. Field offsets come from
// the cloud's PointField table (the Velodyne layout has `time` at the
// unaligned offset 18), values are read with memcpy.
//
// With --out=FILE it also writes what it reads, as a user's own extraction
// tool would: per cloud its stamp, point count and the columns x, y, z,
// intensity (float32), ring (uint16) and time offset (int32 ns, the float
// seconds rounded), per IMU message its stamp and six doubles, all to FILE
// through stdio (1 MiB buffer; no checksum, no fsync). That is the
// decoder's job without its checksums, atomic rename and durable write.
//
// Usage: rosbag_cpp_reader [--out=FILE] BAG
// Prints one line: messages, clouds, points, imu messages, checksums, wall s.
// Not part of the project build: see bench/decode/CMakeLists.txt.

#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/PointField.h>

namespace {

// Byte offset of field `name` of type `datatype`, or -1.
int FieldOffset(const sensor_msgs::PointCloud2& cloud, const char* name, uint8_t datatype) {
  for (const sensor_msgs::PointField& field : cloud.fields) {
    if (field.name == name && field.datatype == datatype) return static_cast<int>(field.offset);
  }
  return -1;
}

int Float32FieldOffset(const sensor_msgs::PointCloud2& cloud, const char* name) {
  return FieldOffset(cloud, name, sensor_msgs::PointField::FLOAT32);
}

// The columns of one cloud, written as x, y, z, intensity, ring, time.
struct Columns {
  std::vector<float> x, y, z, intensity;
  std::vector<uint16_t> ring;
  std::vector<int32_t> time_ns;
  void Resize(size_t n) {
    x.resize(n), y.resize(n), z.resize(n), intensity.resize(n), ring.resize(n), time_ns.resize(n);
  }
};

template <class T>
bool WriteAll(std::FILE* out, const T* data, size_t n) {
  return std::fwrite(data, sizeof(T), n, out) == n;
}

inline float LoadFloat(const uint8_t* p) {
  float value;
  std::memcpy(&value, p, sizeof(value));
  return value;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string out_flag = "--out=";
  std::string out_path;
  if (argc == 3 && std::string(argv[1]).rfind(out_flag, 0) == 0) {
    out_path = std::string(argv[1]).substr(out_flag.size());
    argv[1] = argv[2];
    argc = 2;
  }
  if (argc != 2 || argv[1][0] == '-') {
    std::fprintf(stderr, "usage: %s [--out=FILE] BAG\n", argv[0]);
    return 2;
  }
  std::FILE* out = nullptr;
  // Static: an early return leaves `out` open, and exit() flushes it after
  // main's locals are gone.
  static char out_buffer[1 << 20];
  if (!out_path.empty()) {
    out = std::fopen(out_path.c_str(), "wb");
    if (out == nullptr || std::setvbuf(out, out_buffer, _IOFBF, sizeof(out_buffer)) != 0) {
      std::fprintf(stderr, "%s: cannot open for writing\n", out_path.c_str());
      return 1;
    }
  }
  Columns columns;
  bool written = true;
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
        const size_t n = static_cast<size_t>(cloud->width) * cloud->height;
        if (out == nullptr) {
          for (uint32_t row = 0; row < cloud->height; ++row) {
            const uint8_t* p = cloud->data.data() + static_cast<size_t>(row) * cloud->row_step;
            for (uint32_t col = 0; col < cloud->width; ++col, p += step) {
              sum_xyz += static_cast<double>(LoadFloat(p + ox)) + LoadFloat(p + oy) + LoadFloat(p + oz);
              sum_time_s += LoadFloat(p + ot);
            }
          }
        } else {
          // One pass: the columns, and the sums from them.
          const int oi = Float32FieldOffset(*cloud, "intensity");
          const int oring = FieldOffset(*cloud, "ring", sensor_msgs::PointField::UINT16);
          if (oi < 0 || oring < 0) {
            std::fprintf(stderr, "%s: cloud %" PRIu64 " lacks FLOAT32 intensity, UINT16 ring\n",
                         argv[1], num_clouds);
            return 1;
          }
          columns.Resize(n);
          size_t j = 0;
          for (uint32_t row = 0; row < cloud->height; ++row) {
            const uint8_t* p = cloud->data.data() + static_cast<size_t>(row) * cloud->row_step;
            for (uint32_t col = 0; col < cloud->width; ++col, p += step, ++j) {
              columns.x[j] = LoadFloat(p + ox);
              columns.y[j] = LoadFloat(p + oy);
              columns.z[j] = LoadFloat(p + oz);
              columns.intensity[j] = LoadFloat(p + oi);
              std::memcpy(&columns.ring[j], p + oring, sizeof(uint16_t));
              const float time_s = LoadFloat(p + ot);
              columns.time_ns[j] = static_cast<int32_t>(std::llround(static_cast<double>(time_s) * 1e9));
              sum_xyz += static_cast<double>(columns.x[j]) + columns.y[j] + columns.z[j];
              sum_time_s += time_s;
            }
          }
          const uint32_t header[3] = {cloud->header.stamp.sec, cloud->header.stamp.nsec,
                                      static_cast<uint32_t>(n)};
          written = written && WriteAll(out, header, 3) && WriteAll(out, columns.x.data(), n) &&
                    WriteAll(out, columns.y.data(), n) && WriteAll(out, columns.z.data(), n) &&
                    WriteAll(out, columns.intensity.data(), n) &&
                    WriteAll(out, columns.ring.data(), n) && WriteAll(out, columns.time_ns.data(), n);
        }
        num_points += n;
        ++num_clouds;
      } else if (sensor_msgs::Imu::ConstPtr imu = message.instantiate<sensor_msgs::Imu>()) {
        sum_imu += imu->angular_velocity.x + imu->angular_velocity.y + imu->angular_velocity.z +
                   imu->linear_acceleration.x + imu->linear_acceleration.y +
                   imu->linear_acceleration.z;
        if (out != nullptr) {
          const uint32_t stamp[2] = {imu->header.stamp.sec, imu->header.stamp.nsec};
          const double values[6] = {imu->angular_velocity.x,    imu->angular_velocity.y,
                                    imu->angular_velocity.z,    imu->linear_acceleration.x,
                                    imu->linear_acceleration.y, imu->linear_acceleration.z};
          written = written && WriteAll(out, stamp, 2) && WriteAll(out, values, 6);
        }
        ++num_imu;
      }
    }
    bag.close();
    if (out != nullptr && (std::fclose(out) != 0 || !written)) {
      std::fprintf(stderr, "%s: write failed\n", out_path.c_str());
      return 1;
    }
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
