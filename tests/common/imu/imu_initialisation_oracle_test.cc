// Oracle tests (analytic ZYX kinematics, simulated bias and noise) of the IMU
// initialisation the calibrator uses (common/imu).
#include "common/geometry/angles.h"
#include "common/imu/gyro_integrator.h"
#include "common/imu/imu_initialisation.h"
#include "common/imu/imu_reading.h"
#include "common/imu/static_detection.h"

#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>
#include "tests/common/imu/imu_test_options.h"
#include "tests/testing/random_vector.h"

namespace tiltcal::calibrate {
namespace {

using imu::DetectStaticStart;
using imu::GyroIntegrator;
using imu::ImuInitialisation;
using imu::ImuInitialisationOptions;
using imu::ImuReading;
using imu::InitialiseImu;
using imu::StaticDetectionOptions;
using imu::StaticInterval;
using imu::ValidateImuReadings;

using geometry::AngleBetweenDeg;
using geometry::kRadPerDeg;

// Ground truth attitude C_wb(t) = Rz(yaw) Ry(pitch) Rx(roll) with smooth
// angles, and its body rate from the ZYX kinematics (independent of the
// integrator under test).
struct EulerMotion {
  double start_s = 0.0;  // angles are constant before start_s
  double yaw0 = 0.0, pitch0 = 0.0, roll0 = 0.0;
  double yaw_amp = 0.0, pitch_amp = 0.0, roll_amp = 0.0;
  double yaw_w = 0.0, pitch_w = 0.0, roll_w = 0.0;  // rad/s

  // angle = a0 + amp (1 - cos(w (t - start))) after the start: C^1 at start.
  static void Angle(double a0, double amp, double w, double s, double* a, double* a_dot) {
    if (s <= 0.0) {
      *a = a0;
      *a_dot = 0.0;
      return;
    }
    *a = a0 + amp * (1.0 - std::cos(w * s));
    *a_dot = amp * w * std::sin(w * s);
  }

