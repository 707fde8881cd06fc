// tiltcal_decode as a user runs it: bad input gives ONE error line naming the
// file (and record), a non-zero exit and no output file; params are checked.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "common/geometry/angles.h"
#include "common/io/record_stream.h"
#include "tests/bag/ros1/bag_test_util.h"
#include "tests/stages/decode/vehicle_bag.h"
#include "tests/testing/test_env.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal {
namespace {

namespace fs = std::filesystem;

class DecodeCli : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(testing::FileExists(testing::ToolPath("tiltcal_decode")))
        << "build the tiltcal_decode target first";
    fs::create_directories(tmp_.File("out"));
    params_ = testing::SourceDir() + "/stages/decode/default_params.txtpb";
  }

  // Runs the tool on `bag` with `params`; returns the exit status.
  int Decode(const std::string& bag, const std::string& params, std::string* output,
             const std::string& extra = "") {
    const std::string command = testing::ToolPath("tiltcal_decode") + " --bag='" + bag +
                                "' --params='" + params + "' --out_imu=" +
                                tmp_.File("out/imu.binpb") + " --out_scans=" +
                                tmp_.File("out/scans.binpb.lz4") + " " + extra;
    return testing::RunCommand(command, output);
  }

  // One line, naming `must_contain`, non-zero exit, nothing in out/.
  void ExpectCleanFailure(int rc, const std::string& output,
                          const std::vector<std::string>& must_contain) {
    EXPECT_NE(rc, 0);
    EXPECT_EQ(std::count(output.begin(), output.end(), '\n'), 1) << output;
    for (const std::string& s : must_contain) {
      EXPECT_NE(output.find(s), std::string::npos) << "'" << s << "' not in: " << output;
    }
    EXPECT_TRUE(fs::is_empty(tmp_.File("out"))) << "output left behind";
  }

  std::string WrittenBag(const std::string& name) {
    std::string log;
    const std::string dir = testing::WrittenBagsDir(&log);
    if (dir.empty() && !testing::HaveRosbagPython()) return "";
    EXPECT_FALSE(dir.empty()) << log;
    return dir.empty() ? "" : dir + "/" + name;
  }

  // A copy of the default params at `path` with the line `from` replaced by
  // `to`; false when the defaults have no such line.
  bool WriteDefaultParamsWith(const std::string& path, const std::string& from,
                              const std::string& to) {
    std::string text = testing::ReadFileOrEmpty(params_);
    const size_t at = text.find(from);
    if (at == std::string::npos) return false;
    WriteFile(path, text.replace(at, from.size(), to));
    return true;
  }

  void WriteFile(const std::string& path, const std::string& contents) {
    std::ofstream out(path, std::ios::binary);
    out << contents;
  }

  // A valid rig.txtpb naming the topics of the written velodyne bags (and
  // of the vehicle bags), with `extra` fields.
  std::string WriteRigWithTopics(const std::string& extra = "") {
    const std::string rig = tmp_.File("rig.txtpb");
    WriteFile(rig,
              "imu_from_lidar { rotation { w: 1 } translation { x: 0.1 } }\nimu_height_m: 0.3\n"
              "imu_topic: \"/imu/data\"\nlidar_topic: \"/points\"\n" +
                  extra);
    return rig;
  }

  // A vehicle bag (tests/stages/decode/vehicle_bag.h) in tmp_.
  std::string VehicleBag(const std::string& name, const testing::VehicleBagOptions& options) {
    const std::string bag = tmp_.File(name);
    EXPECT_TRUE(testing::WriteVehicleBag(bag, options));
    return bag;
  }

  testing::TempDir tmp_;
  std::string params_;
};

#define REQUIRE_WRITTEN_BAG(var, name)                                                  \
  const std::string var = WrittenBag(name);                                             \
  if (var.empty()) {                                                                    \
    GTEST_SKIP() << "/usr/bin/python3 cannot import rosbag; no written test bags";      \
  }

