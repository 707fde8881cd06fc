// tiltcal_decode and /tf_static: bags written by the project's ROS 1 writer
// (tests/stages/decode/vehicle_bag.h) with a chain of static transforms
// between the IMU frame "imu_link" and the LiDAR frame "lidar", some walked
// against their direction; the IMU-from-LiDAR in both outputs' provenance
// (read back by common/io/tf_static_extrinsic.h) against the real tf2
// (tests/oracle/tf2_lookup.py: python3-rosbag + python3-tf2), and the same
// bag as MCAP and rosbag2 sqlite3 (CDR, through the npm oracles) against the
// ROS 1 result. No chain is a sentence in the summary, not an error.
#include <cmath>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "common/io/tf_static_extrinsic.h"
#include "tests/bag/ros2/ros2_oracle.h"
#include "tests/stages/decode/vehicle_bag.h"
#include "tests/testing/test_env.h"

namespace tiltcal {
namespace {

using testing::ToolPath;

bag::TransformStamped Transform(const std::string& parent, const std::string& child,
                                std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Quaterniond q(u(*rng), u(*rng), u(*rng), u(*rng));
  q.normalize();
  bag::TransformStamped t;
  t.header.stamp = {1700000000, 0};
  t.header.frame_id = parent;
  t.child_frame_id = child;
  for (int i = 0; i < 3; ++i) t.translation[i] = u(*rng);
  const double rotation[4] = {q.x(), q.y(), q.z(), q.w()};
  std::copy(rotation, rotation + 4, t.rotation);
  return t;
}

// imu_link <- base_link <- mount <- lidar: base_link -> imu_link and
// mount -> base_link are walked inverted, mount -> lidar as published; the
// mount frame published with a leading '/'; a GPS and a camera frame beside
// the chain; base_link -> imu_link published again, unchanged, in the second
// message.
std::vector<bag::TfMessage> ChainMessages(bool join) {
  std::mt19937 rng(7);
  bag::TfMessage first, second;
  first.transforms.push_back(Transform("base_link", "imu_link", &rng));
  first.transforms.push_back(Transform("/mount", "base_link", &rng));
  first.transforms.push_back(Transform("base_link", "gps", &rng));
  second.transforms.push_back(Transform("lidar", "camera", &rng));
  const bag::TransformStamped lidar = Transform("mount", "lidar", &rng);
  if (join) second.transforms.push_back(lidar);
  second.transforms.push_back(first.transforms[0]);
  return {first, second};
}

// Decodes `bag` into dir/out_<name>; *log is stdout + stderr.
int Decode(const testing::TempDir& dir, const std::string& bag, const std::string& name,
           std::string* log) {
  const std::string out = dir.File("out_" + name);
  return testing::RunCommand("mkdir -p " + out + " && " + ToolPath("tiltcal_decode") +
                                 " --bag=" + bag + " --out_imu=" + out + "/imu.binpb" +
                                 " --out_scans=" + out + "/scans.binpb.lz4 2>&1",
                             log);
}

// The tf2 oracle's imu_link <- lidar: 7 numbers (t, q x y z w), or none.
std::optional<std::vector<double>> Tf2Lookup(const std::string& bag) {
  std::string output;
  EXPECT_EQ(testing::RunCommand(std::string(testing::kDebianPython) + " " +
                                    testing::SourceDir() + "/tests/oracle/tf2_lookup.py " + bag +
                                    " imu_link lidar",
                                &output),
            0)
      << output;
  if (output.rfind("none", 0) == 0) return std::nullopt;
  std::istringstream in(output);
  std::vector<double> values(7);
  for (double& v : values) in >> v;
  EXPECT_TRUE(in) << output;
  return values;
}

bool HaveTf2Python() {
  return testing::RunCommand(std::string(testing::kDebianPython) +
                             " -c 'import rosbag, tf2_py' 2>/dev/null") == 0;
}

class DecodeTfStatic : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(testing::FileExists(ToolPath("tiltcal_decode"))) << "build tiltcal_decode first";
    if (!HaveTf2Python()) {
      GTEST_SKIP() << "/usr/bin/python3 cannot import rosbag and tf2_py (Debian python3-rosbag "
                      "python3-tf2, scripts/setup.sh)";
    }
  }
  std::string WriteBag(const std::string& name, bool join) {
    testing::VehicleBagOptions options;
    options.duration_s = 4.0;
    options.tf_static = ChainMessages(join);
    const std::string path = dir_.File(name);
    EXPECT_TRUE(testing::WriteVehicleBag(path, options));
    return path;
  }
  testing::TempDir dir_;
};

