// The binary PCD header against PCL's own writer, and a file of that header
// and packed points as PCL's reader reads it back.

#include "common/io/binary_pcd.h"

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>

#include "common/io/atomic_file.h"
#include "tests/testing/test_env.h"

namespace tiltcal {
namespace {

const std::vector<PcdField> kFields = {{"x", 4, 'F'},    {"y", 4, 'F'}, {"z", 4, 'F'},
                                       {"ring", 4, 'U'}, {"t", 4, 'I'}, {"label", 1, 'U'}};

TEST(BinaryPcd, HeaderIsTheOnePclWrites) {
  pcl::PCLPointCloud2 cloud;
  const std::vector<std::pair<uint32_t, uint8_t>> layout = {
      {0, pcl::PCLPointField::FLOAT32}, {4, pcl::PCLPointField::FLOAT32},
      {8, pcl::PCLPointField::FLOAT32}, {12, pcl::PCLPointField::UINT32},
      {16, pcl::PCLPointField::INT32},  {20, pcl::PCLPointField::UINT8}};
  for (size_t i = 0; i < kFields.size(); ++i) {
    pcl::PCLPointField field;
    field.name = kFields[i].name;
    field.offset = layout[i].first;
    field.datatype = layout[i].second;
    field.count = 1;
    cloud.fields.push_back(field);
  }
  cloud.width = 7;
  cloud.height = 1;
  cloud.point_step = 21;
  cloud.row_step = 21 * 7;
  cloud.data.assign(21 * 7, 0);
  pcl::PCDWriter writer;
  EXPECT_EQ(BinaryPcdHeader(kFields, 7),
            writer.generateHeaderBinary(cloud, Eigen::Vector4f::Zero(),
                                        Eigen::Quaternionf::Identity()) +
                "DATA binary\n");
}

TEST(BinaryPcd, PclReadsThePointsBack) {
  constexpr size_t kPoints = 5;
  constexpr size_t kStep = 21;
  std::string pcd = BinaryPcdHeader(kFields, kPoints);
  const size_t begin = pcd.size();
  pcd.resize(begin + kPoints * kStep);
  for (size_t i = 0; i < kPoints; ++i) {
    char* p = pcd.data() + begin + i * kStep;
    const float xyz[3] = {1.5f * i, -2.0f * i, 0.25f};
    const uint32_t ring = 10 + i;
    const int32_t t = -1000 * static_cast<int32_t>(i);
    std::memcpy(p, xyz, 12);
    std::memcpy(p + 12, &ring, 4);
    std::memcpy(p + 16, &t, 4);
    p[20] = static_cast<char>(i % 3);
  }
  testing::TempDir dir;
  const std::string path = dir.File("points.pcd");
  ASSERT_TRUE(WriteFileAtomically(path, pcd).ok());

  pcl::PCLPointCloud2 cloud;
  ASSERT_EQ(pcl::io::loadPCDFile(path, cloud), 0);
  ASSERT_EQ(cloud.width * cloud.height, kPoints);
  ASSERT_EQ(cloud.fields.size(), kFields.size());
  ASSERT_EQ(cloud.point_step, kStep);
  for (size_t f = 0; f < kFields.size(); ++f) EXPECT_EQ(cloud.fields[f].name, kFields[f].name);
  EXPECT_EQ(cloud.fields[3].datatype, pcl::PCLPointField::UINT32);
  EXPECT_EQ(cloud.fields[4].datatype, pcl::PCLPointField::INT32);
  EXPECT_EQ(cloud.fields[5].datatype, pcl::PCLPointField::UINT8);
  for (size_t i = 0; i < kPoints; ++i) {
    const uint8_t* p = cloud.data.data() + i * cloud.point_step;
    float x = 0, y = 0;
    uint32_t ring = 0;
    int32_t t = 0;
    std::memcpy(&x, p + cloud.fields[0].offset, 4);
    std::memcpy(&y, p + cloud.fields[1].offset, 4);
    std::memcpy(&ring, p + cloud.fields[3].offset, 4);
    std::memcpy(&t, p + cloud.fields[4].offset, 4);
    EXPECT_EQ(x, 1.5f * i);
    EXPECT_EQ(y, -2.0f * i);
    EXPECT_EQ(ring, 10 + i);
    EXPECT_EQ(t, -1000 * static_cast<int32_t>(i));
    EXPECT_EQ(p[cloud.fields[5].offset], i % 3);
  }
}

}  // namespace
}  // namespace tiltcal
