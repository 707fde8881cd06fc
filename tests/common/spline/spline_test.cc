// Tests of the cubic B-splines on SO(3) and R^3 (common/spline): basis,
// knot grid, values and derivatives against closed forms, against an
// independent quaternion product-rule implementation (spline_reference.h),
// against finite differences of the spline itself, and knot / time
// Jacobians against autodiff (ceres::Jet) and finite differences.

#include <cmath>
#include <random>
#include <vector>

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include "common/geometry/so3.h"
#include "common/spline/cubic_basis.h"
#include "common/spline/knot_grid.h"
#include "common/spline/r3_spline.h"
#include "common/spline/so3_spline.h"
#include "common/spline/spline_trajectory.h"
#include "tests/common/spline/spline_reference.h"
#include "tests/testing/random_vector.h"

namespace tiltcal::spline {
namespace {

using geometry::ExpMatrix;
using geometry::ExpQuaternion;
using geometry::LogMatrix;
using testing::ReferenceSo3;

const double kSpacings[] = {0.02, 0.05, 0.1};
// Normalised times including both ends of the segment and values just inside.
const double kTimes[] = {0.0, 1e-9, 0.013, 0.5, 0.77, 1.0 - 1e-9, 1.0};

// Four random knots: a random walk of rotation increments of ~`step` rad.
struct Knots {
  Eigen::Quaterniond q[4];
  Eigen::Vector3d p[4];
  const double* q_ptr[4];
  const double* p_ptr[4];
  Knots() { Refresh(); }
  void Refresh() {
    for (int i = 0; i < 4; ++i) {
      q_ptr[i] = q[i].coeffs().data();
      p_ptr[i] = p[i].data();
    }
  }
};

Knots RandomKnots(std::mt19937* rng, double step) {
  std::normal_distribution<double> n(0.0, 1.0);
  Knots k;
  k.q[0] = ExpQuaternion(tiltcal::testing::RandomVector3(n, *rng));
  k.p[0] = tiltcal::testing::RandomVector3(n, *rng);
  for (int i = 1; i < 4; ++i) {
    k.q[i] = k.q[i - 1] * ExpQuaternion(Eigen::Vector3d(step * tiltcal::testing::RandomVector3(n, *rng)));
    k.p[i] = k.p[i - 1] + 0.3 * tiltcal::testing::RandomVector3(n, *rng);
  }
  k.Refresh();
  return k;
}

constexpr int kAll = kSo3Rotation | kSo3AngularVelocity | kSo3AngularAcceleration |
                     kSo3RotationJacobian | kSo3AngularVelocityJacobian;

TEST(CubicBasisTest, PartitionOfUnityAndCumulativeSums) {
  for (double u : {0.0, 0.25, 0.5, 0.9, 1.0, -0.05, 1.05}) {
    const CubicBasis b = UniformCubicBasis(u, 20.0);
    const CubicBasis c = CumulativeCubicBasis(u, 20.0);
    EXPECT_NEAR(b.value.sum(), 1.0, 1e-15);
    EXPECT_NEAR(b.d1.sum(), 0.0, 1e-12);
    EXPECT_NEAR(b.d2.sum(), 0.0, 1e-10);
    EXPECT_NEAR(b.d3.sum(), 0.0, 1e-8);
    for (int j = 0; j < 4; ++j) {
      double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
      for (int i = j; i < 4; ++i) {
        s0 += b.value[i];
        s1 += b.d1[i];
        s2 += b.d2[i];
        s3 += b.d3[i];
      }
      EXPECT_NEAR(c.value[j], s0, 1e-15);
      if (j > 0) {
        EXPECT_NEAR(c.d1[j], s1, 1e-12);
        EXPECT_NEAR(c.d2[j], s2, 1e-10);
        EXPECT_NEAR(c.d3[j], s3, 1e-8);
      }
    }
    // Derivatives vs central differences in t (u = t / dt, dt = 0.05).
    const double h = 1e-4;
    const CubicBasis bp = UniformCubicBasis(u + h, 20.0), bm = UniformCubicBasis(u - h, 20.0);
    const double dt_h = h / 20.0;
    EXPECT_LT(((bp.value - bm.value) / (2 * dt_h) - b.d1).norm(), 1e-6);
    EXPECT_LT(((bp.d1 - bm.d1) / (2 * dt_h) - b.d2).norm(), 1e-4);
    EXPECT_LT(((bp.d2 - bm.d2) / (2 * dt_h) - b.d3).norm(), 1e-2);
  }
}

TEST(KnotGridTest, CountsAndLocate) {
  EXPECT_EQ(UniformKnotGrid::NumKnotsForDuration(2.0, 0.1), 23);
  EXPECT_EQ(UniformKnotGrid::NumKnotsForDuration(2.01, 0.1), 24);
  EXPECT_EQ(UniformKnotGrid::NumKnotsForDuration(60.0, 0.05), 1203);
  const UniformKnotGrid grid = UniformKnotGrid::ForDuration(1.5, 2.0, 0.1);
  EXPECT_EQ(grid.num_knots(), 23);
  EXPECT_EQ(grid.num_segments(), 20);
  EXPECT_NEAR(grid.end_s(), 3.5, 1e-12);
  KnotWindow w;
  ASSERT_TRUE(grid.Locate(1.5, &w));
  EXPECT_EQ(w.first_knot, 0);
  EXPECT_EQ(w.u, 0.0);
  ASSERT_TRUE(grid.Locate(1.5 + 0.1 * 7.25, &w));
  EXPECT_EQ(w.first_knot, 7);
  EXPECT_NEAR(w.u, 0.25, 1e-9);
  ASSERT_TRUE(grid.Locate(3.5, &w));
  EXPECT_EQ(w.first_knot, 19);
  EXPECT_NEAR(w.u, 1.0, 1e-9);
  EXPECT_FALSE(grid.Locate(1.5 - 1e-9, &w));
  EXPECT_FALSE(grid.Locate(3.5 + 1e-9, &w));
  EXPECT_FALSE(grid.Locate(std::nan(""), &w));
}

// Knots R_i = Exp(i c a): the spline is Exp((s + 1 + u) c a) exactly
// (lambda_1 + lambda_2 + lambda_3 = 1 + u), omega = c/dt a, alpha = 0.
// Knots p_i = p0 + v i dt: p(t) = p0 + v (t - t0 + dt), p' = v, p'' = 0.
TEST(SplineTrajectoryTest, ConstantRatesAreReproducedExactly) {
  for (double dt : kSpacings) {
    const UniformKnotGrid grid(0.3, dt, 12);
    SplineTrajectory traj(grid);
    const Eigen::Vector3d axis = Eigen::Vector3d(0.2, -0.5, 0.9).normalized();
    const double c = 0.4;  // rad per knot
    const Eigen::Vector3d p0(1, 2, 3), v(0.5, -1.0, 0.25);
    for (int i = 0; i < grid.num_knots(); ++i) {
      traj.SetRotationKnot(i, ExpQuaternion(Eigen::Vector3d(i * c * axis)));
      traj.SetPositionKnot(i, p0 + v * i * dt);
    }
    for (double t = grid.t0_s(); t <= grid.end_s(); t += 0.37 * dt) {
      So3SplineSample r;
      R3SplineSample p;
      ASSERT_TRUE(traj.Evaluate(t, kAll, &r, &p));
      const double k = (t - grid.t0_s()) / dt + 1.0;
      EXPECT_LT((r.rotation - ExpMatrix(k * c * axis)).norm(), 1e-12) << t;
      EXPECT_LT((r.angular_velocity - c / dt * axis).norm(), 1e-10 / dt);
      EXPECT_LT(r.angular_acceleration.norm(), 1e-9 / (dt * dt));
      EXPECT_LT((p.position - (p0 + v * (t - grid.t0_s() + dt))).norm(), 1e-12);
      EXPECT_LT((p.velocity - v).norm(), 1e-11 / dt);
      EXPECT_LT(p.acceleration.norm(), 1e-10 / (dt * dt));
    }
  }
}

TEST(So3SplineTest, MatchesProductRuleReference) {
  std::mt19937 rng(11);
  for (double dt : kSpacings) {
    for (int trial = 0; trial < 5; ++trial) {
      const Knots k = RandomKnots(&rng, 0.6);
      for (double u : kTimes) {
        So3SplineSample s;
        EvaluateSo3Spline(k.q_ptr, u, 1.0 / dt, kAll, &s);
        const auto ref = ReferenceSo3<double>(k.q, u, 1.0 / dt);
        EXPECT_LT((s.rotation - ref.q.toRotationMatrix()).norm(), 1e-13);
        EXPECT_LT((s.angular_velocity - ref.omega).norm(), 1e-12 * (1.0 + ref.omega.norm()));
        EXPECT_LT((s.angular_acceleration - ref.alpha).norm(), 1e-11 * (1.0 + ref.alpha.norm()));
        // The Jet Sommer recursion (benchmark anchor) agrees as well.
        const auto sommer = testing::SommerSo3<double>(k.q, u, 1.0 / dt);
        EXPECT_LT((sommer.q.toRotationMatrix() - ref.q.toRotationMatrix()).norm(), 1e-13);
        EXPECT_LT((sommer.omega - ref.omega).norm(), 1e-12 * (1.0 + ref.omega.norm()));
        EXPECT_LT((sommer.alpha - ref.alpha).norm(), 1e-11 * (1.0 + ref.alpha.norm()));
        R3SplineSample p;
        EvaluateR3Spline(k.p_ptr, u, 1.0 / dt, &p);
        const auto ref_p = testing::ReferenceR3<double>(k.p, u, 1.0 / dt);
        EXPECT_LT((p.position - ref_p.position).norm(), 1e-13);
        EXPECT_LT((p.velocity - ref_p.velocity).norm(), 1e-10);
        EXPECT_LT((p.acceleration - ref_p.acceleration).norm(), 1e-8);
      }
    }
  }
}

// A long random trajectory, evaluated through SplineTrajectory (segment
// look-up included), against central differences of its own value.
TEST(SplineTrajectoryTest, DerivativesMatchFiniteDifferencesAcrossSegments) {
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  for (double dt : kSpacings) {
    const UniformKnotGrid grid(0.0, dt, 15);
    SplineTrajectory traj(grid);
    Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
    for (int i = 0; i < grid.num_knots(); ++i) {
      q = q * ExpQuaternion(Eigen::Vector3d(0.3 * tiltcal::testing::RandomVector3(n, rng)));
      traj.SetRotationKnot(i, q);
      traj.SetPositionKnot(i, tiltcal::testing::RandomVector3(n, rng));
    }
    const double h = 1e-5 * dt;
    auto rot = [&](double t) {
      So3SplineSample s;
      EXPECT_TRUE(traj.Evaluate(t, kSo3Rotation | kSo3AngularVelocity | kSo3AngularAcceleration, &s, nullptr));
      return s;
    };
    auto pos = [&](double t) {
      R3SplineSample p;
      EXPECT_TRUE(traj.Evaluate(t, 0, nullptr, &p));
      return p;
    };
    // Includes knot times (segment boundaries) in the interior.
    for (double t = 2 * h; t < grid.end_s() - 2 * h; t += 0.25 * dt) {
      const So3SplineSample s = rot(t);
      const Eigen::Vector3d omega_fd =
          LogMatrix(rot(t - h).rotation.transpose() * rot(t + h).rotation) / (2 * h);
      EXPECT_LT((s.angular_velocity - omega_fd).norm(), 1e-6 * (1.0 + s.angular_velocity.norm())) << t;
      const Eigen::Vector3d alpha_fd = (rot(t + h).angular_velocity - rot(t - h).angular_velocity) / (2 * h);
      EXPECT_LT((s.angular_acceleration - alpha_fd).norm(), 1e-5 * (1.0 + s.angular_acceleration.norm())) << t;
      const R3SplineSample p = pos(t);
      EXPECT_LT((p.velocity - (pos(t + h).position - pos(t - h).position) / (2 * h)).norm(),
                1e-6 * (1.0 + p.velocity.norm()));
      EXPECT_LT((p.acceleration - (pos(t + h).velocity - pos(t - h).velocity) / (2 * h)).norm(),
                1e-6 * (1.0 + p.acceleration.norm()));
      EXPECT_LT((p.jerk - (pos(t + h).acceleration - pos(t - h).acceleration) / (2 * h)).norm(),
                1e-5 * (1.0 + p.jerk.norm()));
    }
    // C2 continuity at the knots: segment s at u = 1 equals segment s + 1 at u = 0.
    for (int seg = 0; seg + 1 < grid.num_segments(); ++seg) {
      const double* a[4];
      const double* b[4];
      traj.RotationKnots(seg, a);
      traj.RotationKnots(seg + 1, b);
      So3SplineSample sa, sb;
      EvaluateSo3Spline(a, 1.0, grid.inv_dt(), kSo3Rotation | kSo3AngularAcceleration, &sa);
      EvaluateSo3Spline(b, 0.0, grid.inv_dt(), kSo3Rotation | kSo3AngularAcceleration, &sb);
      EXPECT_LT((sa.rotation - sb.rotation).norm(), 1e-13);
      EXPECT_LT((sa.angular_velocity - sb.angular_velocity).norm(), 1e-10 / dt);
      EXPECT_LT((sa.angular_acceleration - sb.angular_acceleration).norm(), 1e-9 / (dt * dt));
    }
  }
}

// Knot Jacobians of R(t) and omega(t), right perturbations, against
// (a) autodiff of the reference spline with Jet perturbations delta_i and
// (b) central differences of the production code.
TEST(So3SplineTest, KnotJacobiansMatchAutodiffAndFiniteDifferences) {
  using J = ceres::Jet<double, 12>;
  std::mt19937 rng(13);
  for (double dt : kSpacings) {
    for (int trial = 0; trial < 4; ++trial) {
      const Knots k = RandomKnots(&rng, 0.8);
      for (double u : kTimes) {
        So3SplineSample s;
        EvaluateSo3Spline(k.q_ptr, u, 1.0 / dt, kAll, &s);

        // (a) autodiff: knots q_i Exp(delta_i), delta = 0 with 12 derivative lanes.
        Eigen::Quaternion<J> qj[4];
        for (int i = 0; i < 4; ++i) {
          Eigen::Matrix<J, 3, 1> delta;
          for (int c = 0; c < 3; ++c) delta[c] = J(0.0, 3 * i + c);
          qj[i] = k.q[i].cast<J>() * ExpQuaternion(delta);
        }
        const auto ref = ReferenceSo3<J>(qj, J(u), 1.0 / dt);
        // eps = Log(R0^T R(delta)).
        const Eigen::Quaternion<J> r0 = Eigen::Quaterniond(s.rotation).cast<J>();
        const Eigen::Matrix<J, 3, 1> eps = geometry::LogQuaternion(Eigen::Quaternion<J>(r0.conjugate() * ref.q));
        for (int i = 0; i < 4; ++i) {
          for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 3; ++c) {
              EXPECT_NEAR(s.rotation_jacobian[i](r, c), eps[r].v[3 * i + c], 1e-10)
                  << "dt " << dt << " u " << u << " knot " << i;
              EXPECT_NEAR(s.angular_velocity_jacobian[i](r, c), ref.omega[r].v[3 * i + c],
                          1e-9 * (1.0 / dt))
                  << "dt " << dt << " u " << u << " knot " << i;
            }
          }
        }

        // (b) central differences.
        const double h = 1e-6;
        for (int i = 0; i < 4; ++i) {
          for (int c = 0; c < 3; ++c) {
            Knots kp = k, km = k;
            kp.q[i] = k.q[i] * ExpQuaternion(Eigen::Vector3d(h * Eigen::Vector3d::Unit(c)));
            km.q[i] = k.q[i] * ExpQuaternion(Eigen::Vector3d(-h * Eigen::Vector3d::Unit(c)));
            kp.Refresh();
            km.Refresh();
            So3SplineSample sp, sm;
            EvaluateSo3Spline(kp.q_ptr, u, 1.0 / dt, kSo3Rotation | kSo3AngularVelocity, &sp);
            EvaluateSo3Spline(km.q_ptr, u, 1.0 / dt, kSo3Rotation | kSo3AngularVelocity, &sm);
            const Eigen::Vector3d deps = LogMatrix(sm.rotation.transpose() * sp.rotation) / (2 * h);
            const Eigen::Vector3d domega = (sp.angular_velocity - sm.angular_velocity) / (2 * h);
            EXPECT_LT((deps - s.rotation_jacobian[i].col(c)).norm(), 1e-7);
            EXPECT_LT((domega - s.angular_velocity_jacobian[i].col(c)).norm(), 1e-7 / dt);
          }
        }
      }
    }
  }
}

