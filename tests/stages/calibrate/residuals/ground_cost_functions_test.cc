// Analytic ground residuals (stages/calibrate/residuals/ground_cost_functions.h) vs
// autodiff twins written here on the independent templated reference spline
// (tests/common/spline/spline_reference.h), vs central differences in the
// tangent spaces of every block, and (for the blocks without tau) vs
// ceres::GradientChecker. Random states with a non-trivial tau, at several
// knot spacings and normalised times including segment ends and values that
// tau has pushed slightly outside [0, 1], with non-diagonal weights.

#include <memory>
#include <random>
#include <string>
#include <vector>

#include <ceres/autodiff_cost_function.h>
#include <gtest/gtest.h>

#include "common/geometry/so3.h"
#include "stages/calibrate/residuals/ground_cost_functions.h"
#include "tests/common/spline/spline_reference.h"
#include "tests/stages/calibrate/residuals/jacobian_checks.h"
#include "tests/testing/random_vector.h"

namespace tiltcal::calibrate {
namespace {

using geometry::ExpQuaternion;

template <typename T>
using Vec3 = Eigen::Matrix<T, 3, 1>;

// ------------------------------------------------------------ autodiff twins
// Same formulas, same blocks; gravity up g~_b = -C^T n_g / |n_g| and C_bl
// normalised inside (the analytic code treats both as unit, which they are at
// the probe points; normalising here makes the twin's ambient Jacobian differ
// only in the directions the manifolds never move).

template <typename T>
Eigen::Quaternion<T> SplineRotation(const T* const q0, const T* const q1, const T* const q2,
                                    const T* const q3, const T& u, double inv_dt) {
  const T* const ptr[4] = {q0, q1, q2, q3};
  Eigen::Quaternion<T> q[4];
  for (int i = 0; i < 4; ++i) q[i] = Eigen::Map<const Eigen::Quaternion<T>>(ptr[i]);
  return testing::ReferenceSo3<T>(q, u, inv_dt).q;
}

struct FlatTwin {
  double time_in_segment_s, inv_dt;
  Eigen::Vector3d normal;
  Eigen::Matrix3d w;
  template <typename T>
  bool operator()(const T* const q0, const T* const q1, const T* const q2, const T* const q3,
                  const T* const gravity, const T* const q_bl_ptr, const T* const tau,
                  T* residual) const {
    const T u = (T(time_in_segment_s) + tau[0]) * inv_dt;
    const Eigen::Quaternion<T> c_ab = SplineRotation(q0, q1, q2, q3, u, inv_dt);
    const Vec3<T> n_g = Eigen::Map<const Vec3<T>>(gravity).normalized();
    const Vec3<T> up_b = -(c_ab.conjugate() * n_g);
    const Eigen::Quaternion<T> q_bl = Eigen::Map<const Eigen::Quaternion<T>>(q_bl_ptr).normalized();
    const Vec3<T> e = normal.cast<T>() - q_bl.conjugate() * up_b;
    Eigen::Map<Vec3<T>> r(residual);
    r = w.cast<T>() * e;
    return true;
  }
  using AutoDiff = ceres::AutoDiffCostFunction<FlatTwin, 3, 4, 4, 4, 4, 3, 4, 1>;
};

struct DistTwin {
  Eigen::Vector3d normal;
  double d_l, d_b, w;
  template <typename T>
  bool operator()(const T* const q_bl_ptr, const T* const r_ptr, T* residual) const {
    const Eigen::Quaternion<T> q_bl = Eigen::Map<const Eigen::Quaternion<T>>(q_bl_ptr).normalized();
    const Vec3<T> r_l = q_bl.conjugate() * Eigen::Map<const Vec3<T>>(r_ptr);
    residual[0] = w * (T(d_l) - T(d_b) - normal.cast<T>().dot(r_l));
    return true;
  }
  using AutoDiff = ceres::AutoDiffCostFunction<DistTwin, 1, 4, 3>;
};

struct InclTwin {
  double time_in_segment_s, inv_dt;
  Eigen::Vector3d normal, gravity_flat;
  double w;
  template <typename T>
  bool operator()(const T* const q0, const T* const q1, const T* const q2, const T* const q3,
                  const T* const gravity, const T* const q_bl_ptr, const T* const tau,
                  T* residual) const {
    const T u = (T(time_in_segment_s) + tau[0]) * inv_dt;
    const Eigen::Quaternion<T> c_ab = SplineRotation(q0, q1, q2, q3, u, inv_dt);
    const Vec3<T> n_g = Eigen::Map<const Vec3<T>>(gravity).normalized();
    const Vec3<T> up_b = -(c_ab.conjugate() * n_g);
    const Vec3<T> up_f = -gravity_flat.normalized().cast<T>();
    const Eigen::Quaternion<T> q_bl = Eigen::Map<const Eigen::Quaternion<T>>(q_bl_ptr).normalized();
    residual[0] = w * up_b.dot(up_f - q_bl * normal.cast<T>());
    return true;
  }
  using AutoDiff = ceres::AutoDiffCostFunction<InclTwin, 1, 4, 4, 4, 4, 3, 4, 1>;
};

// r = W C_bl^T (C_bl n_l - g~_f).
struct UpTwin {
  Eigen::Vector3d normal, gravity_flat;
  Eigen::Matrix3d w;
  template <typename T>
  bool operator()(const T* const q_bl_ptr, T* residual) const {
    const Eigen::Quaternion<T> q_bl = Eigen::Map<const Eigen::Quaternion<T>>(q_bl_ptr).normalized();
    const Vec3<T> up_f = -gravity_flat.normalized().cast<T>();
    const Vec3<T> e_up = q_bl * normal.cast<T>() - up_f;
    Eigen::Map<Vec3<T>> r(residual);
    r = w.cast<T>() * (q_bl.conjugate() * e_up);
    return true;
  }
  using AutoDiff = ceres::AutoDiffCostFunction<UpTwin, 3, 4>;
};

// ------------------------------------------------------------ states

struct State {
  Eigen::Quaterniond q[4];
  Eigen::Vector3d gravity_dir, r_b_lb;
  Eigen::Quaterniond q_bl;
  double tau = 0.0;
};

State RandomState(std::mt19937* rng, double dt) {
  std::normal_distribution<double> n(0.0, 1.0);
  auto v = [&](double s) { return Eigen::Vector3d(s * tiltcal::testing::RandomVector3(n, *rng)); };
  State s;
  s.q[0] = ExpQuaternion(v(1.0));
  // Angular rates ~ 1-3 rad/s whatever dt.
  for (int i = 1; i < 4; ++i) s.q[i] = s.q[i - 1] * ExpQuaternion(Eigen::Vector3d(v(2.0 * dt)));
  s.gravity_dir = (Eigen::Vector3d(0, 0, -1) + v(0.2)).normalized();
  s.r_b_lb = v(0.5);
  s.q_bl = ExpQuaternion(v(1.0));
  s.tau = 0.003 * n(*rng) + 0.002;
  return s;
}

Eigen::Vector3d RandomUnit(std::mt19937* rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return tiltcal::testing::RandomVector3(n, *rng).normalized();
}

// A non-symmetric, well-conditioned weight.
Eigen::Matrix3d RandomWeight(std::mt19937* rng) {
  std::uniform_real_distribution<double> uni(-0.3, 0.3);
  Eigen::Matrix3d w = Eigen::Matrix3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) w(r, c) += uni(*rng);
  }
  return 20.0 * w;
}

