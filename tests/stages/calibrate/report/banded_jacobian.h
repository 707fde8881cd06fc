#ifndef TILTCAL_TESTS_STAGES_CALIBRATE_REPORT_BANDED_JACOBIAN_H_
#define TILTCAL_TESTS_STAGES_CALIBRATE_REPORT_BANDED_JACOBIAN_H_

#include <cmath>
#include <random>

#include <Eigen/Core>

namespace tiltcal::calibrate::testing {

// A spline-like Jacobian (rows x n): each row touches 4 consecutive "knot"
// columns of the first n - k and every one of the last k, with standard
// normal entries drawn from `seed`; column j is scaled by
// 10^(j mod decades - (decades - 1) / 2), so that the units differ by
// decades - 1 orders of magnitude. decades odd.
inline Eigen::MatrixXd BandedJacobian(int rows, int n, int k, unsigned seed, int decades) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(rows, n);
  const int knots = n - k;
  for (int r = 0; r < rows; ++r) {
    const int first = (r * (knots - 3)) / rows;
    for (int c = first; c < first + 4; ++c) j(r, c) = normal(rng);
    for (int c = knots; c < n; ++c) j(r, c) = normal(rng);
  }
  for (int c = 0; c < n; ++c) j.col(c) *= std::pow(10.0, c % decades - (decades - 1) / 2);
  return j;
}

}  // namespace tiltcal::calibrate::testing

#endif  // TILTCAL_TESTS_STAGES_CALIBRATE_REPORT_BANDED_JACOBIAN_H_
