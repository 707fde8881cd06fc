// Ground residuals on a synthetic, physically consistent configuration: a
// vehicle driving (yawing) on a tilted plane, with the IMU mounted off-axis
// and a LiDAR at a known extrinsic. The plane (n_l, d_l) of each scan is
// computed from the geometry (LiDAR origin height and the plane normal
// carried into the LiDAR frame), independently of the residual formulas.
// Checks: e_dist, e_incl, e_up vanish at the true state and e_flat does not
// (its norm is 2 sin(phi/2), phi the ground slope); the selection logic;
// invalid and out-of-spline planes are skipped; the covariance weighting;
// and that solving with dist / up alone recovers exactly the directions they
// observe.

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <ceres/ceres.h>
#include <ceres/sphere_manifold.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "common/geometry/angles.h"
#include "common/geometry/so3.h"
#include "common/spline/quaternion_manifold.h"
#include "stages/calibrate/problem/calibration_state.h"
#include "stages/calibrate/problem/ground_residuals.h"
#include "tests/stages/calibrate/calibrate_params_text.h"

namespace tiltcal::calibrate {
namespace {

using geometry::kRadPerDeg;
constexpr int64_t kOriginNs = 1'700'000'000'000'000'000;

Eigen::Matrix3d Rx(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix(); }
Eigen::Matrix3d Ry(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix(); }
Eigen::Matrix3d Rz(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix(); }

// Frames: p = plane frame (z = plane normal, the plane is z = 0), v = vehicle
// (z = plane normal, yawing), b = IMU (C_vb = mount), l = LiDAR, a = world
// (the IMU frame at the start: C_ab(t) = C_pb(0)^T C_pb(t)).
struct Scenario {
  double pitch_deg = 8.0, roll_deg = 3.0;  // gravity-up vs the plane normal
  Eigen::Matrix3d c_vb = Rx(0.04) * Ry(-0.03) * Rz(0.5);  // IMU mount
  Eigen::Quaterniond q_bl = Eigen::Quaterniond(Rz(1.2) * Rx(0.05) * Ry(-0.1));
  Eigen::Vector3d r_b_lb = Eigen::Vector3d(0.25, -0.12, 0.48);
  double d_b = 0.35;     // IMU height above the plane, m
  double tau = 0.0123;   // t_imu = t_lidar + tau
  double dt = 0.05;
  double duration = 6.0;

  double Yaw(double t) const { return 0.3 * t + 0.6 * std::sin(0.9 * t); }
  Eigen::Vector3d UpInPlane() const {  // gravity-up, frame p
    return Rx(roll_deg * kRadPerDeg) * Ry(pitch_deg * kRadPerDeg) * Eigen::Vector3d::UnitZ();
  }
  Eigen::Matrix3d StartFromPlane() const { return (Rz(Yaw(0.0)) * c_vb).transpose(); }  // A = C_pb(0)^T
  // g_f: IMU-frame gravity on level ground (plane normal = up), m/s^2.
  Eigen::Vector3d GravityFlat() const { return -9.81 * c_vb.transpose() * Eigen::Vector3d::UnitZ(); }
  // n_g: gravity direction (down) in a.
  Eigen::Vector3d GravityDirection() const { return -(StartFromPlane() * UpInPlane()); }

  // The ground plane seen by the LiDAR at any time: n_l = C_pl^T e_z, and
  // d_l = height of the LiDAR origin p_b + C_pb r_b above z = 0.
  proto::GroundPlane Plane(double t_imu) const {
    const Eigen::Matrix3d c_pb = Rz(Yaw(t_imu)) * c_vb;
    const Eigen::Vector3d p_b(3.0 * t_imu, 0.5 * t_imu * t_imu, d_b);
    const Eigen::Vector3d p_l = p_b + c_pb * r_b_lb;
    const Eigen::Vector3d n_l = (c_pb * q_bl.toRotationMatrix()).transpose() * Eigen::Vector3d::UnitZ();
    proto::GroundPlane plane;
    plane.set_valid(true);
    plane.set_stamp_ns(kOriginNs + std::llround((t_imu - tau) * 1e9));
    plane.mutable_normal_in_lidar()->set_x(n_l.x());
    plane.mutable_normal_in_lidar()->set_y(n_l.y());
    plane.mutable_normal_in_lidar()->set_z(n_l.z());
    plane.set_height_m(p_l.z());
    return plane;
  }

