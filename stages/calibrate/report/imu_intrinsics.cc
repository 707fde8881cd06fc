#include "stages/calibrate/report/imu_intrinsics.h"

#include <cmath>

#include <ceres/crs_matrix.h>

#include "common/geometry/angles.h"
#include "common/imu/triad_errors.h"
#include "common/io/eigen_proto.h"
#include "common/linear_algebra/dense_decompositions.h"
#include "stages/calibrate/report/covariance_report.h"

namespace tiltcal::calibrate {
namespace {

using geometry::kDegPerRad;

// Row-major indices of the 3 x 3 entries; the upper triangles (1, 2, 5)
// are held by the problem's manifold.
const std::vector<int> kGyroEntries = {0, 3, 4, 6, 7, 8};
const std::vector<int> kAccelEntries = {0, 3, 4, 6, 7, 8};

std::string IntrinsicEntryName(const char* triad, int entry) {
  static const char* const kAxis[] = {"x", "y", "z"};
  const int row = entry / 3;
  const int col = entry % 3;
  if (row == col) return std::string(triad) + " " + kAxis[row] + " scale";
  return std::string(triad) + " " + kAxis[row] + " axis towards " + kAxis[col];
}

}  // namespace

const std::vector<int>& GyroErrorEntries() { return kGyroEntries; }
const std::vector<int>& AccelErrorEntries() { return kAccelEntries; }

double IntrinsicPriorSigma(int row, int col, const proto::ImuIntrinsicsParams& params) {
  return row == col ? params.scale_prior_ppm() * 1e-6
                    : params.misalignment_prior_deg() / kDegPerRad;
}

Status ScoreTestImuIntrinsics(ceres::Problem* problem, CalibrationState* state,
                              const proto::ImuIntrinsicsParams& params, int num_threads,
                              ImuIntrinsicsScore* score) {
  *score = ImuIntrinsicsScore();
  double* const gyro = state->gyro_triad_errors.data();
  double* const accel = state->accel_triad_errors.data();
  for (double* k : {gyro, accel}) {
    if (!problem->HasParameterBlock(k) || !problem->IsParameterBlockConstant(k)) {
      return Status::Error("IMU intrinsics score test: the triad errors must be held");
    }
  }
  score->sigma0_squared = std::max(ComputeVarianceFactor(problem).sigma0_squared, 1e-12);

  ceres::Problem::EvaluateOptions options;
  options.parameter_blocks = {gyro, accel};
  for (double* k : {gyro, accel}) {
    std::vector<ceres::ResidualBlockId> users;
    problem->GetResidualBlocksForParameterBlock(k, &users);
    options.residual_blocks.insert(options.residual_blocks.end(), users.begin(), users.end());
  }
  options.apply_loss_function = true;
  options.num_threads = std::max(1, num_threads);
  std::vector<double> gradient;
  ceres::CRSMatrix jacobian;
  problem->SetParameterBlockVariable(gyro);
  problem->SetParameterBlockVariable(accel);
  const bool evaluated = !options.residual_blocks.empty() &&
                         problem->Evaluate(options, nullptr, nullptr, &gradient, &jacobian);
  problem->SetParameterBlockConstant(gyro);
  problem->SetParameterBlockConstant(accel);
  const int n = static_cast<int>(kGyroEntries.size() + kAccelEntries.size());
  if (!evaluated || jacobian.num_cols != n || static_cast<int>(gradient.size()) != n) {
    return Status::Error("IMU intrinsics score test: the IMU residuals could not be evaluated");
  }

  // H = J^T J + P over the free entries.
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(n, n);
  for (int row = 0; row < jacobian.num_rows; ++row) {
    for (int a = jacobian.rows[row]; a < jacobian.rows[row + 1]; ++a) {
      for (int b = jacobian.rows[row]; b < jacobian.rows[row + 1]; ++b) {
        h(jacobian.cols[a], jacobian.cols[b]) += jacobian.values[a] * jacobian.values[b];
      }
    }
  }
  int column = 0;
  for (const std::vector<int>* entries : {&kGyroEntries, &kAccelEntries}) {
    for (int entry : *entries) {
      const double sigma = IntrinsicPriorSigma(entry / 3, entry % 3, params);
      h(column, column) += 1.0 / (sigma * sigma);
      ++column;
    }
  }
  const Eigen::Map<const Eigen::VectorXd> g(gradient.data(), n);
  bool factorised = false;
  const Eigen::VectorXd step = -linear_algebra::SolveByLdlt(h, g, &factorised);
  if (!factorised) {
    return Status::Error("IMU intrinsics score test: the information is not positive");
  }
  score->chi2 = -g.dot(step) / score->sigma0_squared;
  score->dof = n;
  column = 0;
  for (int entry : kGyroEntries) score->gyro_triad_errors[entry] = step[column++];
  for (int entry : kAccelEntries) score->accel_triad_errors[entry] = step[column++];
  return Status::Ok();
}

proto::ImuTriadEstimate DescribeTriad(const std::array<double, 9>& errors,
                                      const std::vector<int>& free,
                                      const Eigen::MatrixXd& covariance) {
  const Eigen::Matrix3d t = Eigen::Matrix3d::Identity() + imu::TriadErrorsMatrix(errors.data());
  Eigen::Matrix3d sigma = Eigen::Matrix3d::Zero();
  if (covariance.rows() == static_cast<int>(free.size())) {
    for (int i = 0; i < static_cast<int>(free.size()); ++i) {
      sigma(free[i] / 3, free[i] % 3) = std::sqrt(std::max(covariance(i, i), 0.0));
    }
  }
  proto::ImuTriadEstimate out;
  *out.mutable_scale_ppm() = ToProto(Eigen::Vector3d((t.diagonal().array() - 1.0) * 1e6));
  *out.mutable_scale_sigma_ppm() = ToProto(Eigen::Vector3d(sigma.diagonal() * 1e6));
  *out.mutable_misalignment_deg() =
      ToProto(Eigen::Vector3d(t(1, 0), t(2, 0), t(2, 1)) * kDegPerRad);
  *out.mutable_misalignment_sigma_deg() =
      ToProto(Eigen::Vector3d(sigma(1, 0), sigma(2, 0), sigma(2, 1)) * kDegPerRad);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      out.add_measured_from_true(t(i, j));
      out.add_measured_from_true_sigma(sigma(i, j));
    }
  }
  return out;
}

std::vector<std::string> UndeterminedIntrinsics(const Eigen::MatrixXd& covariance,
                                                const proto::ImuIntrinsicsParams& params) {
  std::vector<std::string> out;
  const int n = static_cast<int>(kGyroEntries.size() + kAccelEntries.size());
  if (covariance.rows() != n) return out;
  int column = 0;
  for (const auto& [triad, entries] :
       {std::pair{"gyroscope", &kGyroEntries}, std::pair{"accelerometer", &kAccelEntries}}) {
    for (int entry : *entries) {
      const double prior = IntrinsicPriorSigma(entry / 3, entry % 3, params);
      const double sigma = std::sqrt(std::max(covariance(column, column), 0.0));
      if (sigma > params.undetermined_sigma_fraction() * prior) {
        out.push_back(IntrinsicEntryName(triad, entry));
      }
      ++column;
    }
  }
  return out;
}

}  // namespace tiltcal::calibrate