TEST_F(DecodeCli, DecodesAWrittenBagWithRig) {
  REQUIRE_WRITTEN_BAG(bag, "velodyne_bz2.bag");
  const std::string rig = WriteRigWithTopics();
  std::string output;
  EXPECT_EQ(Decode(bag, params_, &output, "--rig=" + rig), 0) << output;
  EXPECT_TRUE(testing::FileExists(tmp_.File("out/imu.binpb")));
  EXPECT_TRUE(testing::FileExists(tmp_.File("out/scans.binpb.lz4")));
  // The summary (no progress: stderr is not a terminal here).
  EXPECT_NE(output.find("imu   '/imu/data': 201 msgs, 200 written"), std::string::npos) << output;
  EXPECT_NE(output.find("MB/s"), std::string::npos) << output;
  EXPECT_EQ(output.find('\r'), std::string::npos);
}

TEST_F(DecodeCli, EmptyFile) {
  const std::string bag = tmp_.File("empty.bag");
  WriteFile(bag, "");
  std::string output;
  const int rc = Decode(bag, params_, &output);
  ExpectCleanFailure(rc, output, {bag, "empty file"});
}

TEST_F(DecodeCli, WrongMagic) {
  const std::string bag = tmp_.File("notabag.bag");
  WriteFile(bag, "This is a text file, not a bag.\n" + std::string(5000, 'x'));
  std::string output;
  const int rc = Decode(bag, params_, &output);
  ExpectCleanFailure(rc, output, {bag, "wrong magic"});
}

TEST_F(DecodeCli, Version12BagIsRejected) {
  const std::string bag = tmp_.File("old.bag");
  WriteFile(bag, "#ROSRECORD V1.2\n" + std::string(100, '\0'));
  std::string output;
  const int rc = Decode(bag, params_, &output);
  ExpectCleanFailure(rc, output, {bag, "V1.2 is not supported"});
}

TEST_F(DecodeCli, TruncatedBag) {
  REQUIRE_WRITTEN_BAG(source, "velodyne_lz4.bag");
  const std::string bytes = testing::ReadFileOrEmpty(source);
  const std::string bag = tmp_.File("truncated.bag");
  WriteFile(bag, bytes.substr(0, bytes.size() * 6 / 10));
  std::string output;
  const int rc = Decode(bag, params_, &output);
  ExpectCleanFailure(rc, output, {bag, "truncated"});
}

void FlipBytes(std::string* bytes, size_t at, size_t n) {
  for (size_t i = at; i < at + n && i < bytes->size(); ++i) (*bytes)[i] ^= 0x5A;
}

TEST_F(DecodeCli, CorruptedBz2Chunk) {
  REQUIRE_WRITTEN_BAG(source, "ouster_bz2.bag");
  std::string bytes = testing::ReadFileOrEmpty(source);
  FlipBytes(&bytes, 4117 + 400, 16);  // inside the compressed data of the first chunk
  const std::string bag = tmp_.File("corrupt_bz2.bag");
  WriteFile(bag, bytes);
  std::string output;
  const int rc = Decode(bag, params_, &output);
  ExpectCleanFailure(rc, output, {bag, "record at byte 4117", "bz2"});
}

TEST_F(DecodeCli, CorruptedLz4Chunk) {
  REQUIRE_WRITTEN_BAG(source, "hesai_lz4.bag");
  std::string bytes = testing::ReadFileOrEmpty(source);
  FlipBytes(&bytes, 4117 + 400, 16);
  const std::string bag = tmp_.File("corrupt_lz4.bag");
  WriteFile(bag, bytes);
  std::string output;
  const int rc = Decode(bag, params_, &output);
  ExpectCleanFailure(rc, output, {bag, "record at byte 4117", "lz4"});
}

TEST_F(DecodeCli, BagWithoutPointCloud2) {
  REQUIRE_WRITTEN_BAG(bag, "imu_only.bag");
  std::string output;
  const int rc = Decode(bag, params_, &output);
  ExpectCleanFailure(rc, output, {bag, "no sensor_msgs/PointCloud2 topic", "/imu/data"});
}

TEST_F(DecodeCli, RealBagWithoutPointCloud2) {
  const std::string dir = testing::SharedFixturesDir();
  if (dir.empty()) GTEST_SKIP() << "../shared/fixtures absent";
  const std::string bag = dir + "/bags/ros1/robot_localization_test2_bz2_imu.bag";
  std::string output;
  const int rc = Decode(bag, params_, &output);
  ExpectCleanFailure(rc, output, {bag, "no sensor_msgs/PointCloud2 topic"});
}

