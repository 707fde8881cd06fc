#ifndef TILTCAL_COMMON_GEOMETRY_TRANSLATION_PRIOR_H_
#define TILTCAL_COMMON_GEOMETRY_TRANSLATION_PRIOR_H_

#include <Eigen/Core>

namespace tiltcal::geometry {

// Information of the prior on r_b^{lb} (docs/design.md §11), frame b, 1/m^2:
// a a^T / sigma^2 along a unit axis a, I / sigma^2 for a zero axis, zero for
// sigma <= 0.
Eigen::Matrix3d TranslationPriorInformation(double sigma_m, const Eigen::Vector3d& axis_b);

}  // namespace tiltcal::geometry

#endif  // TILTCAL_COMMON_GEOMETRY_TRANSLATION_PRIOR_H_
