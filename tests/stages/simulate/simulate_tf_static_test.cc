// tiltcal_simulate's /tf_static (SimTfStaticParams): off by default, the bag
// byte for byte the one without the message; on, the IMU-from-LiDAR the real
// tf2 reads from the bag (tests/oracle/tf2_lookup.py: python3-rosbag +
// python3-tf2) is the true extrinsic with the URDF error of the params,
// (C_bl C(error), r_b^{lb} + C_bv error_m).
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "common/geometry/euler_angles.h"
#include "common/io/atomic_file.h"
#include "common/io/eigen_proto.h"
#include "common/io/text_proto.h"
#include "stages/simulate/simulate.h"
#include "tests/testing/test_env.h"

namespace tiltcal {
namespace {

proto::SimulateParams ShortScenario() {
  proto::SimulateParams params;
  EXPECT_TRUE(ReadTextProto(
                  testing::SourceDir() + "/stages/simulate/scenarios/short_test_vlp16.txtpb",
                  &params)
                  .ok());
  params.set_duration_s(1.0);
  params.set_num_threads(1);
  return params;
}

std::string Simulate(const testing::TempDir& dir, const std::string& name,
                     const proto::SimulateParams& params) {
  simulate::SimulatePaths paths;
  paths.out_bag = dir.File(name + ".bag");
  paths.out_truth = dir.File(name + "_truth.txtpb");
  const Status status = simulate::Run(paths, params, nullptr);
  EXPECT_TRUE(status.ok()) << status.message();
  std::string bytes;
  EXPECT_TRUE(ReadFileToString(paths.out_bag, &bytes).ok());
  return bytes;
}

TEST(SimulateTfStatic, OffByDefaultLeavesTheBagUnchanged) {
  testing::TempDir dir;
  proto::SimulateParams params = ShortScenario();
  const std::string plain = Simulate(dir, "plain", params);
  params.mutable_tf_static()->set_base_frame_id("chassis");  // present, write false
  EXPECT_TRUE(Simulate(dir, "off", params) == plain);
  params.mutable_tf_static()->set_write(true);
  EXPECT_FALSE(Simulate(dir, "on", params) == plain);
}

TEST(SimulateTfStatic, Tf2ReadsTheTrueExtrinsicWithTheUrdfError) {
  if (testing::RunCommand(std::string(testing::kDebianPython) +
                          " -c 'import rosbag, tf2_py' 2>/dev/null") != 0) {
    GTEST_SKIP() << "/usr/bin/python3 cannot import rosbag and tf2_py (Debian python3-rosbag "
                    "python3-tf2, scripts/setup.sh)";
  }
  testing::TempDir dir;
  proto::SimulateParams params = ShortScenario();
  proto::SimTfStaticParams* tf = params.mutable_tf_static();
  tf->set_write(true);
  *tf->mutable_lidar_rotation_error_deg() = ToProto(Eigen::Vector3d(0.5, -1.0, 2.0));
  *tf->mutable_lidar_translation_error_m() = ToProto(Eigen::Vector3d(0.01, -0.02, 0.03));
  Simulate(dir, "urdf", params);
  std::string output;
  ASSERT_EQ(testing::RunCommand(std::string(testing::kDebianPython) + " " +
                                    testing::SourceDir() + "/tests/oracle/tf2_lookup.py " +
                                    dir.File("urdf.bag") + " " + params.imu().frame_id() + " " +
                                    params.lidar().frame_id(),
                                &output),
            0)
      << output;
  std::istringstream in(output);
  std::vector<double> v(7);
  for (double& x : v) in >> x;
  ASSERT_TRUE(in) << output;
  const Eigen::Matrix3d c_vb =
      geometry::RotationFromEuler123Deg(ToEigen(params.rig().imu_rotation_in_vehicle_deg()));
  const Eigen::Matrix3d c_bl =
      geometry::RotationFromEuler123Deg(ToEigen(params.rig().lidar_rotation_in_imu_deg())) *
      geometry::RotationFromEuler123Deg(Eigen::Vector3d(0.5, -1.0, 2.0));
  const Eigen::Vector3d r_bl = ToEigen(params.rig().lidar_translation_in_imu_m()) +
                               c_vb.transpose() * Eigen::Vector3d(0.01, -0.02, 0.03);
  const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
  EXPECT_LT(q.angularDistance(Eigen::Quaterniond(c_bl)), 1e-12) << output;
  EXPECT_LT((Eigen::Vector3d(v[0], v[1], v[2]) - r_bl).norm(), 1e-12) << output;
}

}  // namespace
}  // namespace tiltcal