TEST_F(DecodeCli, BagWithoutMessages) {
  const std::string dir = testing::SharedFixturesDir();
  if (dir.empty()) GTEST_SKIP() << "../shared/fixtures absent";
  const std::string bag = dir + "/bags/ros1/rosbagjs_no-messages.bag";
  std::string output;
  const int rc = Decode(bag, params_, &output);
  ExpectCleanFailure(rc, output, {bag, "holds no messages"});
}

TEST_F(DecodeCli, MessageRunningPastItsRecord) {
  REQUIRE_WRITTEN_BAG(bag, "truncated_message.bag");
  std::string output;
  const int rc = Decode(bag, params_, &output);
  ExpectCleanFailure(rc, output,
                     {bag, "topic '/imu/data' message 3", "runs past its record"});
}

TEST_F(DecodeCli, ParamsOutOfRange) {
  const std::string params = tmp_.File("bad.txtpb");
  ASSERT_TRUE(WriteDefaultParamsWith(params, "min_range_m: 0.5", "min_range_m: -1"));
  std::string output;
  const int rc = Decode("/nonexistent.bag", params, &output);
  ExpectCleanFailure(rc, output, {params, "min_range_m = -1 is below its minimum"});
}

TEST_F(DecodeCli, ParamsUnknownField) {
  const std::string params = tmp_.File("bad.txtpb");
  WriteFile(params, "chunk_cache_size: 4\nmin_rang_m: 1\n");
  std::string output;
  const int rc = Decode("/nonexistent.bag", params, &output);
  ExpectCleanFailure(rc, output, {params, "min_rang_m"});
}

// Without --params the stage runs on its defaults, the values of
// stages/decode/default_params.txtpb: the same counts as with that file.
TEST_F(DecodeCli, MissingParamsMeanTheDefaults) {
  REQUIRE_WRITTEN_BAG(bag, "velodyne_bz2.bag");
  const std::string rig = WriteRigWithTopics();
  std::string with_file;
  ASSERT_EQ(Decode(bag, params_, &with_file, "--rig=" + rig), 0) << with_file;
  std::string with_defaults;
  const std::string command = testing::ToolPath("tiltcal_decode") + " --bag='" + bag +
                              "' --rig=" + rig + " --out_imu=" + tmp_.File("out/imu.binpb") +
                              " --out_scans=" + tmp_.File("out/scans.binpb.lz4");
  ASSERT_EQ(testing::RunCommand(command, &with_defaults), 0) << with_defaults;
  // Every line but the wall time.
  auto counts = [](const std::string& output) { return output.substr(0, output.find("  wall")); };
  EXPECT_NE(counts(with_file).find("points: "), std::string::npos) << with_file;
  EXPECT_EQ(counts(with_defaults), counts(with_file));
}

// The scan stream is one LZ4 frame either way: stored blocks with the content
// checksum by default (FLG 0x64, BD 0x50, the first block's size word with
// bit 31 set); compressed blocks with store_blocks false, as a params file
// written before scans_output gets. The records are the same.
TEST_F(DecodeCli, ScansFrameStoredByDefaultCompressedOnRequest) {
  REQUIRE_WRITTEN_BAG(bag, "velodyne_bz2.bag");
  const std::string rig = WriteRigWithTopics();
  std::string output;
  ASSERT_EQ(Decode(bag, params_, &output, "--rig=" + rig), 0) << output;
  const std::string stored = testing::ReadFileOrEmpty(tmp_.File("out/scans.binpb.lz4"));
  ASSERT_GT(stored.size(), 11u);
  EXPECT_EQ(stored.substr(0, 6), std::string("\x04\x22\x4d\x18\x64\x50", 6));
  EXPECT_NE(static_cast<unsigned char>(stored[10]) & 0x80, 0);
  const std::string params = tmp_.File("compressed.txtpb");
  ASSERT_TRUE(WriteDefaultParamsWith(params, "store_blocks: true", "store_blocks: false"));
  ASSERT_EQ(Decode(bag, params, &output, "--rig=" + rig), 0) << output;
  const std::string compressed = testing::ReadFileOrEmpty(tmp_.File("out/scans.binpb.lz4"));
  ASSERT_GT(compressed.size(), 11u);
  EXPECT_EQ(compressed.substr(0, 6), std::string("\x04\x22\x4d\x18\x64\x50", 6));
  EXPECT_LT(compressed.size(), stored.size());
  if (testing::RunCommand("command -v lz4 >/dev/null") != 0) return;
  const std::string a = tmp_.File("stored.lz4"), b = tmp_.File("compressed.lz4");
  WriteFile(a, stored);
  WriteFile(b, compressed);
  std::string plain_a, plain_b;
  ASSERT_EQ(testing::RunCommand("lz4 -dc " + a, &plain_a), 0);
  ASSERT_EQ(testing::RunCommand("lz4 -dc " + b, &plain_b), 0);
  // The same records after the header (provenance: params and time).
  ASSERT_GT(plain_a.size(), 1000u);
  ASSERT_GT(plain_b.size(), 1000u);
  EXPECT_EQ(plain_a.substr(plain_a.size() - 1000), plain_b.substr(plain_b.size() - 1000));
}

