// End-to-end sanity of the spline residuals: fit the split SO(3) x R^3
// spline to gyro and accelerometer samples of a known smooth trajectory,
// starting from identity / zero knots, and recover the trajectory.
//
// Truth (closed form, independent of the spline):
//   C_ab(t) = Exp(phi(t)),  omega_b = Jr(phi) phi'(t),
//   r_a(t) sinusoidal,      f_b = C_ab^T (r_a'' - g_a).
// IMU residuals leave a gauge free (yaw about gravity, position and
// velocity); three test-only autodiff priors fix it: C_ab(0), r_a(0), r_a(T).
//
// Second test: point-to-plane residuals alone, with the trajectory held at
// the truth, recover the extrinsic (C_bl, r_b^{lb}) and the time offset tau,
// with windows binned from the current tau and re-binned once (the outer
// iteration the stage performs).

#include <array>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include <ceres/autodiff_cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/problem.h>
#include <ceres/solver.h>
#include <ceres/sphere_manifold.h>
#include <gtest/gtest.h>

#include "common/geometry/so3.h"
#include "common/spline/knot_grid.h"
#include "common/spline/quaternion_manifold.h"
#include "common/spline/spline_trajectory.h"
#include "stages/calibrate/residuals/accel_cost_function.h"
#include "stages/calibrate/residuals/gyro_cost_function.h"
#include "stages/calibrate/residuals/point_to_plane_cost_function.h"
#include "tests/common/spline/spline_reference.h"
#include "tests/testing/random_vector.h"

