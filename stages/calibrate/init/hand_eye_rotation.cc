#include "common/geometry/angles.h"
#include "stages/calibrate/init/hand_eye_rotation.h"

#include <cmath>

#include <Eigen/Eigenvalues>

#include "common/linear_algebra/dense_decompositions.h"

namespace tiltcal::calibrate {
namespace {

using geometry::kDegPerRad;

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// Left / right product matrices in (w, x, y, z) order: p (x) q = L(p) q = R(q) p.
Eigen::Matrix4d LeftMatrix(const Eigen::Quaterniond& q) {
  Eigen::Matrix4d m;
  m(0, 0) = q.w();
  m.block<1, 3>(0, 1) = -q.vec().transpose();
  m.block<3, 1>(1, 0) = q.vec();
  m.block<3, 3>(1, 1) = q.w() * Eigen::Matrix3d::Identity() + Skew(q.vec());
  return m;
}

Eigen::Matrix4d RightMatrix(const Eigen::Quaterniond& q) {
  Eigen::Matrix4d m;
  m(0, 0) = q.w();
  m.block<1, 3>(0, 1) = -q.vec().transpose();
  m.block<3, 1>(1, 0) = q.vec();
  m.block<3, 3>(1, 1) = q.w() * Eigen::Matrix3d::Identity() - Skew(q.vec());
  return m;
}

// Rotation angle in [0, pi], rad.
double Angle(const Eigen::Quaterniond& q) {
  return 2.0 * std::atan2(q.vec().norm(), std::abs(q.w()));
}

// Log: unit quaternion -> rotation vector (rad).
Eigen::Vector3d LogQ(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in.normalized();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const double n = q.vec().norm();
  if (n < 1e-12) return 2.0 * q.vec();
  return 2.0 * std::atan2(n, q.w()) * q.vec() / n;
}

}  // namespace

HandEyeResult EstimateHandEyeRotation(const std::vector<RotationPair>& pairs,
                                      const proto::HandEyeParams& params) {
  HandEyeResult result;
  result.num_pairs = static_cast<int>(pairs.size());
  if (pairs.empty() || result.num_pairs < static_cast<int>(params.min_pairs())) return result;

  Eigen::MatrixXd a(4 * pairs.size(), 4);
  double sum_h_sq = 0.0;
  Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const Eigen::Quaterniond qb = pairs[i].imu_delta.normalized();
    const Eigen::Quaterniond ql = pairs[i].lidar_delta.normalized();
    const double difference_deg = std::abs(Angle(qb) - Angle(ql)) * kDegPerRad;
    const double h = difference_deg <= params.consistent_angle_deg() ? 1.0 : 1.0 / difference_deg;
    // Same sign convention (w >= 0) for both: conjugation keeps w, so the
    // consistent pair satisfies the equation without a sign flip.
    Eigen::Quaterniond qb_pos = qb, ql_pos = ql;
    if (qb_pos.w() < 0.0) qb_pos.coeffs() = -qb_pos.coeffs();
    if (ql_pos.w() < 0.0) ql_pos.coeffs() = -ql_pos.coeffs();
    a.block<4, 4>(4 * i, 0) = h * (LeftMatrix(qb_pos) - RightMatrix(ql_pos));
    sum_h_sq += h * h;
    const Eigen::Vector3d phi = LogQ(qb);
    spread += phi * phi.transpose();
  }
  spread /= static_cast<double>(pairs.size());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> spread_solver(spread);
  const Eigen::Vector3d ev = spread_solver.eigenvalues().cwiseMax(0.0);
  result.rotation_spread_rad = Eigen::Vector3d(ev(2), ev(1), ev(0)).cwiseSqrt();

  const linear_algebra::RightSingularVectors svd = linear_algebra::DecomposeSingular(a);
  result.singular_values = svd.values;
  const Eigen::Vector4d x = svd.v.col(3);  // (w, x, y, z)
  Eigen::Quaterniond q_bl(x(0), x(1), x(2), x(3));
  q_bl.normalize();
  if (q_bl.w() < 0.0) q_bl.coeffs() = -q_bl.coeffs();
  result.imu_from_lidar_rotation = q_bl;
  result.solved = true;
  result.excitation_rad = result.singular_values(2) / std::sqrt(sum_h_sq);
  result.excitation_ratio =
      result.singular_values(0) > 0.0 ? result.singular_values(2) / result.singular_values(0) : 0.0;
  result.excited = result.excitation_rad >= params.min_excitation_rad();

  double sum_sq = 0.0;
  for (const RotationPair& p : pairs) {
    const Eigen::Quaterniond e = q_bl * p.lidar_delta * q_bl.conjugate() * p.imu_delta.conjugate();
    const double angle = Angle(e.normalized());
    sum_sq += angle * angle;
  }
  result.rms_residual_deg = std::sqrt(sum_sq / static_cast<double>(pairs.size())) * kDegPerRad;
  return result;
}

std::vector<RotationPair> MakeRotationPairs(const std::vector<Eigen::Quaterniond>& imu_rotations,
                                            const std::vector<Eigen::Quaterniond>& lidar_rotations,
                                            int step) {
  std::vector<RotationPair> pairs;
  if (step < 1 || imu_rotations.size() != lidar_rotations.size()) return pairs;
  const std::size_t s = static_cast<std::size_t>(step);
  for (std::size_t k = 0; k + s < imu_rotations.size(); k += s) {
    RotationPair p;
    p.imu_delta = (imu_rotations[k].conjugate() * imu_rotations[k + s]).normalized();
    p.lidar_delta = (lidar_rotations[k].conjugate() * lidar_rotations[k + s]).normalized();
    pairs.push_back(p);
  }
  return pairs;
}

Eigen::Quaterniond ChooseInitialRotation(const Eigen::Quaterniond& measured_imu_from_lidar,
                                         const HandEyeResult& result) {
  return result.excited ? result.imu_from_lidar_rotation : measured_imu_from_lidar.normalized();
}

}  // namespace tiltcal::calibrate