using testing::Block;
using testing::EvaluateAll;
using testing::ExpectGradientCheckerPasses;
using testing::ExpectTangentDifferencesMatch;
using testing::RowMajor;

const double kSpacings[] = {0.02, 0.05, 0.1};
// Normalised time of t_k + tau in the frozen window, including tau pushing it
// slightly outside [0, 1].
const double kTimes[] = {-0.02, 0.0, 1e-9, 0.31, 0.5, 0.93, 1.0 - 1e-9, 1.0, 1.02};

const std::vector<Block> kSplineBlocks = {Block::kQuaternion, Block::kQuaternion,
                                          Block::kQuaternion, Block::kQuaternion,
                                          Block::kSphere,     Block::kQuaternion,
                                          Block::kEuclidean};

std::vector<double*> SplineParams(State* s) {
  return {s->q[0].coeffs().data(), s->q[1].coeffs().data(), s->q[2].coeffs().data(),
          s->q[3].coeffs().data(), s->gravity_dir.data(),   s->q_bl.coeffs().data(),
          &s->tau};
}

TEST(FlatGroundCostFunctionTest, MatchesAutodiffTwinAndNumericDifferences) {
  std::mt19937 rng(61);
  for (double dt : kSpacings) {
    for (double u : kTimes) {
      State s = RandomState(&rng, dt);
      const double segment_start = 7.0;
      const double scan_time = segment_start + u * dt - s.tau;
      const Eigen::Vector3d normal = RandomUnit(&rng);
      const Eigen::Matrix3d w = RandomWeight(&rng);
      FlatGroundCostFunction analytic(segment_start, 1.0 / dt, scan_time, normal, w);
      EXPECT_NEAR(analytic.NormalizedTime(s.tau), u, 1e-9);
      FlatTwin::AutoDiff twin(new FlatTwin{scan_time - segment_start, 1.0 / dt, normal, w});
      const std::string label = "flat dt " + std::to_string(dt) + " u " + std::to_string(u);
      const std::vector<double*> params = SplineParams(&s);
      testing::ExpectSameTangentJacobians(analytic, twin, params, kSplineBlocks, 1e-9, label);
      ExpectTangentDifferencesMatch(analytic, params, kSplineBlocks, label);
    }
  }
}