// Every record of a scan stream, serialized.
std::vector<std::string> ReadScanRecords(const std::string& path) {
  std::vector<std::string> records;
  RecordReader reader;
  EXPECT_TRUE(reader.Open(path, proto::Scan::descriptor()->full_name()).ok()) << path;
  proto::Scan scan;
  for (bool end = false;;) {
    const Status status = reader.Read(&scan, &end);
    EXPECT_TRUE(status.ok()) << status.message();
    if (!status.ok() || end) break;
    records.push_back(scan.SerializeAsString());
  }
  return records;
}

// The scans are written past the page cache by default; through it with
// bypass_page_cache false. The file is the same but for the params in its
// header.
TEST_F(DecodeCli, ScansPastThePageCacheAreTheSameRecords) {
  REQUIRE_WRITTEN_BAG(bag, "velodyne_bz2.bag");
  const std::string rig = WriteRigWithTopics();
  std::string output;
  ASSERT_EQ(Decode(bag, params_, &output, "--rig=" + rig), 0) << output;
  const std::string past = tmp_.File("past.binpb.lz4");
  fs::rename(tmp_.File("out/scans.binpb.lz4"), past);
  const std::string params = tmp_.File("through.txtpb");
  ASSERT_TRUE(
      WriteDefaultParamsWith(params, "bypass_page_cache: true", "bypass_page_cache: false"));
  ASSERT_EQ(Decode(bag, params, &output, "--rig=" + rig), 0) << output;
  const std::vector<std::string> through = ReadScanRecords(tmp_.File("out/scans.binpb.lz4"));
  ASSERT_FALSE(through.empty());
  EXPECT_TRUE(ReadScanRecords(past) == through);
}

// A missing output flag is a usage error (exit 2) naming the flag.
TEST_F(DecodeCli, RequiredFlagMissing) {
  std::string output;
  const int rc = testing::RunCommand(
      testing::ToolPath("tiltcal_decode") + " --bag=/nonexistent.bag --out_imu=" +
          tmp_.File("out/imu.binpb"),
      &output);
  EXPECT_EQ(rc, 2);
  EXPECT_NE(output.find("--out_scans"), std::string::npos) << output;
  EXPECT_EQ(std::count(output.begin(), output.end(), '\n'), 1) << output;
  EXPECT_TRUE(fs::is_empty(tmp_.File("out")));
}

// The rig is validated: a zero rotation quaternion is an error naming the field.
TEST_F(DecodeCli, InvalidRigIsRejected) {
  const std::string rig = tmp_.File("rig.txtpb");
  WriteFile(rig, "imu_from_lidar { rotation { w: 0 } translation {} }\n");
  std::string output;
  const int rc = Decode("/nonexistent.bag", params_, &output, "--rig=" + rig);
  ExpectCleanFailure(rc, output, {rig, "imu_from_lidar.rotation"});
}

TEST_F(DecodeCli, MissingBag) {
  std::string output;
  const int rc = Decode(tmp_.File("missing.bag"), params_, &output);
  ExpectCleanFailure(rc, output, {tmp_.File("missing.bag"), "cannot open"});
}

testing::VehicleBagOptions InGAndDegrees() {
  testing::VehicleBagOptions options;
  options.accel_scale = 1.0 / 9.80665;
  options.gyro_scale = geometry::kDegPerRad;
  return options;
}

