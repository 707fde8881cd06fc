#include "stages/calibrate/report/residual_statistics.h"

#include <cmath>

#include <ceres/problem.h>
#include <gtest/gtest.h>

#include "stages/calibrate/residuals/gyro_cost_function.h"

namespace tiltcal::calibrate {
namespace {

// Bins of 0.25 from -5: -5.0 is bin 0, -0.1 bin 19, 0.0 and 0.2 bin 20,
// 4.99 bin 39; -5.01 is below, 5.0 above.
TEST(ResidualHistogram, CountsSignedValuesPerBinAndOutsideTheRange) {
  const proto::ResidualStatistics s =
      SummariseResiduals("lidar", {-5.0, -0.1, 0.0, 0.2, 4.99, -5.01, 5.0, 7.0});
  EXPECT_EQ(s.histogram_min(), -5.0);
  EXPECT_EQ(s.histogram_bin_width(), 0.25);
  ASSERT_EQ(s.histogram_counts_size(), 40);
  EXPECT_EQ(s.histogram_counts(0), 1);
  EXPECT_EQ(s.histogram_counts(19), 1);
  EXPECT_EQ(s.histogram_counts(20), 2);
  EXPECT_EQ(s.histogram_counts(39), 1);
  int inside = 0;
  for (const int c : s.histogram_counts()) inside += c;
  EXPECT_EQ(inside, 5);
  EXPECT_EQ(s.histogram_below(), 1);
  EXPECT_EQ(s.histogram_above(), 2);
  EXPECT_EQ(s.count(), 8);
}

// Four bins over [0, 4) s: bin 0 holds 1..20 (nearest rank: 5 % -> 1st,
// median -> 10th, 95 % -> 19th), bin 1 nothing, bin 2 a single -3, and a
// value at 4.5 s is clamped into the last bin.
TEST(ResidualTimeSeries, BinsQuantilesAndRms) {
  std::vector<TimedResidual> values;
  for (int i = 1; i <= 20; ++i) values.push_back({0.5, static_cast<double>(i)});
  values.push_back({2.2, -3.0});
  values.push_back({4.5, 2.0});
  proto::ResidualStatistics s;
  FillTimeSeries(values, 0.0, 4.0, 4, &s);
  EXPECT_EQ(s.time_start_s(), 0.0);
  EXPECT_EQ(s.time_bin_s(), 1.0);
  ASSERT_EQ(s.time_bin_count_size(), 4);
  EXPECT_EQ(s.time_bin_count(0), 20);
  EXPECT_EQ(s.time_bin_count(1), 0);
  EXPECT_EQ(s.time_bin_count(2), 1);
  EXPECT_EQ(s.time_bin_count(3), 1);
  EXPECT_FLOAT_EQ(s.time_bin_p05(0), 1.0f);
  EXPECT_FLOAT_EQ(s.time_bin_median(0), 10.0f);
  EXPECT_FLOAT_EQ(s.time_bin_p95(0), 19.0f);
  EXPECT_FLOAT_EQ(s.time_bin_rms(0), std::sqrt(2870.0f / 20.0f));  // sum i^2 = 2870
  EXPECT_FLOAT_EQ(s.time_bin_rms(1), 0.0f);
  EXPECT_FLOAT_EQ(s.time_bin_median(2), -3.0f);
  EXPECT_FLOAT_EQ(s.time_bin_rms(2), 3.0f);
  EXPECT_FLOAT_EQ(s.time_bin_p95(3), 2.0f);
}

// Gyro residuals dated by their spline segment: on an identity spline with
// zero bias the normalised residual is -omega_m / sigma, so samples measured
// at +1 sigma in the first second and -2 sigma after 3 s land in the first
// and last of four bins with medians -1 and +2 (per component).
TEST(ResidualTimeSeries, ResidualBlocksAreDatedByTheirSplineSegment) {
  const spline::UniformKnotGrid grid = spline::UniformKnotGrid::ForDuration(0.0, 4.0, 0.1);
  CalibrationState state(grid);
  ASSERT_TRUE(state.SetBiasSegments(0.0, 0.0).ok());
  ceres::Problem::Options options;
  ceres::Problem problem(options);
  const double sigma = 0.01;
  for (const double t : {0.12, 0.47, 0.93, 3.05, 3.51, 3.97}) {
    spline::KnotWindow w;
    ASSERT_TRUE(grid.Locate(t, &w));
    const double measured = (t < 1.0 ? 1.0 : -2.0) * sigma;
    std::vector<double*> blocks;
    for (int k = 0; k < 4; ++k) blocks.push_back(state.trajectory.rotation_knot(w.first_knot + k));
    blocks.push_back(state.gyro_bias.values[0].data());
    blocks.push_back(state.gyro_triad_errors.data());
    problem.AddResidualBlock(
        new GyroCostFunction(w, 1.0 / grid.dt_s(), Eigen::Vector3d::Constant(measured), sigma),
        nullptr, blocks);
  }
  proto::ResidualTimeSeriesParams params;
  params.set_bins(4);
  const auto stats = ComputeResidualStatistics(&problem, state, params);
  ASSERT_EQ(stats.size(), 1u);
  const proto::ResidualStatistics& s = stats[0];
  EXPECT_EQ(s.type(), "gyro");
  EXPECT_DOUBLE_EQ(s.time_bin_s(), grid.num_segments() * grid.dt_s() / 4);
  ASSERT_EQ(s.time_bin_count_size(), 4);
  EXPECT_EQ(s.time_bin_count(0), 9);
  EXPECT_EQ(s.time_bin_count(1), 0);
  EXPECT_EQ(s.time_bin_count(2), 0);
  EXPECT_EQ(s.time_bin_count(3), 9);
  EXPECT_NEAR(s.time_bin_median(0), -1.0, 1e-6);
  EXPECT_NEAR(s.time_bin_median(3), 2.0, 1e-6);
}

}  // namespace
}  // namespace tiltcal::calibrate