  // The true state: knots C_ab,i = A Rz(psi_i) C_vb keep the spline in the
  // family A Rz(psi(t)) C_vb (all knot increments share the axis C_vb^T e_z).
  void FillState(CalibrationState* state) const {
    const spline::UniformKnotGrid& grid = state->trajectory.grid();
    const Eigen::Matrix3d a = StartFromPlane();
    for (int i = 0; i < grid.num_knots(); ++i) {
      const double psi = Yaw(grid.t0_s() + (i - 1) * grid.dt_s());
      state->trajectory.SetRotationKnot(i, Eigen::Quaterniond(a * Rz(psi) * c_vb));
    }
    state->SetImuFromLidarRotation(q_bl);
    state->SetImuFromLidarTranslation(r_b_lb);
    state->time_offset_s[0] = tau;
    state->SetGravityDirection(GravityDirection());
  }

  spline::UniformKnotGrid Grid() const {
    return spline::UniformKnotGrid::ForDuration(0.0, duration, dt);
  }

  // Scans at 10 Hz well inside the spline.
  std::vector<proto::GroundPlane> Planes() const {
    std::vector<proto::GroundPlane> planes;
    for (double t = 0.2; t < duration - 0.2; t += 0.1) planes.push_back(Plane(t));
    return planes;
  }

