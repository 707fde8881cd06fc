// tiltcal_ground as a program: synthetic IMU + scans written as our streams,
// the executable run on them, its outputs read back and compared with the
// ray-cast truth; bad inputs give one error line and no output.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/geometry/angles.h"
#include "common/io/atomic_file.h"
#include "common/io/eigen_proto.h"
#include "common/io/provenance.h"
#include "common/io/record_stream.h"
#include "common/io/text_proto.h"
#include "tests/stages/ground/ground_test_util.h"
#include "tests/testing/synthetic_lidar.h"
#include "tiltcal/proto/ground.pb.h"
#include "tiltcal/proto/imu.pb.h"
#include "tiltcal/proto/rig.pb.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal {
namespace {

using geometry::AngleBetweenDeg;
using testing::NormalOf;
using testing::RollPitchYaw;
using testing::SyntheticPose;
using testing::TempDir;

constexpr int kNumScans = 10;
constexpr int64_t kFirstStampNs = 1500000000LL;

Eigen::Matrix3d Exp(const Eigen::Vector3d& phi) {
  const double a = phi.norm();
  return a < 1e-15 ? Eigen::Matrix3d::Identity()
                   : Eigen::AngleAxisd(a, phi / a).toRotationMatrix();
}

struct Dataset {
  std::string imu, scans, rig, params;
  std::vector<SyntheticPose> poses;
};

// Static for 1 s (gyro bias only), then a constant LiDAR body rate; scans at
// 10 Hz from 1.5 s. C_bl is a small rotation; the rig's height prior comes
// from imu_height_m and the lever arm.
Dataset WriteDataset(const TempDir& dir, bool corrupt_scan, bool bad_imu_stamp) {
  Dataset data;
  data.imu = dir.File("imu.binpb");
  data.scans = dir.File("scans.binpb.lz4");
  data.rig = dir.File("rig.txtpb");
  data.params = testing::SourceDir() + "/stages/ground/default_params.txtpb";
  const Eigen::Matrix3d c_bl = RollPitchYaw(0.01, -0.02, 0.05);
  const Eigen::Vector3d omega_l(0.05, -0.04, 0.6), bias(0.003, -0.002, 0.004);
  const Eigen::Vector3d omega_b = c_bl * omega_l;
  const Eigen::Matrix3d r0 = RollPitchYaw(0.02, 0.03, 0.0);  // R_gl at t = 1 s

  proto::Rig rig;
  const Eigen::Quaterniond q(c_bl);
  *rig.mutable_imu_from_lidar()->mutable_rotation() = ToProto(q);
  rig.mutable_imu_from_lidar()->mutable_translation()->set_z(0.4);
  rig.set_imu_height_m(0.5);
  EXPECT_TRUE(WriteTextProto(data.rig, rig).ok());

  proto::Provenance provenance;
  provenance.set_producer("ground_cli_test");
  RecordWriter imu_writer;
  EXPECT_TRUE(imu_writer.Open(data.imu, "tiltcal.proto.ImuSample", provenance, false).ok());
  for (int64_t t = 0; t <= 3000000000LL; t += 2500000) {
    proto::ImuSample s;
    s.set_stamp_ns(bad_imu_stamp && t == 500000000LL ? 1000 : t);
    const Eigen::Vector3d w = (t < 1000000000LL ? Eigen::Vector3d::Zero() : omega_b) + bias;
    s.mutable_angular_velocity_radps()->set_x(w.x());
    s.mutable_angular_velocity_radps()->set_y(w.y());
    s.mutable_angular_velocity_radps()->set_z(w.z());
    s.mutable_linear_acceleration_mps2()->set_z(9.81);
    EXPECT_TRUE(imu_writer.Write(s).ok());
  }
  EXPECT_TRUE(imu_writer.Close().ok());

  RecordWriter scan_writer;
  EXPECT_TRUE(scan_writer.Open(data.scans, "tiltcal.proto.Scan", provenance, true).ok());
  for (int k = 0; k < kNumScans; ++k) {
    const int64_t stamp = kFirstStampNs + k * 100000000LL;
    SyntheticPose pose;
    pose.position_g = Eigen::Vector3d(0.3 * k, 0.0, 0.9);
    pose.g_from_lidar = r0 * Exp(omega_l * (1e-9 * stamp - 1.0));
    pose.omega_lidar_radps = omega_l;
    proto::Scan scan = testing::CastScan(testing::StreetScene(k), testing::SyntheticLidar::Vlp16(),
                                         pose, stamp, 20 + k);
    scan.set_index(k);
    if (corrupt_scan && k == 3) scan.mutable_z()->RemoveLast();
    EXPECT_TRUE(scan_writer.Write(scan).ok());
    data.poses.push_back(pose);
  }
  EXPECT_TRUE(scan_writer.Close().ok());
  return data;
}

// The command line of tiltcal_ground on `data`; without --params when
// `params` is empty.
std::string Command(const Dataset& data, const TempDir& dir, const std::string& params) {
  return testing::ToolPath("tiltcal_ground") + " --imu=" + data.imu + " --scans=" + data.scans +
         " --rig=" + data.rig + (params.empty() ? "" : " --params=" + params) + " --out_ground=" +
         dir.File("ground.binpb") + " --out_scans=" + dir.File("deskewed.binpb.lz4");
}

TEST(GroundCli, PlanesMatchTheTruthAndDeskewedScansAreWritten) {
  TempDir dir;
  const Dataset data = WriteDataset(dir, false, false);
  std::string output;
  ASSERT_EQ(testing::RunCommand(Command(data, dir, data.params), &output), 0) << output;
  EXPECT_NE(output.find("10 scans, 10 valid, 10 deskewed"), std::string::npos) << output;
  EXPECT_NE(output.find("static start: yes"), std::string::npos) << output;

  std::vector<proto::GroundPlane> planes;
  proto::StreamHeader header;
  const Status status =
      ReadAllRecords<proto::GroundPlane>(dir.File("ground.binpb"), &planes, &header);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(header.provenance().producer(), "tiltcal_ground");
  EXPECT_NE(header.provenance().params_txtpb().find("radius_first_ring_ratio"),
            std::string::npos);
  ASSERT_EQ(planes.size(), static_cast<size_t>(kNumScans));
  for (int k = 0; k < kNumScans; ++k) {
    const proto::GroundPlane& p = planes[k];
    EXPECT_TRUE(p.valid()) << k << ": " << p.reject_detail();
    EXPECT_TRUE(p.deskewed());
    EXPECT_TRUE(testing::NoNan(p));
    EXPECT_EQ(p.stamp_ns(), kFirstStampNs + k * 100000000LL);
    EXPECT_NEAR(p.height_prior_m(), 0.9, 0.01);  // 0.5 m + 0.4 m lever arm
    EXPECT_LT(AngleBetweenDeg(NormalOf(p), testing::TrueNormal(data.poses[k])), 0.1) << k;
    EXPECT_NEAR(p.height_m(), 0.9, 0.005) << k;
  }
  std::vector<proto::Scan> deskewed;
  ASSERT_TRUE(ReadAllRecords<proto::Scan>(dir.File("deskewed.binpb.lz4"), &deskewed).ok());
  ASSERT_EQ(deskewed.size(), static_cast<size_t>(kNumScans));
  for (const proto::Scan& scan : deskewed) EXPECT_TRUE(scan.deskewed());
}

// Splits a CSV line (no quoted fields in these tables).
std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> cells;
  size_t start = 0;
  for (;;) {
    const size_t comma = line.find(',', start);
    cells.push_back(line.substr(start, comma - start));
    if (comma == std::string::npos) return cells;
    start = comma + 1;
  }
}

