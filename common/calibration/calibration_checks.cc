#include "common/calibration/calibration_checks.h"

#include <fmt/format.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "common/geometry/translation_prior.h"
#include "common/io/eigen_proto.h"
#include "common/linear_algebra/dense_decompositions.h"

namespace tiltcal::calibration {
namespace {

using RowMajor7d = Eigen::Matrix<double, 7, 7, Eigen::RowMajor>;

// Relative rounding allowed when the data's information P^{-1} - L_p is
// tested for a negative eigenvalue (P^{-1} is computed, not stored).
constexpr double kInformationRounding = 1e-6;

std::string CheckVector(const proto::Vector3& v, const std::string& field) {
  if (std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z())) return "";
  return fmt::format("{} ({}, {}, {}) is not finite", field, v.x(), v.y(), v.z());
}

std::string CheckTransform(bool present, const proto::Rigid3& t, const std::string& field,
                           double max_norm_error) {
  if (!present || !t.has_rotation()) return field + ".rotation is missing";
  const proto::Quaternion& q = t.rotation();
  const double norm = std::sqrt(q.w() * q.w() + q.x() * q.x() + q.y() * q.y() + q.z() * q.z());
  if (!std::isfinite(norm)) {
    return fmt::format("{}.rotation (w {}, x {}, y {}, z {}) is not finite", field, q.w(), q.x(),
                       q.y(), q.z());
  }
  if (!(std::abs(norm - 1.0) <= max_norm_error)) {
    return fmt::format("{}.rotation is not a unit quaternion (norm {:.9g}, tolerance {:g})", field,
                       norm, max_norm_error);
  }
  return CheckVector(t.translation(), field + ".translation");
}

std::string CheckCovariance(const proto::CalibrationResult& r, int n,
                            const proto::SequenceInputParams& params) {
  if (r.covariance_size() != 49) {
    return fmt::format("covariance has {} values, not 49 (7x7)", r.covariance_size());
  }
  for (int k = 0; k < 49; ++k) {
    if (!std::isfinite(r.covariance(k))) {
      return fmt::format("covariance[{}] = {} is not finite", k, r.covariance(k));
    }
  }
  const Eigen::MatrixXd p = Eigen::Map<const RowMajor7d>(r.covariance().data()).topLeftCorner(n, n);
  const double largest = p.cwiseAbs().maxCoeff();
  if (!(largest > 0.0)) return fmt::format("covariance ({}x{} block) is zero", n, n);
  const double asymmetry = (p - p.transpose()).cwiseAbs().maxCoeff() / largest;
  if (!(asymmetry <= params.max_covariance_asymmetry())) {
    return fmt::format(
        "covariance is not symmetric (largest |P_ij - P_ji| / max |P_ij| {:.3g} > "
        "input.max_covariance_asymmetry {:g})",
        asymmetry, params.max_covariance_asymmetry());
  }
  // Scaled to a largest entry of 1 so that no eigenvalue under- or overflows.
  const linear_algebra::SymmetricEigen eig = linear_algebra::DecomposeSymmetric(
      0.5 * (p + p.transpose()) / largest, linear_algebra::EigenvectorsToo::kNo);
  if (!eig.converged) return "covariance: eigenvalues not computed";
  const double smallest_scaled = eig.values.minCoeff();
  const double largest_scaled = eig.values.maxCoeff();
  if (!(smallest_scaled > 0.0)) {
    return fmt::format(
        "covariance ({}x{} block) is not positive definite (eigenvalues {:.3g} to "
        "{:.3g})",
        n, n, smallest_scaled * largest, largest_scaled * largest);
  }
  const double sigma_min = std::sqrt(smallest_scaled) * std::sqrt(largest);
  const double sigma_max = std::sqrt(largest_scaled) * std::sqrt(largest);
  if (!(sigma_min >= params.min_sigma())) {
    return fmt::format("covariance: smallest sigma {:.3g} < input.min_sigma {:g}", sigma_min,
                       params.min_sigma());
  }
  if (!(sigma_max <= params.max_sigma())) {
    return fmt::format("covariance: largest sigma {:.3g} > input.max_sigma {:g}", sigma_max,
                       params.max_sigma());
  }
  const double condition = largest_scaled / smallest_scaled;
  if (!(condition <= params.max_condition_number())) {
    return fmt::format("covariance: condition number {:.3g} > input.max_condition_number {:g}",
                       condition, params.max_condition_number());
  }
  return "";
}

// The covariance's information P^{-1} holds the solve's prior L_p (the
// fusion removes it, extrinsic_fusion.h), so P^{-1} - L_p, the data's
// information, is positive semidefinite up to rounding.
std::string CheckPriorWithinCovariance(const proto::CalibrationResult& r, int n) {
  const Eigen::MatrixXd p = Eigen::Map<const RowMajor7d>(r.covariance().data()).topLeftCorner(n, n);
  const Eigen::MatrixXd information = linear_algebra::Inverse(p);
  Eigen::MatrixXd prior = Eigen::MatrixXd::Zero(n, n);
  prior.block<3, 3>(3, 3) = geometry::TranslationPriorInformation(
      r.translation_prior_sigma_m(), ToEigen(r.translation_prior_axis_b()));
  const Eigen::MatrixXd data = information - prior;
  const linear_algebra::SymmetricEigen eig = linear_algebra::DecomposeSymmetric(
      0.5 * (data + data.transpose()), linear_algebra::EigenvectorsToo::kNo);
  const double scale = information.cwiseAbs().maxCoeff();
  if (!eig.converged || !(eig.values.minCoeff() >= -kInformationRounding * scale)) {
    return fmt::format(
        "covariance holds less information than its own translation prior "
        "(translation_prior_sigma_m {} along ({}, {}, {}))",
        r.translation_prior_sigma_m(), r.translation_prior_axis_b().x(),
        r.translation_prior_axis_b().y(), r.translation_prior_axis_b().z());
  }
  return "";
}

}  // namespace