  double SlopeRad() const { return std::acos(UpInPlane().z()); }
};

// Adds every block of the state with its manifold, as the problem builder does.
void AddStateBlocks(CalibrationState* state, ceres::Problem* problem) {
  for (int i = 0; i < state->trajectory.num_knots(); ++i) {
    problem->AddParameterBlock(state->trajectory.rotation_knot(i), 4,
                               new spline::RightQuaternionManifold);
  }
  problem->AddParameterBlock(state->imu_from_lidar_rotation, 4, new spline::RightQuaternionManifold);
  problem->AddParameterBlock(state->imu_from_lidar_translation, 3);
  problem->AddParameterBlock(state->time_offset_s, 1);
  problem->AddParameterBlock(state->gravity_direction, 3, new ceres::SphereManifold<3>);
}

// The tests' problems do not own loss functions, as CalibrationProblem.
ceres::Problem::Options ProblemOptions() {
  ceres::Problem::Options options;
  options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  return options;
}

GroundSequenceInfo InfoFor(const Scenario& sc, bool level) {
  GroundSequenceInfo info;
  info.imu_height_m = sc.d_b;
  info.level_known = true;
  info.is_level = level;
  info.has_gravity_flat = true;
  info.gravity_flat_in_imu = sc.GravityFlat();
  return info;
}

// The program's ground residual settings (every mode AUTO).
proto::GroundResidualsParams DefaultGround() {
  return tiltcal::testing::DefaultCalibrateParamsWith().ground();
}

// Sigma 1 and no robust loss for every residual type.
proto::GroundResidualsParams UnitSigmaParams() {
  proto::GroundResidualsParams params = DefaultGround();
  for (auto* p : {params.mutable_flat(), params.mutable_dist(), params.mutable_incl(),
                  params.mutable_up()}) {
    p->set_sigma(1.0);
    p->set_cauchy_scale(0.0);
  }
  return params;
}

// No robust losses (cauchy_scale 0).
const GroundLosses& NoLosses() {
  static const GroundLosses losses(UnitSigmaParams());
  return losses;
}

// Cost 0.5 sum r^2 of one residual kind at the true state.
double CostOf(const Scenario& sc, bool level, GroundResidualSelection selection,
              GroundResidualSummary* summary = nullptr) {
  CalibrationState state(sc.Grid());
  sc.FillState(&state);
  ceres::Problem problem{ProblemOptions()};
  AddStateBlocks(&state, &problem);
  GroundResidualSummary local;
  const Status status = AddGroundResiduals({sc.Planes(), selection, UnitSigmaParams(), InfoFor(sc, level), NoLosses(), kOriginNs}, &state, &problem, summary ? summary : &local);
  EXPECT_TRUE(status.ok()) << status.message();
  double cost = 0.0;
  problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr);
  return cost;
}

GroundResidualSelection Only(bool flat, bool dist, bool incl, bool up) {
  GroundResidualSelection s;
  s.flat = flat;
  s.dist = dist;
  s.incl = incl;
  s.up = up;
  return s;
}

TEST(GroundResidualsTest, TiltedPlaneTrueStateZeroesDistInclUpButNotFlat) {
  const Scenario sc;  // 8 deg pitch, 3 deg roll
  const int n = static_cast<int>(sc.Planes().size());
  GroundResidualSummary summary;
  EXPECT_LT(CostOf(sc, false, Only(false, true, false, false), &summary), 1e-20);
  EXPECT_EQ(summary.num_dist, n);
  EXPECT_LT(CostOf(sc, false, Only(false, false, true, false), &summary), 1e-20);
  EXPECT_EQ(summary.num_incl, n);
  EXPECT_LT(CostOf(sc, false, Only(false, false, false, true), &summary), 1e-20);
  EXPECT_EQ(summary.num_up, n);
  // e_flat = n_l - C_bl^T g~_b has norm 2 sin(phi/2) on a plane of slope phi.
  const double flat = CostOf(sc, false, Only(true, false, false, false), &summary);
  EXPECT_EQ(summary.num_flat, n);
  const double expected = 0.5 * n * std::pow(2.0 * std::sin(0.5 * sc.SlopeRad()), 2);
  EXPECT_GT(sc.SlopeRad(), 8.0 * kRadPerDeg);
  EXPECT_NEAR(flat, expected, 1e-9 * expected);
}

TEST(GroundResidualsTest, LevelPlaneTrueStateZeroesAllFour) {
  Scenario sc;
  sc.pitch_deg = 0.0;
  sc.roll_deg = 0.0;
  EXPECT_LT(CostOf(sc, true, Only(true, true, true, true)), 1e-20);
}

// A wrong extrinsic shows in the residuals (the oracle is not trivially zero).
TEST(GroundResidualsTest, WrongExtrinsicGivesNonZeroResiduals) {
  Scenario truth;
  Scenario wrong = truth;
  wrong.r_b_lb += Eigen::Vector3d(0.0, 0.0, 0.05);
  wrong.q_bl = wrong.q_bl * geometry::ExpQuaternion(Eigen::Vector3d(0.02, -0.01, 0.0));
  // The planes come from the truth, the state from `wrong`.
  for (int kind = 0; kind < 3; ++kind) {
    CalibrationState state(truth.Grid());
    wrong.FillState(&state);
    ceres::Problem problem{ProblemOptions()};
    AddStateBlocks(&state, &problem);
    GroundResidualSummary summary;
    const GroundResidualSelection sel = Only(false, kind == 0, kind == 1, kind == 2);
    ASSERT_TRUE(AddGroundResiduals({truth.Planes(), sel, UnitSigmaParams(), InfoFor(truth, false), NoLosses(), kOriginNs}, &state, &problem, &summary)
                    .ok());
    double cost = 0.0;
    problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr);
    EXPECT_GT(cost, 1e-6) << "kind " << kind;
  }
}

