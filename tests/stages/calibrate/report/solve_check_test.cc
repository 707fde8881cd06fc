// The failed-solve path of the calibrator (solve_check.h) on real Ceres
// solves: one whose cost overflows a double (a measurement of 1e300 makes
// the squared residual infinite, as one accelerometer sample of 1e300 in a
// recording would) and one whose residual cannot be evaluated must be
// errors; a solve that converges must not.

#include <string>

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include "stages/calibrate/report/solve_check.h"

namespace tiltcal::calibrate {
namespace {

// r = x - measurement; evaluable = false makes the evaluation fail.
struct Residual {
  template <typename T>
  bool operator()(const T* x, T* r) const {
    r[0] = x[0] - T(measurement);
    return evaluable;
  }
  double measurement;
  bool evaluable;
};

ceres::Solver::Summary Solve(double measurement, bool evaluable) {
  double x = 1.0;
  ceres::Problem problem;
  problem.AddResidualBlock(
      new ceres::AutoDiffCostFunction<Residual, 1, 1>(new Residual{measurement, evaluable}),
      nullptr, &x);
  ceres::Solver::Options options;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  return summary;
}

TEST(SolveCheckTest, ConvergedSolveIsUsable) {
  const ceres::Solver::Summary summary = Solve(3.0, true);
  ASSERT_EQ(summary.termination_type, ceres::CONVERGENCE) << summary.FullReport();
  EXPECT_TRUE(CheckSolveUsable(summary).ok());
}

TEST(SolveCheckTest, CostOverflowingADoubleIsAnError) {
  const ceres::Solver::Summary summary = Solve(1e300, true);
  const Status status = CheckSolveUsable(summary);
  ASSERT_FALSE(status.ok()) << summary.FullReport();
  EXPECT_EQ(status.message().rfind("the solve failed (termination ", 0), 0u) << status.message();
  EXPECT_EQ(status.message().find('\n'), std::string::npos) << status.message();
}

TEST(SolveCheckTest, ResidualThatDoesNotEvaluateIsAnError) {
  const ceres::Solver::Summary summary = Solve(3.0, false);
  EXPECT_EQ(summary.termination_type, ceres::FAILURE) << summary.FullReport();
  const Status status = CheckSolveUsable(summary);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("FAILURE"), std::string::npos) << status.message();
}

}  // namespace
}  // namespace tiltcal::calibrate
