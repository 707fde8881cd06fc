// The IMU intrinsics in the solve (stages/calibrate/report/imu_intrinsics.h): a
// rotation spline whose gyroscope reads T omega + noise with a consumer
// triad's T (scale errors of 0.2-0.5 %, axes 0.2-0.3 deg off). The score
// test must find T and not an ideal triad; the estimated errors must give T
// back where the motion excites it and name the rest as undetermined.

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <ceres/covariance.h>
#include <ceres/solver.h>
#include <gtest/gtest.h>

#include "common/geometry/angles.h"
#include "common/geometry/so3.h"
#include "common/imu/triad_errors.h"
#include "stages/calibrate/problem/calibration_state.h"
#include "stages/calibrate/problem/problem_builder.h"
#include "stages/calibrate/report/imu_intrinsics.h"
#include "tests/stages/calibrate/calibrate_params_text.h"

namespace tiltcal::calibrate {
namespace {

using geometry::kRadPerDeg;
constexpr double kGyroSigma = 1e-3;  // rad/s, the noise and the residuals' sigma

// A consumer gyroscope: measured = T true, T lower triangular (the
// simulator's model and the problem's).
Eigen::Matrix3d ConsumerGyro() {
  Eigen::Matrix3d t = Eigen::Matrix3d::Identity();
  t.diagonal() += Eigen::Vector3d(3000e-6, -2000e-6, 5000e-6);
  t(1, 0) = 0.3 * kRadPerDeg;
  t(2, 0) = -0.2 * kRadPerDeg;
  t(2, 1) = 0.25 * kRadPerDeg;
  return t;
}

// A state whose rotation spline turns about z at 0.5 rad/s, with a roll and
// pitch wobble when `wobble`, and gyro readings of it at 200 Hz through T.
struct TurningSpline {
  TurningSpline(bool wobble, const Eigen::Matrix3d& t, unsigned seed)
      : state(spline::UniformKnotGrid::ForDuration(0.0, 20.0, 0.1)) {
    EXPECT_TRUE(state.SetBiasSegments(0.0, 0.0).ok());
    spline::SplineTrajectory& traj = state.trajectory;
    Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
    for (int i = 0; i < traj.num_knots(); ++i) {
      const double s = 0.1 * i;
      const Eigen::Vector3d omega(wobble ? 0.4 * std::sin(1.3 * s) : 0.0,
                                  wobble ? 0.3 * std::cos(0.9 * s) : 0.0, 0.5);
      q = (q * geometry::ExpQuaternion(Eigen::Vector3d(0.1 * omega))).normalized();
      traj.SetRotationKnot(i, q);
    }
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, kGyroSigma);
    for (double time = 0.2; time < 19.8; time += 0.005) {
      spline::So3SplineSample r;
      spline::R3SplineSample p;
      EXPECT_TRUE(traj.Evaluate(time, spline::kSo3AngularVelocity, &r, &p));
      imu::ImuReading reading;
      reading.time_s = time;
      reading.angular_velocity_radps =
          t * r.angular_velocity + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
      samples.push_back(reading);
    }
  }
  CalibrationState state;
  std::vector<imu::ImuReading> samples;
};

proto::ImuNoiseParams GyroNoise() {
  proto::ImuNoiseParams noise;
  noise.set_gyro_sigma_radps(kGyroSigma);
  noise.set_accel_sigma_mps2(0.01);
  return noise;
}

// The gyro rows on the fixed spline; the triad errors held or estimated.
std::unique_ptr<CalibrationProblem> GyroProblem(TurningSpline* s, bool estimate,
                                                const proto::ImuIntrinsicsParams& params) {
  ProblemOptions options;
  options.estimate_biases = false;
  options.estimate_imu_intrinsics = estimate;
  options.intrinsics_scale_prior_sigma = params.scale_prior_ppm() * 1e-6;
  options.intrinsics_misalignment_prior_sigma_rad = params.misalignment_prior_deg() * kRadPerDeg;
  auto problem = std::make_unique<CalibrationProblem>(&s->state, GyroNoise(),
                                                      proto::LidarResidualParams(), options);
  problem->AddImuResiduals(s->samples, true, false);
  problem->SetRotationKnotsConstant();
  return problem;
}

proto::ImuIntrinsicsParams DefaultIntrinsics() {
  return testing::DefaultCalibrateParamsWith("").imu_intrinsics();
}

TEST(ImuIntrinsicsTest, DescribeTriadGivesTheSensorModelBack) {
  const Eigen::Matrix3d t = ConsumerGyro();
  std::array<double, 9> errors;
  Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(errors.data()) =
      t - Eigen::Matrix3d::Identity();
  const proto::ImuTriadEstimate d = DescribeTriad(errors, {}, {});
  EXPECT_NEAR(d.scale_ppm().x(), 3000.0, 1e-6);
  EXPECT_NEAR(d.scale_ppm().y(), -2000.0, 1e-6);
  EXPECT_NEAR(d.scale_ppm().z(), 5000.0, 1e-6);
  EXPECT_NEAR(d.misalignment_deg().x(), 0.3, 1e-9);
  EXPECT_NEAR(d.misalignment_deg().y(), -0.2, 1e-9);
  EXPECT_NEAR(d.misalignment_deg().z(), 0.25, 1e-9);
  ASSERT_EQ(d.measured_from_true_size(), 9);
  EXPECT_NEAR(d.measured_from_true(2), t(0, 2), 1e-12);
  EXPECT_EQ(d.scale_sigma_ppm().z(), 0.0);  // not estimated
}

TEST(ImuIntrinsicsTest, ScoreTestFindsAConsumerGyroAndNotAnIdealOne) {
  const proto::ImuIntrinsicsParams params = DefaultIntrinsics();
  for (const bool consumer : {false, true}) {
    TurningSpline s(true, consumer ? ConsumerGyro() : Eigen::Matrix3d::Identity(), 7);
    auto problem = GyroProblem(&s, false, params);
    ImuIntrinsicsScore score;
    ASSERT_TRUE(ScoreTestImuIntrinsics(problem->problem(), &s.state, params, 1, &score).ok());
    EXPECT_EQ(score.dof, 12);
    EXPECT_TRUE(problem->problem()->IsParameterBlockConstant(s.state.gyro_triad_errors.data()));
    const proto::ImuTriadEstimate step = DescribeTriad(score.gyro_triad_errors, {}, {});
    std::printf("%s: score %.1f, one-step gyro scale (%.0f, %.0f, %.0f) ppm\n",
                consumer ? "consumer" : "ideal", score.chi2, step.scale_ppm().x(),
                step.scale_ppm().y(), step.scale_ppm().z());
    if (!consumer) {
      // 6 informative degrees of freedom of noise: far below the limit.
      EXPECT_LT(score.chi2, params.min_score_chi2());
      continue;
    }
    EXPECT_GT(score.chi2, 100.0 * params.min_score_chi2());
    // The well-excited z scale, as the one step points to it.
    EXPECT_NEAR(step.scale_ppm().z(), 5000.0, 150.0);
  }
}

TEST(ImuIntrinsicsTest, EstimateRecoversTheExcitedEntriesAndNamesTheOthers) {
  const proto::ImuIntrinsicsParams params = DefaultIntrinsics();
  const Eigen::Matrix3d t = ConsumerGyro();
  // Turning about z only: E_g's z scale is determined, the entries that
  // multiply the x and y rates are not, nor any accelerometer entry (no
  // accelerometer rows).
  TurningSpline s(false, t, 11);
  auto problem = GyroProblem(&s, true, params);
  ceres::Solver::Options options;
  options.max_num_iterations = 20;
  ceres::Solver::Summary summary;
  ceres::Solve(options, problem->problem(), &summary);
  ASSERT_EQ(summary.termination_type, ceres::CONVERGENCE) << summary.BriefReport();

  ceres::Covariance::Options covariance_options;
  ceres::Covariance covariance(covariance_options);
  double* gyro = s.state.gyro_triad_errors.data();
  double* accel = s.state.accel_triad_errors.data();
  const std::vector<const double*> blocks = {gyro, accel};
  ASSERT_TRUE(covariance.Compute(blocks, problem->problem()));
  // Row-major 12 x 12 (symmetric, so Eigen's column-major storage reads the same).
  Eigen::MatrixXd c(12, 12);
  ASSERT_TRUE(covariance.GetCovarianceMatrixInTangentSpace(blocks, c.data()));

  const proto::ImuTriadEstimate d =
      DescribeTriad(s.state.gyro_triad_errors, GyroErrorEntries(), c.topLeftCorner(6, 6));
  EXPECT_NEAR(d.scale_ppm().z(), 5000.0, 3.0 * d.scale_sigma_ppm().z() + 1.0);
  EXPECT_LT(d.scale_sigma_ppm().z(), 50.0);
  // The upper triangle is held at zero by the problem.
  EXPECT_EQ(d.measured_from_true(2), 0.0);
  EXPECT_EQ(d.measured_from_true_sigma(2), 0.0);
  const std::vector<std::string> open = UndeterminedIntrinsics(c, params);
  auto named = [&](const std::string& name) {
    return std::find(open.begin(), open.end(), name) != open.end();
  };
  EXPECT_FALSE(named("gyroscope z scale"));
  // The x and y columns multiply the x and y rates, noise only here.
  EXPECT_TRUE(named("gyroscope y scale"));
  EXPECT_TRUE(named("gyroscope y axis towards x"));
  EXPECT_TRUE(named("gyroscope z axis towards y"));
  EXPECT_FALSE(named("gyroscope x axis towards z"));  // held, not estimated
  EXPECT_TRUE(named("accelerometer z scale"));
  EXPECT_TRUE(named("accelerometer y axis towards x"));
}

}  // namespace
}  // namespace tiltcal::calibrate