TEST(GroundResidualsTest, InvalidAndOutOfSplinePlanesAreSkipped) {
  const Scenario sc;
  std::vector<proto::GroundPlane> planes = sc.Planes();
  const int good = static_cast<int>(planes.size());
  proto::GroundPlane invalid = sc.Plane(1.0);
  invalid.set_valid(false);
  proto::GroundPlane nan_normal = sc.Plane(1.1);
  nan_normal.mutable_normal_in_lidar()->set_x(std::nan(""));
  proto::GroundPlane long_normal = sc.Plane(1.2);
  long_normal.mutable_normal_in_lidar()->set_z(2.0);
  proto::GroundPlane negative_height = sc.Plane(1.3);
  negative_height.set_height_m(-0.5);
  proto::GroundPlane before = sc.Plane(-1.0);
  proto::GroundPlane after = sc.Plane(sc.duration + 1.0);
  for (const auto& p : {invalid, nan_normal, long_normal, negative_height, before, after}) {
    planes.push_back(p);
  }
  CalibrationState state(sc.Grid());
  sc.FillState(&state);
  ceres::Problem problem{ProblemOptions()};
  AddStateBlocks(&state, &problem);
  GroundResidualSummary summary;
  ASSERT_TRUE(AddGroundResiduals({planes, Only(true, true, true, true), UnitSigmaParams(), InfoFor(sc, false), NoLosses(), kOriginNs}, &state, &problem, &summary)
                  .ok());
  EXPECT_EQ(summary.num_planes, good + 6);
  EXPECT_EQ(summary.num_invalid, 4);
  EXPECT_EQ(summary.num_outside_spline, 2);
  EXPECT_EQ(summary.num_used, good);
  EXPECT_EQ(summary.num_flat, good);
  EXPECT_EQ(summary.num_dist, good);
  EXPECT_EQ(summary.num_incl, good);
  EXPECT_EQ(summary.num_up, good);
  EXPECT_EQ(problem.NumResidualBlocks(), 4 * good);
  EXPECT_NE(summary.ToString().find("4 invalid"), std::string::npos) << summary.ToString();
}

// Each residual type gets the Cauchy loss of its own params: cost
// 0.5 a^2 log(1 + r^2 / a^2) per block with r the weighted residual.
TEST(GroundResidualsTest, CauchyLossPerResidualType) {
  const Scenario sc;
  proto::GroundPlane plane = sc.Plane(2.0);
  plane.set_height_m(plane.height_m() + 0.05);  // e_dist = 0.05 m
  proto::GroundResidualsParams params = UnitSigmaParams();
  params.mutable_dist()->set_sigma(0.01);        // r = 5
  params.mutable_dist()->set_cauchy_scale(2.0);
  params.mutable_up()->set_cauchy_scale(7.0);    // e_up = 0: no contribution
  const GroundLosses losses(params);
  ASSERT_NE(losses.dist(), nullptr);
  EXPECT_EQ(losses.flat(), nullptr);
  CalibrationState state(sc.Grid());
  sc.FillState(&state);
  ceres::Problem problem{ProblemOptions()};
  AddStateBlocks(&state, &problem);
  GroundResidualSummary summary;
  ASSERT_TRUE(AddGroundResiduals({{plane}, Only(false, true, false, true), params, InfoFor(sc, false), losses, kOriginNs}, &state, &problem, &summary)
                  .ok());
  double cost = 0.0;
  problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr);
  const double r = 0.05 / 0.01, a = 2.0;
  EXPECT_NEAR(cost, 0.5 * a * a * std::log1p(r * r / (a * a)), 1e-9);
  EXPECT_LT(cost, 0.5 * r * r);
}

TEST(GroundResidualsTest, MissingParameterBlockIsAnError) {
  const Scenario sc;
  CalibrationState state(sc.Grid());
  sc.FillState(&state);
  ceres::Problem problem{ProblemOptions()};  // no blocks added
  GroundResidualSummary summary;
  const Status status = AddGroundResiduals({sc.Planes(), Only(false, true, false, false), UnitSigmaParams(), InfoFor(sc, false), NoLosses(), kOriginNs}, &state, &problem, &summary);
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("imu_from_lidar_rotation"), std::string::npos);
}

