// Analytic spline residuals of the calibrator vs their autodiff twins
// (tests/testing/cost_function_twins.h) and vs ceres::GradientChecker
// (numeric differences through the manifolds), at several knot spacings and
// normalised times including segment ends, and the time-offset window
// behaviour of the point-to-plane residual at a segment boundary; the
// random-walk prior between consecutive bias segments; the clock drift's
// wrapper (tau(t) = tau0 + rho (t - t_ref)) around the LiDAR and ground
// residuals.

#include <memory>
#include <random>
#include <string>
#include <vector>

#include <ceres/loss_function.h>
#include <ceres/problem.h>
#include <ceres/solver.h>
#include <gtest/gtest.h>

#include "common/geometry/so3.h"
#include "common/spline/quaternion_manifold.h"
#include "stages/calibrate/residuals/accel_cost_function.h"
#include "stages/calibrate/residuals/bias_random_walk_cost_function.h"
#include "stages/calibrate/residuals/drifting_time_offset_cost_function.h"
#include "stages/calibrate/residuals/ground_cost_functions.h"
#include "stages/calibrate/residuals/gyro_cost_function.h"
#include "stages/calibrate/residuals/interval_manifold.h"
#include "stages/calibrate/residuals/orientation_sample_cost_function.h"
#include "stages/calibrate/residuals/point_to_plane_cost_function.h"
#include "stages/calibrate/residuals/stacked_cost_function.h"
#include "tests/stages/calibrate/residuals/jacobian_checks.h"
#include "tests/testing/cost_function_twins.h"
#include "tests/testing/random_vector.h"

