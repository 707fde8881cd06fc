#ifndef TILTCAL_STAGES_CALIBRATE_REPORT_MARGINAL_COVARIANCE_H_
#define TILTCAL_STAGES_CALIBRATE_REPORT_MARGINAL_COVARIANCE_H_

// Marginal covariance of the last k parameters of a weighted least-squares
// problem from its Jacobian, in time and memory linear in the number of
// parameters for a banded problem such as a spline's (docs/design.md §11).
//
// J is m x n, weighted (every residual divided by its sigma, the robust
// loss's correction applied), its columns ordered so that the k parameters of
// interest come last:
//   H = J^T J = [ A    B ]   A: (n-k) x (n-k), B: (n-k) x k, C: k x k.
//               [ B^T  C ]
// The covariance of the last k with all others marginalised is the
// bottom-right k x k block of H^{-1}, the inverse of the Schur complement:
//   Cov = (C - B^T A^{-1} B)^{-1}.
// A (the knots: banded, plus a few blocks shared by many residuals such as
// gravity and the bias segments) is factored by a sparse LDL^T with AMD
// fill-reducing ordering; A^{-1} B is k solves. Nothing of size n^2 is formed.
//
// Rank: H is scaled to a unit diagonal first (S H S, S = diag(H)^{-1/2}; the
// covariance is scaled back), so the test does not depend on the units of
// the parameters. The problem is rank deficient (an error, no covariance)
// when a column of J is zero, when a pivot of the scaled A's LDL^T is below
// min_relative_pivot, or when the smallest eigenvalue of the scaled Schur
// complement is: some combination of the parameters is then not determined
// by the data beyond 1/sqrt(min_relative_pivot) times its unmarginalised
// sigma.

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "common/status.h"

namespace tiltcal::calibrate {

Status MarginalCovarianceOfLastColumns(
    const Eigen::SparseMatrix<double, Eigen::RowMajor>& weighted_jacobian, int k,
    double min_relative_pivot, Eigen::MatrixXd* covariance);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_REPORT_MARGINAL_COVARIANCE_H_