// With use_plane_covariance the residuals are whitened by sigma^2 + the
// propagated fit covariance: check r^T r against e^T C^{-1} e computed here.
TEST(GroundResidualsTest, PlaneCovarianceWhitening) {
  Scenario sc;
  sc.r_b_lb = Eigen::Vector3d(0.4, -0.3, 0.5);
  proto::GroundPlane plane = sc.Plane(2.0);
  // A covariance of (n, d): tangent normal noise, height noise, correlation.
  const Eigen::Vector3d n_l(plane.normal_in_lidar().x(), plane.normal_in_lidar().y(),
                            plane.normal_in_lidar().z());
  const Eigen::Matrix3d p = Eigen::Matrix3d::Identity() - n_l * n_l.transpose();
  Eigen::Matrix4d cov = Eigen::Matrix4d::Zero();
  cov.topLeftCorner<3, 3>() = p * Eigen::Vector3d(4e-4, 1e-4, 2e-4).asDiagonal() * p;
  cov(3, 3) = 9e-4;
  const Eigen::Vector3d cross = 1e-4 * p * Eigen::Vector3d(1.0, -0.5, 0.2);
  cov.block<3, 1>(0, 3) = cross;
  cov.block<1, 3>(3, 0) = cross.transpose();
  for (int i = 0; i < 16; ++i) plane.add_covariance(cov(i / 4, i % 4));
  // Perturb the measurement so the residuals are non-zero.
  plane.set_height_m(plane.height_m() + 0.03);
  const Eigen::Vector3d n_meas =
      (n_l + Eigen::Vector3d(0.01, -0.02, 0.0)).normalized();
  plane.mutable_normal_in_lidar()->set_x(n_meas.x());
  plane.mutable_normal_in_lidar()->set_y(n_meas.y());
  plane.mutable_normal_in_lidar()->set_z(n_meas.z());

  proto::GroundResidualsParams params = UnitSigmaParams();
  const double sigma = 0.01;
  for (auto* k : {params.mutable_flat(), params.mutable_dist(), params.mutable_incl(),
                  params.mutable_up()}) {
    k->set_sigma(sigma);
    k->set_use_plane_covariance(true);
  }
  const GroundSequenceInfo info = InfoFor(sc, false);
  for (int kind = 0; kind < 4; ++kind) {
    CalibrationState state(sc.Grid());
    sc.FillState(&state);
    ceres::Problem problem{ProblemOptions()};
    AddStateBlocks(&state, &problem);
    GroundResidualSummary summary;
    ASSERT_TRUE(AddGroundResiduals({{plane}, Only(kind == 0, kind == 1, kind == 2, kind == 3), params, info, NoLosses(), kOriginNs}, &state, &problem, &summary)
                    .ok());
    EXPECT_EQ(summary.num_without_covariance, 0);
    double cost = 0.0;
    problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr);

    // Independent evaluation of e and its covariance at the true state.
    const Eigen::Matrix3d c_bl = sc.q_bl.toRotationMatrix();
    spline::So3SplineSample s;
    const double t = (plane.stamp_ns() - kOriginNs) * 1e-9 + sc.tau;
    ASSERT_TRUE(state.trajectory.Evaluate(t, spline::kSo3Rotation, &s, nullptr));
    const Eigen::Vector3d up_b = -(s.rotation.transpose() * sc.GravityDirection());
    const Eigen::Vector3d up_f = -sc.GravityFlat().normalized();
    double expected = 0.0;
    if (kind == 0 || kind == 3) {
      const Eigen::Vector3d e = kind == 0 ? Eigen::Vector3d(n_meas - c_bl.transpose() * up_b)
                                          : Eigen::Vector3d(n_meas - c_bl.transpose() * up_f);
      const Eigen::Matrix3d c = sigma * sigma * Eigen::Matrix3d::Identity() + cov.topLeftCorner<3, 3>();
      expected = 0.5 * e.dot(c.inverse() * e);
    } else if (kind == 1) {
      const Eigen::Vector3d r_l = c_bl.transpose() * sc.r_b_lb;
      const double e = plane.height_m() - sc.d_b - n_meas.dot(r_l);
      Eigen::Vector4d j;
      j << -r_l, 1.0;
      expected = 0.5 * e * e / (sigma * sigma + j.dot(cov * j));
    } else {
      const double e = up_b.dot(up_f - c_bl * n_meas);
      const Eigen::Vector3d j = c_bl.transpose() * up_b;
      expected = 0.5 * e * e / (sigma * sigma + j.dot(cov.topLeftCorner<3, 3>() * j));
    }
    ASSERT_GT(expected, 1e-6) << kind;
    EXPECT_NEAR(cost, expected, 1e-9 * expected) << "kind " << kind;
  }
  // A plane without (or with a broken) covariance falls back to sigma alone.
  proto::GroundPlane bare = plane;
  bare.clear_covariance();
  CalibrationState state(sc.Grid());
  sc.FillState(&state);
  ceres::Problem problem{ProblemOptions()};
  AddStateBlocks(&state, &problem);
  GroundResidualSummary summary;
  ASSERT_TRUE(AddGroundResiduals({{bare}, Only(false, true, false, false), params, info, NoLosses(), kOriginNs}, &state, &problem, &summary)
                  .ok());
  EXPECT_EQ(summary.num_without_covariance, 1);
  EXPECT_EQ(summary.num_dist, 1);
}

