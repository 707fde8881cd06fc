// A clock offset of seconds between LiDAR and IMU on the short simulated
// sequence (short_sequence_fixture.h): the full solve, so labelled slow.

#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "common/geometry/angles.h"
#include "common/io/eigen_proto.h"
#include "common/io/text_proto.h"
#include "tests/stages/calibrate/short_sequence_fixture.h"

namespace tiltcal::calibrate {
namespace {

using CalibrateClockTest = ShortSequenceTest;

TEST_F(CalibrateClockTest, ClockOffsetOfTwoSecondsIsRecovered) {
  const double shift_s = 2.0;
  for (LidarScan& scan : inputs_.scans) scan.stamp_s -= shift_s;
  const double imu_end_s = inputs_.imu.back().time_s - 2.0;
  while (inputs_.imu.back().time_s > imu_end_s) inputs_.imu.pop_back();
  proto::CalibrationResult result;
  std::string log;
  const Status status = Run(&result, &log);
  ASSERT_TRUE(status.ok()) << status.message() << "\n" << log;
  const double tau_truth = truth_.time_offset_s() + shift_s;
  const Rigid3d est = ToEigen(result.imu_from_lidar());
  const Rigid3d tru = ToEigen(truth_.imu_from_lidar());
  const Eigen::Vector3d up_b = -ToEigen(truth_.gravity_in_world()).normalized();
  const Eigen::Vector3d dt = est.translation - tru.translation;
  const double planar_cm = (dt - dt.dot(up_b) * up_b).norm() * 100.0;
  const double rot_deg = Eigen::AngleAxisd(est.rotation.conjugate() * tru.rotation).angle() *
                         geometry::kDegPerRad;
  const double tau_ms = (result.time_offset_s() - tau_truth) * 1e3;
  std::printf("tau %.1f s: coarse %.4f s (r %.3f, second %.3f, scale %.3f), %d scans dropped; "
              "errors: rotation %.4f deg, planar translation %.3f cm, tau %.3f ms\n",
              tau_truth, result.coarse_time_offset_s(), result.coarse_time_offset_correlation(),
              result.coarse_time_offset_second_peak_correlation(),
              result.gyro_to_lidar_rate_scale(), result.dropped_scans_outside_imu(), rot_deg,
              planar_cm, tau_ms);
  EXPECT_TRUE(result.coarse_time_offset_trusted());
  EXPECT_NEAR(result.coarse_time_offset_s(), tau_truth, 0.05);
  EXPECT_NEAR(result.gyro_to_lidar_rate_scale(), 1.0, 0.1);
  EXPECT_GE(result.dropped_scans_outside_imu(), 15);
  EXPECT_LT(std::abs(tau_ms), 0.5);
  EXPECT_LT(rot_deg, 0.1);
  EXPECT_LT(planar_cm, 1.0);
}

}  // namespace
}  // namespace tiltcal::calibrate