namespace tiltcal::calibrate {
namespace {

struct Truth {
  static Eigen::Vector3d Phi(double t) {
    return {0.3 * std::sin(1.1 * t), 0.2 * std::sin(0.7 * t + 0.5), 0.6 * std::sin(0.9 * t)};
  }
  static Eigen::Vector3d PhiDot(double t) {
    return {0.33 * std::cos(1.1 * t), 0.14 * std::cos(0.7 * t + 0.5), 0.54 * std::cos(0.9 * t)};
  }
  static Eigen::Matrix3d Rotation(double t) { return geometry::ExpMatrix(Phi(t)); }
  static Eigen::Vector3d Omega(double t) { return geometry::RightJacobian(Phi(t)) * PhiDot(t); }
  static Eigen::Vector3d Position(double t) {
    return {2.0 * std::sin(0.5 * t), 1.5 * std::cos(0.4 * t) - 1.5, 0.3 * std::sin(0.8 * t)};
  }
  static Eigen::Vector3d Acceleration(double t) {
    return {-0.5 * std::sin(0.5 * t), -0.24 * std::cos(0.4 * t), -0.192 * std::sin(0.8 * t)};
  }
};

// Test-only gauge priors on the reference (Jet) spline at a fixed u.
struct RotationPrior {
  double u, inv_dt;
  Eigen::Quaterniond expected;
  template <typename T>
  bool operator()(const T* q0, const T* q1, const T* q2, const T* q3, T* r) const {
    const T* ptr[4] = {q0, q1, q2, q3};
    Eigen::Quaternion<T> q[4];
    for (int i = 0; i < 4; ++i) q[i] = Eigen::Map<const Eigen::Quaternion<T>>(ptr[i]);
    const auto s = testing::ReferenceSo3<T>(q, T(u), inv_dt);
    const Eigen::Matrix<T, 3, 1> e =
        geometry::LogQuaternion(Eigen::Quaternion<T>(expected.cast<T>().conjugate() * s.q));
    for (int k = 0; k < 3; ++k) r[k] = T(100.0) * e[k];
    return true;
  }
};

struct PositionPrior {
  double u, inv_dt;
  Eigen::Vector3d expected;
  template <typename T>
  bool operator()(const T* p0, const T* p1, const T* p2, const T* p3, T* r) const {
    const T* ptr[4] = {p0, p1, p2, p3};
    Eigen::Matrix<T, 3, 1> p[4];
    for (int i = 0; i < 4; ++i) p[i] = Eigen::Map<const Eigen::Matrix<T, 3, 1>>(ptr[i]);
    const auto s = testing::ReferenceR3<T>(p, T(u), inv_dt);
    for (int k = 0; k < 3; ++k) r[k] = T(100.0) * (s.position[k] - T(expected[k]));
    return true;
  }
};

TEST(ImuSplineFitTest, RecoversKnownTrajectoryFromGyroAndAccel) {
  const double duration = 3.0, dt = 0.1, rate_hz = 200.0;
  const double gravity_norm = 9.81;
  const spline::UniformKnotGrid grid = spline::UniformKnotGrid::ForDuration(0.0, duration, dt);
  spline::SplineTrajectory traj(grid);  // identity / zero knots
  Eigen::Vector3d gravity_dir(0.0, 0.0, -1.0);
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero(), accel_bias = Eigen::Vector3d::Zero();
  std::array<double, 9> gyro_triad_errors{}, accel_triad_errors{};  // ideal triads, held
  const Eigen::Vector3d g_a = gravity_norm * gravity_dir;

  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  spline::RightQuaternionManifold quaternion_manifold;
  for (int i = 0; i < grid.num_knots(); ++i) {
    problem.AddParameterBlock(traj.rotation_knot(i), 4, &quaternion_manifold);
    problem.AddParameterBlock(traj.position_knot(i), 3);
  }
  const int num_samples = static_cast<int>(duration * rate_hz) + 1;
  for (int k = 0; k < num_samples; ++k) {
    const double t = k / rate_hz;
    spline::KnotWindow w;
    ASSERT_TRUE(grid.Locate(t, &w));
    double* q[4];
    double* p[4];
    for (int j = 0; j < 4; ++j) {
      q[j] = traj.rotation_knot(w.first_knot + j);
      p[j] = traj.position_knot(w.first_knot + j);
    }
    const Eigen::Vector3d f_b = Truth::Rotation(t).transpose() * (Truth::Acceleration(t) - g_a);
    problem.AddResidualBlock(new GyroCostFunction(w, grid.inv_dt(), Truth::Omega(t), 0.01), nullptr,
                             q[0], q[1], q[2], q[3], gyro_bias.data(), gyro_triad_errors.data());
    problem.AddResidualBlock(new AccelCostFunction(w, grid.inv_dt(), f_b, 0.05, gravity_norm), nullptr,
                             q[0], q[1], q[2], q[3], p[0], p[1], p[2], p[3], gravity_dir.data(),
                             accel_bias.data(), accel_triad_errors.data());
  }
  problem.SetParameterBlockConstant(gyro_triad_errors.data());
  problem.SetParameterBlockConstant(accel_triad_errors.data());
  problem.SetParameterBlockConstant(gyro_bias.data());
  problem.SetParameterBlockConstant(accel_bias.data());
  problem.SetParameterBlockConstant(gravity_dir.data());
  // Gauge priors.
  for (double t : {0.0, duration}) {
    spline::KnotWindow w;
    ASSERT_TRUE(grid.Locate(t, &w));
    const int s = w.first_knot;
    if (t == 0.0) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<RotationPrior, 3, 4, 4, 4, 4>(
              new RotationPrior{w.u, grid.inv_dt(), Eigen::Quaterniond(Truth::Rotation(t))}),
          nullptr, traj.rotation_knot(s), traj.rotation_knot(s + 1), traj.rotation_knot(s + 2),
          traj.rotation_knot(s + 3));
    }
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<PositionPrior, 3, 3, 3, 3, 3>(
            new PositionPrior{w.u, grid.inv_dt(), Truth::Position(t)}),
        nullptr, traj.position_knot(s), traj.position_knot(s + 1), traj.position_knot(s + 2),
        traj.position_knot(s + 3));
  }

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.max_num_iterations = 50;
  options.function_tolerance = 1e-12;
  options.gradient_tolerance = 1e-12;
  options.parameter_tolerance = 1e-12;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();

  double max_rot_err = 0, max_pos_err = 0, max_omega_err = 0;
  for (double t = 0.0; t <= duration; t += 0.01) {
    spline::So3SplineSample r;
    spline::R3SplineSample p;
    ASSERT_TRUE(traj.Evaluate(t, spline::kSo3Rotation | spline::kSo3AngularVelocity, &r, &p));
    max_rot_err = std::max(max_rot_err, geometry::LogMatrix(Truth::Rotation(t).transpose() * r.rotation).norm());
    max_pos_err = std::max(max_pos_err, (p.position - Truth::Position(t)).norm());
    max_omega_err = std::max(max_omega_err, (r.angular_velocity - Truth::Omega(t)).norm());
  }
  EXPECT_LT(max_rot_err, 1e-5) << summary.BriefReport();
  EXPECT_LT(max_pos_err, 1e-5) << summary.BriefReport();
  EXPECT_LT(max_omega_err, 1e-3) << summary.BriefReport();
  // Residuals are noise-free, so the final cost is tiny (model error only).
  EXPECT_LT(summary.final_cost, 1e-2 * summary.initial_cost);
  RecordProperty("max_rotation_error_rad", std::to_string(max_rot_err));
  std::printf("iterations %d, cost %.3e -> %.3e, max errors: rotation %.2e rad, position %.2e m, omega %.2e rad/s\n",
              static_cast<int>(summary.iterations.size()), summary.initial_cost, summary.final_cost,
              max_rot_err, max_pos_err, max_omega_err);
}