// Solving with e_dist alone (C_bl held) recovers the component of r_b^{lb}
// along the ground normal in the IMU frame from the
// paper's misinitialisation [-0.6, 1.0, 0.6] m; with e_up alone, C_bl
// recovers the two directions that tilt the normal (the rotation about it is
// left to the other residuals).
TEST(GroundResidualsTest, DistAndUpRecoverTheirObservableDirections) {
  const Scenario sc;
  const Eigen::Vector3d n_b = sc.c_vb.transpose() * Eigen::Vector3d::UnitZ();
  {
    CalibrationState state(sc.Grid());
    sc.FillState(&state);
    const Eigen::Vector3d init(-0.6, 1.0, 0.6);
    state.SetImuFromLidarTranslation(init);
    ceres::Problem problem{ProblemOptions()};
    AddStateBlocks(&state, &problem);
    GroundResidualSummary summary;
    proto::GroundResidualsParams params = UnitSigmaParams();
    params.mutable_dist()->set_sigma(0.02);
    ASSERT_TRUE(AddGroundResiduals({sc.Planes(), Only(false, true, false, false), params, InfoFor(sc, false), NoLosses(), kOriginNs}, &state, &problem, &summary)
                    .ok());
    problem.SetParameterBlockConstant(state.imu_from_lidar_rotation);
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    ceres::Solver::Summary solver;
    ceres::Solve(options, &problem, &solver);
    const Eigen::Vector3d r = state.ImuFromLidarTranslation();
    EXPECT_NEAR(n_b.dot(r), n_b.dot(sc.r_b_lb), 1e-8);
    // Far from it before.
    EXPECT_GT(std::abs(n_b.dot(init - sc.r_b_lb)), 0.1);
  }
  {
    CalibrationState state(sc.Grid());
    sc.FillState(&state);
    const Eigen::Quaterniond init =
        sc.q_bl * geometry::ExpQuaternion(Eigen::Vector3d(0.05, -0.04, 0.03));
    state.SetImuFromLidarRotation(init);
    ceres::Problem problem{ProblemOptions()};
    AddStateBlocks(&state, &problem);
    GroundResidualSummary summary;
    ASSERT_TRUE(AddGroundResiduals({sc.Planes(), Only(false, false, false, true), UnitSigmaParams(), InfoFor(sc, false), NoLosses(), kOriginNs}, &state, &problem, &summary)
                    .ok());
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    ceres::Solver::Summary solver;
    ceres::Solve(options, &problem, &solver);
    const Eigen::Quaterniond q = state.ImuFromLidarRotation();
    const Eigen::Vector3d n_l = sc.q_bl.conjugate() * n_b;  // true normal, LiDAR frame
    EXPECT_LT((q * n_l - n_b).norm(), 1e-8);
    EXPECT_GT((init * n_l - n_b).norm(), 0.03);
    // So the remaining error is a rotation about the normal only.
    const Eigen::Vector3d err = geometry::BoxMinus(q, sc.q_bl);  // C_true^T C, frame l
    EXPECT_LT((err - err.dot(n_l) * n_l).norm(), 1e-6) << err.transpose();
  }
}