namespace tiltcal::calibrate {
namespace {

using geometry::ExpQuaternion;

const double kSpacings[] = {0.02, 0.05, 0.1};
const double kTimes[] = {0.0, 1e-9, 0.31, 0.5, 0.93, 1.0 - 1e-9, 1.0};

// A full set of parameter blocks for any of the residuals. Five knots so the
// boundary test can use two overlapping windows.
struct State {
  Eigen::Quaterniond q[5];
  Eigen::Vector3d p[5];
  Eigen::Vector3d gyro_bias, accel_bias, gravity_dir, r_b_lb;
  // IMU triad errors E (row-major), a consumer IMU's size (~1 %).
  Eigen::Matrix<double, 9, 1> gyro_triad_errors, accel_triad_errors;
  Eigen::Quaterniond q_bl;
  double tau = 0.0;
};

State RandomState(std::mt19937* rng, double dt) {
  std::normal_distribution<double> n(0.0, 1.0);
  auto v = [&](double s) { return Eigen::Vector3d(s * tiltcal::testing::RandomVector3(n, *rng)); };
  State s;
  s.q[0] = ExpQuaternion(v(1.0));
  s.p[0] = v(2.0);
  // Angular rates ~ 1-3 rad/s and speeds ~ 5 m/s whatever dt.
  for (int i = 1; i < 5; ++i) {
    s.q[i] = s.q[i - 1] * ExpQuaternion(Eigen::Vector3d(v(2.0 * dt)));
    s.p[i] = s.p[i - 1] + v(5.0 * dt);
  }
  s.gyro_bias = v(0.01);
  s.accel_bias = v(0.1);
  for (auto* k : {&s.gyro_triad_errors, &s.accel_triad_errors}) {
    for (int i = 0; i < 9; ++i) (*k)[i] = 0.01 * n(*rng);
  }
  for (int i : {1, 2, 5}) s.accel_triad_errors[i] = 0.0;  // lower triangular
  s.gravity_dir = (Eigen::Vector3d(0, 0, -1) + v(0.1)).normalized();
  s.r_b_lb = v(0.5);
  s.q_bl = ExpQuaternion(v(1.0));
  s.tau = 0.003 * n(*rng);
  return s;
}

using testing::Block;
using testing::ExpectGradientCheckerPasses;
using testing::ExpectTangentDifferencesMatch;

TEST(GyroCostFunctionTest, MatchesAutodiffTwinAndNumericDifferences) {
  std::mt19937 rng(41);
  for (double dt : kSpacings) {
    for (double u : kTimes) {
      State s = RandomState(&rng, dt);
      const Eigen::Vector3d measured(0.3, -0.2, 0.5);
      const double sigma = 0.01;
      GyroCostFunction analytic(spline::KnotWindow{0, u}, 1.0 / dt, measured, sigma);
      testing::GyroTwin::AutoDiff twin(new testing::GyroTwin{u, 1.0 / dt, sigma, measured});
      testing::GyroTwinT<true>::AutoDiff sommer(new testing::GyroTwinT<true>{u, 1.0 / dt, sigma, measured});
      std::vector<double*> params = {s.q[0].coeffs().data(), s.q[1].coeffs().data(),
                                     s.q[2].coeffs().data(), s.q[3].coeffs().data(),
                                     s.gyro_bias.data(), s.gyro_triad_errors.data()};
      const std::vector<Block> blocks = {Block::kQuaternion, Block::kQuaternion, Block::kQuaternion,
                                         Block::kQuaternion, Block::kEuclidean, Block::kEuclidean};
      const std::string label = "dt " + std::to_string(dt) + " u " + std::to_string(u);
      testing::ExpectSameTangentJacobians(analytic, twin, params, blocks, 1e-9, label);
      testing::ExpectSameTangentJacobians(analytic, sommer, params, blocks, 1e-9, label + " sommer");
      ExpectGradientCheckerPasses(analytic, params, blocks, label);
      ExpectTangentDifferencesMatch(analytic, params, blocks, label);
    }
  }
}

TEST(OrientationSampleCostFunctionTest, MatchesAutodiffTwinAndNumericDifferences) {
  std::mt19937 rng(47);
  std::normal_distribution<double> n(0.0, 1.0);
  for (double dt : kSpacings) {
    for (double u : kTimes) {
      State s = RandomState(&rng, dt);
      // Measured orientations a few degrees to ~0.5 rad from the spline's, so
      // J_r^{-1} of the residual matters.
      const double size = 0.05 + 0.5 * std::abs(n(rng));
      const Eigen::Quaterniond measured =
          s.q[1] * ExpQuaternion(Eigen::Vector3d(size * tiltcal::testing::RandomVector3(n, rng)));
      const double sigma = 0.002;
      OrientationSampleCostFunction analytic(spline::KnotWindow{0, u}, 1.0 / dt, measured, sigma);
      testing::OrientationTwin::AutoDiff twin(
          new testing::OrientationTwin{u, 1.0 / dt, sigma, measured});
      testing::OrientationTwinT<true>::AutoDiff sommer(
          new testing::OrientationTwinT<true>{u, 1.0 / dt, sigma, measured});
      std::vector<double*> params = {s.q[0].coeffs().data(), s.q[1].coeffs().data(),
                                     s.q[2].coeffs().data(), s.q[3].coeffs().data()};
      const std::vector<Block> blocks = {Block::kQuaternion, Block::kQuaternion, Block::kQuaternion,
                                         Block::kQuaternion};
      const std::string label = "dt " + std::to_string(dt) + " u " + std::to_string(u);
      testing::ExpectSameTangentJacobians(analytic, twin, params, blocks, 1e-8, label);
      testing::ExpectSameTangentJacobians(analytic, sommer, params, blocks, 1e-8, label + " sommer");
      // No ceres::GradientChecker here: it differentiates in the ambient
      // quaternion space, where off the unit sphere the spline's C(t) is not
      // a rotation and Log of it is not smooth; the tangent differences below
      // stay on the manifold.
      ExpectTangentDifferencesMatch(analytic, params, blocks, label);
    }
  }
}

TEST(AccelCostFunctionTest, MatchesAutodiffTwinAndNumericDifferences) {
  std::mt19937 rng(43);
  for (double dt : kSpacings) {
    for (double u : kTimes) {
      State s = RandomState(&rng, dt);
      const Eigen::Vector3d measured(0.1, 0.4, 9.7);
      const double sigma = 0.05, g = 9.81;
      AccelCostFunction analytic(spline::KnotWindow{0, u}, 1.0 / dt, measured, sigma, g);
      testing::AccelTwin::AutoDiff twin(new testing::AccelTwin{u, 1.0 / dt, sigma, g, measured});
      testing::AccelTwinT<true>::AutoDiff sommer(new testing::AccelTwinT<true>{u, 1.0 / dt, sigma, g, measured});
      std::vector<double*> params = {
          s.q[0].coeffs().data(), s.q[1].coeffs().data(), s.q[2].coeffs().data(),
          s.q[3].coeffs().data(), s.p[0].data(),          s.p[1].data(),
          s.p[2].data(),          s.p[3].data(),          s.gravity_dir.data(),
          s.accel_bias.data(),    s.accel_triad_errors.data()};
      const std::vector<Block> blocks = {Block::kQuaternion, Block::kQuaternion, Block::kQuaternion,
                                         Block::kQuaternion, Block::kEuclidean,  Block::kEuclidean,
                                         Block::kEuclidean,  Block::kEuclidean,  Block::kSphere,
                                         Block::kEuclidean,  Block::kEuclidean};
      const std::string label = "dt " + std::to_string(dt) + " u " + std::to_string(u);
      testing::ExpectSameTangentJacobians(analytic, twin, params, blocks, 1e-9, label);
      testing::ExpectSameTangentJacobians(analytic, sommer, params, blocks, 1e-9, label + " sommer");
      ExpectGradientCheckerPasses(analytic, params, blocks, label);
      ExpectTangentDifferencesMatch(analytic, params, blocks, label);
    }
  }
}

std::vector<double*> PlaneParams(State* s, int first) {
  return {s->q[first].coeffs().data(),     s->q[first + 1].coeffs().data(),
          s->q[first + 2].coeffs().data(), s->q[first + 3].coeffs().data(),
          s->p[first].data(),              s->p[first + 1].data(),
          s->p[first + 2].data(),          s->p[first + 3].data(),
          s->q_bl.coeffs().data(),         s->r_b_lb.data(),
          &s->tau};
}

const std::vector<Block> kPlaneBlocks = {
    Block::kQuaternion, Block::kQuaternion, Block::kQuaternion, Block::kQuaternion,
    Block::kEuclidean,  Block::kEuclidean,  Block::kEuclidean,  Block::kEuclidean,
    Block::kQuaternion, Block::kEuclidean,  Block::kEuclidean};

TEST(PointToPlaneCostFunctionTest, MatchesAutodiffTwinAndNumericDifferences) {
  std::mt19937 rng(47);
  // Normalised times of t_j + tau in the frozen window, including values that
  // tau has pushed slightly outside [0, 1].
  const double times[] = {-0.02, 0.0, 1e-9, 0.31, 0.5, 0.93, 1.0 - 1e-9, 1.0, 1.02};
  for (double dt : kSpacings) {
    for (double u : times) {
      State s = RandomState(&rng, dt);
      const double segment_start = 10.0;
      const double point_time = segment_start + u * dt - s.tau;
      const Eigen::Vector3d point(4.0, -2.0, 0.7);
      const Eigen::Vector3d normal = Eigen::Vector3d(0.2, -0.3, 0.9).normalized();
      const double offset = -1.3, sigma = 0.03;
      PointToPlaneCostFunction analytic(segment_start, 1.0 / dt, point_time, point, normal, offset, sigma);
      EXPECT_NEAR(analytic.NormalizedTime(s.tau), u, 1e-9);
      testing::PointToPlaneTwin::AutoDiff twin(new testing::PointToPlaneTwin{
          point_time - segment_start, 1.0 / dt, sigma, offset, point, normal});
      testing::PointToPlaneTwinT<true>::AutoDiff sommer(new testing::PointToPlaneTwinT<true>{
          point_time - segment_start, 1.0 / dt, sigma, offset, point, normal});
      const std::vector<double*> params = PlaneParams(&s, 0);
      const std::string label = "dt " + std::to_string(dt) + " u " + std::to_string(u);
      testing::ExpectSameTangentJacobians(analytic, twin, params, kPlaneBlocks, 1e-9, label);
      testing::ExpectSameTangentJacobians(analytic, sommer, params, kPlaneBlocks, 1e-9, label + " sommer");
      // Not ceres::GradientChecker here: in Ceres 2.1.0 its numeric Jacobian of
      // a size-1 parameter block (tau) is wrong even for r = sin(50 t) (it
      // reports ~8.5 instead of 50), so the tangent-space central differences
      // below are used instead.
      ExpectTangentDifferencesMatch(analytic, params, kPlaneBlocks, label);
    }
  }
}

// The frozen window at a segment boundary: a point binned into segment 0 at
// u = 1 - 0.001, then tau pushes it to u = 1 + delta. The extended segment-0
// polynomial agrees with the true spline (segment 1 at u = delta) up to
// O(delta^3) in the residual and O(delta^2) in dr/dtau, and exactly at the
// boundary.
TEST(PointToPlaneCostFunctionTest, FrozenWindowAtSegmentBoundary) {
  std::mt19937 rng(53);
  for (double dt : kSpacings) {
    State s = RandomState(&rng, dt);
    s.tau = 0.0;
    const double t0 = 0.0;
    const double point_time = t0 + (1.0 - 0.001) * dt;
    const Eigen::Vector3d point(8.0, 3.0, -1.0);
    const Eigen::Vector3d normal = Eigen::Vector3d(0.6, 0.0, 0.8);
    const double sigma = 1.0;
    const PointToPlaneCostFunction frozen(t0, 1.0 / dt, point_time, point, normal, 0.5, sigma);
    const PointToPlaneCostFunction rebinned(t0 + dt, 1.0 / dt, point_time, point, normal, 0.5, sigma);
    auto eval = [&](const PointToPlaneCostFunction& cost, int first, double tau, double* d_tau) {
      State local = s;
      local.tau = tau;
      std::vector<double*> params = PlaneParams(&local, first);
      double r;
      double* jac[11] = {nullptr};
      jac[10] = d_tau;
      EXPECT_TRUE(cost.Evaluate(params.data(), &r, jac));
      return r;
    };
    // Exactly at the boundary (u = 1 in segment 0, u = 0 in segment 1).
    double j_frozen, j_rebinned;
    const double tau_boundary = 0.001 * dt;
    EXPECT_NEAR(eval(frozen, 0, tau_boundary, &j_frozen), eval(rebinned, 1, tau_boundary, &j_rebinned),
                1e-11);
    EXPECT_NEAR(j_frozen, j_rebinned, 1e-8 * (1.0 + std::abs(j_rebinned)));
    // Beyond it: errors scale like delta^3 (residual) and delta^2 (dr/dtau).
    double err_r[2], err_j[2];
    const double deltas[2] = {0.02, 0.04};
    for (int k = 0; k < 2; ++k) {
      const double tau = tau_boundary + deltas[k] * dt;
      err_r[k] = eval(frozen, 0, tau, &j_frozen) - eval(rebinned, 1, tau, &j_rebinned);
      err_j[k] = j_frozen - j_rebinned;
    }
    ASSERT_GT(std::abs(err_r[0]), 0.0);
    EXPECT_NEAR(err_r[1] / err_r[0], 8.0, 0.5) << "dt " << dt;
    EXPECT_NEAR(err_j[1] / err_j[0], 4.0, 0.3) << "dt " << dt;
    // And they are small for a realistic excursion (2% of a segment).
    EXPECT_LT(std::abs(err_r[0]), 1e-3) << "dt " << dt;
  }
}

TEST(BiasRandomWalkCostFunctionTest, ValueAndJacobians) {
  // sigma_rw 0.01 over 4 s: sigma of the step 0.02.
  const BiasRandomWalkCostFunction cost(0.01, 4.0);
  double b0[3] = {1.0, 2.0, 3.0};
  double b1[3] = {1.5, 1.0, 3.0};
  const std::vector<double*> params = {b0, b1};
  Eigen::VectorXd r;
  std::vector<testing::RowMajor> jacobians;
  testing::EvaluateAll(cost, params, &r, &jacobians);
  EXPECT_TRUE(r.isApprox(Eigen::Vector3d(25.0, -50.0, 0.0), 1e-12)) << r.transpose();
  EXPECT_TRUE(jacobians[0].isApprox(-50.0 * Eigen::Matrix3d::Identity()));
  EXPECT_TRUE(jacobians[1].isApprox(50.0 * Eigen::Matrix3d::Identity()));
  const std::vector<Block> blocks = {Block::kEuclidean, Block::kEuclidean};
  ExpectTangentDifferencesMatch(cost, params, blocks, "bias random walk");
  ExpectGradientCheckerPasses(cost, params, blocks, "bias random walk");
}

// ---- Stacked residual blocks (stacked_cost_function.h) ----

// Rows of LiDAR points on one knot window: ranges of residuals from inliers
// (|r| ~ 0.1) to outliers (|r| ~ 30, far beyond the Cauchy scale 2) and one
// exactly on its plane (r = 0).
std::vector<std::unique_ptr<ceres::CostFunction>> PlaneRows(const State& s, double dt,
                                                            std::mt19937* rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<std::unique_ptr<ceres::CostFunction>> rows;
  const double segment_start = 10.0, sigma = 0.03;
  const double offsets[] = {-1.3, -0.5, 0.2, 0.9, 4.0};
  for (int i = 0; i < 5; ++i) {
    const double point_time = segment_start + (0.1 + 0.2 * i) * dt - s.tau;
    const Eigen::Vector3d point = 4.0 * tiltcal::testing::RandomVector3(n, *rng);
    const Eigen::Vector3d normal = tiltcal::testing::RandomVector3(n, *rng).normalized();
    rows.emplace_back(new PointToPlaneCostFunction(segment_start, 1.0 / dt, point_time, point,
                                                   normal, offsets[i], sigma));
  }
  return rows;
}

double RowResidual(const ceres::CostFunction& row, const std::vector<double*>& params) {
  double r = 0.0;
  EXPECT_TRUE(row.Evaluate(params.data(), &r, nullptr));
  return r;
}

TEST(StackedCostFunctionTest, WithoutALossRowsAreStackedUnchanged) {
  std::mt19937 rng(61);
  State s = RandomState(&rng, 0.05);
  const std::vector<double*> params = PlaneParams(&s, 0);
  auto rows = PlaneRows(s, 0.05, &rng);
  std::vector<const ceres::CostFunction*> plain;
  for (const auto& r : rows) plain.push_back(r.get());
  const StackedCostFunction stacked(std::move(rows), nullptr);
  ASSERT_EQ(stacked.num_residuals(), 5);
  Eigen::VectorXd residual;
  std::vector<testing::RowMajor> jacobians;
  testing::EvaluateAll(stacked, params, &residual, &jacobians);
  for (int i = 0; i < 5; ++i) {
    Eigen::VectorXd row_residual;
    std::vector<testing::RowMajor> row_jacobians;
    testing::EvaluateAll(*plain[i], params, &row_residual, &row_jacobians);
    EXPECT_EQ(residual[i], row_residual[0]);
    for (std::size_t k = 0; k < params.size(); ++k) {
      EXPECT_EQ(jacobians[k].row(i), row_jacobians[k].row(0)) << "row " << i << " block " << k;
    }
  }
}

TEST(StackedCostFunctionTest, FoldedCauchyLossKeepsTheCostAndDifferentiatesCorrectly) {
  std::mt19937 rng(67);
  const ceres::CauchyLoss loss(2.0);
  for (double dt : kSpacings) {
    State s = RandomState(&rng, dt);
    const std::vector<double*> params = PlaneParams(&s, 0);
    auto rows = PlaneRows(s, dt, &rng);
    double raw[5];
    for (int i = 0; i < 5; ++i) raw[i] = RowResidual(*rows[static_cast<std::size_t>(i)], params);
    const StackedCostFunction stacked(std::move(rows), &loss);
    double folded[5];
    ASSERT_TRUE(stacked.Evaluate(params.data(), folded, nullptr));
    double rows_again[5];
    ASSERT_TRUE(stacked.EvaluateRows(params.data(), rows_again));
    bool has_outlier = false;
    for (int i = 0; i < 5; ++i) {
      EXPECT_EQ(rows_again[i], raw[i]);
      // 1/2 r~^2 = 1/2 rho(r^2), same sign as r.
      double rho[3];
      loss.Evaluate(raw[i] * raw[i], rho);
      EXPECT_NEAR(folded[i] * folded[i], rho[0], 1e-12 * (1.0 + rho[0])) << "row " << i;
      EXPECT_GE(folded[i] * raw[i], 0.0);
      has_outlier = has_outlier || std::abs(raw[i]) > 10.0;
    }
    EXPECT_TRUE(has_outlier) << "the rows should include one far beyond the Cauchy scale";
    ExpectTangentDifferencesMatch(stacked, params, kPlaneBlocks, "stacked dt " + std::to_string(dt));
  }
}

TEST(StackedCostFunctionTest, FoldedLossAtAZeroResidual) {
  // r = x (one row, one parameter): at x = 0, r~ = 0 and dr~/dx = sqrt(rho'(0)) = 1.
  class Identity final : public ceres::SizedCostFunction<1, 1> {
   public:
    bool Evaluate(double const* const* p, double* r, double** j) const override {
      r[0] = p[0][0];
      if (j != nullptr && j[0] != nullptr) j[0][0] = 1.0;
      return true;
    }
  };
  const ceres::CauchyLoss loss(2.0);
  std::vector<std::unique_ptr<ceres::CostFunction>> rows;
  rows.emplace_back(new Identity);
  const StackedCostFunction stacked(std::move(rows), &loss);
  double x = 0.0;
  const double* params[] = {&x};
  double r = 1.0, jacobian = 0.0;
  double* jacobians[] = {&jacobian};
  ASSERT_TRUE(stacked.Evaluate(params, &r, jacobians));
  EXPECT_EQ(r, 0.0);
  EXPECT_DOUBLE_EQ(jacobian, 1.0);
  // Near zero: r~ = b sqrt(log(1 + x^2 / b^2)) and its derivative, to
  // rounding (Ceres' own log(1 + s / b^2) is inexact there).
  for (const double v : {1e-9, 1e-7, 1e-4, 1e-2, 0.5, 3.0, 30.0}) {
    x = v;
    ASSERT_TRUE(stacked.Evaluate(params, &r, jacobians));
    const double expected = 2.0 * std::sqrt(std::log1p(v * v / 4.0));
    // d/dx of 2 sqrt(L), L = log1p(x^2 / 4): (x / 2) / ((1 + x^2 / 4) sqrt(L)).
    const double expected_derivative =
        v < 1e-3 ? 1.0 - 3.0 * v * v / 16.0
                 : (v / 2.0) / ((1.0 + v * v / 4.0) * std::sqrt(std::log1p(v * v / 4.0)));
    EXPECT_NEAR(r, expected, 1e-10 * expected) << "x " << v;
    EXPECT_NEAR(jacobian, expected_derivative, 1e-9) << "x " << v;
  }
}

TEST(StackedCostFunctionTest, SameMinimumAsOneBlockPerRowWithTheLoss) {
  // Fit the extrinsic translation (and tau) to points on planes with Cauchy
  // outliers: per-row blocks with Ceres' loss and stacked blocks with the
  // folded loss minimise the same cost.
  std::mt19937 rng(71);
  const double dt = 0.05, sigma = 0.03;
  State truth = RandomState(&rng, dt);
  std::normal_distribution<double> n(0.0, 1.0);
  struct Point {
    double time_s;
    Eigen::Vector3d point, normal;
    double offset;
  };
  // Planes through the points as the true state maps them, with 1 cm of
  // noise; every 7th point 0.5 m off its plane (an outlier).
  std::vector<Point> points;
  const std::vector<double*> truth_params = PlaneParams(&truth, 0);
  for (int i = 0; i < 60; ++i) {
    Point p;
    p.time_s = 10.0 + (i % 20) / 20.0 * dt - truth.tau;
    p.point = 5.0 * tiltcal::testing::RandomVector3(n, rng);
    p.normal = tiltcal::testing::RandomVector3(n, rng).normalized();
    const PointToPlaneCostFunction through_origin(10.0, 1.0 / dt, p.time_s, p.point, p.normal,
                                                  0.0, sigma);
    p.offset = -RowResidual(through_origin, truth_params) * sigma + 0.01 * n(rng) +
               (i % 7 == 0 ? 0.5 : 0.0);
    points.push_back(p);
  }
  State start = truth;
  start.r_b_lb += Eigen::Vector3d(0.05, -0.03, 0.04);
  ceres::CauchyLoss loss(2.0);
  auto solve = [&](bool stack) {
    State s = start;
    ceres::Problem::Options options;
    options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(options);
    spline::RightQuaternionManifold quaternion;
    const std::vector<double*> params = PlaneParams(&s, 0);
    for (std::size_t k = 0; k < params.size(); ++k) {
      problem.AddParameterBlock(params[k], kPlaneBlocks[k] == Block::kQuaternion ? 4 : (k == 10 ? 1 : 3),
                                kPlaneBlocks[k] == Block::kQuaternion ? &quaternion : nullptr);
      if (k != 9) problem.SetParameterBlockConstant(params[k]);
    }
    StackedResidualAdder adder(&loss);
    for (const Point& p : points) {
      auto* row = new PointToPlaneCostFunction(10.0, 1.0 / dt, p.time_s, p.point, p.normal,
                                               p.offset, sigma);
      if (stack) {
        adder.Add(row, params);
      } else {
        problem.AddResidualBlock(row, &loss, params);
      }
    }
    EXPECT_EQ(adder.Flush(&problem), stack ? 1 : 0);
    ceres::Solver::Options solver;
    solver.function_tolerance = 1e-14;
    solver.gradient_tolerance = 1e-14;
    solver.parameter_tolerance = 1e-14;
    solver.max_num_iterations = 200;
    ceres::Solver::Summary summary;
    ceres::Solve(solver, &problem, &summary);
    EXPECT_EQ(summary.termination_type, ceres::CONVERGENCE);
    return std::make_pair(s.r_b_lb, summary.final_cost);
  };
  const auto [per_row, per_row_cost] = solve(false);
  const auto [stacked, stacked_cost] = solve(true);
  EXPECT_LT((per_row - stacked).norm(), 1e-7) << per_row.transpose() << " vs " << stacked.transpose();
  EXPECT_NEAR(per_row_cost, stacked_cost, 1e-9 * per_row_cost);
  EXPECT_LT((stacked - truth.r_b_lb).norm(), 0.01) << "the outliers should not pull it away";
}

TEST(StackedResidualAdderTest, GroupsRowsWithTheSameParameterBlocks) {
  std::mt19937 rng(73);
  State s = RandomState(&rng, 0.05);
  ceres::Problem problem;
  StackedResidualAdder adder(nullptr);
  auto rows = PlaneRows(s, 0.05, &rng);
  // Rows 0, 2, 4 on the window starting at knot 0, rows 1, 3 at knot 1.
  for (int i = 0; i < 5; ++i) adder.Add(rows[static_cast<std::size_t>(i)].release(), PlaneParams(&s, i % 2));
  EXPECT_EQ(adder.Flush(&problem), 2);
  EXPECT_EQ(problem.NumResidualBlocks(), 2);
  EXPECT_EQ(problem.NumResiduals(), 5);
  EXPECT_EQ(adder.Flush(&problem), 0) << "a flush empties the adder";
}

// ---- The time offset's interval (interval_manifold.h) ----

TEST(IntervalManifoldTest, StepsAreProjectedOntoTheInterval) {
  const IntervalManifold interval(-0.01, 0.02);
  double x = 0.015, delta = 0.01, out = 0.0;
  ASSERT_TRUE(interval.Plus(&x, &delta, &out));
  EXPECT_EQ(out, 0.02);
  delta = -0.1;
  ASSERT_TRUE(interval.Plus(&x, &delta, &out));
  EXPECT_EQ(out, -0.01);
  delta = -0.005;
  ASSERT_TRUE(interval.Plus(&x, &delta, &out));
  EXPECT_DOUBLE_EQ(out, 0.01);
  double jacobian = 0.0;
  ASSERT_TRUE(interval.PlusJacobian(&x, &jacobian));
  EXPECT_EQ(jacobian, 1.0);
}

TEST(IntervalManifoldTest, SolveEndsAtTheBoundLikeCeresBounds) {
  // r = x - 1 with x in [-0.5, 0.25]: the minimum of the interval is its upper end.
  class Offset final : public ceres::SizedCostFunction<1, 1> {
   public:
    bool Evaluate(double const* const* p, double* r, double** j) const override {
      r[0] = p[0][0] - 1.0;
      if (j != nullptr && j[0] != nullptr) j[0][0] = 1.0;
      return true;
    }
  };
  const IntervalManifold interval(-0.5, 0.25);
  ceres::Problem::Options options;
  options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(options);
  double x = 0.0;
  problem.AddParameterBlock(&x, 1, const_cast<IntervalManifold*>(&interval));
  problem.AddResidualBlock(new Offset, nullptr, &x);
  ceres::Solver::Summary summary;
  ceres::Solve(ceres::Solver::Options(), &problem, &summary);
  EXPECT_EQ(x, 0.25);
  EXPECT_FALSE(summary.is_constrained) << "no Ceres bounds: no projected line search";
}

// The clock drift's wrapper around the point-to-plane residual: the value is
// the inner residual's at tau(t_j) = tau0 + rho (t_j - t_ref), dr/drho is
// (t_j - t_ref) dr/dtau, and every Jacobian (rho's too) matches central
// differences. t_j - t_ref of both signs and up to 80 s (a 160 s sequence),
// rho up to 500 ppm. The shared check steps every block by 1e-6, which moves
// tau by 1e-6 (t_j - t_ref): beyond 1 s its truncation error grows with the
// lever, so there rho's difference is taken with a step of 1e-7 s in tau.
TEST(DriftingTimeOffsetCostFunctionTest, PointToPlaneMatchesNumericDifferences) {
  std::mt19937 rng(61);
  std::uniform_real_distribution<double> rate(-5e-4, 5e-4);
  for (double dt : kSpacings) {
    for (double from_reference : {-80.0, -0.9, 0.0, 0.7, 45.0}) {
      for (double u : {0.0, 0.37, 0.96}) {
        State s = RandomState(&rng, dt);
        double rho = rate(rng);
        const double tau = s.tau + rho * from_reference;
        const double segment_start = 100.0;
        const double point_time = segment_start + u * dt - tau;
        const Eigen::Vector3d point(4.0, -2.0, 0.7);
        const Eigen::Vector3d normal = Eigen::Vector3d(0.2, -0.3, 0.9).normalized();
        auto* inner = new PointToPlaneCostFunction(segment_start, 1.0 / dt, point_time, point,
                                                   normal, -1.3, 0.03);
        const DriftingTimeOffsetCostFunction drifting(inner, 10, from_reference);
        std::vector<double*> params = PlaneParams(&s, 0);
        params.push_back(&rho);
        std::vector<Block> blocks = kPlaneBlocks;
        blocks.push_back(Block::kEuclidean);
        const std::string label = "dt " + std::to_string(dt) + " t-t_ref " +
                                  std::to_string(from_reference) + " u " + std::to_string(u);
        if (std::abs(from_reference) <= 1.0) {
          ExpectTangentDifferencesMatch(drifting, params, blocks, label);
        }

        // Value and tau Jacobian are the inner function's at tau(t_j).
        State at = s;
        at.tau = tau;
        const std::vector<double*> inner_params = PlaneParams(&at, 0);
        Eigen::VectorXd r_inner, r_drift;
        std::vector<testing::RowMajor> j_inner, j_drift;
        testing::EvaluateAll(*inner, inner_params, &r_inner, &j_inner);
        testing::EvaluateAll(drifting, params, &r_drift, &j_drift);
        EXPECT_NEAR(r_drift[0], r_inner[0], 1e-12 * (1.0 + std::abs(r_inner[0]))) << label;
        EXPECT_NEAR(j_drift[10](0, 0), j_inner[10](0, 0),
                    1e-12 * (1.0 + std::abs(j_inner[10](0, 0))))
            << label;
        EXPECT_NEAR(j_drift[11](0, 0), from_reference * j_inner[10](0, 0),
                    1e-12 * (1.0 + std::abs(from_reference * j_inner[10](0, 0))))
            << label;
        EXPECT_NEAR(u, inner->NormalizedTime(tau), 1e-9) << label;
        if (from_reference != 0.0) {
          const double h = 1e-7 / std::abs(from_reference);
          const double rho0 = rho;
          double r_plus, r_minus;
          rho = rho0 + h;
          ASSERT_TRUE(drifting.Evaluate(params.data(), &r_plus, nullptr));
          rho = rho0 - h;
          ASSERT_TRUE(drifting.Evaluate(params.data(), &r_minus, nullptr));
          rho = rho0;
          const double numeric = (r_plus - r_minus) / (2.0 * h);
          EXPECT_NEAR(j_drift[11](0, 0), numeric, 1e-5 * (1.0 + std::abs(numeric))) << label;
        }
      }
    }
  }
}

// dr/drho asked for without dr/dtau0 (tau0 held, rho free) is the same.
TEST(DriftingTimeOffsetCostFunctionTest, RateJacobianWithoutTheOffsetJacobian) {
  std::mt19937 rng(67);
  State s = RandomState(&rng, 0.05);
  double rho = 2e-4;
  auto* inner = new PointToPlaneCostFunction(10.0, 20.0, 10.02 - s.tau, Eigen::Vector3d(3, 1, -1),
                                             Eigen::Vector3d(0, 0.6, 0.8), 0.4, 0.02);
  const DriftingTimeOffsetCostFunction drifting(inner, 10, -12.5);
  std::vector<double*> params = PlaneParams(&s, 0);
  params.push_back(&rho);
  double r_all, r_rate_only, j_tau, j_rate_all, j_rate_only;
  double* all[12] = {nullptr};
  all[10] = &j_tau;
  all[11] = &j_rate_all;
  ASSERT_TRUE(drifting.Evaluate(params.data(), &r_all, all));
  double* rate_only[12] = {nullptr};
  rate_only[11] = &j_rate_only;
  ASSERT_TRUE(drifting.Evaluate(params.data(), &r_rate_only, rate_only));
  EXPECT_EQ(r_all, r_rate_only);
  EXPECT_EQ(j_rate_all, j_rate_only);
  EXPECT_DOUBLE_EQ(j_rate_all, -12.5 * j_tau);
  EXPECT_NE(j_tau, 0.0);
}

// The ground residuals that use tau (flat: 3 rows, inclination: 1), wrapped:
// central differences of every block, rho's included.
TEST(DriftingTimeOffsetCostFunctionTest, GroundResidualsMatchNumericDifferences) {
  std::mt19937 rng(71);
  for (double from_reference : {-0.8, 0.6}) {
    State s = RandomState(&rng, 0.05);
    double rho = -3e-4;
    const double tau = s.tau + rho * from_reference;
    const double segment_start = 4.0;
    const double scan_time = segment_start + 0.4 * 0.05 - tau;
    const Eigen::Vector3d normal = Eigen::Vector3d(0.05, -0.1, 1.0).normalized();
    std::vector<double*> params = {s.q[0].coeffs().data(), s.q[1].coeffs().data(),
                                   s.q[2].coeffs().data(), s.q[3].coeffs().data(),
                                   s.gravity_dir.data(),   s.q_bl.coeffs().data(),
                                   &s.tau,                 &rho};
    const std::vector<Block> blocks = {Block::kQuaternion, Block::kQuaternion, Block::kQuaternion,
                                       Block::kQuaternion, Block::kSphere,     Block::kQuaternion,
                                       Block::kEuclidean,  Block::kEuclidean};
    const DriftingTimeOffsetCostFunction flat(
        new FlatGroundCostFunction(segment_start, 20.0, scan_time, normal,
                                   Eigen::Matrix3d::Identity() / 0.01),
        6, from_reference);
    ExpectTangentDifferencesMatch(flat, params, blocks, "flat " + std::to_string(from_reference));
    const DriftingTimeOffsetCostFunction incl(
        new InclinationCostFunction(segment_start, 20.0, scan_time, normal,
                                    Eigen::Vector3d(0.1, 0.2, -9.8), 100.0),
        6, from_reference);
    ExpectTangentDifferencesMatch(incl, params, blocks, "incl " + std::to_string(from_reference));
  }
}

}  // namespace
}  // namespace tiltcal::calibrate
