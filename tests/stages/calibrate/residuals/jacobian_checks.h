#ifndef TILTCAL_TESTS_STAGES_CALIBRATE_RESIDUALS_JACOBIAN_CHECKS_H_
#define TILTCAL_TESTS_STAGES_CALIBRATE_RESIDUALS_JACOBIAN_CHECKS_H_

// Checks of the calibrator's analytic cost functions, shared by the spline
// and ground residual tests. Parameter blocks are quaternions on
// spline::RightQuaternionManifold, unit vectors on ceres::SphereManifold<3>
// or Euclidean; Jacobians are compared in the tangent space (ambient
// Jacobian times the manifold's PlusJacobian).

#include <string>
#include <vector>

#include <ceres/cost_function.h>
#include <ceres/manifold.h>

#include <Eigen/Core>

namespace tiltcal::testing {

enum class Block { kQuaternion, kSphere, kEuclidean };

// The manifold of a block kind (nullptr: Euclidean).
const ceres::Manifold* ManifoldOf(Block b);

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Residuals and ambient Jacobians (m x size each, NaN where not written).
void EvaluateAll(const ceres::CostFunction& cost, const std::vector<double*>& params,
                 Eigen::VectorXd* residual, std::vector<RowMajor>* jacobians);

// Tangent Jacobian = ambient Jacobian * PlusJacobian.
Eigen::MatrixXd Tangent(const RowMajor& ambient, Block b, const double* x);

// Analytic vs autodiff twin: residuals (1e-10 relative) and every tangent
// Jacobian block (tol relative), all blocks written.
void ExpectSameTangentJacobians(const ceres::CostFunction& analytic,
                                const ceres::CostFunction& twin,
                                const std::vector<double*>& params,
                                const std::vector<Block>& blocks, double tol,
                                const std::string& label);

// Central differences (h = 1e-6) through each block's manifold Plus;
// tolerance: truncation O(h^2) plus rounding ~ eps |r| / h.
void ExpectTangentDifferencesMatch(const ceres::CostFunction& cost,
                                   const std::vector<double*>& params,
                                   const std::vector<Block>& blocks, const std::string& label);

// ceres::GradientChecker, judged block-wise in the Frobenius norm (its own
// verdict is entry-wise relative and flags numeric noise on exact zeros).
// Not for size-1 blocks: Ceres 2.1.0's numeric Jacobian of a size-1 block is
// wrong.
void ExpectGradientCheckerPasses(const ceres::CostFunction& cost,
                                 const std::vector<double*>& params,
                                 const std::vector<Block>& blocks, const std::string& label);

}  // namespace tiltcal::testing

#endif  // TILTCAL_TESTS_STAGES_CALIBRATE_RESIDUALS_JACOBIAN_CHECKS_H_