  Eigen::Matrix3d Rotation(double t, Eigen::Vector3d* body_rate) const {
    const double s = t - start_s;
    double y, yd, p, pd, r, rd;
    Angle(yaw0, yaw_amp, yaw_w, s, &y, &yd);
    Angle(pitch0, pitch_amp, pitch_w, s, &p, &pd);
    Angle(roll0, roll_amp, roll_w, s, &r, &rd);
    if (body_rate != nullptr) {
      *body_rate = Eigen::Vector3d(rd - yd * std::sin(p), pd * std::cos(r) + yd * std::cos(p) * std::sin(r),
                                   -pd * std::sin(r) + yd * std::cos(p) * std::cos(r));
    }
    return (Eigen::AngleAxisd(y, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(p, Eigen::Vector3d::UnitY()) *
            Eigen::AngleAxisd(r, Eigen::Vector3d::UnitX()))
        .toRotationMatrix();
  }
};

double RotationErrorDeg(const Eigen::Quaterniond& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.toRotationMatrix().transpose() * b).angle() / kRadPerDeg;
}

// IMU samples of `motion` (world gravity g_w = (0, 0, -9.81), no translation
// acceleration: pure rotation about the IMU origin) with bias and noise.
std::vector<ImuReading> SimulateImu(const EulerMotion& motion, double duration_s, double rate_hz,
                                    const Eigen::Vector3d& gyro_bias, double gyro_sigma, double accel_sigma,
                                    unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::Vector3d g_w(0.0, 0.0, -9.81);
  std::vector<ImuReading> out;
  const int count = static_cast<int>(duration_s * rate_hz);
  for (int i = 0; i < count; ++i) {
    ImuReading s;
    s.time_s = 100.0 + i / rate_hz;  // arbitrary sequence origin
    Eigen::Vector3d w;
    const Eigen::Matrix3d c_wb = motion.Rotation(s.time_s - 100.0, &w);
    s.angular_velocity_radps = w + gyro_bias + gyro_sigma * tiltcal::testing::RandomVector3(n, rng);
    s.linear_acceleration_mps2 = -c_wb.transpose() * g_w + accel_sigma * tiltcal::testing::RandomVector3(n, rng);
    out.push_back(s);
  }
  return out;
}

TEST(CalibrateGyroIntegratorTest, MatchesAnalyticAttitudeAtAndBetweenSamples) {
  EulerMotion m;
  m.yaw_amp = 1.2;
  m.yaw_w = 0.9;
  m.pitch_amp = 0.3;
  m.pitch_w = 2.1;
  m.roll_amp = 0.25;
  m.roll_w = 3.3;
  m.pitch0 = 0.1;
  m.roll0 = -0.2;
  const std::vector<ImuReading> samples = SimulateImu(m, 10.0, 200.0, Eigen::Vector3d::Zero(), 0.0, 0.0, 1);
  ASSERT_TRUE(ValidateImuReadings(samples).ok());
  const GyroIntegrator integrator(samples, Eigen::Vector3d::Zero());
  const Eigen::Matrix3d c0 = m.Rotation(0.0, nullptr);
  double worst_deg = 0.0;
  for (double t = 0.0; t < 9.99; t += 0.0137) {  // mostly between samples
    const Eigen::Matrix3d truth = c0.transpose() * m.Rotation(t, nullptr);  // C_ab(t), a = b(t0)
    worst_deg = std::max(worst_deg, RotationErrorDeg(integrator.Rotation(100.0 + t), truth));
  }
  std::printf("gyro integration: worst error %.5f deg over 10 s at 200 Hz\n", worst_deg);
  EXPECT_LT(worst_deg, 0.01) << "midpoint integration error after 10 s at 200 Hz";
  EXPECT_LT(RotationErrorDeg(integrator.Rotation(100.0), Eigen::Matrix3d::Identity()), 1e-12);
  // Relative rotation is consistent with the absolute ones.
  const Eigen::Matrix3d rel = (c0.transpose() * m.Rotation(2.0, nullptr)).transpose() *
                              (c0.transpose() * m.Rotation(7.5, nullptr));
  EXPECT_LT(RotationErrorDeg(integrator.RelativeRotation(102.0, 107.5), rel), 0.01);
}

TEST(CalibrateGyroIntegratorTest, RemovesTheGivenBias) {
  EulerMotion m;  // static
  const Eigen::Vector3d bias(0.01, -0.02, 0.005);
  const std::vector<ImuReading> samples = SimulateImu(m, 5.0, 100.0, bias, 0.0, 0.0, 2);
  const GyroIntegrator with_bias(samples, bias);
  const GyroIntegrator without(samples, Eigen::Vector3d::Zero());
  EXPECT_LT(RotationErrorDeg(with_bias.Rotation(104.9), Eigen::Matrix3d::Identity()), 1e-9);
  EXPECT_NEAR(Eigen::AngleAxisd(without.Rotation(104.9)).angle(), bias.norm() * 4.9, 1e-9);
}

TEST(CalibrateImuReadingsTest, RejectsNonMonotonicAndNonFinite) {
  std::vector<ImuReading> samples(3);
  samples[0].time_s = 0.0;
  samples[1].time_s = 0.01;
  samples[2].time_s = 0.01;
  const Status status = ValidateImuReadings(samples);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("IMU sample 2"), std::string::npos) << status.message();
  samples[2].time_s = 0.02;
  samples[1].angular_velocity_radps.x() = std::nan("");
  EXPECT_FALSE(ValidateImuReadings(samples).ok());
  EXPECT_FALSE(ValidateImuReadings({}).ok());
  ImuInitialisation init;
  EXPECT_FALSE(InitialiseImu({}, imu::testing::ImuInitialisationTestOptions(), &init).ok());
}

TEST(CalibrateImuInitialisationTest, StaticStartGivesBiasAndGravityWithinNoise) {
  EulerMotion m;
  m.start_s = 3.0;  // static for 3 s, then turning and rocking
  m.yaw0 = 0.4;
  m.pitch0 = -3.0 * kRadPerDeg;  // tilted rest attitude
  m.roll0 = 5.0 * kRadPerDeg;
  m.yaw_amp = 0.8;
  m.yaw_w = 1.5;
  m.pitch_amp = 0.05;
  m.pitch_w = 4.0;
  const Eigen::Vector3d bias(0.012, -0.021, 0.004);
  const double gyro_sigma = 0.002, accel_sigma = 0.02;
  const std::vector<ImuReading> samples = SimulateImu(m, 10.0, 200.0, bias, gyro_sigma, accel_sigma, 3);

  ImuInitialisationOptions options = imu::testing::ImuInitialisationTestOptions();
  options.gravity_norm_mps2 = 9.81;
  ImuInitialisation init;
  ASSERT_TRUE(InitialiseImu(samples, options, &init).ok());
  ASSERT_TRUE(init.static_start.found);
  EXPECT_TRUE(init.from_static_start);
  EXPECT_DOUBLE_EQ(init.static_start.begin_s, 100.0);
  // Motion starts at 103 s; the end is the last static window end before it.
  EXPECT_LE(init.static_start.end_s, 103.0 + 1e-9);
  EXPECT_GE(init.static_start.end_s, 103.0 - 0.25);
  // Mean of ~600 samples: sigma 0.002 / sqrt(600) = 8e-5 rad/s per axis.
  EXPECT_LT((init.gyro_bias_radps - bias).norm(), 5e-4) << init.gyro_bias_radps.transpose();
  // Gravity in a = b(t0): C_wb(0)^T g_w.
  const Eigen::Vector3d g_truth = m.Rotation(0.0, nullptr).transpose() * Eigen::Vector3d(0.0, 0.0, -9.81);
  std::printf("static start: end %.3f s (motion at 103 s), |bias error| %.2e rad/s, gravity error %.4f deg\n",
              init.static_start.end_s, (init.gyro_bias_radps - bias).norm(),
              AngleBetweenDeg(init.gravity_in_world_mps2, g_truth));
  EXPECT_NEAR(init.gravity_in_world_mps2.norm(), 9.81, 1e-9);
  EXPECT_LT(AngleBetweenDeg(init.gravity_in_world_mps2, g_truth), 0.05);
  EXPECT_NEAR(init.accel_norm_mismatch_mps2, 0.0, 0.01);
}

TEST(CalibrateImuInitialisationTest, DetectsNoStaticStartWhenMovingAndFallsBack) {
  EulerMotion m;
  m.start_s = -1.0;  // already moving at the first sample
  m.pitch0 = 2.0 * kRadPerDeg;
  m.roll0 = -4.0 * kRadPerDeg;
  m.yaw_amp = 0.6;
  m.yaw_w = 1.3;
  m.pitch_amp = 0.04;
  m.pitch_w = 3.0;
  m.roll_amp = 0.03;
  m.roll_w = 2.5;
  const Eigen::Vector3d bias(0.003, 0.002, -0.004);
  const std::vector<ImuReading> samples = SimulateImu(m, 8.0, 200.0, bias, 0.002, 0.02, 4);
  ImuInitialisation init;
  ASSERT_TRUE(InitialiseImu(samples, imu::testing::ImuInitialisationTestOptions(), &init).ok());
  EXPECT_FALSE(init.static_start.found);
  EXPECT_FALSE(init.from_static_start);
  EXPECT_EQ(init.gyro_bias_radps, Eigen::Vector3d::Zero());
  const Eigen::Vector3d g_truth = m.Rotation(0.0, nullptr).transpose() * Eigen::Vector3d(0.0, 0.0, -9.81);
  // Rotation-compensated mean of pure-rotation data: the unmodelled gyro bias
  // (~0.005 rad/s over 2 s) is the main error.
  std::printf("no static start: gravity error %.3f deg\n", AngleBetweenDeg(init.gravity_in_world_mps2, g_truth));
  EXPECT_LT(AngleBetweenDeg(init.gravity_in_world_mps2, g_truth), 1.0);
  EXPECT_NEAR(init.averaging_end_s - init.averaging_begin_s, 2.0, 0.01);
}

TEST(CalibrateImuInitialisationTest, ShortStaticStartIsNotUsed) {
  EulerMotion m;
  m.start_s = 0.6;  // shorter than min_duration_s = 1 s
  m.yaw_amp = 0.8;
  m.yaw_w = 2.0;
  const std::vector<ImuReading> samples = SimulateImu(m, 4.0, 200.0, Eigen::Vector3d::Zero(), 0.001, 0.01, 5);
  const StaticInterval interval = DetectStaticStart(samples, imu::testing::StaticDetectionTestOptions());
  EXPECT_FALSE(interval.found);
  StaticDetectionOptions shorter = imu::testing::StaticDetectionTestOptions();
  shorter.min_duration_s = 0.5;
  const StaticInterval found = DetectStaticStart(samples, shorter);
  ASSERT_TRUE(found.found);
  EXPECT_LE(found.end_s, 100.6 + 1e-9);
  EXPECT_GE(found.end_s, 100.6 - 0.25);
  // First sample at or after end_s (sample spacing 5 ms).
  EXPECT_NEAR(static_cast<double>(found.end_index), (found.end_s - 100.0) * 200.0, 1.0);
}

}  // namespace
}  // namespace tiltcal::calibrate
