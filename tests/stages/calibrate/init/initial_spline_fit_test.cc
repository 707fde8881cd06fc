// Initialisation fits of the calibrator's splines (initialisation.h):
//  - step 4c: a gyro-only rotation spline drifts in heading when the gyro
//    bias it was given is off; refitted to the gyro and orientation samples
//    (10 Hz, as from the LiDAR odometry) it follows the samples;
//  - step 5: the position spline fitted to LiDAR position samples and the
//    accelerometer recovers the accelerometer bias and a lever arm given
//    half a metre off, and keeps the positions, where a bias held at zero
//    would bend them; with a drifting bias, its piecewise-constant segments
//    (tied by the random-walk prior) follow the drift;
//  - the problem builder's gyro bias segments: with 10 Hz orientation samples
//    (as the LiDAR gives) they follow a drifting gyro bias, which a constant
//    b_g can only average;
//  - the state's bias segments: count, lookup, clamping, mean.
//
// Truth (closed form, C_ab(0) = 1 as the gyro integration starts): planar
// driving with a wobble,
//   C_ab(t) = Exp(phi(t)),  phi = (0.02 sin 3t, 0.02 sin 2t, 1.2 sin 0.5t),
//   omega_b = J_r(phi) phi',
//   r_a(t) = (2 sin 0.4t, 1.5 (cos 0.3t - 1), 0),  f_b = C_ab^T (r_a'' - g_a).

#include <cmath>
#include <random>
#include <vector>

#include <ceres/problem.h>
#include <ceres/solver.h>
#include <gtest/gtest.h>

#include "common/geometry/so3.h"
#include "common/spline/knot_grid.h"
#include "stages/calibrate/init/initialisation.h"
#include "stages/calibrate/problem/calibration_state.h"
#include "stages/calibrate/problem/problem_builder.h"
#include "stages/calibrate/residuals/orientation_sample_cost_function.h"
#include "tests/stages/calibrate/calibrate_params_text.h"
#include "tests/testing/random_vector.h"