TEST(GroundCli, InspectCsvAndPcdShowThePlanesAndLabels) {
  TempDir dir;
  const Dataset data = WriteDataset(dir, false, false);
  std::string output;
  ASSERT_EQ(testing::RunCommand(Command(data, dir, data.params), &output), 0) << output;
  std::vector<proto::GroundPlane> planes;
  ASSERT_TRUE(ReadAllRecords<proto::GroundPlane>(dir.File("ground.binpb"), &planes).ok());
  const std::string inspect = testing::ToolPath("tiltcal_inspect");

  // CSV: a header of dotted field paths (normal_in_lidar.z), one row per
  // plane, values as written.
  std::string csv;
  ASSERT_EQ(testing::RunCommand("(" + inspect + " csv " + dir.File("ground.binpb") +
                                    " 2>/dev/null)", &csv), 0) << csv;
  std::vector<std::string> lines;
  for (size_t start = 0; start < csv.size();) {
    const size_t end = csv.find('\n', start);
    lines.push_back(csv.substr(start, end - start));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  while (!lines.empty() && lines.back().empty()) lines.pop_back();
  ASSERT_EQ(lines.size(), planes.size() + 1) << csv;
  const std::vector<std::string> header = SplitCsv(lines[0]);
  auto column = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    EXPECT_NE(it, header.end()) << name << " missing in " << lines[0];
    return static_cast<size_t>(it - header.begin());
  };
  const size_t nz = column("normal_in_lidar.z"), h = column("height_m"), v = column("valid");
  column("stamp_ns");
  column("reject_reason");
  column("rms_m");
  column("azimuth_coverage");
  column("height_std_m");
  for (size_t k = 0; k < planes.size(); ++k) {
    const std::vector<std::string> row = SplitCsv(lines[k + 1]);
    ASSERT_EQ(row.size(), header.size()) << lines[k + 1];
    EXPECT_NEAR(std::stod(row[nz]), planes[k].normal_in_lidar().z(), 1e-12);
    EXPECT_NEAR(std::stod(row[h]), planes[k].height_m(), 1e-12);
    EXPECT_EQ(row[v], "1");
    EXPECT_EQ(lines[k + 1].find("nan"), std::string::npos);
  }

  // The summary of rejections goes to stderr, not into the table.
  std::string summary;
  ASSERT_EQ(testing::RunCommand("(" + inspect + " csv " + dir.File("ground.binpb") +
                                    " 2>&1 >/dev/null)", &summary), 0);
  EXPECT_NE(summary.find("10 scans, 10 valid"), std::string::npos) << summary;

  // PCD of scan 2 (deskewed and raw) with labels from the ground masks.
  for (const std::string& scans : {dir.File("deskewed.binpb.lz4"), data.scans}) {
    const std::string pcd = dir.File("scan.pcd");
    std::string log;
    ASSERT_EQ(testing::RunCommand(inspect + " pcd " + scans + " --record=2 --ground=" +
                                      dir.File("ground.binpb") + " --out=" + pcd,
                                  &log), 0) << log;
    std::string bytes;
    ASSERT_TRUE(ReadFileToString(pcd, &bytes).ok());
    const size_t data_pos = bytes.find("DATA binary\n");
    ASSERT_NE(data_pos, std::string::npos);
    const std::string pcd_header = bytes.substr(0, data_pos);
    EXPECT_NE(pcd_header.find("FIELDS x y z intensity ring time_offset_ns label"),
              std::string::npos) << pcd_header;
    EXPECT_NE(pcd_header.find("POINTS " + std::to_string(planes[2].num_points())),
              std::string::npos) << pcd_header;
    const size_t begin = data_pos + std::string("DATA binary\n").size();
    ASSERT_EQ(bytes.size() - begin, static_cast<size_t>(planes[2].num_points()) * 25)
        << pcd_header;
    uint32_t ground = 0, inliers = 0;
    for (uint32_t i = 0; i < planes[2].num_points(); ++i) {
      const uint8_t label = static_cast<uint8_t>(bytes[begin + i * 25 + 24]);
      ground += label >= 1 ? 1 : 0;
      inliers += label == 2 ? 1 : 0;
    }
    EXPECT_EQ(ground, planes[2].num_ground_points());
    EXPECT_EQ(inliers, planes[2].num_inliers());
  }
  // A record that does not exist is one clear error.
  std::string log;
  EXPECT_EQ(testing::RunCommand(inspect + " pcd " + data.scans + " --record=99 --out=" +
                                    dir.File("x.pcd"), &log), 1);
  EXPECT_NE(log.find("no record 99"), std::string::npos) << log;
  EXPECT_FALSE(testing::FileExists(dir.File("x.pcd")));
}

