// tiltcal_inspect on a first bag, as a user runs it: `check` reads every
// input decode reads and finds the same in a simulated sequence written as
// a ROS 1 bag (tiltcal_simulate with /tf_static), as MCAP and as a rosbag2
// sqlite3 folder (tests/oracle/ros1_bag_to_ros2_jsonl.py, write_ros2_bags.mjs)
// and as a Livox CustomMsg bag (tests/oracle/pointcloud2_bag_to_livox.py),
// including the extrinsic of /tf_static; `rig` drafts a rig.txtpb that
// parses as a Rig and that tiltcal_decode accepts once imu_height_m is
// filled in, with /tf_static's extrinsic or, without it, a comment.
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "common/io/atomic_file.h"
#include "common/io/rig.h"
#include "common/io/text_proto.h"
#include "tests/bag/ros2/ros2_oracle.h"
#include "tests/testing/test_env.h"
#include "tiltcal/proto/rig.pb.h"
#include "tiltcal/proto/simulate_params.pb.h"
#include "tiltcal/proto/truth.pb.h"

namespace tiltcal {
namespace {

using testing::ToolPath;

class InspectFirstContact : public ::testing::Test {
 protected:
  void SetUp() override {
    for (const char* tool : {"tiltcal_simulate", "tiltcal_inspect", "tiltcal_decode"}) {
      ASSERT_TRUE(testing::FileExists(ToolPath(tool))) << "build " << tool << " first";
    }
  }
  // A 3 s simulated sequence; with /tf_static when `tf_static`.
  std::string Simulate(const std::string& name, bool tf_static) {
    proto::SimulateParams scenario;
    EXPECT_TRUE(ReadTextProto(
                    testing::SourceDir() + "/stages/simulate/scenarios/short_test_vlp16.txtpb",
                    &scenario)
                    .ok());
    scenario.set_duration_s(3.0);
    scenario.set_num_threads(1);
    scenario.mutable_tf_static()->set_write(tf_static);
    EXPECT_TRUE(WriteTextProto(dir_.File(name + ".txtpb"), scenario).ok());
    std::string output;
    EXPECT_EQ(testing::RunCommand(ToolPath("tiltcal_simulate") + " --quiet --params=" +
                                      dir_.File(name + ".txtpb") + " --out_bag=" +
                                      dir_.File(name + ".bag") + " --out_truth=" +
                                      dir_.File(name + "_truth.txtpb") + " 2>&1",
                                  &output),
              0)
        << output;
    return dir_.File(name + ".bag");
  }
  // `tiltcal_inspect check` without its first line (path, format, size).
  std::string CheckFindings(const std::string& bag) {
    std::string output;
    const int rc =
        testing::RunCommand(ToolPath("tiltcal_inspect") + " check --bag=" + bag, &output);
    EXPECT_EQ(rc, 0) << output;
    EXPECT_EQ(output.rfind("bag      " + bag, 0), 0u) << output;
    return output.substr(output.find('\n') + 1);
  }
  testing::TempDir dir_;
};

TEST_F(InspectFirstContact, CheckFindsTheSameInRos1McapRosbag2AndLivox) {
  if (const std::string missing = testing::Ros2OracleMissing(); !missing.empty()) {
    GTEST_SKIP() << missing;
  }
  if (!testing::HaveRosbagPython()) GTEST_SKIP() << "/usr/bin/python3 cannot import rosbag";
  const std::string bag = Simulate("run", true);
  ASSERT_EQ(testing::RunCommand(std::string(testing::kDebianPython) + " " +
                                testing::SourceDir() + "/tests/oracle/ros1_bag_to_ros2_jsonl.py " +
                                bag + " > " + dir_.File("run.jsonl")),
            0);
  std::string error;
  ASSERT_TRUE(testing::WriteRos2Bag(dir_.File("run.mcap"),
                                    "--format=mcap --compression=lz4 --messages=" +
                                        dir_.File("run.jsonl"),
                                    "", &error))
      << error;
  ASSERT_TRUE(testing::WriteRos2Bag(dir_.File("run_ros2"),
                                    "--format=sqlite3 --messages=" + dir_.File("run.jsonl"), "",
                                    &error))
      << error;
  const std::string ros1 = CheckFindings(bag);
  EXPECT_EQ(ros1.rfind("tf_static imu_from_lidar along imu_link <- base_link <- velodyne", 0), 0u)
      << ros1;
  EXPECT_NE(ros1.find("verdict: can be calibrated"), std::string::npos) << ros1;
  EXPECT_EQ(CheckFindings(dir_.File("run.mcap")), ros1);
  EXPECT_EQ(CheckFindings(dir_.File("run_ros2")), ros1);

  // The same clouds as livox_ros_driver/CustomMsg: only the two lines that
  // name the format's own fields for the point time and the ring differ.
  ASSERT_EQ(testing::RunCommand(std::string(testing::kDebianPython) + " " +
                                testing::SourceDir() +
                                "/tests/oracle/pointcloud2_bag_to_livox.py " + bag + " " +
                                dir_.File("run_livox.bag")),
            0);
  std::string livox = CheckFindings(dir_.File("run_livox.bag"));
  const std::pair<std::string, std::string> format_fields[] = {
      {"offset_time UINT32 (ns after timebase (Livox CustomMsg))\n",
       "time FLOAT32 (s after the stamp)\n"},
      {"line UINT8\n", "ring UINT16\n"}};
  for (const auto& [livox_field, pointcloud2_field] : format_fields) {
    const size_t at = livox.find(livox_field);
    ASSERT_NE(at, std::string::npos) << livox;
    livox.replace(at, livox_field.size(), pointcloud2_field);
  }
  EXPECT_EQ(livox, ros1);
}

TEST_F(InspectFirstContact, RigDraftIsARigThatDecodeAccepts) {
  for (const bool tf_static : {true, false}) {
    const std::string name = tf_static ? "with_tf" : "without_tf";
    const std::string bag = Simulate(name, tf_static);
    const std::string rig = dir_.File(name + "_rig.txtpb");
    std::string output;
    ASSERT_EQ(testing::RunCommand(ToolPath("tiltcal_inspect") + " rig --bag=" + bag +
                                      " --out=" + rig + " 2>&1",
                                  &output),
              0)
        << output;
    std::string text;
    ASSERT_TRUE(ReadFileToString(rig, &text).ok());
    proto::Rig parsed;
    ASSERT_TRUE(ReadTextProto(rig, &parsed).ok()) << text;
    // With or without /tf_static the draft is a valid rig (without, the
    // rotation comes from the motion).
    proto::Rig validated;
    EXPECT_TRUE(LoadRig(rig, &validated).ok()) << text;
    EXPECT_EQ(parsed.imu_topic(), "/imu/data") << text;
    EXPECT_EQ(parsed.lidar_topic(), "/velodyne_points") << text;
    EXPECT_EQ(parsed.imu_accel_unit(), proto::AccelUnit::MPS2) << text;
    EXPECT_EQ(parsed.imu_gyro_unit(), proto::GyroUnit::RADPS) << text;
    EXPECT_EQ(parsed.has_imu_from_lidar(), tf_static) << text;
    EXPECT_NE(text.find("# imu_height_m: 0.0\n"), std::string::npos) << text;
    if (tf_static) {
      proto::SimulationTruth truth;
      ASSERT_TRUE(ReadTextProto(dir_.File(name + "_truth.txtpb"), &truth).ok());
      const proto::Quaternion& q = parsed.imu_from_lidar().rotation();
      const proto::Quaternion& t = truth.imu_from_lidar().rotation();
      EXPECT_NEAR(std::abs(q.w() * t.w() + q.x() * t.x() + q.y() * t.y() + q.z() * t.z()), 1.0,
                  1e-12)
          << text;
      EXPECT_NEAR(parsed.imu_from_lidar().translation().x(),
                  truth.imu_from_lidar().translation().x(), 1e-12);
      EXPECT_NEAR(parsed.imu_from_lidar().translation().z(),
                  truth.imu_from_lidar().translation().z(), 1e-12);
    } else {
      EXPECT_NE(text.find("# imu_from_lidar: not in the bag (no /tf_static in the bag"),
                std::string::npos)
          << text;
    }
    // The user fills in the IMU height (and, without /tf_static, a starting
    // extrinsic from the commented template).
    const size_t line = text.find("# imu_height_m: 0.0");
    text.replace(line, 19, "imu_height_m: 0.5");
    if (!tf_static) {
      const size_t extrinsic = text.find("# imu_from_lidar { rotation");
      ASSERT_NE(extrinsic, std::string::npos) << text;
      text.erase(extrinsic, 2);
    }
    ASSERT_TRUE(WriteFileAtomically(rig, text).ok());
    ASSERT_EQ(testing::RunCommand("mkdir -p " + dir_.File("out_" + name) + " && " +
                                      ToolPath("tiltcal_decode") + " --bag=" + bag + " --rig=" +
                                      rig + " --out_imu=" + dir_.File("out_" + name) +
                                      "/imu.binpb --out_scans=" + dir_.File("out_" + name) +
                                      "/scans.binpb.lz4 2>&1",
                                  &output),
              0)
        << output;
  }
}

}  // namespace
}  // namespace tiltcal
