// The I/O-free parts of `tiltcal_inspect check`: stamp statistics, sign
// changes, excitation, scan geometry and the params rules.
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bag/ros1/message_encoding.h"
#include "bag/ros1/messages.h"
#include "stages/inspect/check.h"
#include "common/timing/clock_rate.h"
#include "stages/inspect/default_params_text.h"
#include "stages/inspect/excitation.h"
#include "stages/inspect/point_cloud_sample.h"
#include "stages/inspect/scan_geometry.h"
#include "stages/inspect/stamp_statistics.h"
#include "tests/testing/params_text.h"

namespace tiltcal::inspect {
namespace {

// 60 s of 10 Hz messages received with a delay of 2 ms plus an exponential
// queueing delay (mean 3 ms) on a recorder whose clock the stamps run
// `ppm` fast against.
void DriftingStamps(double ppm, std::vector<int64_t>* stamps, std::vector<int64_t>* records) {
  std::mt19937 rng(3);
  std::exponential_distribution<double> queueing(1.0 / 0.003);
  for (int i = 0; i < 600; ++i) {
    const double t = 0.1 * i;
    const double delay = 0.002 + queueing(rng);
    stamps->push_back(1'000'000'000'000LL + std::llround(1e9 * t * (1.0 + ppm * 1e-6)));
    records->push_back(1'000'000'000'000LL + std::llround(1e9 * (t + delay)));
  }
}

TEST(ClockRate, SlopeOfStampMinusRecordInPpm) {
  for (const double ppm : {0.0, 50.0, -120.0}) {
    std::vector<int64_t> stamps, records;
    DriftingStamps(ppm, &stamps, &records);
    const timing::ClockRate r = timing::EstimateClockRate(stamps, records, 5.0);
    ASSERT_TRUE(r.measured);
    EXPECT_FALSE(r.stamps_are_record);
    EXPECT_EQ(r.windows, 12);
    // The queueing delay's medians scatter by about 0.3 ms per window:
    // sigma ~ 0.3e-3 / sqrt(sum (t - mean)^2) ~ 5 ppm.
    EXPECT_NEAR(r.rate_ppm, ppm, 3.0 * r.sigma_ppm + 1.0) << ppm;
    EXPECT_LT(r.sigma_ppm, 10.0);
  }
}

TEST(ClockRate, StampsThatAreTheRecordTimesAndTooFewWindows) {
  std::vector<int64_t> stamps;
  for (int i = 0; i < 100; ++i) stamps.push_back(1'000'000'000LL * i);
  const timing::ClockRate same = timing::EstimateClockRate(stamps, stamps, 5.0);
  EXPECT_TRUE(same.stamps_are_record);
  EXPECT_TRUE(same.measured);
  EXPECT_EQ(same.rate_ppm, 0.0);
  const timing::ClockRate short_one = timing::EstimateClockRate(stamps, stamps, 50.0);  // 2 windows
  EXPECT_FALSE(short_one.measured);
}

TEST(StampStatistics, RateJitterGapsDuplicatesAndBackwards) {
  // 100 Hz with a 50 ms hole after 1.00 s, one repeated and one backward stamp.
  std::vector<int64_t> stamps;
  for (int i = 0; i <= 100; ++i) stamps.push_back(10'000'000LL * i);
  for (int i = 105; i <= 200; ++i) stamps.push_back(10'000'000LL * i);
  stamps.push_back(stamps.back());              // repeated
  stamps.push_back(stamps.back() - 5'000'000);  // backwards
  stamps.push_back(10'000'000LL * 201);
  const StampStatistics s = ComputeStampStatistics(stamps, 3.0);
  EXPECT_EQ(s.count, static_cast<int64_t>(stamps.size()));
  EXPECT_EQ(s.first_ns, 0);
  EXPECT_EQ(s.last_ns, 2'010'000'000);
  EXPECT_NEAR(s.nominal_interval_s, 0.01, 1e-12);
  EXPECT_NEAR(s.rate_hz, 100.0, 1e-9);
  EXPECT_EQ(s.num_gaps, 1);
  EXPECT_NEAR(s.longest_gap_s, 0.05, 1e-12);
  EXPECT_EQ(s.num_missing, 4);
  EXPECT_EQ(s.num_duplicates, 1);
  EXPECT_EQ(s.num_backwards, 1);
  // Positive intervals that are not gaps: 100 + 95 of 10 ms and one of 15 ms
  // (after the backward step): σ = 5 ms · sqrt(195)/196.
  EXPECT_NEAR(s.interval_stddev_s, 0.005 * std::sqrt(195.0) / 196.0, 1e-9);
}

// 10 Hz scans with single scans dropped (5 %) and one run of three: with the
// LiDAR's gap factor 1.5 every drop is a gap and counted, and the jitter is
// that of the scans kept (before, a factor 3 let a dropped scan pass as
// 25 ms of jitter and "no gaps").
TEST(StampStatistics, DroppedScansAreGapsWithTheirCount) {
  std::vector<int64_t> stamps;
  int64_t dropped = 0;
  for (int i = 0; i < 400; ++i) {
    const bool drop = (i % 20 == 7) || (i >= 300 && i < 303);
    if (drop) {
      ++dropped;
      continue;
    }
    stamps.push_back(100'000'000LL * i);
  }
  const StampStatistics s = ComputeStampStatistics(stamps, 1.5);
  EXPECT_EQ(s.num_gaps, 21);  // 20 single drops and the run of 3
  EXPECT_EQ(s.num_missing, dropped);
  EXPECT_NEAR(s.longest_gap_s, 0.4, 1e-12);
  EXPECT_NEAR(s.interval_stddev_s, 0.0, 1e-12);
  EXPECT_NEAR(s.rate_hz, 10.0, 1e-9);
}

TEST(StampStatistics, JitterOfAlternatingIntervals) {
  std::vector<int64_t> stamps{0};
  for (int i = 0; i < 1000; ++i) stamps.push_back(stamps.back() + (i % 2 ? 4'900'000 : 5'100'000));
  const StampStatistics s = ComputeStampStatistics(stamps, 3.0);
  EXPECT_NEAR(s.interval_stddev_s, 1e-4, 1e-9);
  EXPECT_EQ(s.num_gaps, 0);
  EXPECT_NEAR(s.rate_hz, 200.0, 4.0);
}

TEST(SignChanges, HysteresisIgnoresNoiseAroundZero) {
  EXPECT_EQ(CountSignChanges({0.0, 0.2, -0.2, 0.2, -0.2}, 0.5), 0);
  EXPECT_EQ(CountSignChanges({1.0, 0.2, -0.2, -1.0, 0.0, 1.0, 1.0}, 0.5), 2);
  EXPECT_EQ(CountSignChanges({-1.0, 1.0, -1.0, 1.0}, 0.5), 3);
  EXPECT_EQ(CountSignChanges({}, 0.5), 0);
}

TEST(MovingAverage, CentredWindowShrinksAtTheEnds) {
  const std::vector<double> out = MovingAverage({0, 3, 6, 9}, 3);
  ASSERT_EQ(out.size(), 4u);
  EXPECT_DOUBLE_EQ(out[0], 1.5);
  EXPECT_DOUBLE_EQ(out[1], 3.0);
  EXPECT_DOUBLE_EQ(out[2], 6.0);
  EXPECT_DOUBLE_EQ(out[3], 7.5);
}

TEST(Excitation, SlalomGivesYawSignChangesAboutTheUpAxis) {
  // IMU upside down (up = −z in b), 200 Hz, yaw rate 0.5 sin(2π t / 4) for
  // 20 s: sign changes every 2 s → 9; lateral acceleration 1.0 cos(...) along
  // b's y changes sign 10 times.
  std::vector<imu::ImuReading> samples;
  const Eigen::Vector3d bias(0.01, -0.02, 0.03);
  const Eigen::Vector3d f_rest(0, 0, -9.81);
  for (int i = 0; i <= 4000; ++i) {
    imu::ImuReading r;
    r.time_s = 0.005 * i;
    const double phase = 2.0 * M_PI * r.time_s / 4.0;
    r.angular_velocity_radps = bias + Eigen::Vector3d(0, 0, -0.5 * std::sin(phase));
    r.linear_acceleration_mps2 = f_rest + Eigen::Vector3d(0, std::cos(phase), 0);
    samples.push_back(r);
  }
  const ImuExcitation e = MeasureImuExcitation(samples, bias, f_rest, {0.5, 0.05, 0.2});
  EXPECT_EQ(e.yaw_rate_sign_changes, 9);
  EXPECT_EQ(e.lateral_accel_reversals, 10);
  EXPECT_FALSE(e.lateral_axis_is_x);
  EXPECT_NEAR(e.max_abs_yaw_rate_radps, 0.5, 0.02);
  // |sin| of a uniform phase: P(|sin| ≤ s) = (2/π) asin s.
  EXPECT_NEAR(e.rotation_speed_p95_radps, 0.5 * std::sin(0.95 * M_PI / 2), 0.005);
}

// Points of a flat ground 1.5 m below the sensor (every 0.5 m within 10 m)
// and a wall 3 m high at x = 8 m, in a LiDAR frame rotated about x by 180°
// (up = −z).
void GroundAndWall(std::vector<float>* x, std::vector<float>* y, std::vector<float>* z) {
  for (double u = -10; u <= 10; u += 0.5) {
    for (double v = -10; v <= 10; v += 0.5) {
      if (u * u + v * v > 100.0) continue;
      x->push_back(u);
      y->push_back(-v);
      z->push_back(1.5f);
    }
  }
  for (double v = -5; v <= 5; v += 0.25) {
    for (double h = -1.5; h <= 1.5; h += 0.25) {
      x->push_back(8.0f);
      y->push_back(-v);
      z->push_back(-h);
    }
  }
}

TEST(ScanGeometry, FindsTheGroundAndTheStructureAlongUp) {
  std::vector<float> x, y, z;
  GroundAndWall(&x, &y, &z);
  ScanGeometryOptions options;
  options.ground_min_depth_m = 0.3;
  options.ground_max_range_m = 15.0;
  options.ground_inlier_distance_m = 0.1;
  options.ground_max_tilt_deg = 25.0;
  options.min_ground_fraction = 0.1;
  options.ground_fit_max_iterations = 5;
  options.structure_min_height_m = 0.5;
  options.structure_max_range_m = 30.0;
  const ScanGeometry g = MeasureScanGeometry(x, y, z, Eigen::Vector3d(0, 0, -1), options);
  EXPECT_TRUE(g.has_ground);
  EXPECT_NEAR(g.ground_tilt_deg, 0.0, 1e-3);
  const double n = static_cast<double>(x.size());
  double num_ground = 0;
  for (float zi : z) num_ground += zi == 1.5f ? 1 : 0;  // the ground and the wall's foot
  EXPECT_NEAR(g.ground_fraction, num_ground / n, 1e-9);
  // Wall points higher than 0.5 m: 0.75, 1.0, 1.25, 1.5 m, 41 each.
  EXPECT_NEAR(g.structure_fraction, 41.0 * 4.0 / n, 1e-9);
  // With the wrong up (+z), the ground is overhead: no ground.
  const ScanGeometry wrong = MeasureScanGeometry(x, y, z, Eigen::Vector3d(0, 0, 1), options);
  EXPECT_FALSE(wrong.has_ground);
}

TEST(ScanGeometry, EmptyScanHasNothing) {
  const ScanGeometry g = MeasureScanGeometry({}, {}, {}, Eigen::Vector3d::UnitZ(), {});
  EXPECT_FALSE(g.has_ground);
  EXPECT_EQ(g.num_points, 0u);
}

// A cloud of 4 points (x, y, z FLOAT32, then the time fields, then a UINT16
// ring) stamped 1 ns before a whole second: point k at stamp − 0.03 k s.
struct TestCloud {
  std::string message;
  ros1::PointCloud2View view;
};

void AppendBytes(std::string* data, const void* value, size_t size) {
  data->append(static_cast<const char*>(value), size);
}

void MakeCloud(bool sec_nsec, TestCloud* cloud) {
  const int64_t stamp_ns = 1700000000999999999LL;
  std::vector<ros1::PointField> fields = {{"x", 0, ros1::kFloat32, 1},
                                          {"y", 4, ros1::kFloat32, 1},
                                          {"z", 8, ros1::kFloat32, 1}};
  uint32_t step = 12;
  if (sec_nsec) {
    fields.push_back({"time_sec", 12, ros1::kUint32, 1});
    fields.push_back({"time_nsec", 16, ros1::kUint32, 1});
    step = 20;
  } else {
    fields.push_back({"t", 12, ros1::kUint32, 1});  // Ouster: ns after the stamp
    step = 16;
  }
  fields.push_back({"ring", step, ros1::kUint16, 1});
  step += 2;
  std::string data;
  for (int k = 0; k < 4; ++k) {
    const float xyz[3] = {1.0f + k, 2.0f, -1.5f};
    AppendBytes(&data, xyz, sizeof(xyz));
    if (sec_nsec) {
      const int64_t t_ns = stamp_ns - 30'000'000LL * k;
      const uint32_t sec = static_cast<uint32_t>(t_ns / 1000000000);
      const uint32_t nsec = static_cast<uint32_t>(t_ns % 1000000000);
      AppendBytes(&data, &sec, 4);
      AppendBytes(&data, &nsec, 4);
    } else {
      const uint32_t t = 30'000'000u * k;
      AppendBytes(&data, &t, 4);
    }
    const uint16_t ring = static_cast<uint16_t>(k);
    AppendBytes(&data, &ring, 2);
  }
  ASSERT_TRUE(ros1::SerializePointCloud2(0, stamp_ns, "lidar", 1, 4, fields, step, data, true,
                                         &cloud->message));
  ASSERT_TRUE(ros1::DecodePointCloud2(reinterpret_cast<const uint8_t*>(cloud->message.data()),
                                      cloud->message.size(), &cloud->view)
                  .ok());
}

TEST(PointCloudSample, AbsoluteSecondsAndNanosecondsNearASecondBoundary) {
  TestCloud cloud;
  MakeCloud(/*sec_nsec=*/true, &cloud);
  const CloudLayout layout = DescribeCloudLayout(cloud.view);
  EXPECT_TRUE(layout.has_xyz);
  EXPECT_EQ(layout.time_field, "time_sec+time_nsec");
  EXPECT_EQ(layout.time_type, "UINT32");
  EXPECT_EQ(layout.ring_field, "ring");
  EXPECT_EQ(layout.ring_type, "UINT16");
  CloudSample sample;
  ASSERT_TRUE(SampleCloud(cloud.view, 1, &sample).ok());
  ASSERT_EQ(sample.x.size(), 4u);
  EXPECT_FLOAT_EQ(sample.x[3], 4.0f);
  ASSERT_TRUE(sample.has_time);
  EXPECT_NEAR(sample.min_time_offset_s, -0.09, 1e-9);
  EXPECT_NEAR(sample.max_time_offset_s, 0.0, 1e-9);
  // Every 2nd point: points 0 and 2.
  ASSERT_TRUE(SampleCloud(cloud.view, 2, &sample).ok());
  EXPECT_EQ(sample.x.size(), 2u);
  EXPECT_NEAR(sample.min_time_offset_s, -0.06, 1e-9);
}

TEST(PointCloudSample, OusterNanosecondsAfterTheStamp) {
  TestCloud cloud;
  MakeCloud(/*sec_nsec=*/false, &cloud);
  EXPECT_EQ(DescribeCloudLayout(cloud.view).time_meaning, "ns after the stamp");
  CloudSample sample;
  ASSERT_TRUE(SampleCloud(cloud.view, 1, &sample).ok());
  EXPECT_NEAR(sample.min_time_offset_s, 0.0, 1e-12);
  EXPECT_NEAR(sample.max_time_offset_s, 0.09, 1e-12);
}

TEST(PointCloudSample, FieldOutsideThePointIsAnError) {
  TestCloud cloud;
  MakeCloud(/*sec_nsec=*/false, &cloud);
  cloud.view.fields[2].offset = 100;  // z
  CloudSample sample;
  const Status status = SampleCloud(cloud.view, 1, &sample);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message(), "field 'z' lies outside the point (offset 100, point_step 18)");
}

TEST(CheckParams, DefaultsAreValidAndRulesNameTheField) {
  const auto defaults = testing::DefaultParamsWith<proto::CheckParams>(DefaultParamsText());
  EXPECT_TRUE(CheckParamsAreValid(defaults).ok());
  const auto hop = testing::DefaultParamsWith<proto::CheckParams>(
      DefaultParamsText(), "static_detection { hop_s: 1.0 window_s: 0.5 }");
  const Status status = CheckParamsAreValid(hop);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("static_detection.hop_s"), std::string::npos) << status.message();
  const auto rates = testing::DefaultParamsWith<proto::CheckParams>(
      DefaultParamsText(), "imu { min_rotation_radps: 0.9 max_vehicle_turn_rate_radps: 0.5 }");
  EXPECT_NE(CheckParamsAreValid(rates).message().find("imu.min_rotation_radps"), std::string::npos);
}

}  // namespace
}  // namespace tiltcal::inspect