TEST_F(DecodeTfStatic, ChainOfStaticTransformsMatchesTf2) {
  const std::string bag = WriteBag("chain.bag", true);
  std::string log;
  ASSERT_EQ(Decode(dir_, bag, "ros1", &log), 0) << log;
  EXPECT_NE(log.find("tf_static: imu_from_lidar along imu_link <- base_link <- mount <- lidar"),
            std::string::npos)
      << log;
  EXPECT_EQ(log.find("WARNING: tf_static"), std::string::npos) << log;
  const std::optional<std::vector<double>> oracle = Tf2Lookup(bag);
  ASSERT_TRUE(oracle.has_value());
  const Eigen::Vector3d t_oracle((*oracle)[0], (*oracle)[1], (*oracle)[2]);
  const Eigen::Quaterniond q_oracle((*oracle)[6], (*oracle)[3], (*oracle)[4], (*oracle)[5]);
  for (const char* stream : {"imu.binpb", "scans.binpb.lz4"}) {
    std::optional<Rigid3d> imu_from_lidar;
    proto::TfStaticExtrinsic record;
    ASSERT_TRUE(
        ReadTfStaticExtrinsic(dir_.File(std::string("out_ros1/") + stream), &imu_from_lidar,
                              &record)
            .ok());
    ASSERT_TRUE(imu_from_lidar.has_value()) << stream;
    EXPECT_LT((imu_from_lidar->translation - t_oracle).norm(), 1e-12) << stream;
    EXPECT_LT(imu_from_lidar->rotation.angularDistance(q_oracle), 1e-12) << stream;
    EXPECT_EQ(record.imu_frame_id(), "imu_link");
    EXPECT_EQ(record.lidar_frame_id(), "lidar");
    EXPECT_EQ(std::vector<std::string>(record.chain().begin(), record.chain().end()),
              (std::vector<std::string>{"imu_link", "base_link", "mount", "lidar"}));
    EXPECT_EQ(record.num_messages(), 2);
    EXPECT_EQ(record.num_transforms(), 6);
  }
}

TEST_F(DecodeTfStatic, NoChainIsSaidNotAnError) {
  const std::string bag = WriteBag("apart.bag", false);
  std::string log;
  ASSERT_EQ(Decode(dir_, bag, "apart", &log), 0) << log;
  EXPECT_NE(log.find("no tf_static transform joins 'imu_link' and 'lidar'"), std::string::npos)
      << log;
  EXPECT_FALSE(Tf2Lookup(bag).has_value()) << "the oracle finds a chain";
  std::optional<Rigid3d> imu_from_lidar;
  ASSERT_TRUE(ReadTfStaticExtrinsic(dir_.File("out_apart/imu.binpb"), &imu_from_lidar).ok());
  EXPECT_FALSE(imu_from_lidar.has_value());

  // A bag without /tf_static at all.
  testing::VehicleBagOptions options;
  options.duration_s = 4.0;
  ASSERT_TRUE(testing::WriteVehicleBag(dir_.File("plain.bag"), options));
  ASSERT_EQ(Decode(dir_, dir_.File("plain.bag"), "plain", &log), 0) << log;
  EXPECT_NE(log.find("no /tf_static in the bag: no tf_static transform joins 'imu_link' and "
                     "'lidar'"),
            std::string::npos)
      << log;
}

TEST_F(DecodeTfStatic, Ros2BagsGiveTheRos1Extrinsic) {
  if (const std::string missing = testing::Ros2OracleMissing(); !missing.empty()) {
    GTEST_SKIP() << missing;
  }
  const std::string bag = WriteBag("chain.bag", true);
  std::string log;
  ASSERT_EQ(Decode(dir_, bag, "ros1", &log), 0) << log;
  ASSERT_EQ(testing::RunCommand(std::string(testing::kDebianPython) + " " +
                                testing::SourceDir() + "/tests/oracle/ros1_bag_to_ros2_jsonl.py " +
                                bag + " > " + dir_.File("chain.jsonl")),
            0);
  std::string error;
  ASSERT_TRUE(testing::WriteRos2Bag(dir_.File("chain.mcap"),
                                    "--format=mcap --compression=zstd --messages=" +
                                        dir_.File("chain.jsonl"),
                                    "", &error))
      << error;
  ASSERT_TRUE(testing::WriteRos2Bag(dir_.File("chain_ros2"),
                                    "--format=sqlite3 --messages=" + dir_.File("chain.jsonl"), "",
                                    &error))
      << error;
  proto::TfStaticExtrinsic ros1;
  std::optional<Rigid3d> unused;
  ASSERT_TRUE(ReadTfStaticExtrinsic(dir_.File("out_ros1/imu.binpb"), &unused, &ros1).ok());
  ASSERT_TRUE(ros1.has_imu_from_lidar());
  for (const char* name : {"chain.mcap", "chain_ros2"}) {
    ASSERT_EQ(Decode(dir_, dir_.File(name), name, &log), 0) << log;
    proto::TfStaticExtrinsic ros2;
    ASSERT_TRUE(
        ReadTfStaticExtrinsic(dir_.File(std::string("out_") + name + "/imu.binpb"), &unused, &ros2)
            .ok());
    EXPECT_EQ(ros2.imu_from_lidar().SerializeAsString(), ros1.imu_from_lidar().SerializeAsString())
        << name << ": " << ros2.summary();
    EXPECT_EQ(ros2.chain_size(), 4) << name;
  }
}

}  // namespace
}  // namespace tiltcal