TEST(LidarSplineFitTest, PointToPlaneRecoversExtrinsicAndTimeOffset) {
  const double duration = 10.0, dt = 0.05;
  const spline::UniformKnotGrid grid = spline::UniformKnotGrid::ForDuration(0.0, duration, dt);
  spline::SplineTrajectory traj(grid);
  for (int i = 0; i < grid.num_knots(); ++i) {
    const double t = (i - 1) * dt;
    traj.SetRotationKnot(i, geometry::ExpQuaternion(Eigen::Vector3d(
                                0.2 * std::sin(1.3 * t), 0.15 * std::sin(0.9 * t + 1.0), 0.8 * std::sin(0.4 * t))));
    traj.SetPositionKnot(i, Eigen::Vector3d(3.0 * std::sin(0.3 * t), 2.0 * std::cos(0.25 * t), 0.3 * std::sin(1.1 * t)));
  }
  const Eigen::Quaterniond q_bl_true = geometry::ExpQuaternion(Eigen::Vector3d(0.02, -0.03, 1.5));
  const Eigen::Vector3d r_b_true(0.12, -0.05, 0.31);
  const double tau_true = 0.013;  // a quarter of a segment

  struct Point {
    double t_lidar;
    Eigen::Vector3d p_l, normal;
    double offset;
  };
  std::mt19937 rng(61);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> uni(0.1, duration - 0.1);
  std::vector<Point> points;
  for (int k = 0; k < 3000; ++k) {
    Point pt;
    pt.t_lidar = uni(rng);
    pt.p_l = tiltcal::testing::RandomVector3(n, rng).cwiseProduct(Eigen::Vector3d(8.0, 8.0, 1.5));
    pt.normal = tiltcal::testing::RandomVector3(n, rng).normalized();
    spline::So3SplineSample r;
    spline::R3SplineSample p;
    ASSERT_TRUE(traj.Evaluate(pt.t_lidar + tau_true, spline::kSo3Rotation, &r, &p));
    const Eigen::Vector3d p_a = r.rotation * (q_bl_true * pt.p_l + r_b_true) + p.position;
    pt.offset = -pt.normal.dot(p_a);
    points.push_back(pt);
  }

  Eigen::Quaterniond q_bl = geometry::BoxPlus(q_bl_true, Eigen::Vector3d(0.04, -0.03, 0.05));
  Eigen::Vector3d r_b = r_b_true + Eigen::Vector3d(0.05, -0.04, 0.03);
  double tau = 0.0;
  spline::RightQuaternionManifold quaternion_manifold;
  for (int outer = 0; outer < 2; ++outer) {
    ceres::Problem::Options problem_options;
    problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(problem_options);
    for (const Point& pt : points) {
      spline::KnotWindow w;
      ASSERT_TRUE(grid.Locate(pt.t_lidar + tau, &w));  // binned with the current tau
      double* q[4];
      double* x[4];
      for (int j = 0; j < 4; ++j) {
        q[j] = traj.rotation_knot(w.first_knot + j);
        x[j] = traj.position_knot(w.first_knot + j);
      }
      problem.AddResidualBlock(
          new PointToPlaneCostFunction(grid.SegmentStart(w.first_knot), grid.inv_dt(), pt.t_lidar, pt.p_l,
                                       pt.normal, pt.offset, 0.02),
          nullptr, q[0], q[1], q[2], q[3], x[0], x[1], x[2], x[3], q_bl.coeffs().data(), r_b.data(), &tau);
    }
    problem.SetManifold(q_bl.coeffs().data(), &quaternion_manifold);
    for (int i = 0; i < grid.num_knots(); ++i) {
      if (problem.HasParameterBlock(traj.rotation_knot(i))) {
        problem.SetManifold(traj.rotation_knot(i), &quaternion_manifold);
        problem.SetParameterBlockConstant(traj.rotation_knot(i));
      }
      if (problem.HasParameterBlock(traj.position_knot(i))) problem.SetParameterBlockConstant(traj.position_knot(i));
    }
    problem.SetParameterLowerBound(&tau, 0, tau - 0.5 * dt);
    problem.SetParameterUpperBound(&tau, 0, tau + 0.5 * dt);
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;  // 7 free parameters
    options.max_num_iterations = 30;
    options.function_tolerance = 1e-14;
    options.parameter_tolerance = 1e-14;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
    std::printf("outer %d: cost %.3e -> %.3e, tau %.6f s, rotation error %.2e rad, translation error %.2e m\n",
                outer, summary.initial_cost, summary.final_cost, tau,
                geometry::BoxMinus(q_bl, q_bl_true).norm(), (r_b - r_b_true).norm());
  }
  // Noise-free data: after re-binning, the frozen windows match the true
  // segments and the solution is exact up to solver tolerance.
  EXPECT_NEAR(tau, tau_true, 1e-9);
  EXPECT_LT(geometry::BoxMinus(q_bl, q_bl_true).norm(), 1e-9);
  EXPECT_LT((r_b - r_b_true).norm(), 1e-9);
}

}  // namespace
}  // namespace tiltcal::calibrate
