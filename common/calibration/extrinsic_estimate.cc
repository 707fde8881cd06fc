#include "common/calibration/extrinsic_estimate.h"

#include <fmt/format.h>

#include "common/geometry/translation_prior.h"
#include "common/io/eigen_proto.h"

namespace tiltcal::calibration {

using RowMajor7d = Eigen::Matrix<double, 7, 7, Eigen::RowMajor>;

Eigen::MatrixXd PriorInformation(const proto::CalibrationResult& r, int n) {
  Eigen::MatrixXd information = Eigen::MatrixXd::Zero(n, n);
  information.block<3, 3>(3, 3) = geometry::TranslationPriorInformation(
      r.translation_prior_sigma_m(), ToEigen(r.translation_prior_axis_b()));
  return information;
}

geometry::ExtrinsicEstimate ToEstimate(const proto::CalibrationResult& r, int n) {
  const RowMajor7d covariance = Eigen::Map<const RowMajor7d>(r.covariance().data());
  const Rigid3d extrinsic = ToEigen(r.imu_from_lidar());
  geometry::ExtrinsicEstimate e;
  e.rotation = extrinsic.rotation;
  e.rest = Eigen::VectorXd(n - 3);
  e.rest.head<3>() = extrinsic.translation;
  if (n == 7) e.rest[3] = r.time_offset_s();
  e.covariance = covariance.topLeftCorner(n, n);
  e.prior_information = PriorInformation(r, n);
  return e;
}

std::string DescribeComponent(int component, double z) {
  static const char* kNames[] = {"rotation about l-x", "rotation about l-y",
                                 "rotation about l-z", "translation along b-x",
                                 "translation along b-y", "translation along b-z",
                                 "time offset"};
  return fmt::format("{}: {:+.1f} sigma", kNames[component], z);
}

}  // namespace tiltcal::calibration