namespace tiltcal::calibrate {
namespace {

constexpr double kDuration = 40.0;
constexpr double kImuRate = 200.0;
const Eigen::Vector3d kGravity(0.0, 0.0, -9.81);

Eigen::Vector3d Phi(double t) {
  return {0.02 * std::sin(3.0 * t), 0.02 * std::sin(2.0 * t), 1.2 * std::sin(0.5 * t)};
}
Eigen::Vector3d PhiDot(double t) {
  return {0.06 * std::cos(3.0 * t), 0.04 * std::cos(2.0 * t), 0.6 * std::cos(0.5 * t)};
}
Eigen::Matrix3d Rotation(double t) { return geometry::ExpMatrix(Phi(t)); }
Eigen::Vector3d Position(double t) {
  return {2.0 * std::sin(0.4 * t), 1.5 * (std::cos(0.3 * t) - 1.0), 0.0};
}
Eigen::Vector3d Acceleration(double t) {
  return {-0.32 * std::sin(0.4 * t), -0.135 * std::cos(0.3 * t), 0.0};
}

// Biases b_g(t) = gyro_bias + gyro_bias_drift * t,
// b_a(t) = accel_bias + accel_bias_drift * t.
std::vector<imu::ImuReading> Imu(const Eigen::Vector3d& gyro_bias,
                                 const Eigen::Vector3d& accel_bias, std::mt19937* rng,
                                 const Eigen::Vector3d& accel_bias_drift = Eigen::Vector3d::Zero(),
                                 const Eigen::Vector3d& gyro_bias_drift = Eigen::Vector3d::Zero()) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<imu::ImuReading> out;
  for (int i = 0; i <= static_cast<int>(kDuration * kImuRate); ++i) {
    const double t = i / kImuRate;
    imu::ImuReading r;
    r.time_s = t;
    r.angular_velocity_radps = geometry::RightJacobian(Phi(t)) * PhiDot(t) + gyro_bias +
                               gyro_bias_drift * t + 0.002 * tiltcal::testing::RandomVector3(n, *rng);
    r.linear_acceleration_mps2 = Rotation(t).transpose() * (Acceleration(t) - kGravity) +
                                 accel_bias + accel_bias_drift * t +
                                 0.014 * tiltcal::testing::RandomVector3(n, *rng);
    out.push_back(r);
  }
  return out;
}

// Largest rotation angle between the spline and the truth on a 0.1 s grid, rad.
double MaxRotationError(const CalibrationState& state) {
  double worst = 0.0;
  for (double t = 0.5; t < kDuration - 0.5; t += 0.1) {
    spline::So3SplineSample rot;
    if (!state.trajectory.Evaluate(t, spline::kSo3Rotation, &rot, nullptr)) continue;
    worst = std::max(worst, geometry::LogMatrix(Rotation(t).transpose() * rot.rotation).norm());
  }
  return worst;
}

// LiDAR positions p_l = r_a^{ba} + C_ab r_b^{lb} at 10 Hz, 1 cm noise.
void LidarPositions(const Eigen::Vector3d& r_bl, std::mt19937* rng, std::vector<double>* times,
                    std::vector<Eigen::Vector3d>* positions) {
  std::normal_distribution<double> n(0.0, 1.0);
  for (double t = 0.1; t < kDuration - 0.1; t += 0.1) {
    times->push_back(t);
    positions->push_back(Position(t) + Rotation(t) * r_bl +
                         0.01 * tiltcal::testing::RandomVector3(n, *rng));
  }
}

// The fits as tested: the program's settings with position samples of 2 cm,
// orientation samples of 0.0017 rad and 30 LM iterations.
proto::CalibrateParams Options() {
  return tiltcal::testing::DefaultCalibrateParamsWith(R"pb(
    init {
      odometry_position_sigma_m: 0.02
      odometry_rotation_sigma_deg: 0.097402825172239
      solver_iterations: 30
    })pb");
}

TEST(InitialSplineFitTest, OrientationSamplesRemoveTheHeadingDriftOfAWrongGyroBias) {
  std::mt19937 rng(7);
  const Eigen::Vector3d true_bias(0.002, -0.003, 0.0015);
  const std::vector<imu::ImuReading> imu = Imu(true_bias, Eigen::Vector3d::Zero(), &rng);
  const spline::UniformKnotGrid grid = spline::UniformKnotGrid::ForDuration(0.0, kDuration, 0.05);
  CalibrationState state(grid);
  // The bias left after a short static start is off by ~1e-3 rad/s: 40 s
  // of it is 2.3 deg of heading.
  state.SetGyroBias(true_bias + Eigen::Vector3d(0.0, 0.0, 1e-3));
  FitRotationSplineToGyro(imu, Options(), &state);
  // The gyro fit holds knot 0, so its error grows from the start.
  const double gyro_only = MaxRotationError(state);
  EXPECT_GT(gyro_only, 0.03);

  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<double> times;
  std::vector<Eigen::Quaterniond> orientations;
  for (double t = 0.1; t < kDuration - 0.1; t += 0.1) {
    times.push_back(t);
    const Eigen::Vector3d noise = 0.001 * tiltcal::testing::RandomVector3(n, rng);
    orientations.emplace_back(Rotation(t) * geometry::ExpMatrix(noise));
  }
  RefineRotationSpline(times, orientations, imu, Options(), &state);
  EXPECT_LT(MaxRotationError(state), 0.003) << "gyro only: " << gyro_only;
}

TEST(InitialSplineFitTest, PositionFitEstimatesTheAccelerometerBiasAndTheLeverArm) {
  std::mt19937 rng(11);
  const Eigen::Vector3d gyro_bias(0.002, -0.003, 0.0015);
  const Eigen::Vector3d accel_bias(0.05, -0.03, 0.08);
  const Eigen::Vector3d r_bl(0.2477, -0.0699, -0.4636);  // r_b^{lb}, m
  const std::vector<imu::ImuReading> imu = Imu(gyro_bias, accel_bias, &rng);
  const spline::UniformKnotGrid grid = spline::UniformKnotGrid::ForDuration(0.0, kDuration, 0.05);
  CalibrationState state(grid);
  state.SetGyroBias(gyro_bias);
  state.SetGravityDirection(kGravity + Eigen::Vector3d(0.2, -0.1, 0.0));  // off by ~1.3 deg
  const Eigen::Vector3d r_bl_given = r_bl + Eigen::Vector3d(-0.3, 0.4, 0.0);
  state.SetImuFromLidarTranslation(r_bl_given);
  FitRotationSplineToGyro(imu, Options(), &state);
  ASSERT_LT(MaxRotationError(state), 0.01);

  std::vector<double> times;
  std::vector<Eigen::Vector3d> positions;
  LidarPositions(r_bl, &rng, &times, &positions);
  FitPositionSpline(times, positions, imu, Options(), Eigen::Vector3d::Zero(), &state);
  // The gyro-only rotation's tilt error (~1 mrad) tilts g_b by as much:
  // ~0.01 m/s^2 of bias.
  EXPECT_LT((state.AccelBias() - accel_bias).norm(), 0.02) << state.AccelBias().transpose();
  // In the plane of the turns the lever arm is observable (centripetal and
  // angular accelerations); along the yaw axis it stays near the given value.
  const Eigen::Vector3d dr = state.ImuFromLidarTranslation() - r_bl;
  EXPECT_LT(dr.head<2>().norm(), 0.02) << "r_b^{lb} error " << dr.transpose();
  double sum_sq = 0.0;
  int count = 0;
  for (double t = 0.5; t < kDuration - 0.5; t += 0.1) {
    spline::R3SplineSample pos;
    ASSERT_TRUE(state.trajectory.Evaluate(t, 0, nullptr, &pos));
    sum_sq += (pos.position - Position(t)).squaredNorm();
    ++count;
  }
  // The gravity leak of the ~1 mrad tilt error is held by the 10 Hz samples
  // to 1-2 cm RMS; with the bias held at zero the positions are several
  // centimetres off.
  EXPECT_LT(std::sqrt(sum_sq / count), 0.03)
      << "bias " << state.AccelBias().transpose() << " g " << state.GravityInWorld().transpose();
}

// Largest error of the estimated segments against a bias + drift * t,
// at 2.5, 7.5, ..., 37.5 s (the centres of 5 s segments).
double WorstBiasError(const BiasSegments& estimated, const Eigen::Vector3d& bias,
                      const Eigen::Vector3d& drift) {
  double worst = 0.0;
  for (double t = 2.5; t < kDuration; t += 5.0) {
    worst = std::max(worst, (estimated.At(t) - (bias + drift * t)).norm());
  }
  return worst;
}

// Fits the position spline to 10 Hz LiDAR positions (r_b^{lb} known, 1 cm
// noise) with b_a in segments of segment_s (0: one constant bias); returns
// the largest error of b_a against the truth at 2.5, 7.5, ..., 37.5 s.
double WorstAccelBiasSegmentError(double segment_s, const Eigen::Vector3d& accel_bias,
                                  const Eigen::Vector3d& drift) {
  std::mt19937 rng(13);
  const Eigen::Vector3d gyro_bias(0.002, -0.003, 0.0015);
  const Eigen::Vector3d r_bl(0.2477, -0.0699, -0.4636);
  const std::vector<imu::ImuReading> imu = Imu(gyro_bias, accel_bias, &rng, drift);
  const spline::UniformKnotGrid grid = spline::UniformKnotGrid::ForDuration(0.0, kDuration, 0.05);
  CalibrationState state(grid);
  EXPECT_TRUE(state.SetBiasSegments(0.0, segment_s).ok());
  state.SetGyroBias(gyro_bias);
  state.SetGravityDirection(kGravity);
  state.SetImuFromLidarTranslation(r_bl);
  // Segments tied by a random walk of 1e-3 m/s^3/sqrt(Hz).
  proto::CalibrateParams options = Options();
  options.mutable_imu_noise()->set_accel_bias_random_walk_mps3_sqrthz(1e-3);
  FitRotationSplineToGyro(imu, options, &state);
  std::vector<double> times;
  std::vector<Eigen::Vector3d> positions;
  LidarPositions(r_bl, &rng, &times, &positions);
  FitPositionSpline(times, positions, imu, options, Eigen::Vector3d::Zero(), &state);
  return WorstBiasError(state.accel_bias, accel_bias, drift);
}

TEST(InitialSplineFitTest, AccelerometerBiasSegmentsFollowADriftingBias) {
  const Eigen::Vector3d accel_bias(0.05, -0.03, 0.08);
  // 0.08 m/s^2 of drift over the 40 s (a fast-warming MEMS accelerometer).
  const Eigen::Vector3d drift(0.0015, -0.001, 0.0);
  const double segmented = WorstAccelBiasSegmentError(5.0, accel_bias, drift);
  const double constant = WorstAccelBiasSegmentError(0.0, accel_bias, drift);
  // 8 segments of 5 s; each is held to its centre's bias within the gravity
  // leak of the gyro-only rotation (~0.01 m/s^2); the constant bias is off by
  // 0.031 m/s^2 at 2.5 s and 37.5 s.
  EXPECT_LT(segmented, 0.015);
  EXPECT_GT(constant, 0.025);
}

// Fits the rotation spline to the gyro and to 10 Hz orientation samples
// (1 mrad noise, as from the LiDAR) with b_g free in segments of segment_s
// (0: one constant bias), tied by a random walk of 1e-4 rad/s^2/sqrt(Hz);
// returns the largest error of b_g against the truth at 2.5, 7.5, ..., 37.5 s.
double WorstGyroBiasSegmentError(double segment_s, const Eigen::Vector3d& gyro_bias,
                                 const Eigen::Vector3d& drift) {
  std::mt19937 rng(17);
  const std::vector<imu::ImuReading> imu =
      Imu(gyro_bias, Eigen::Vector3d::Zero(), &rng, Eigen::Vector3d::Zero(), drift);
  const spline::UniformKnotGrid grid = spline::UniformKnotGrid::ForDuration(0.0, kDuration, 0.05);
  CalibrationState state(grid);
  EXPECT_TRUE(state.SetBiasSegments(segment_s, 0.0).ok());
  state.SetGyroBias(gyro_bias);
  FitRotationSplineToGyro(imu, Options(), &state);

  const proto::CalibrateParams params = tiltcal::testing::DefaultCalibrateParamsWith(
      "imu_noise { gyro_sigma_radps: 0.003 gyro_bias_random_walk_radps2_sqrthz: 1e-4 }");
  ProblemOptions options;
  options.time_offset_bound_s = params.time_offset_bound_s();
  options.time_offset_step_bound_s = params.outer_loop().time_offset_step_bound_s();
  options.estimate_extrinsic = false;
  options.estimate_time_offset = false;
  options.estimate_gravity = false;
  CalibrationProblem problem(&state, params.imu_noise(), params.lidar(), options);
  problem.AddImuResiduals(imu, /*gyro=*/true, /*accel=*/false);
  std::normal_distribution<double> n(0.0, 1.0);
  const Status status =
      problem.AddExtraResiduals([&](CalibrationState* s, ceres::Problem* p, int* added) {
        for (double t = 0.1; t < kDuration - 0.1; t += 0.1) {
          spline::KnotWindow w;
          if (!grid.Locate(t, &w)) continue;
          const Eigen::Vector3d noise = 0.001 * tiltcal::testing::RandomVector3(n, rng);
          const int f = w.first_knot;
          p->AddResidualBlock(
              new OrientationSampleCostFunction(w, grid.inv_dt(),
                                                Eigen::Quaterniond(Rotation(t) *
                                                                   geometry::ExpMatrix(noise)),
                                                0.001),
              nullptr, s->trajectory.rotation_knot(f), s->trajectory.rotation_knot(f + 1),
              s->trajectory.rotation_knot(f + 2), s->trajectory.rotation_knot(f + 3));
          ++*added;
        }
        return Status::Ok();
      });
  EXPECT_TRUE(status.ok());
  problem.RemoveUnusedKnots();
  ceres::Solver::Summary summary;
  ceres::Solve(MakeSolverOptions(SolverSettings{30, 2, 1e-10}), problem.problem(), &summary);
  return WorstBiasError(state.gyro_bias, gyro_bias, drift);
}

TEST(InitialSplineFitTest, GyroBiasSegmentsFollowADriftingBias) {
  const Eigen::Vector3d gyro_bias(0.002, -0.003, 0.0015);
  // 3.3e-3 rad/s of drift over the 40 s (a warming MEMS gyro).
  const Eigen::Vector3d drift(6e-5, -4e-5, 4e-5);
  const double segmented = WorstGyroBiasSegmentError(5.0, gyro_bias, drift);
  const double constant = WorstGyroBiasSegmentError(0.0, gyro_bias, drift);
  // Each 5 s segment holds its centre's bias to ~1e-4 rad/s per axis (the
  // 1 mrad samples over 5 s); the constant bias is off by 1.4e-3 rad/s at
  // 2.5 s and 37.5 s.
  EXPECT_LT(segmented, 4e-4) << "constant: " << constant;
  EXPECT_GT(constant, 1e-3) << "segmented: " << segmented;
}

TEST(CalibrationStateTest, BiasSegmentsCoverTheSplineAndClampOutside) {
  const spline::UniformKnotGrid grid = spline::UniformKnotGrid::ForDuration(2.0, 12.0, 0.05);
  CalibrationState state(grid);
  ASSERT_EQ(state.accel_bias.size(), 1);
  ASSERT_EQ(state.gyro_bias.size(), 1);
  state.SetAccelBias(Eigen::Vector3d(0.1, 0.2, 0.3));
  state.SetGyroBias(Eigen::Vector3d(-1.0, -2.0, -3.0));
  ASSERT_TRUE(state.SetBiasSegments(4.0, 5.0).ok());
  ASSERT_EQ(state.gyro_bias.size(), 3);   // ceil(12 / 4)
  ASSERT_EQ(state.accel_bias.size(), 3);  // ceil(12 / 5)
  EXPECT_TRUE(state.gyro_bias.At(13.9).isApprox(Eigen::Vector3d(-1.0, -2.0, -3.0)));
  EXPECT_EQ(state.gyro_bias.Index(5.99), 0);
  EXPECT_EQ(state.gyro_bias.Index(6.01), 1);
  EXPECT_EQ(state.accel_bias.Index(1.0), 0);  // before t0: clamped
  EXPECT_EQ(state.accel_bias.Index(2.0), 0);
  EXPECT_EQ(state.accel_bias.Index(7.01), 1);
  EXPECT_EQ(state.accel_bias.Index(13.9), 2);
  EXPECT_EQ(state.accel_bias.Index(100.0), 2);  // after the end: clamped
  state.accel_bias.values[2] = {0.4, 0.5, 0.6};
  EXPECT_TRUE(state.accel_bias.At(13.0).isApprox(Eigen::Vector3d(0.4, 0.5, 0.6)));
  EXPECT_TRUE(state.AccelBias().isApprox(Eigen::Vector3d(0.2, 0.3, 0.4)));  // the mean
  EXPECT_EQ(state.accel_bias.Block(3.0), state.accel_bias.values[0].data());
  // Back to one segment: the mean.
  ASSERT_TRUE(state.SetBiasSegments(0.0, 0.0).ok());
  ASSERT_EQ(state.accel_bias.size(), 1);
  EXPECT_TRUE(state.accel_bias.At(13.0).isApprox(Eigen::Vector3d(0.2, 0.3, 0.4)));
  // A segment longer than the spline: one segment.
  ASSERT_TRUE(state.SetBiasSegments(20.0, 20.0).ok());
  EXPECT_EQ(state.gyro_bias.size(), 1);
  EXPECT_EQ(state.gyro_bias.segment_s, 0.0);
}

}  // namespace
}  // namespace tiltcal::calibrate