TEST(GroundCli, MismatchedColumnsAreOneErrorLineAndNoOutput) {
  TempDir dir;
  const Dataset data = WriteDataset(dir, true, false);
  std::string output;
  EXPECT_EQ(testing::RunCommand(Command(data, dir, data.params), &output), 1);
  EXPECT_NE(output.find("record 3"), std::string::npos) << output;
  EXPECT_NE(output.find("scans.binpb.lz4"), std::string::npos) << output;
  EXPECT_EQ(std::count(output.begin(), output.end(), '\n'), 1) << output;
  EXPECT_FALSE(testing::FileExists(dir.File("ground.binpb")));
  EXPECT_FALSE(testing::FileExists(dir.File("deskewed.binpb.lz4")));
}

TEST(GroundCli, NonMonotonicImuIsAnError) {
  TempDir dir;
  const Dataset data = WriteDataset(dir, false, true);
  std::string output;
  EXPECT_EQ(testing::RunCommand(Command(data, dir, data.params), &output), 1);
  EXPECT_NE(output.find("imu.binpb: IMU sample 200"), std::string::npos) << output;
  EXPECT_FALSE(testing::FileExists(dir.File("ground.binpb")));
}

TEST(GroundCli, WithoutParamsTheDefaultsAreUsed) {
  TempDir dir;
  const Dataset data = WriteDataset(dir, false, false);
  std::string output;
  ASSERT_EQ(testing::RunCommand(Command(data, dir, data.params), &output), 0) << output;
  std::vector<proto::GroundPlane> with_file;
  ASSERT_TRUE(ReadAllRecords<proto::GroundPlane>(dir.File("ground.binpb"), &with_file).ok());
  ASSERT_EQ(testing::RunCommand(Command(data, dir, ""), &output), 0) << output;
  std::vector<proto::GroundPlane> without;
  proto::StreamHeader header;
  ASSERT_TRUE(
      ReadAllRecords<proto::GroundPlane>(dir.File("ground.binpb"), &without, &header).ok());
  ASSERT_EQ(without.size(), with_file.size());
  for (size_t k = 0; k < without.size(); ++k) {
    EXPECT_EQ(without[k].SerializeAsString(), with_file[k].SerializeAsString()) << k;
  }
  EXPECT_NE(header.provenance().params_txtpb().find("radius_first_ring_ratio"),
            std::string::npos);
}

