#ifndef TILTCAL_COMMON_GEOMETRY_EXTRINSIC_FUSION_H_
#define TILTCAL_COMMON_GEOMETRY_EXTRINSIC_FUSION_H_

// One extrinsic from several sequences' calibrations (docs/design.md §11).
//
// Each sequence i calibrated alone gives x_i = (C_i, r_i[, tau_i]) and its
// covariance P_i in the tangent space at x_i, C = C_i Exp(delta) (right
// perturbation, delta in rad in frame l), then r [m], then tau [s] when the
// clocks are shared. Given the extrinsic, the sequences are independent
// (each has its own trajectory, biases, gravity), so P_i is the Schur
// complement of everything else of sequence i, and the joint problem,
// linearised at the per-sequence optima, is
//
//   min_x  sum_i e_i(x)^T P_i^{-1} e_i(x)  +  e_p(x)^T L_net e_p(x)
//   e_i(x) = (Log(C_i^T C), r - r_i[, tau - tau_i]),  e_p the same against
//   the prior's centre (the rig), L_net = L_p - sum_i L_p,i.
//
// The priors: every P_i contains the prior information L_p,i of its own
// solve (e.g. a prior on r along the motion's rotation axis); the joint
// problem counts a prior once, so L_net removes each sequence's copy and adds
// the prior back once (L_p). Solved by Gauss-Newton on the manifold:
// J_i = blockdiag(Jr^{-1}(e_i,rot), I); the joint covariance is H^{-1}.
//
// Consistency of a sequence with the joint value: d_i = e_i(x_joint), whose
// covariance is P_i - P_joint when x_joint contains x_i (P_i + P_joint when
// it does not); chi^2 = d_i^T D^+ d_i over the directions where D is
// positive (relative eigenvalue floor 1e-9), chi^2 with that many degrees of
// freedom.

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tiltcal::geometry {

// A sequence's estimate; vectors and matrices are 6x6 (rotation,
// translation) or 7x7 (and tau), the same size for every input.
struct ExtrinsicEstimate {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();  // C_bl
  Eigen::VectorXd rest;            // r_b^{lb} [m] (3)[, tau [s]]
  Eigen::MatrixXd covariance;      // P_i
  Eigen::MatrixXd prior_information;  // L_p,i (zero: none), same size
};

// The prior every solve used, counted once in the joint problem.
struct ExtrinsicPrior {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::VectorXd rest;
  Eigen::MatrixXd information;  // L_p (zero: none)
};

struct FusedExtrinsic {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::VectorXd rest;
  Eigen::MatrixXd covariance;  // H^{-1} at the solution
  int iterations = 0;
  bool converged = false;  // |step| below 1e-12 within the iterations
};

// Requires at least one estimate, all of one size (6 or 7), covariances
// positive definite. Starts at the first estimate.
FusedExtrinsic FuseExtrinsics(const std::vector<ExtrinsicEstimate>& estimates,
                              const ExtrinsicPrior& prior, int max_iterations = 20);

// e(x) of an estimate at x: (Log(C_i^T C), rest - rest_i).
Eigen::VectorXd ExtrinsicError(const ExtrinsicEstimate& estimate, const Eigen::Quaterniond& rotation,
                               const Eigen::VectorXd& rest);

struct ExtrinsicConsistency {
  Eigen::VectorXd difference;  // d_i = e_i(x_joint)
  double chi2 = 0.0;
  int dof = 0;
  // The component of d_i with the largest |d_j| / sqrt(D_jj)
  // and that ratio (its z-score).
  int worst_component = 0;
  double worst_z = 0.0;
};
ExtrinsicConsistency TestConsistency(const ExtrinsicEstimate& estimate,
                                     const FusedExtrinsic& fused, bool estimate_in_fused = true);

// Upper quantile of chi^2 with dof degrees of freedom: the x with
// P(chi^2 > x) = p (Wilson-Hilferty; within 1 % for dof >= 3, p >= 1e-4).
double ChiSquareUpperQuantile(int dof, double p);

}  // namespace tiltcal::geometry

#endif  // TILTCAL_COMMON_GEOMETRY_EXTRINSIC_FUSION_H_
