// The initialisation's LiDAR odometry in the result and the log, on the
// short simulated sequence (short_sequence_fixture.h): its scan counts
// always, its registration quality when odometry.registration_quality asks
// for it (GICP), and the same calibration either way. Two full solves.

#include <cstdio>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "tests/stages/calibrate/short_sequence_fixture.h"

namespace tiltcal::calibrate {
namespace {

using OdometryQualityReportTest = ShortSequenceTest;

TEST_F(OdometryQualityReportTest, QualityReachesResultAndLogOnlyWhenMeasured) {
  proto::CalibrateParams without = LidarImuParams();
  ASSERT_EQ(without.odometry().method(), proto::LidarOdometryParams::GICP);
  ASSERT_FALSE(without.odometry().registration_quality());
  proto::CalibrateParams with = without;
  with.mutable_odometry()->set_registration_quality(true);

  proto::CalibrationResult plain, measured;
  std::ostringstream plain_log, measured_log;
  const Status plain_status = Calibrate(inputs_, without, &plain, nullptr, &plain_log);
  ASSERT_TRUE(plain_status.ok()) << plain_status.message() << "\n" << plain_log.str();
  const Status measured_status = Calibrate(inputs_, with, &measured, nullptr, &measured_log);
  ASSERT_TRUE(measured_status.ok()) << measured_status.message() << "\n" << measured_log.str();

  // 16 s of 10 Hz scans: nearly all given to the odometry and registered.
  for (const proto::CalibrationResult* r : {&plain, &measured}) {
    EXPECT_GE(r->odometry_scans(), 150);
    EXPECT_GE(r->odometry_registered_scans(), r->odometry_scans() - 3);
  }

  // Off: nothing measured, nothing claimed.
  EXPECT_EQ(plain.odometry_quality_scans(), 0);
  EXPECT_EQ(plain.odometry_mean_fitness_m(), 0.0);
  EXPECT_EQ(plain.odometry_mean_inlier_fraction(), 0.0);
  EXPECT_EQ(plain_log.str().find("odometry registration quality"), std::string::npos);

  // On: a good registration of a LiDAR with 15 mm range noise sits within a
  // few noise sigmas of the map's planes, with most points inliers.
  std::printf("odometry: %d scans, %d registered, quality over %d: inlier rms %.2f mm, "
              "inliers %.1f %%\n",
              measured.odometry_scans(), measured.odometry_registered_scans(),
              measured.odometry_quality_scans(), measured.odometry_mean_fitness_m() * 1e3,
              measured.odometry_mean_inlier_fraction() * 100.0);
  EXPECT_GE(measured.odometry_quality_scans(), measured.odometry_registered_scans() - 3);
  EXPECT_LE(measured.odometry_quality_scans(), measured.odometry_registered_scans());
  EXPECT_GT(measured.odometry_mean_fitness_m(), 0.005);
  EXPECT_LT(measured.odometry_mean_fitness_m(), 0.045);
  EXPECT_GT(measured.odometry_mean_inlier_fraction(), 0.8);
  EXPECT_LE(measured.odometry_mean_inlier_fraction(), 1.0);
  EXPECT_NE(measured_log.str().find("odometry registration quality over"), std::string::npos)
      << measured_log.str();

  // A diagnostic: the calibration does not depend on it.
  EXPECT_EQ(plain.imu_from_lidar().DebugString(), measured.imu_from_lidar().DebugString());
  EXPECT_EQ(plain.time_offset_s(), measured.time_offset_s());
  EXPECT_EQ(plain.verdict(), measured.verdict());
}

}  // namespace
}  // namespace tiltcal::calibrate
