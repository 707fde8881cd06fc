// Ground segmentation + per-scan plane on ray-cast VLP-16-like scans with a
// known ground plane (the oracle is the scene geometry, not our code).
#include "stages/ground/scan_processor.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "common/geometry/angles.h"
#include "common/io/eigen_proto.h"
#include "tests/stages/ground/ground_test_util.h"
#include "tests/testing/synthetic_lidar.h"

namespace tiltcal::ground {
namespace {

using geometry::AngleBetweenDeg;
using testing::CastScan;
using testing::DefaultGroundParams;
using testing::NoNan;
using testing::NormalOf;
using testing::RollPitchYaw;
using testing::StreetScene;
using testing::SyntheticLidar;
using testing::SyntheticPose;
using testing::SyntheticScene;
using testing::TrueHeight;
using testing::TrueNormal;

double Median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::infinity();
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

struct SequenceErrors {
  std::vector<double> normal_deg;
  std::vector<double> height_m;
  int valid = 0;
  int total = 0;
};

// A smooth sequence of poses over a street scene: roll/pitch amplitudes (deg)
// of the LiDAR relative to the ground, heights around height_m.
SequenceErrors RunSequence(double roll_deg, double pitch_deg, double height_m, int num_scans,
                           const GroundFrame& frame) {
  const proto::GroundParams params = DefaultGroundParams();
  ScanProcessor processor(params, frame, nullptr);
  const SyntheticLidar lidar = SyntheticLidar::Vlp16();
  std::vector<proto::GroundPlane> planes;
  std::vector<SyntheticPose> poses;
  for (int k = 0; k < num_scans; ++k) {
    SyntheticPose pose;
    const double s = static_cast<double>(k) / num_scans;
    pose.position_g = Eigen::Vector3d(0.5 * k, 0.0, height_m + 0.02 * std::sin(7.0 * s));
    pose.g_from_lidar = RollPitchYaw(geometry::DegToRad(roll_deg) * std::cos(3.0 * s),
                                     geometry::DegToRad(pitch_deg) * std::sin(2.0 * s + 0.5),
                                     0.3 * std::sin(5.0 * s));
    const SyntheticScene scene = StreetScene(100 + k);
    proto::Scan scan = CastScan(scene, lidar, pose, 1000000000LL + k * 100000000LL, 7 + k);
    scan.set_index(k);
    planes.push_back(processor.Process(&scan));
    poses.push_back(pose);
  }
  ApplyTiltJumpGate(params.tilt_jump_gate(), &planes);
  SequenceErrors errors;
  for (int k = 0; k < num_scans; ++k) {
    const proto::GroundPlane& plane = planes[k];
    EXPECT_TRUE(NoNan(plane)) << "scan " << k;
    ++errors.total;
    if (!plane.valid()) {
      ADD_FAILURE() << "scan " << k << " rejected: " << plane.reject_detail();
      continue;
    }
    ++errors.valid;
    errors.normal_deg.push_back(AngleBetweenDeg(NormalOf(plane), TrueNormal(poses[k])));
    errors.height_m.push_back(std::fabs(plane.height_m() - TrueHeight(poses[k])));
  }
  return errors;
}

void ExpectAccurate(const SequenceErrors& e) {
  const double normal = Median(e.normal_deg), height = Median(e.height_m);
  ::testing::Test::RecordProperty("median_normal_error_deg", std::to_string(normal));
  ::testing::Test::RecordProperty("median_height_error_mm", std::to_string(height * 1e3));
  std::printf("median normal error %.4f deg, median height error %.2f mm, valid %d/%d\n", normal,
              height * 1e3, e.valid, e.total);
  EXPECT_LE(normal, 0.1);
  EXPECT_LE(height, 0.005);
  EXPECT_GE(e.valid, 0.95 * e.total);
}

TEST(ScanProcessor, FlatSequenceMatchesTruth) {
  ExpectAccurate(RunSequence(0.0, 0.0, 0.85, 20, GroundFrame()));
}

TEST(ScanProcessor, TiltedSequenceMatchesTruth) {
  ExpectAccurate(RunSequence(6.0, -10.0, 0.9, 20, GroundFrame()));
}

TEST(ScanProcessor, HighMountWithHeightPriorMatchesTruth) {
  GroundFrame frame;
  frame.height_prior_m = 1.8;
  ExpectAccurate(RunSequence(2.0, 3.0, 1.73, 10, frame));
}

TEST(ScanProcessor, UpsideDownLidarWithRigUpDirection) {
  // LiDAR mounted upside down under an upright IMU: the rig's flat gravity
  // (IMU frame, pointing down) gives up in the LiDAR frame; the normal must
  // still point towards the sensor (here −z_l) with d > 0.
  proto::Rig rig;
  const Eigen::Quaterniond c_bl(RollPitchYaw(M_PI, 0.0, 0.3));
  *rig.mutable_imu_from_lidar()->mutable_rotation() = ToProto(c_bl);
  rig.mutable_gravity_flat_in_imu()->set_z(-9.81);
  const GroundFrame frame = MakeGroundFrame(rig, DefaultGroundParams().frame());
  ScanProcessor processor(DefaultGroundParams(), frame, nullptr);
  SyntheticPose pose;
  pose.position_g = Eigen::Vector3d(0, 0, 1.2);
  pose.g_from_lidar = RollPitchYaw(M_PI + 0.03, -0.05, 0.3);
  proto::Scan scan = CastScan(StreetScene(3), SyntheticLidar::Vlp16(), pose, 1, 3);
  const proto::GroundPlane plane = processor.Process(&scan);
  ASSERT_TRUE(plane.valid()) << plane.reject_detail();
  EXPECT_LT(AngleBetweenDeg(NormalOf(plane), TrueNormal(pose)), 0.2);
  EXPECT_LT(NormalOf(plane).z(), -0.9);
  EXPECT_NEAR(plane.height_m(), 1.2, 0.01);
}

TEST(ScanProcessor, CovarianceIsPositiveAndMasksMatchCounts) {
  ScanProcessor processor(DefaultGroundParams(), GroundFrame(), nullptr);
  SyntheticPose pose;
  proto::Scan scan = CastScan(StreetScene(5), SyntheticLidar::Vlp16(), pose, 1, 5);
  const proto::GroundPlane plane = processor.Process(&scan);
  ASSERT_TRUE(plane.valid()) << plane.reject_detail();
  ASSERT_EQ(plane.covariance_size(), 16);
  Eigen::Matrix4d cov;
  for (int i = 0; i < 16; ++i) cov(i / 4, i % 4) = plane.covariance(i);
  EXPECT_TRUE(cov.isApprox(cov.transpose()));
  EXPECT_GT(cov(3, 3), 0.0);
  EXPECT_GT(cov(0, 0), 0.0);
  // Height standard deviation is small but not zero for 2 cm noise.
  EXPECT_LT(std::sqrt(cov(3, 3)), 0.005);
  // The normal stays unit: no variance along itself; the floors are applied.
  const Eigen::Vector3d n = NormalOf(plane);
  EXPECT_NEAR(n.dot(cov.topLeftCorner<3, 3>() * n), 0.0, 1e-12);
  const proto::GroundParams params = DefaultGroundParams();
  EXPECT_GE(plane.normal_std_deg(), params.covariance_floor().normal_deg());
  EXPECT_GE(plane.height_std_m(), params.covariance_floor().height_m());
  int ground = 0, inliers = 0;
  for (uint64_t w : plane.ground_mask()) ground += __builtin_popcountll(w);
  for (uint64_t w : plane.inlier_mask()) inliers += __builtin_popcountll(w);
  EXPECT_EQ(static_cast<uint32_t>(ground), plane.num_ground_points());
  EXPECT_EQ(static_cast<uint32_t>(inliers), plane.num_inliers());
  EXPECT_EQ(static_cast<uint32_t>(plane.ground_mask_size()), (plane.num_points() + 63) / 64);
  EXPECT_GT(plane.height_std_m(), 0.0);
  EXPECT_GT(plane.normal_std_deg(), 0.0);
  // Labelled-ground points really lie near the ground (truth z = 0 in g):
  // segmentation precision of the Patchwork++ class (a few percent of wall
  // and car-side feet), and every point of the final fit on the ground.
  const Eigen::Matrix3d r = pose.g_from_lidar;
  int far_from_ground = 0, inlier_off_ground = 0;
  for (int i = 0; i < scan.x_size(); ++i) {
    const Eigen::Vector3d p =
        r * Eigen::Vector3d(scan.x(i), scan.y(i), scan.z(i)) + pose.position_g;
    if (MaskBit(plane.ground_mask(), i) && std::fabs(p.z()) > 0.15) ++far_from_ground;
    if (MaskBit(plane.inlier_mask(), i) && std::fabs(p.z()) > 0.1) ++inlier_off_ground;
  }
  EXPECT_LT(far_from_ground, 0.03 * ground);
  EXPECT_EQ(inlier_off_ground, 0);
}

TEST(ScanProcessor, RaisedSidewalkDoesNotTiltTheRoadPlane) {
  // A 15 cm kerb and sidewalk along one side of the road (labelled ground by
  // the segmentation, as in Patchwork++): the robust fit keeps the road.
  SyntheticScene scene = StreetScene(12);
  scene.boxes.emplace_back(Eigen::Vector3d(-60.0, 2.5, 0.0), Eigen::Vector3d(60.0, 6.0, 0.15));
  ScanProcessor processor(DefaultGroundParams(), GroundFrame(), nullptr);
  SyntheticPose pose;
  pose.position_g = Eigen::Vector3d(0.0, 0.0, 0.85);
  pose.g_from_lidar = RollPitchYaw(0.01, -0.02, 0.0);
  proto::Scan scan = CastScan(scene, SyntheticLidar::Vlp16(), pose, 1, 12);
  const proto::GroundPlane plane = processor.Process(&scan);
  ASSERT_TRUE(plane.valid()) << plane.reject_detail();
  EXPECT_LT(AngleBetweenDeg(NormalOf(plane), TrueNormal(pose)), 0.1);
  EXPECT_NEAR(plane.height_m(), 0.85, 0.005);
}

TEST(ScanProcessor, NoGroundAllWallsIsRejected) {
  SyntheticScene scene;
  scene.ground = false;
  for (double s : {-1.0, 1.0}) {
    scene.planes.push_back(Eigen::Vector4d(1, 0, 0, 6.0 * s));
    scene.planes.push_back(Eigen::Vector4d(0, 1, 0, 4.0 * s));
  }
  ScanProcessor processor(DefaultGroundParams(), GroundFrame(), nullptr);
  proto::Scan scan = CastScan(scene, SyntheticLidar::Vlp16(), SyntheticPose(), 1, 1);
  ASSERT_GT(scan.x_size(), 1000);
  const proto::GroundPlane plane = processor.Process(&scan);
  EXPECT_FALSE(plane.valid());
  EXPECT_NE(plane.reject_reason(), proto::GROUND_OK);
  EXPECT_FALSE(plane.reject_detail().empty());
  EXPECT_TRUE(NoNan(plane));
}

TEST(ScanProcessor, CeilingIsNotGroundWhenTheFloorIsVisible) {
  SyntheticScene scene = StreetScene(9);
  scene.planes.push_back(Eigen::Vector4d(0, 0, 1, -2.6));  // ceiling z = 2.6 m
  ScanProcessor processor(DefaultGroundParams(), GroundFrame(), nullptr);
  SyntheticPose pose;
  pose.position_g = Eigen::Vector3d(0, 0, 0.8);
  proto::Scan scan = CastScan(scene, SyntheticLidar::Vlp16(), pose, 1, 2);
  const proto::GroundPlane plane = processor.Process(&scan);
  ASSERT_TRUE(plane.valid()) << plane.reject_detail();
  EXPECT_NEAR(plane.height_m(), 0.8, 0.005);
  EXPECT_LT(AngleBetweenDeg(NormalOf(plane), TrueNormal(pose)), 0.2);
  // No ceiling point is labelled ground.
  for (int i = 0; i < scan.x_size(); ++i) {
    if (scan.z(i) > 1.0) {
      ASSERT_FALSE(MaskBit(plane.ground_mask(), i)) << "ceiling point " << i << " labelled ground";
    }
  }
}

TEST(ScanProcessor, CeilingWithoutFloorIsRejected) {
  SyntheticScene scene;
  scene.ground = false;
  scene.planes.push_back(Eigen::Vector4d(0, 0, 1, -2.0));  // ceiling z = 2 m
  for (double s : {-1.0, 1.0}) {
    scene.planes.push_back(Eigen::Vector4d(1, 0, 0, 15.0 * s));
    scene.planes.push_back(Eigen::Vector4d(0, 1, 0, 15.0 * s));
  }
  ScanProcessor processor(DefaultGroundParams(), GroundFrame(), nullptr);
  SyntheticPose pose;
  pose.position_g = Eigen::Vector3d(0, 0, 0.0);
  proto::Scan scan = CastScan(scene, SyntheticLidar::Vlp16(), pose, 1, 2);
  const proto::GroundPlane plane = processor.Process(&scan);
  EXPECT_FALSE(plane.valid());
  EXPECT_NE(plane.reject_reason(), proto::GROUND_OK);
  EXPECT_TRUE(NoNan(plane));
}

TEST(ScanProcessor, EmptyAndNanScansAreRejectedAsEmpty) {
  ScanProcessor processor(DefaultGroundParams(), GroundFrame(), nullptr);
  proto::Scan empty;
  proto::GroundPlane plane = processor.Process(&empty);
  EXPECT_FALSE(plane.valid());
  EXPECT_EQ(plane.reject_reason(), proto::GROUND_EMPTY_SCAN);
  EXPECT_TRUE(NoNan(plane));

  proto::Scan nan_scan;
  for (int i = 0; i < 500; ++i) {
    nan_scan.add_x(std::numeric_limits<float>::quiet_NaN());
    nan_scan.add_y(1.0f);
    nan_scan.add_z(-1.0f);
  }
  plane = processor.Process(&nan_scan);
  EXPECT_FALSE(plane.valid());
  EXPECT_EQ(plane.reject_reason(), proto::GROUND_EMPTY_SCAN);
  EXPECT_TRUE(NoNan(plane));
}

TEST(ScanProcessor, FewPointsOnALineFailCleanly) {
  ScanProcessor processor(DefaultGroundParams(), GroundFrame(), nullptr);
  proto::Scan line;
  for (int i = 0; i < 400; ++i) {  // a straight line on the ground
    line.add_x(3.0f + 0.01f * i);
    line.add_y(0.0f);
    line.add_z(-1.0f);
  }
  const proto::GroundPlane plane = processor.Process(&line);
  EXPECT_FALSE(plane.valid());
  EXPECT_NE(plane.reject_reason(), proto::GROUND_OK);
  EXPECT_TRUE(NoNan(plane));
}

TEST(ScanProcessor, ResultDoesNotDependOnScanOrder) {
  const proto::GroundParams params = DefaultGroundParams();
  SyntheticPose pose_a, pose_b;
  pose_b.g_from_lidar = RollPitchYaw(0.1, -0.05, 1.0);
  pose_b.position_g.z() = 1.4;
  const proto::Scan a = CastScan(StreetScene(1), SyntheticLidar::Vlp16(), pose_a, 1, 1);
  const proto::Scan b = CastScan(StreetScene(2), SyntheticLidar::Vlp16(), pose_b, 2, 2);
  ScanProcessor first(params, GroundFrame(), nullptr), second(params, GroundFrame(), nullptr);
  proto::Scan a1 = a, a2 = a, b1 = b, b2 = b, b3 = b;
  const std::string plane_a_first = first.Process(&a1).SerializeAsString();
  second.Process(&b2);
  const std::string plane_a_second = second.Process(&a2).SerializeAsString();
  EXPECT_EQ(plane_a_first, plane_a_second);
  EXPECT_EQ(first.Process(&b1).SerializeAsString(), second.Process(&b3).SerializeAsString());
}

TEST(ScanProcessor, HeightPriorGateRejectsAWrongHeight) {
  GroundFrame frame;
  frame.height_prior_m = 2.0;  // true height 1.0 m, gate 0.3 m
  ScanProcessor processor(DefaultGroundParams(), frame, nullptr);
  proto::Scan scan = CastScan(StreetScene(4), SyntheticLidar::Vlp16(), SyntheticPose(), 1, 4);
  const proto::GroundPlane plane = processor.Process(&scan);
  EXPECT_FALSE(plane.valid());
  EXPECT_EQ(plane.reject_reason(), proto::GROUND_HEIGHT_PRIOR) << plane.reject_detail();
  EXPECT_TRUE(NoNan(plane));
}

TEST(TiltJumpGate, RejectsTheOutlierOnly) {
  std::vector<proto::GroundPlane> planes(9);
  for (int i = 0; i < 9; ++i) {
    planes[i].set_valid(true);
    const double tilt = geometry::DegToRad(i == 4 ? 6.0 : 0.1 * i);
    planes[i].mutable_normal_in_lidar()->set_y(std::sin(tilt));
    planes[i].mutable_normal_in_lidar()->set_z(std::cos(tilt));
  }
  ApplyTiltJumpGate(
      testing::GroundParamsWith("tilt_jump_gate { max_jump_deg: 3.0 window: 3 }").tilt_jump_gate(),
      &planes);
  for (int i = 0; i < 9; ++i) {
    EXPECT_EQ(planes[i].valid(), i != 4) << i;
  }
  EXPECT_EQ(planes[4].reject_reason(), proto::GROUND_TILT_JUMP);
  EXPECT_NEAR(planes[4].tilt_jump_deg(), 6.0 - 0.4, 0.2);
}

}  // namespace
}  // namespace tiltcal::ground
