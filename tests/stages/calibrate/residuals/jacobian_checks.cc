#include "tests/stages/calibrate/residuals/jacobian_checks.h"

#include <cmath>

#include <ceres/gradient_checker.h>
#include <ceres/sphere_manifold.h>
#include <gtest/gtest.h>

#include "common/spline/quaternion_manifold.h"

namespace tiltcal::testing {

const ceres::Manifold* ManifoldOf(Block b) {
  static const spline::RightQuaternionManifold quaternion;
  static const ceres::SphereManifold<3> sphere;
  switch (b) {
    case Block::kQuaternion:
      return &quaternion;
    case Block::kSphere:
      return &sphere;
    default:
      return nullptr;
  }
}

void EvaluateAll(const ceres::CostFunction& cost, const std::vector<double*>& params,
                 Eigen::VectorXd* residual, std::vector<RowMajor>* jacobians) {
  const int m = cost.num_residuals();
  const auto& sizes = cost.parameter_block_sizes();
  jacobians->assign(sizes.size(), RowMajor());
  std::vector<double*> ptr(sizes.size());
  for (size_t i = 0; i < sizes.size(); ++i) {
    (*jacobians)[i].setConstant(m, sizes[i], std::nan(""));
    ptr[i] = (*jacobians)[i].data();
  }
  residual->resize(m);
  ASSERT_TRUE(cost.Evaluate(params.data(), residual->data(), ptr.data()));
}

Eigen::MatrixXd Tangent(const RowMajor& ambient, Block b, const double* x) {
  const ceres::Manifold* mf = ManifoldOf(b);
  if (mf == nullptr) return ambient;
  RowMajor plus(mf->AmbientSize(), mf->TangentSize());
  EXPECT_TRUE(mf->PlusJacobian(x, plus.data()));
  return ambient * plus;
}

void ExpectSameTangentJacobians(const ceres::CostFunction& analytic,
                                const ceres::CostFunction& twin,
                                const std::vector<double*>& params,
                                const std::vector<Block>& blocks, double tol,
                                const std::string& label) {
  ASSERT_EQ(analytic.num_residuals(), twin.num_residuals());
  ASSERT_EQ(analytic.parameter_block_sizes(), twin.parameter_block_sizes());
  Eigen::VectorXd ra, rt;
  std::vector<RowMajor> ja, jt;
  EvaluateAll(analytic, params, &ra, &ja);
  EvaluateAll(twin, params, &rt, &jt);
  EXPECT_LT((ra - rt).norm(), 1e-10 * (1.0 + rt.norm())) << label;
  for (size_t i = 0; i < blocks.size(); ++i) {
    ASSERT_TRUE(ja[i].allFinite()) << label << " block " << i << " not written";
    const Eigen::MatrixXd la = Tangent(ja[i], blocks[i], params[i]);
    const Eigen::MatrixXd lt = Tangent(jt[i], blocks[i], params[i]);
    EXPECT_LT((la - lt).norm(), tol * (1.0 + lt.norm()))
        << label << " block " << i << "\nanalytic\n" << la << "\nautodiff\n" << lt;
  }
}

void ExpectTangentDifferencesMatch(const ceres::CostFunction& cost,
                                   const std::vector<double*>& params,
                                   const std::vector<Block>& blocks, const std::string& label) {
  Eigen::VectorXd r0;
  std::vector<RowMajor> jac;
  EvaluateAll(cost, params, &r0, &jac);
  const int m = cost.num_residuals();
  const auto& sizes = cost.parameter_block_sizes();
  for (size_t i = 0; i < blocks.size(); ++i) {
    const ceres::Manifold* mf = ManifoldOf(blocks[i]);
    const int tangent = mf ? mf->TangentSize() : sizes[i];
    const Eigen::MatrixXd analytic = Tangent(jac[i], blocks[i], params[i]);
    const Eigen::VectorXd x0 = Eigen::Map<const Eigen::VectorXd>(params[i], sizes[i]);
    Eigen::MatrixXd numeric(m, tangent);
    const double h = 1e-6;
    for (int k = 0; k < tangent; ++k) {
      Eigen::VectorXd r[2];
      for (int sign = 0; sign < 2; ++sign) {
        Eigen::VectorXd delta = Eigen::VectorXd::Zero(tangent);
        delta[k] = sign == 0 ? h : -h;
        Eigen::Map<Eigen::VectorXd> x(params[i], sizes[i]);
        if (mf != nullptr) {
          Eigen::VectorXd moved(sizes[i]);
          ASSERT_TRUE(mf->Plus(x0.data(), delta.data(), moved.data()));
          x = moved;
        } else {
          x = x0 + delta;
        }
        r[sign].resize(m);
        ASSERT_TRUE(cost.Evaluate(params.data(), r[sign].data(), nullptr));
        x = x0;
      }
      numeric.col(k) = (r[0] - r[1]) / (2 * h);
    }
    const double tol = 1e-6 * (1.0 + numeric.norm()) + 1e-14 * r0.norm() / h;
    EXPECT_LT((analytic - numeric).norm(), tol)
        << label << " block " << i << "\nanalytic\n" << analytic << "\nnumeric\n" << numeric;
  }
}

void ExpectGradientCheckerPasses(const ceres::CostFunction& cost,
                                 const std::vector<double*>& params,
                                 const std::vector<Block>& blocks, const std::string& label) {
  std::vector<const ceres::Manifold*> manifolds;
  for (Block b : blocks) manifolds.push_back(ManifoldOf(b));
  ceres::NumericDiffOptions options;
  ceres::GradientChecker checker(&cost, &manifolds, options);
  ceres::GradientChecker::ProbeResults results;
  checker.Probe(params.data(), 1e-6, &results);
  ASSERT_TRUE(results.return_value) << label;
  for (size_t i = 0; i < blocks.size(); ++i) {
    const ceres::Matrix& user = results.local_jacobians[i];
    const ceres::Matrix& numeric = results.local_numeric_jacobians[i];
    EXPECT_LT((user - numeric).norm(), 1e-6 * (1.0 + numeric.norm()))
        << label << " block " << i << "\nanalytic\n" << user << "\nnumeric\n" << numeric;
  }
}

}  // namespace tiltcal::testing
