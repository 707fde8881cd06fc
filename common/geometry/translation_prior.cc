#include "common/geometry/translation_prior.h"

namespace tiltcal::geometry {

Eigen::Matrix3d TranslationPriorInformation(double sigma_m, const Eigen::Vector3d& axis_b) {
  if (sigma_m <= 0.0) return Eigen::Matrix3d::Zero();
  const Eigen::Matrix3d w = axis_b.norm() > 0.0
                                ? Eigen::Matrix3d(axis_b.normalized() * axis_b.normalized().transpose())
                                : Eigen::Matrix3d::Identity();
  return w / (sigma_m * sigma_m);
}

}  // namespace tiltcal::geometry
