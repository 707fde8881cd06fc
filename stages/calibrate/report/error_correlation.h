#ifndef TILTCAL_STAGES_CALIBRATE_REPORT_ERROR_CORRELATION_H_
#define TILTCAL_STAGES_CALIBRATE_REPORT_ERROR_CORRELATION_H_

// How long the errors of a group of residuals stay correlated along the
// sequence, from the residuals in the order they were measured
// (docs/design.md §11).
//
// For a series e_1 .. e_N of errors with variance sigma^2 and
// autocorrelation rho_j at lag j, the mean's variance is
//   var(mean) = tau sigma^2 / N,   tau = 1 + 2 sum_{j=1}^{N-1} (1 - j/N) rho_j,
// tau = 1 for independent errors, tau ~ (1 + rho) / (1 - rho) for an AR(1)
// series. A parameter that the group determines like a mean over the
// sequence (the vertical of r_b^{lb} from the dist residuals) has tau times
// the variance that independent residuals would give it.
//
// Batch means: the series is cut into b batches of L = floor(N / b)
// consecutive values (the last N - b L dropped), m_i their means and m the
// mean of the values used:
//   tau^ = L sum_i (m_i - m)^2 / (b - 1)  /  (sum_n (e_n - m)^2 / (b L - 1)).
// For white errors its relative standard error is about sqrt(2 / (b - 1));
// it sees correlations up to about L values long.

#include <vector>

#include <Eigen/Core>

namespace tiltcal::calibrate {

// The numerator (L times the batch means' variance) and the denominator (the
// values' variance) of tau^ above, kept apart so that several series pool
// them. Both 0 when the series has fewer than 2 b values or b < 2.
struct BatchMeansVariances {
  double batch_means = 0.0;
  double values = 0.0;
};
BatchMeansVariances BatchMeans(const std::vector<double>& series, int num_batches);

// tau^ pooled over the series of one group's rows: the rows with
// row_group == group, each component (row_component, typed_jacobian.h) a
// series of its own (a 3-row residual gives three), in the rows' order.
// tau^ = the sum of the numerators over the sum of the denominators; 1 when
// there is no variance to compare (too few rows, all residuals equal).
double PooledBatchMeansCorrelation(const Eigen::VectorXd& residuals,
                                   const std::vector<int>& row_group,
                                   const std::vector<int>& row_component, int group,
                                   int num_batches);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_REPORT_ERROR_CORRELATION_H_