TEST(InclinationCostFunctionTest, MatchesAutodiffTwinAndNumericDifferences) {
  std::mt19937 rng(67);
  for (double dt : kSpacings) {
    for (double u : kTimes) {
      State s = RandomState(&rng, dt);
      const double segment_start = 3.0;
      const double scan_time = segment_start + u * dt - s.tau;
      const Eigen::Vector3d normal = RandomUnit(&rng);
      const Eigen::Vector3d gravity_flat = 9.81 * RandomUnit(&rng);
      const double w = 150.0;
      InclinationCostFunction analytic(segment_start, 1.0 / dt, scan_time, normal, gravity_flat, w);
      EXPECT_NEAR(analytic.NormalizedTime(s.tau), u, 1e-9);
      InclTwin::AutoDiff twin(
          new InclTwin{scan_time - segment_start, 1.0 / dt, normal, gravity_flat, w});
      const std::string label = "incl dt " + std::to_string(dt) + " u " + std::to_string(u);
      const std::vector<double*> params = SplineParams(&s);
      testing::ExpectSameTangentJacobians(analytic, twin, params, kSplineBlocks, 1e-9, label);
      ExpectTangentDifferencesMatch(analytic, params, kSplineBlocks, label);
    }
  }
}

TEST(DistanceCostFunctionTest, MatchesAutodiffTwinGradientCheckerAndNumericDifferences) {
  std::mt19937 rng(71);
  const std::vector<Block> blocks = {Block::kQuaternion, Block::kEuclidean};
  for (int trial = 0; trial < 20; ++trial) {
    State s = RandomState(&rng, 0.05);
    const Eigen::Vector3d normal = RandomUnit(&rng);
    const double d_l = 1.2, d_b = 0.4, w = 50.0;
    DistanceCostFunction analytic(normal, d_l, d_b, w);
    DistTwin::AutoDiff twin(new DistTwin{normal, d_l, d_b, w});
    const std::vector<double*> params = {s.q_bl.coeffs().data(), s.r_b_lb.data()};
    const std::string label = "dist trial " + std::to_string(trial);
    testing::ExpectSameTangentJacobians(analytic, twin, params, blocks, 1e-9, label);
    ExpectTangentDifferencesMatch(analytic, params, blocks, label);
    ExpectGradientCheckerPasses(analytic, params, blocks, label);
  }
}

