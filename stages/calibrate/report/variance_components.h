#ifndef TILTCAL_STAGES_CALIBRATE_REPORT_VARIANCE_COMPONENTS_H_
#define TILTCAL_STAGES_CALIBRATE_REPORT_VARIANCE_COMPONENTS_H_

// Variance components of a weighted least-squares problem whose residuals
// fall into groups (one per sensor), by Förstner's / Helmert's estimator
// (docs/design.md §11).
//
// J (m x n) is the Jacobian of the residuals weighted by their model sigma,
// the rows of group k forming J_k, and e_k^T e_k (2F_k with a robust loss)
// the group's weighted square sum at the solution. With weights w_k on the
// groups' information,
//   H   = sum_k w_k J_k^T J_k
//   r_k = n_k - w_k tr(H^{-1} J_k^T J_k)       (the group's redundancy;
//                                               sum_k r_k = m - n)
//   s_k = e_k^T e_k / r_k                       (the group's variance factor)
// s_k is the estimate of (actual / model noise)^2 for group k, as the single
// factor 2F / (m - n) is for all residuals together; the weights the
// covariance then gives the groups are w_k = 1 / s_k. The redundancies are
// those of the model's weights (w_k = 1 in H), at which the problem was
// solved: the estimate is unbiased when the model's sigmas are in the right
// ratio, and a noisier group leaks into the others' residuals through the
// parameters they share otherwise. A group not estimated keeps s_k = w_k = 1
// (priors, random walks: not measurements of noise). A group whose errors
// stay correlated along the sequence (error_correlation.h: tau_k, the
// variance of their mean against that of independent errors) has its
// information divided by tau_k as well, and a group whose fit can fall below
// its noise has a floor f_k under the product:
//   w_k = 1 / max(f_k, s_k max(1, tau_k))
// (tau_k below 1, errors that cancel, is not credited). f_k = 1 for residuals
// whose errors are shared, so that their fit says nothing of their noise
// (the ground's); for a low-passed IMU, whose in-band noise the spline
// absorbs, its noise measured at rest (imu_static_noise.h); 0 otherwise.
// tr(H^{-1} J_k^T J_k) needs H^{-1} only on H's pattern
// (selected_inverse.h).

#include <cstdint>
#include <vector>

#include <Eigen/SparseCore>

#include "common/status.h"

namespace tiltcal::calibrate {

struct VarianceComponentGroup {
  double square_sum = 0.0;  // e_k^T e_k
  bool estimated = true;
  double correlation = 1.0;  // tau_k
  double floor = 0.0;        // f_k
};

struct VarianceComponent {
  int64_t rows = 0;
  double redundancy = 0.0;      // r_k
  double sigma0_squared = 1.0;  // s_k
  double correlation = 1.0;     // max(1, tau_k) as applied
  double floor = 0.0;           // f_k
  double weight = 1.0;          // w_k the covariance uses
};

// row_group: each row's group index into `groups`. A group with
// no redundancy (r_k <= 0) or no residual left keeps s_k = 1. Errors: rank deficiency of H
// (selected_inverse.h), a row group out of range.
Status EstimateVarianceComponents(const Eigen::SparseMatrix<double, Eigen::RowMajor>& jacobian,
                                  const std::vector<int>& row_group,
                                  const std::vector<VarianceComponentGroup>& groups,
                                  double min_relative_pivot,
                                  std::vector<VarianceComponent>* components);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_REPORT_VARIANCE_COMPONENTS_H_