// AUTO converts an IMU in g and deg/s, says so on stderr, one line per
// sensor, and in the provenance of imu.binpb that tiltcal_inspect shows.
TEST_F(DecodeCli, ImuInGAndDegreesIsConvertedAndSaid) {
  ASSERT_TRUE(testing::FileExists(testing::ToolPath("tiltcal_inspect")));
  const std::string bag = VehicleBag("g_deg.bag", InGAndDegrees());
  std::string output;
  ASSERT_EQ(Decode(bag, params_, &output, "--rig=" + WriteRigWithTopics()), 0) << output;
  const std::string accel_line =
      "  imu: accelerometer in g, detected: median |f| 1.0002 over 410 static samples; "
      "converted to m/s² (× 9.80665)\n";
  const std::string gyro_line =
      "  imu: gyro in deg/s, detected: |ω| at percentile 99 is 34.6, above 5 rad/s, the fastest "
      "turn of a ground vehicle; converted to rad/s (× π/180)\n";
  EXPECT_NE(output.find(accel_line), std::string::npos) << output;
  EXPECT_NE(output.find(gyro_line), std::string::npos) << output;
  EXPECT_NE(output.find("  imu: accelerometer sign checked: the mean specific force over 410 "
                        "static samples, (0.002, 0.003, 9.810) m/s² in the IMU frame, points "
                        "0.0 deg from the LiDAR's +z"),
            std::string::npos)
      << output;
  EXPECT_EQ(output.find("WARNING"), std::string::npos) << output;
  std::string info;
  ASSERT_EQ(testing::RunCommand(
                testing::ToolPath("tiltcal_inspect") + " info " + tmp_.File("out/imu.binpb"),
                &info),
            0)
      << info;
  EXPECT_NE(info.find("notes: \"accelerometer in g, detected: median |f| 1.0002"),
            std::string::npos)
      << info;
  EXPECT_NE(info.find("notes: \"gyro in deg/s, detected:"), std::string::npos) << info;
}

TEST_F(DecodeCli, RigStatingTheWrongAccelerometerUnit) {
  const std::string bag = VehicleBag("g_deg.bag", InGAndDegrees());
  const std::string rig = WriteRigWithTopics("imu_accel_unit: MPS2\n");
  std::string output;
  const int rc = Decode(bag, params_, &output, "--rig=" + rig);
  EXPECT_EQ(rc, 1);
  EXPECT_EQ(output, "tiltcal_decode: " + rig + ": imu_accel_unit is MPS2 but the accelerometer of " +
                        bag +
                        " reads in g: median |f| 1.0002 over 410 static samples (one g is 9.81 "
                        "in m/s², 1 in g)\n");
  ExpectCleanFailure(rc, output, {});
}

TEST_F(DecodeCli, RigStatingTheWrongGyroUnit) {
  const std::string bag = VehicleBag("g_deg.bag", InGAndDegrees());
  const std::string rig = WriteRigWithTopics("imu_accel_unit: G\nimu_gyro_unit: RADPS\n");
  std::string output;
  const int rc = Decode(bag, params_, &output, "--rig=" + rig);
  EXPECT_EQ(rc, 1);
  EXPECT_EQ(output, "tiltcal_decode: " + rig + ": imu_gyro_unit is RADPS but the gyro of " + bag +
                        " reads in deg/s: |ω| at percentile 99 is 34.6, above 5 rad/s, the "
                        "fastest turn of a ground vehicle\n");
  ExpectCleanFailure(rc, output, {});
}