TEST(GroundCli, MissingRequiredFlagIsAUsageError) {
  TempDir dir;
  std::string output;
  EXPECT_EQ(testing::RunCommand(testing::ToolPath("tiltcal_ground") + " --imu=a --scans=b " +
                                    "--out_ground=" + dir.File("ground.binpb"),
                                &output),
            2);
  EXPECT_NE(output.find("--rig"), std::string::npos) << output;
  EXPECT_EQ(std::count(output.begin(), output.end(), '\n'), 1) << output;
  EXPECT_FALSE(testing::FileExists(dir.File("ground.binpb")));
}

TEST(GroundCli, BadParamsNameTheField) {
  TempDir dir;
  const Dataset data = WriteDataset(dir, false, false);
  // A fifth zone ring count: within the schema bounds, but 4 zones.
  const std::string params = dir.File("params.txtpb");
  proto::GroundParams five_zones = testing::DefaultGroundParams();
  five_zones.mutable_zone_model()->add_rings(5);
  ASSERT_TRUE(WriteTextProto(params, five_zones).ok());
  std::string output;
  EXPECT_EQ(testing::RunCommand(Command(data, dir, params), &output), 1);
  EXPECT_NE(output.find("zone_model.rings must have exactly 4 values"), std::string::npos)
      << output;
  EXPECT_FALSE(testing::FileExists(dir.File("ground.binpb")));
}

}  // namespace
}  // namespace tiltcal