TEST(UpCostFunctionTest, MatchesAutodiffTwinGradientCheckerAndNumericDifferences) {
  std::mt19937 rng(73);
  const std::vector<Block> blocks = {Block::kQuaternion};
  for (int trial = 0; trial < 20; ++trial) {
    State s = RandomState(&rng, 0.05);
    const Eigen::Vector3d normal = RandomUnit(&rng);
    const Eigen::Vector3d gravity_flat = 9.8 * RandomUnit(&rng);
    const Eigen::Matrix3d w = RandomWeight(&rng);
    UpCostFunction analytic(normal, gravity_flat, w);
    UpTwin::AutoDiff twin(new UpTwin{normal, gravity_flat, w});
    const std::vector<double*> params = {s.q_bl.coeffs().data()};
    const std::string label = "up trial " + std::to_string(trial);
    testing::ExpectSameTangentJacobians(analytic, twin, params, blocks, 1e-9, label);
    ExpectTangentDifferencesMatch(analytic, params, blocks, label);
    ExpectGradientCheckerPasses(analytic, params, blocks, label);
  }
}

// The residual norm of e_up does not depend on the frame it is resolved in:
// with W = I / sigma, |r| = |C_bl n_l - g~_f| / sigma.
TEST(UpCostFunctionTest, IsotropicWeightGivesTheImuFrameNorm) {
  std::mt19937 rng(79);
  for (int trial = 0; trial < 5; ++trial) {
    State s = RandomState(&rng, 0.05);
    const Eigen::Vector3d normal = RandomUnit(&rng);
    const Eigen::Vector3d gravity_flat = 9.8 * RandomUnit(&rng);
    const double sigma = 0.02;
    UpCostFunction cost(normal, gravity_flat, Eigen::Matrix3d::Identity() / sigma);
    const double* params[1] = {s.q_bl.coeffs().data()};
    Eigen::Vector3d r;
    ASSERT_TRUE(cost.Evaluate(params, r.data(), nullptr));
    const Eigen::Vector3d e_up = s.q_bl * normal + gravity_flat.normalized();
    EXPECT_NEAR(r.norm(), e_up.norm() / sigma, 1e-9);
  }
}

// Evaluate with only some Jacobians requested writes those and matches the
// full evaluation (the cost functions skip spline work they do not need).
TEST(FlatGroundCostFunctionTest, PartialJacobianRequests) {
  std::mt19937 rng(83);
  State s = RandomState(&rng, 0.05);
  const Eigen::Vector3d normal = RandomUnit(&rng);
  FlatGroundCostFunction cost(0.0, 20.0, 0.021, normal, Eigen::Matrix3d::Identity());
  const std::vector<double*> params = SplineParams(&s);
  Eigen::VectorXd r_full;
  std::vector<RowMajor> full;
  EvaluateAll(cost, params, &r_full, &full);
  for (int only = 0; only < 7; ++only) {
    std::vector<RowMajor> jac(7);
    std::vector<double*> ptr(7, nullptr);
    jac[only].setZero(3, cost.parameter_block_sizes()[only]);
    ptr[only] = jac[only].data();
    Eigen::Vector3d r;
    ASSERT_TRUE(cost.Evaluate(params.data(), r.data(), ptr.data()));
    EXPECT_LT((r - r_full).norm(), 1e-15);
    EXPECT_LT((jac[only] - full[only]).norm(), 1e-12 * (1.0 + full[only].norm())) << only;
  }
}

}  // namespace
}  // namespace tiltcal::calibrate
