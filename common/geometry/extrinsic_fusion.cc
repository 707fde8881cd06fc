#include "common/geometry/extrinsic_fusion.h"

#include <algorithm>
#include <cmath>

#include "common/geometry/so3.h"
#include "common/linear_algebra/dense_decompositions.h"

namespace tiltcal::geometry {
namespace {

// d e / d step at x for the right update C <- C Exp(step_rot), rest += step_rest.
Eigen::MatrixXd ErrorJacobian(const Eigen::VectorXd& error) {
  const int n = static_cast<int>(error.size());
  Eigen::MatrixXd j = Eigen::MatrixXd::Identity(n, n);
  j.topLeftCorner<3, 3>() = RightJacobianInverse(error.head<3>());
  return j;
}

// The prior as an estimate at its centre.
ExtrinsicEstimate PriorAsEstimate(const ExtrinsicPrior& prior) {
  ExtrinsicEstimate e;
  e.rotation = prior.rotation;
  e.rest = prior.rest;
  return e;
}

}  // namespace

Eigen::VectorXd ExtrinsicError(const ExtrinsicEstimate& estimate, const Eigen::Quaterniond& rotation,
                               const Eigen::VectorXd& rest) {
  Eigen::VectorXd e(3 + rest.size());
  e.head<3>() = BoxMinus(rotation, estimate.rotation);
  e.tail(rest.size()) = rest - estimate.rest;
  return e;
}

FusedExtrinsic FuseExtrinsics(const std::vector<ExtrinsicEstimate>& estimates,
                              const ExtrinsicPrior& prior, int max_iterations) {
  FusedExtrinsic out;
  if (estimates.empty()) return out;
  const int n = static_cast<int>(estimates.front().covariance.rows());
  std::vector<Eigen::MatrixXd> information;
  Eigen::MatrixXd net_prior =
      prior.information.size() == n * n ? prior.information : Eigen::MatrixXd::Zero(n, n);
  for (const ExtrinsicEstimate& e : estimates) {
    information.push_back(linear_algebra::Inverse(e.covariance));
    if (e.prior_information.size() == n * n) net_prior -= e.prior_information;
  }
  const ExtrinsicEstimate prior_estimate = PriorAsEstimate(prior);
  const bool has_prior = net_prior.cwiseAbs().maxCoeff() > 0.0 && prior.rest.size() == n - 3;

  out.rotation = estimates.front().rotation;
  out.rest = estimates.front().rest;
  Eigen::MatrixXd h(n, n);
  for (out.iterations = 1; out.iterations <= max_iterations; ++out.iterations) {
    h.setZero();
    Eigen::VectorXd g = Eigen::VectorXd::Zero(n);
    for (size_t i = 0; i < estimates.size(); ++i) {
      const Eigen::VectorXd e = ExtrinsicError(estimates[i], out.rotation, out.rest);
      const Eigen::MatrixXd j = ErrorJacobian(e);
      h += j.transpose() * information[i] * j;
      g += j.transpose() * information[i] * e;
    }
    if (has_prior) {
      const Eigen::VectorXd e = ExtrinsicError(prior_estimate, out.rotation, out.rest);
      const Eigen::MatrixXd j = ErrorJacobian(e);
      h += j.transpose() * net_prior * j;
      g += j.transpose() * net_prior * e;
    }
    const Eigen::VectorXd step = -linear_algebra::SolveByLdlt(h, g);
    out.rotation = BoxPlus(out.rotation, step.head<3>()).normalized();
    out.rest += step.tail(n - 3);
    if (step.norm() < 1e-12) {
      out.converged = true;
      break;
    }
  }
  out.iterations = std::min(out.iterations, max_iterations);
  out.covariance = linear_algebra::Inverse(h);
  return out;
}

ExtrinsicConsistency TestConsistency(const ExtrinsicEstimate& estimate,
                                     const FusedExtrinsic& fused, bool estimate_in_fused) {
  ExtrinsicConsistency c;
  c.difference = ExtrinsicError(estimate, fused.rotation, fused.rest);
  const Eigen::MatrixXd d = estimate_in_fused ? Eigen::MatrixXd(estimate.covariance - fused.covariance)
                                              : Eigen::MatrixXd(estimate.covariance + fused.covariance);
  const linear_algebra::SymmetricEigen eig =
      linear_algebra::DecomposeSymmetric(0.5 * (d + d.transpose()));
  const double floor = 1e-9 * std::max(eig.values.cwiseAbs().maxCoeff(), 1e-300);
  for (int k = 0; k < eig.values.size(); ++k) {
    if (eig.values[k] <= floor) continue;
    const double projection = eig.vectors.col(k).dot(c.difference);
    c.chi2 += projection * projection / eig.values[k];
    ++c.dof;
  }
  for (int j = 0; j < c.difference.size(); ++j) {
    if (d(j, j) <= 0.0) continue;
    const double z = c.difference[j] / std::sqrt(d(j, j));
    if (std::abs(z) > std::abs(c.worst_z)) {
      c.worst_z = z;
      c.worst_component = j;
    }
  }
  return c;
}

double ChiSquareUpperQuantile(int dof, double p) {
  // Standard normal upper quantile z with 0.5 erfc(z / sqrt 2) = p, by bisection.
  double lo = -10.0, hi = 10.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
  }
  const double z = 0.5 * (lo + hi);
  const double k = static_cast<double>(dof);
  const double a = 2.0 / (9.0 * k);
  return k * std::pow(1.0 - a + z * std::sqrt(a), 3);
}

}  // namespace tiltcal::geometry
