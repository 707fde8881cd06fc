// The specialised conversion loops against the generic one: both must give
// byte-identical Scans (serialised bytes compared) on the common driver
// layouts with awkward values (NaN, Inf, zero range, times on half-ns
// rounding ties, out-of-range times) and on the clouds of the fixture bags.
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bag/ros1/bag_reader.h"
#include "bag/ros1/messages.h"
#include "stages/decode/point_cloud_conversion.h"
#include "tests/testing/test_env.h"

namespace tiltcal {
namespace {

using ros1::PointCloud2View;
using ros1::PointField;

struct Converted {
  Status status = Status::Ok();
  std::string bytes;
};

Converted ConvertWith(const PointCloud2View& cloud, bool fast, double min_range_m) {
  PointConversionOptions options;
  options.min_range_m = min_range_m;
  options.allow_fast_path = fast;
  proto::Scan scan;
  Converted out;
  out.status = ConvertPointCloud2ToScan(cloud, options, &scan);
  if (out.status.ok()) out.bytes = scan.SerializeAsString();
  return out;
}

// Fast and generic loop agree on status, error text and output bytes.
void ExpectSameOutput(const PointCloud2View& cloud, const std::string& what,
                      double min_range_m = 0.0) {
  const Converted generic = ConvertWith(cloud, false, min_range_m);
  const Converted fast = ConvertWith(cloud, true, min_range_m);
  ASSERT_EQ(generic.status.ok(), fast.status.ok()) << what << ": " << generic.status.message()
                                                   << " / " << fast.status.message();
  EXPECT_EQ(generic.status.message(), fast.status.message()) << what;
  EXPECT_TRUE(generic.bytes == fast.bytes) << what << ": outputs differ";
}

struct Layout {
  std::string name;
  uint32_t point_step;
  std::vector<PointField> fields;
};

// Real driver layouts (ros-drivers/velodyne, ouster-ros, hesai) and variants.
std::vector<Layout> Layouts() {
  using ros1::kFloat32;
  using ros1::kFloat64;
  using ros1::kUint16;
  using ros1::kUint32;
  using ros1::kUint8;
  return {
      {"velodyne22", 22, {{"x", 0, kFloat32, 1}, {"y", 4, kFloat32, 1}, {"z", 8, kFloat32, 1},
                          {"intensity", 12, kFloat32, 1}, {"ring", 16, kUint16, 1},
                          {"time", 18, kFloat32, 1}}},
      {"ouster48", 48, {{"x", 0, kFloat32, 1}, {"y", 4, kFloat32, 1}, {"z", 8, kFloat32, 1},
                        {"intensity", 16, kFloat32, 1}, {"t", 20, kUint32, 1},
                        {"reflectivity", 24, kUint16, 1}, {"ring", 26, kUint8, 1},
                        {"ambient", 28, kUint16, 1}, {"range", 32, kUint32, 1}}},
      {"hesai", 32, {{"x", 0, kFloat32, 1}, {"y", 4, kFloat32, 1}, {"z", 8, kFloat32, 1},
                     {"intensity", 12, kFloat32, 1}, {"timestamp", 16, kFloat64, 1},
                     {"ring", 24, kUint16, 1}}},
      {"xyz_uint8_intensity_no_ring_no_time", 16,
       {{"x", 0, kFloat32, 1}, {"y", 4, kFloat32, 1}, {"z", 8, kFloat32, 1},
        {"intensity", 12, kUint8, 1}}},
      {"xyz_only", 12, {{"x", 0, kFloat32, 1}, {"y", 4, kFloat32, 1}, {"z", 8, kFloat32, 1}}},
      {"uint16_intensity_uint8_ring_time", 20,
       {{"x", 0, kFloat32, 1}, {"y", 4, kFloat32, 1}, {"z", 8, kFloat32, 1},
        {"intensity", 12, kUint16, 1}, {"ring", 14, kUint8, 1}, {"time", 15, kFloat32, 1}}},
  };
}

// A cloud of `layout` with random bytes in every field, then plausible values
// with the awkward cases mixed in.
std::string FillCloud(const Layout& layout, uint32_t width, uint32_t height, uint32_t row_step,
                      std::mt19937* rng, bool huge_t, PointCloud2View* cloud) {
  std::string data(static_cast<size_t>(row_step) * height, '\0');
  for (auto& ch : data) ch = static_cast<char>((*rng)());
  std::uniform_real_distribution<float> coord(-50.0f, 50.0f);
  std::uniform_real_distribution<float> rel_time(-0.1f, 0.0f);
  const float kNan = std::numeric_limits<float>::quiet_NaN();
  const float kInf = std::numeric_limits<float>::infinity();
  for (uint32_t r = 0; r < height; ++r) {
    for (uint32_t c = 0; c < width; ++c) {
      char* p = &data[static_cast<size_t>(r) * row_step + static_cast<size_t>(c) * layout.point_step];
      const uint32_t kind = (*rng)() % 16;
      for (const PointField& f : layout.fields) {
        if (f.name == "x" || f.name == "y" || f.name == "z") {
          float v = coord(*rng);
          if (kind == 1 && f.name == "y") v = kNan;
          if (kind == 2 && f.name == "z") v = -kInf;
          if (kind == 3) v = 0.0f;                 // zero range
          if (kind == 4) v = 1e-3f;                // below min_range_m
          std::memcpy(p + f.offset, &v, 4);
        } else if (f.name == "time" && f.datatype == ros1::kFloat32) {
          float v = rel_time(*rng);
          // Exact half-ns ties, a NaN time and a time beyond 1e3 s.
          if (kind == 5) v = -0.0000000005f * 3.0f;
          if (kind == 6) v = 2.5e-9f;
          if (kind == 7) v = kNan;
          if (kind == 8) v = 2e3f;
          if (kind == 9) v = -0.0f;
          std::memcpy(p + f.offset, &v, 4);
        } else if (f.name == "t" && f.datatype == ros1::kUint32) {
          uint32_t v = (*rng)() % 100000000u;
          if (huge_t && r == height - 1 && c == width - 1) v = 0x80000000u;  // > int32
          std::memcpy(p + f.offset, &v, 4);
        } else if (f.name == "timestamp") {
          const double v = 1700000000.5 - 0.05 * ((*rng)() % 1000) / 1000.0;
          std::memcpy(p + f.offset, &v, 8);
        } else if (f.name == "intensity" && f.datatype == ros1::kFloat32) {
          float v = static_cast<float>((*rng)() % 25600) / 100.0f;
          if (kind == 10) v = kNan;
          std::memcpy(p + f.offset, &v, 4);
        }
      }
    }
  }
  cloud->fields = layout.fields;
  cloud->point_step = layout.point_step;
  cloud->width = width;
  cloud->height = height;
  cloud->row_step = row_step;
  cloud->is_bigendian = false;
  cloud->header.stamp = ros1::RosTime{1700000000, 500000000};
  cloud->header.frame_id = "lidar";
  return data;
}

TEST(PointCloudFastPath, SameBytesAsGenericLoopOnDriverLayouts) {
  std::mt19937 rng(42);
  for (const Layout& layout : Layouts()) {
    for (uint32_t height : {1u, 3u}) {
      for (double min_range_m : {0.0, 0.5}) {
        const uint32_t width = 2000;
        const uint32_t row_step = layout.point_step * width + (height > 1 ? 7 : 0);
        PointCloud2View cloud;
        const std::string data = FillCloud(layout, width, height, row_step, &rng, false, &cloud);
        cloud.data = reinterpret_cast<const uint8_t*>(data.data());
        cloud.data_size = static_cast<uint32_t>(data.size());
        ExpectSameOutput(cloud, layout.name + " height " + std::to_string(height), min_range_m);
      }
    }
  }
}

TEST(PointCloudFastPath, SameErrorWhenOusterTimeLeavesInt32) {
  std::mt19937 rng(7);
  const Layout ouster = Layouts()[1];
  PointCloud2View cloud;
  const std::string data = FillCloud(ouster, 500, 1, 500 * 48, &rng, true, &cloud);
  cloud.data = reinterpret_cast<const uint8_t*>(data.data());
  cloud.data_size = static_cast<uint32_t>(data.size());
  ExpectSameOutput(cloud, "ouster with t = 2^31");
  EXPECT_FALSE(ConvertWith(cloud, true, 0.0).status.ok());
}

// Velodyne times on and next to rounding ties round half away from zero like
// std::llround.
TEST(PointCloudFastPath, VelodyneTimesOnEveryFloatNearTies) {
  const Layout velodyne = Layouts()[0];
  std::vector<float> times;
  for (int k = -2000; k <= 2000; ++k) {
    const float tie = static_cast<float>((k + 0.5) * 1e-9);
    times.push_back(tie);
    times.push_back(std::nextafter(tie, 1.0f));
    times.push_back(std::nextafter(tie, -1.0f));
  }
  // m / 1024 s for odd m is m * 976562.5 ns: exact ties in double.
  for (int m = -101; m <= 101; m += 2) times.push_back(static_cast<float>(m) / 1024.0f);
  for (float t = -0.1f; t < 0.0f; t += 1.37e-5f) times.push_back(t);
  const uint32_t width = static_cast<uint32_t>(times.size());
  std::string data(static_cast<size_t>(width) * 22, '\0');
  for (uint32_t c = 0; c < width; ++c) {
    const float xyz[3] = {1.0f, 2.0f, 3.0f};
    std::memcpy(&data[c * 22], xyz, 12);
    std::memcpy(&data[c * 22 + 18], &times[c], 4);
  }
  PointCloud2View cloud;
  cloud.fields = velodyne.fields;
  cloud.point_step = 22;
  cloud.width = width;
  cloud.height = 1;
  cloud.row_step = width * 22;
  cloud.header.stamp = ros1::RosTime{1700000000, 0};
  cloud.data = reinterpret_cast<const uint8_t*>(data.data());
  cloud.data_size = static_cast<uint32_t>(data.size());
  ExpectSameOutput(cloud, "velodyne ties");
  PointConversionOptions options;
  proto::Scan scan;
  ASSERT_TRUE(ConvertPointCloud2ToScan(cloud, options, &scan).ok());
  ASSERT_EQ(scan.time_offset_ns_size(), static_cast<int>(width));
  for (uint32_t c = 0; c < width; ++c) {
    ASSERT_EQ(scan.time_offset_ns(c), std::llround(static_cast<double>(times[c]) * 1e9)) << c;
  }
}

// Every PointCloud2 of the fixture bags.
TEST(PointCloudFastPath, SameBytesOnFixtureBagClouds) {
  const std::string dir = testing::SharedFixturesDir();
  if (dir.empty()) GTEST_SKIP() << "../shared/fixtures absent; skipping the fixture clouds";
  int clouds = 0;
  for (const char* name : {"embag_test_lz4_pointcloud2.bag", "ros_numpy_test_pointcloud2.bag",
                           "rosbagjs_example-lz4.bag", "rosbagjs_example-bz2.bag"}) {
    const std::string path = dir + "/bags/ros1/" + name;
    if (!testing::FileExists(path)) continue;
    ros1::BagReader reader;
    ASSERT_TRUE(reader.Open(path).ok()) << path;
    ros1::ReadOptions options;
    options.topics = reader.TopicsOfType("sensor_msgs/PointCloud2");
    if (options.topics.empty()) continue;
    const Status status = reader.ReadMessages(options, [&](const ros1::MessageView& m) {
      ros1::PointCloud2View cloud;
      if (!ros1::DecodePointCloud2(m.data, m.size, &cloud).ok()) return Status::Ok();
      ExpectSameOutput(cloud, std::string(name) + " message " + std::to_string(m.sequence));
      ++clouds;
      return Status::Ok();
    });
    EXPECT_TRUE(status.ok()) << status.message();
  }
  if (clouds == 0) GTEST_SKIP() << "no PointCloud2 in the fixture bags";
}

}  // namespace
}  // namespace tiltcal