// The adder handed to the calibrate stage's problem builder.
TEST(GroundResidualsTest, AdderForTheProblemBuilder) {
  const Scenario sc;
  const std::vector<proto::GroundPlane> planes = sc.Planes();
  proto::Rig rig;
  rig.set_imu_height_m(sc.d_b);
  proto::GravityReference gravity;
  gravity.set_is_level(false);
  gravity.set_has_gravity_flat(true);
  const Eigen::Vector3d g_f = sc.GravityFlat();
  gravity.mutable_gravity_flat_in_imu()->set_x(g_f.x());
  gravity.mutable_gravity_flat_in_imu()->set_y(g_f.y());
  gravity.mutable_gravity_flat_in_imu()->set_z(g_f.z());
  const proto::GroundResidualsParams params = UnitSigmaParams();
  const GroundLosses losses(params);
  GroundAdderInputs inputs;
  inputs.planes = &planes;
  inputs.time_origin_ns = kOriginNs;
  inputs.rig = &rig;
  inputs.gravity = &gravity;
  inputs.params = &params;
  inputs.losses = &losses;
  GroundAdder ground;
  ASSERT_TRUE(MakeGroundResidualAdder(inputs, &ground).ok());
  EXPECT_EQ(ground.used, (std::vector<std::string>{"dist", "incl"}));
  EXPECT_EQ(ground.reason.rfind("ground residuals dist+incl: ", 0), 0u) << ground.reason;
  ASSERT_TRUE(static_cast<bool>(ground.add));
  CalibrationState state(sc.Grid());
  sc.FillState(&state);
  ceres::Problem problem{ProblemOptions()};
  AddStateBlocks(&state, &problem);
  int added = 0;
  ASSERT_TRUE(ground.add(&state, &problem, &added).ok());
  EXPECT_EQ(added, 2 * static_cast<int>(planes.size()));
  EXPECT_EQ(problem.NumResidualBlocks(), added);
  // No planes: no adder, and the reason says why.
  const std::vector<proto::GroundPlane> none;
  GroundAdderInputs no_planes = inputs;
  no_planes.planes = &none;
  ASSERT_TRUE(MakeGroundResidualAdder(no_planes, &ground).ok());
  EXPECT_FALSE(static_cast<bool>(ground.add));
  EXPECT_TRUE(ground.used.empty());
  EXPECT_NE(ground.reason.find("no ground planes"), std::string::npos) << ground.reason;
  // ON without its input is an error here too.
  proto::GroundResidualsParams on = params;
  on.mutable_up()->set_mode(proto::GroundResidualParams::ON);
  GroundAdderInputs forced = inputs;
  forced.gravity = nullptr;
  forced.params = &on;
  EXPECT_FALSE(MakeGroundResidualAdder(forced, &ground).ok());
}

// ------------------------------------------------------------ selection

GroundSequenceInfo Info(double d_b, bool level_known, bool level, bool g_f) {
  GroundSequenceInfo info;
  info.imu_height_m = d_b;
  info.level_known = level_known;
  info.is_level = level;
  info.has_gravity_flat = g_f;
  if (g_f) info.gravity_flat_in_imu = Eigen::Vector3d(0.1, 0.2, -9.8);
  return info;
}

std::string Select(const proto::GroundResidualsParams& params, const GroundSequenceInfo& info) {
  GroundResidualSelection selection;
  const Status status = SelectGroundResiduals(params, info, &selection);
  EXPECT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(selection.reason.find('\n'), std::string::npos);
  EXPECT_EQ(selection.reason.rfind("ground residuals " + selection.Names() + ": ", 0), 0u)
      << selection.reason;
  return selection.Names();
}

TEST(SelectGroundResidualsTest, AutoDefaults) {
  const proto::GroundResidualsParams params = DefaultGround();  // all AUTO
  // Level: flat, plus dist when d_b is known; never incl on level ground.
  EXPECT_EQ(Select(params, Info(0.4, true, true, true)), "flat+dist");
  EXPECT_EQ(Select(params, Info(0.0, true, true, true)), "flat");
  EXPECT_EQ(Select(params, Info(0.4, true, true, false)), "flat+dist");
  // Tilted: incl when g_f is known, dist when d_b is known, no flat.
  EXPECT_EQ(Select(params, Info(0.4, true, false, true)), "dist+incl");
  EXPECT_EQ(Select(params, Info(0.4, true, false, false)), "dist");
  EXPECT_EQ(Select(params, Info(0.0, true, false, true)), "incl");
  EXPECT_EQ(Select(params, Info(0.0, true, false, false)), "none");
  // No gravity reference: the slope is unknown, so neither flat nor incl.
  EXPECT_EQ(Select(params, Info(0.4, false, false, true)), "dist");
}