// LiDAR stamps 10 min after the IMU's: one line with both spans and the
// field to set; with the field set the bag decodes.
TEST_F(DecodeCli, ClockDomainsTenMinutesApart) {
  testing::VehicleBagOptions late;
  late.lidar_stamp_offset_ns = 600LL * 1000000000LL;
  const std::string bag = VehicleBag("late.bag", late);
  std::string output;
  const int rc = Decode(bag, params_, &output);
  EXPECT_EQ(rc, 1);
  EXPECT_EQ(output,
            "tiltcal_decode: " + bag +
                ": the LiDAR and IMU stamps do not overlap (two clocks?): IMU stamps "
                "1700000000.000 .. 1700000012.000 s (2023-11-14 22:13:20 UTC .. 2023-11-14 "
                "22:13:32 UTC), LiDAR stamps 1700000600.000 .. 1700000611.900 s (2023-11-14 "
                "22:23:20 UTC .. 2023-11-14 22:23:31 UTC), the LiDAR 588.000 s after the IMU; "
                "set lidar_stamp_shift_s in the decode params (added to every LiDAR stamp, s) "
                "to decode anyway: the bag's record times suggest lidar_stamp_shift_s: "
                "-599.981\n");
  ExpectCleanFailure(rc, output, {});

  // The defaults with lidar_stamp_shift_s replaced (a field given twice is an error).
  const std::string params = tmp_.File("params.txtpb");
  ASSERT_TRUE(
      WriteDefaultParamsWith(params, "lidar_stamp_shift_s: 0", "lidar_stamp_shift_s: -599.981"));
  ASSERT_EQ(Decode(bag, params, &output), 0) << output;
  EXPECT_NE(output.find("  clocks: IMU and LiDAR stamps overlap for 11.900 s (LiDAR stamps "
                        "shifted by -599.981 s, lidar_stamp_shift_s)\n"),
            std::string::npos)
      << output;
}

// A driver publishing gravity instead of the specific force: against the
// rig's g_f an error, against its rotation alone a warning (exit 0).
TEST_F(DecodeCli, SignFlippedAccelerometer) {
  testing::VehicleBagOptions flipped;
  flipped.accel_scale = -1.0;
  const std::string bag = VehicleBag("flipped.bag", flipped);
  const std::string rig = WriteRigWithTopics("gravity_flat_in_imu { z: -9.81 }\n");
  std::string output;
  const int rc = Decode(bag, params_, &output, "--rig=" + rig);
  EXPECT_EQ(rc, 1);
  EXPECT_EQ(output,
            "tiltcal_decode: " + rig +
                ": the mean specific force over 410 static samples, (-0.002, -0.003, -9.810) "
                "m/s² in the IMU frame, points 180.0 deg from up (−gravity_flat_in_imu of the "
                "rig; more than 90): the accelerometer of " +
                bag +
                " publishes gravity instead of specific force (sign-flipped), or "
                "gravity_flat_in_imu has the wrong sign (g_f points down: it is minus the mean "
                "accelerometer reading at rest on flat ground)\n");
  ExpectCleanFailure(rc, output, {});

  ASSERT_EQ(Decode(bag, params_, &output, "--rig=" + WriteRigWithTopics()), 0) << output;
  const std::string warning =
      "  WARNING: imu: the mean specific force over 410 static samples, (-0.002, -0.003, "
      "-9.810) m/s² in the IMU frame, points 180.0 deg from the LiDAR's +z (through "
      "imu_from_lidar of the rig; more than 90): the accelerometer publishes gravity instead of "
      "specific force (sign-flipped), or the rig's rotation is wrong (an IMU mounted upside "
      "down and not declared), or the LiDAR is mounted upside down; imu.binpb keeps the "
      "published sign\n";
  EXPECT_NE(output.find(warning), std::string::npos) << output;
  EXPECT_EQ(output.find("WARNING"), output.rfind("WARNING")) << output;  // said once
}

TEST_F(DecodeCli, ImuUnitsParamsAreValidated) {
  std::string text = testing::ReadFileOrEmpty(params_);
  for (const std::string field : {"accel_norm_ratio_min: 0.8", "accel_norm_ratio_max: 1.25"}) {
    ASSERT_NE(text.find(field), std::string::npos) << field;
    text.replace(text.find(field), field.size(), field.substr(0, field.find(':')) + ": 1");
  }
  const std::string params = tmp_.File("params.txtpb");
  WriteFile(params, text);
  std::string output;
  const int rc = Decode(VehicleBag("si.bag", {}), params, &output);
  EXPECT_EQ(rc, 1);
  EXPECT_EQ(output, "tiltcal_decode: " + params +
                        ": field imu_units.accel_norm_ratio_max must be greater than "
                        "imu_units.accel_norm_ratio_min\n");
  ExpectCleanFailure(rc, output, {});
}

}  // namespace
}  // namespace tiltcal