Status ValidateSequenceInputParams(const proto::SequenceInputParams& params) {
  if (!(params.min_sigma() < params.max_sigma())) {
    return Status::Error(
        fmt::format("field input.min_sigma = {:g} is not below input.max_sigma = {:g}",
                    params.min_sigma(), params.max_sigma()));
  }
  return Status::Ok();
}

std::string ReasonRefused(const proto::CalibrationResult& r, int n,
                          const proto::SequenceInputParams& params) {
  std::string reason = CheckTransform(r.has_imu_from_lidar(), r.imu_from_lidar(), "imu_from_lidar",
                                      params.max_quaternion_norm_error());
  if (reason.empty()) {
    reason = CheckTransform(r.has_rig_imu_from_lidar(), r.rig_imu_from_lidar(),
                            "rig_imu_from_lidar", params.max_quaternion_norm_error());
  }
  if (!reason.empty()) return reason;
  if (!std::isfinite(r.time_offset_s())) {
    return fmt::format("time_offset_s = {} is not finite", r.time_offset_s());
  }
  if (!(std::isfinite(r.time_offset_sigma_s()) && r.time_offset_sigma_s() >= 0.0)) {
    return fmt::format("time_offset_sigma_s = {} is not a finite sigma >= 0",
                       r.time_offset_sigma_s());
  }
  const double prior_sigma_m = r.translation_prior_sigma_m();
  if (prior_sigma_m != 0.0 &&
      !(prior_sigma_m >= params.min_sigma() && prior_sigma_m <= params.max_sigma())) {
    return fmt::format(
        "translation_prior_sigma_m = {} is neither 0 (no prior) nor within "
        "input.min_sigma {:g} to input.max_sigma {:g}",
        prior_sigma_m, params.min_sigma(), params.max_sigma());
  }
  reason = CheckVector(r.translation_prior_axis_b(), "translation_prior_axis_b");
  if (reason.empty()) reason = CheckVector(r.motion_rotation_axis_b(), "motion_rotation_axis_b");
  if (reason.empty()) reason = CheckCovariance(r, n, params);
  if (reason.empty()) reason = CheckPriorWithinCovariance(r, n);
  return reason;
}

}  // namespace tiltcal::calibration