TEST(SelectGroundResidualsTest, OnAndOffOverride) {
  proto::GroundResidualsParams params = DefaultGround();
  params.mutable_up()->set_mode(proto::GroundResidualParams::ON);
  EXPECT_EQ(Select(params, Info(0.4, true, false, true)), "dist+incl+up");
  params.mutable_dist()->set_mode(proto::GroundResidualParams::OFF);
  params.mutable_incl()->set_mode(proto::GroundResidualParams::OFF);
  EXPECT_EQ(Select(params, Info(0.4, true, false, true)), "up");
  // flat forced on a tilted sequence is allowed (ablation) and said.
  proto::GroundResidualsParams forced = DefaultGround();
  forced.mutable_flat()->set_mode(proto::GroundResidualParams::ON);
  GroundResidualSelection selection;
  ASSERT_TRUE(SelectGroundResiduals(forced, Info(0.4, true, false, false), &selection).ok());
  EXPECT_EQ(selection.Names(), "flat+dist");
  EXPECT_NE(selection.reason.find("forced"), std::string::npos) << selection.reason;
  // OFF on a level sequence.
  proto::GroundResidualsParams off = DefaultGround();
  off.mutable_flat()->set_mode(proto::GroundResidualParams::OFF);
  EXPECT_EQ(Select(off, Info(0.4, true, true, true)), "dist");
}

TEST(SelectGroundResidualsTest, OnWithoutItsInputIsAnError) {
  GroundResidualSelection selection;
  proto::GroundResidualsParams dist_on = DefaultGround();
  dist_on.mutable_dist()->set_mode(proto::GroundResidualParams::ON);
  Status status = SelectGroundResiduals(dist_on, Info(0.0, true, false, true), &selection);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("dist.mode"), std::string::npos) << status.message();
  for (int which = 0; which < 2; ++which) {
    proto::GroundResidualsParams on = DefaultGround();
    (which == 0 ? on.mutable_incl() : on.mutable_up())->set_mode(proto::GroundResidualParams::ON);
    status = SelectGroundResiduals(on, Info(0.4, true, false, false), &selection);
    ASSERT_FALSE(status.ok());
    EXPECT_NE(status.message().find("g_f"), std::string::npos) << status.message();
  }
}

TEST(SelectGroundResidualsTest, SequenceInfoFromRigAndGravityReference) {
  proto::Rig rig;
  rig.set_imu_height_m(0.42);
  proto::GravityReference gravity;
  gravity.set_is_level(false);
  GroundSequenceInfo info = MakeGroundSequenceInfo(rig, &gravity);
  EXPECT_DOUBLE_EQ(info.imu_height_m, 0.42);
  EXPECT_TRUE(info.level_known);
  EXPECT_FALSE(info.is_level);
  EXPECT_FALSE(info.has_gravity_flat);
  // g_f from the rig when the reference has none.
  rig.mutable_gravity_flat_in_imu()->set_z(-9.8);
  info = MakeGroundSequenceInfo(rig, &gravity);
  EXPECT_TRUE(info.has_gravity_flat);
  EXPECT_DOUBLE_EQ(info.gravity_flat_in_imu.z(), -9.8);
  // The reference's g_f wins.
  gravity.set_has_gravity_flat(true);
  gravity.mutable_gravity_flat_in_imu()->set_x(-9.8);
  info = MakeGroundSequenceInfo(rig, &gravity);
  EXPECT_DOUBLE_EQ(info.gravity_flat_in_imu.x(), -9.8);
  EXPECT_DOUBLE_EQ(info.gravity_flat_in_imu.z(), 0.0);
  // No reference at all.
  info = MakeGroundSequenceInfo(proto::Rig(), nullptr);
  EXPECT_FALSE(info.level_known);
  EXPECT_FALSE(info.has_gravity_flat);
  EXPECT_EQ(info.imu_height_m, 0.0);
}

}  // namespace
}  // namespace tiltcal::calibrate