// Time derivatives: d eps/dt = omega, d omega/dt = alpha (autodiff of the
// reference with a Jet u), and the R^3 chain p -> p' -> p'' -> p'''.
TEST(So3SplineTest, TimeDerivativesMatchAutodiff) {
  using J = ceres::Jet<double, 1>;
  std::mt19937 rng(17);
  for (double dt : kSpacings) {
    const Knots k = RandomKnots(&rng, 0.7);
    Eigen::Quaternion<J> qj[4];
    Eigen::Matrix<J, 3, 1> pj[4];
    for (int i = 0; i < 4; ++i) {
      qj[i] = k.q[i].cast<J>();
      pj[i] = k.p[i].cast<J>();
    }
    for (double u : kTimes) {
      So3SplineSample s;
      EvaluateSo3Spline(k.q_ptr, u, 1.0 / dt, kAll, &s);
      R3SplineSample p;
      EvaluateR3Spline(k.p_ptr, u, 1.0 / dt, &p);
      // t = t_s + u dt: a unit Jet on t moves u by 1/dt.
      const J uj(u, 0);
      J u_of_t = uj;
      u_of_t.v[0] = 1.0 / dt;
      const auto ref = ReferenceSo3<J>(qj, u_of_t, 1.0 / dt);
      const Eigen::Quaternion<J> r0 = Eigen::Quaterniond(s.rotation).cast<J>();
      const Eigen::Matrix<J, 3, 1> eps = geometry::LogQuaternion(Eigen::Quaternion<J>(r0.conjugate() * ref.q));
      const auto ref_p = testing::ReferenceR3<J>(pj, u_of_t, 1.0 / dt);
      for (int r = 0; r < 3; ++r) {
        EXPECT_NEAR(eps[r].v[0], s.angular_velocity[r], 1e-10 / dt);
        EXPECT_NEAR(ref.omega[r].v[0], s.angular_acceleration[r], 1e-9 / (dt * dt));
        EXPECT_NEAR(ref_p.position[r].v[0], p.velocity[r], 1e-10 / dt);
        EXPECT_NEAR(ref_p.velocity[r].v[0], p.acceleration[r], 1e-9 / (dt * dt));
        EXPECT_NEAR(ref_p.acceleration[r].v[0], p.jerk[r], 1e-8 / (dt * dt * dt));
      }
    }
  }
}

TEST(R3SplineTest, KnotJacobianIsTheBasis) {
  std::mt19937 rng(19);
  const Knots k = RandomKnots(&rng, 0.5);
  for (double u : kTimes) {
    R3SplineSample p;
    EvaluateR3Spline(k.p_ptr, u, 20.0, &p);
    for (int j = 0; j < 4; ++j) {
      Knots kp = k;
      kp.p[j] += Eigen::Vector3d(1.0, 2.0, 3.0);
      kp.Refresh();
      R3SplineSample pp;
      EvaluateR3Spline(kp.p_ptr, u, 20.0, &pp);
      EXPECT_LT((pp.position - p.position - p.basis.value[j] * Eigen::Vector3d(1, 2, 3)).norm(), 1e-12);
      EXPECT_LT((pp.acceleration - p.acceleration - p.basis.d2[j] * Eigen::Vector3d(1, 2, 3)).norm(), 1e-9);
    }
  }
}

}  // namespace
}  // namespace tiltcal::spline
