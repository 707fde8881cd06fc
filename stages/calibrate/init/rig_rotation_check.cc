#include "stages/calibrate/init/rig_rotation_check.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include <fmt/format.h>

#include "common/geometry/angles.h"
#include "common/spline/linear_interpolation.h"
#include "common/spline/so3_spline.h"

namespace tiltcal::calibrate {
namespace {

using geometry::kDegPerRad;

// World acceleration of the IMU, C_ab f_m + g_a, per IMU sample inside the
// spline (times and values).
void ImuWorldAccelerations(const CalibrationState& state,
                           const std::vector<imu::ImuReading>& imu_samples,
                           std::vector<double>* times, std::vector<Eigen::Vector3d>* values) {
  const Eigen::Vector3d g_a = state.GravityInWorld();
  for (const imu::ImuReading& r : imu_samples) {
    spline::So3SplineSample rot;
    if (!state.trajectory.Evaluate(r.time_s, spline::kSo3Rotation, &rot, nullptr)) continue;
    times->push_back(r.time_s);
    values->push_back(rot.rotation * r.linear_acceleration_mps2 + g_a);
  }
}

// Triangle-kernel mean (half-width h) of (times, values) around t; false
// when the window is not inside the samples.
bool TriangleMean(const std::vector<double>& times, const std::vector<Eigen::Vector3d>& values,
                  double t, double h, Eigen::Vector3d* mean) {
  if (times.empty() || t - h < times.front() || t + h > times.back()) return false;
  const size_t begin = std::lower_bound(times.begin(), times.end(), t - h) - times.begin();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double weight = 0.0;
  for (size_t i = begin; i < times.size() && times[i] <= t + h; ++i) {
    const double w = h - std::abs(times[i] - t);
    sum += w * values[i];
    weight += w;
  }
  if (!(weight > 0.0)) return false;
  *mean = sum / weight;
  return true;
}

// q(t) = C_ab(t) r_b^{lb}; false outside the spline.
bool LeverArmInWorld(const CalibrationState& state, double t, Eigen::Vector3d* q) {
  spline::So3SplineSample rot;
  if (!state.trajectory.Evaluate(t, spline::kSo3Rotation, &rot, nullptr)) return false;
  *q = rot.rotation * state.ImuFromLidarTranslation();
  return true;
}

}  // namespace

bool MatchedPrincipalAxes(const std::vector<RotationPair>& pairs, Eigen::Vector3d* axis_b,
                          Eigen::Vector3d* axis_l) {
  Eigen::Matrix3d mb = Eigen::Matrix3d::Zero(), ml = Eigen::Matrix3d::Zero();
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> phis;
  for (const RotationPair& p : pairs) {
    const Eigen::AngleAxisd ab(p.imu_delta), al(p.lidar_delta);
    const Eigen::Vector3d phi_b = ab.angle() * ab.axis();
    const Eigen::Vector3d phi_l = al.angle() * al.axis();
    mb += phi_b * phi_b.transpose();
    ml += phi_l * phi_l.transpose();
    phis.emplace_back(phi_b, phi_l);
  }
  if (mb.trace() <= 0.0 || ml.trace() <= 0.0) return false;
  *axis_b = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(mb).eigenvectors().col(2);
  *axis_l = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(ml).eigenvectors().col(2);
  double corr = 0.0;
  for (const auto& [pb, pl] : phis) corr += pb.dot(*axis_b) * pl.dot(*axis_l);
  if (corr < 0.0) *axis_l = -*axis_l;
  return true;
}

double RotationAxisDisagreementDeg(const std::vector<RotationPair>& pairs,
                                   const Eigen::Quaterniond& imu_from_lidar) {
  Eigen::Vector3d a_b, a_l;
  if (!MatchedPrincipalAxes(pairs, &a_b, &a_l)) return 0.0;
  const double c = std::clamp((imu_from_lidar * a_l).normalized().dot(a_b.normalized()), -1.0, 1.0);
  return std::acos(c) * kDegPerRad;
}

TurningAmount MeasureTurning(const std::vector<RotationPair>& pairs,
                             const std::vector<std::pair<double, double>>& pair_times_s) {
  TurningAmount turning;
  turning.pairs = static_cast<int>(pairs.size());
  if (!pair_times_s.empty()) turning.span_s = pair_times_s.back().second - pair_times_s.front().first;
  Eigen::Vector3d a_b, a_l;
  if (!MatchedPrincipalAxes(pairs, &a_b, &a_l)) return turning;
  double sum_sq = 0.0;
  for (const RotationPair& p : pairs) {
    const Eigen::AngleAxisd ab(p.imu_delta);
    const double s = ab.angle() * ab.axis().dot(a_b);
    sum_sq += s * s;
    (s > 0.0 ? turning.left_rad : turning.right_rad) += std::abs(s);
  }
  turning.rms_about_axis_rad = std::sqrt(sum_sq / static_cast<double>(pairs.size()));
  return turning;
}

std::string MissingTurning(const TurningAmount& turning, const proto::InitParams& params) {
  if (turning.rms_about_axis_rad >= params.min_axis_rotation_rad()) return "";
  return fmt::format(
      "the motion cannot decide the extrinsic rotation: too little turning, {:.4f} rad RMS about "
      "the motion's main axis per rotation pair (at least init.min_axis_rotation_rad = {} rad), "
      "{} pairs over {:.1f} s of registered motion, {:.2f} rad turned one way and {:.2f} rad the "
      "other: record 30 s or more of driving with turns both ways",
      turning.rms_about_axis_rad, params.min_axis_rotation_rad(), turning.pairs, turning.span_s,
      turning.left_rad, turning.right_rad);
}

AccelerationCheck CheckRigYawByAccelerations(const CalibrationState& state,
                                             const std::vector<imu::ImuReading>& imu_samples,
                                             const std::vector<double>& lidar_times_s,
                                             const std::vector<Eigen::Vector3d>& lidar_positions_l0,
                                             const Eigen::Vector3d& axis_b,
                                             const proto::InitParams& params) {
  AccelerationCheck check;
  const double h = params.acceleration_check_half_window_s();
  const double tau = state.time_offset_s[0];
  if (lidar_times_s.size() < 3 || axis_b.norm() == 0.0) return check;
  spline::So3SplineSample rot0;
  if (!state.trajectory.Evaluate(lidar_times_s.front() + tau, spline::kSo3Rotation, &rot0,
                                 nullptr)) {
    return check;
  }
  const Eigen::Matrix3d b0_from_a = rot0.rotation.transpose();
  const Eigen::Matrix3d c_bl = state.ImuFromLidarRotation().toRotationMatrix();
  const Eigen::Vector3d axis = axis_b.normalized();
  std::vector<double> imu_times;
  std::vector<Eigen::Vector3d> imu_accelerations;
  ImuWorldAccelerations(state, imu_samples, &imu_times, &imu_accelerations);
  double sum_cos = 0.0, sum_sin = 0.0, sum_u2 = 0.0;
  for (const double t : lidar_times_s) {
    if (t - h < lidar_times_s.front() || t + h > lidar_times_s.back()) continue;
    const double t_imu = t + tau;
    Eigen::Vector3d imu_mean, q_minus, q_0, q_plus;
    if (!TriangleMean(imu_times, imu_accelerations, t_imu, h, &imu_mean) ||
        !LeverArmInWorld(state, t_imu - h, &q_minus) || !LeverArmInWorld(state, t_imu, &q_0) ||
        !LeverArmInWorld(state, t_imu + h, &q_plus)) {
      continue;
    }
    const Eigen::Vector3d lidar_l0 =
        (spline::InterpolateLinearly(lidar_times_s, lidar_positions_l0, t + h) -
         2.0 * spline::InterpolateLinearly(lidar_times_s, lidar_positions_l0, t) +
         spline::InterpolateLinearly(lidar_times_s, lidar_positions_l0, t - h)) / (h * h);
    Eigen::Vector3d u = b0_from_a * (imu_mean + (q_plus - 2.0 * q_0 + q_minus) / (h * h));
    Eigen::Vector3d w = c_bl * lidar_l0;
    u -= axis * axis.dot(u);
    w -= axis * axis.dot(w);
    sum_cos += w.dot(u);
    sum_sin += axis.dot(w.cross(u));
    sum_u2 += u.squaredNorm();
    ++check.samples;
  }
  if (check.samples == 0) return check;
  check.rms_horizontal_acceleration_mps2 = std::sqrt(sum_u2 / check.samples);
  check.yaw_error_deg = std::atan2(sum_sin, sum_cos) * kDegPerRad;
  check.decided = check.rms_horizontal_acceleration_mps2 >= params.min_check_acceleration_mps2();
  return check;
}

}  // namespace tiltcal::calibrate
