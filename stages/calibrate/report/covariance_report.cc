#include "stages/calibrate/report/covariance_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCore>

#include "common/geometry/angles.h"
#include "common/linear_algebra/dense_decompositions.h"
#include "stages/calibrate/report/error_correlation.h"
#include "stages/calibrate/report/marginal_covariance.h"
#include "stages/calibrate/report/typed_jacobian.h"

namespace tiltcal::calibrate {

MotionAxis PrincipalRotationAxis(const std::vector<imu::ImuReading>& samples,
                                 const Eigen::Vector3d& gyro_bias_radps) {
  Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
  for (const imu::ImuReading& r : samples) {
    const Eigen::Vector3d w = r.angular_velocity_radps - gyro_bias_radps;
    s += w * w.transpose();
  }
  MotionAxis out;
  if (s.trace() <= 0.0) return out;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(s);
  out.axis_b = eig.eigenvectors().col(2);
  int k = 0;
  out.axis_b.cwiseAbs().maxCoeff(&k);
  if (out.axis_b[k] < 0.0) out.axis_b = -out.axis_b;
  out.fraction = eig.eigenvalues()[2] / s.trace();
  return out;
}

namespace {

// One of the 7 tangent parameters' groups in covariance order.
struct Group {
  double* block;
  int offset;
  int size;
};

// The IMU triad errors when both are free in the problem (12 tangent
// parameters, marginalised last before the 7), else none.
struct IntrinsicsBlocks {
  std::vector<double*> blocks;
  int size = 0;
};

IntrinsicsBlocks FreeIntrinsicsBlocks(ceres::Problem* problem, CalibrationState* state) {
  IntrinsicsBlocks out;
  for (double* b : {state->gyro_triad_errors.data(), state->accel_triad_errors.data()}) {
    if (problem->HasParameterBlock(b) && !problem->IsParameterBlockConstant(b)) {
      out.blocks.push_back(b);
      out.size += problem->ParameterBlockTangentSize(b);
    }
  }
  if (out.size != 12) return IntrinsicsBlocks();
  return out;
}

// The free parameter blocks in elimination order: everything else, then the
// intrinsics, the free groups of the 7 and rho (null: not kept), the last
// `kept` tangent parameters being what the marginal covariance is of.
struct MarginalOrder {
  std::vector<double*> blocks;
  std::vector<const Group*> free_groups;
  int kept = 0;
};

Status OrderForMarginal(ceres::Problem* problem, const Group (&groups)[3],
                        const IntrinsicsBlocks& intrinsics, double* clock_rate,
                        MarginalOrder* order) {
  std::vector<double*> blocks;
  problem->GetParameterBlocks(&blocks);
  std::vector<double*>& ordered = order->blocks;
  for (double* b : blocks) {
    const bool calibration = std::any_of(std::begin(groups), std::end(groups),
                                         [b](const Group& g) { return g.block == b; });
    const bool last = calibration ||
                      std::find(intrinsics.blocks.begin(), intrinsics.blocks.end(), b) !=
                          intrinsics.blocks.end() ||
                      (clock_rate != nullptr && b == clock_rate);
    if (!last && !problem->IsParameterBlockConstant(b)) ordered.push_back(b);
  }
  ordered.insert(ordered.end(), intrinsics.blocks.begin(), intrinsics.blocks.end());
  int k = intrinsics.size;
  for (const Group& g : groups) {
    if (!problem->HasParameterBlock(g.block)) {
      return Status::Error("covariance: the extrinsic / time offset is not in the problem");
    }
    if (problem->IsParameterBlockConstant(g.block)) continue;
    ordered.push_back(g.block);
    order->free_groups.push_back(&g);
    k += g.size;
  }
  if (k == intrinsics.size) {
    return Status::Error("covariance: the extrinsic and time offset are held constant");
  }
  if (clock_rate != nullptr) {
    ordered.push_back(clock_rate);
    ++k;
  }
  order->kept = k;
  return Status::Ok();
}

// The Jacobian of every residual (robust loss applied) in the order's
// columns, each variance group's rows weighted by group_weights (none: 1), and
// the marginal covariance of its last `kept` columns.
Status MarginalOfKept(ceres::Problem* problem, const MarginalOrder& order,
                      const proto::ObservabilityParams& params, int num_threads,
                      const VarianceGroupWeights* group_weights, Eigen::MatrixXd* marginal) {
  TypedJacobian typed;
  const Status evaluated = EvaluateTypedJacobian(problem, order.blocks, num_threads, &typed);
  if (!evaluated.ok()) return Status::Error("covariance: " + evaluated.message());
  if (group_weights != nullptr) {
    for (int r = 0; r < typed.jacobian.outerSize(); ++r) {
      const double scale =
          std::sqrt((*group_weights)[static_cast<size_t>(typed.row_group[static_cast<size_t>(r)])]);
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(typed.jacobian, r); it;
           ++it) {
        it.valueRef() *= scale;
      }
    }
  }
  return MarginalCovarianceOfLastColumns(typed.jacobian, order.kept, params.min_relative_pivot(),
                                         marginal);
}

// The free groups' blocks of the marginal (after the intrinsics' rows) into
// the 7x7; held groups keep zero rows and columns.
void CopyExtrinsicBlocks(const Eigen::MatrixXd& marginal, const MarginalOrder& order,
                         int intrinsics_size, Matrix7d* covariance) {
  int row = intrinsics_size;
  for (const Group* gi : order.free_groups) {
    int col = intrinsics_size;
    for (const Group* gj : order.free_groups) {
      covariance->block(gi->offset, gj->offset, gi->size, gj->size) =
          marginal.block(row, col, gi->size, gj->size);
      col += gj->size;
    }
    row += gi->size;
  }
}

// rho's row (the marginal's last): its covariance with the free groups, then
// its variance.
void CopyClockRateRow(const Eigen::MatrixXd& marginal, const MarginalOrder& order,
                      int intrinsics_size, std::vector<double>* clock_rate_row) {
  const Eigen::Index rate = marginal.rows() - 1;
  clock_rate_row->assign(8, 0.0);
  int col = intrinsics_size;
  for (const Group* g : order.free_groups) {
    for (int j = 0; j < g->size; ++j) {
      (*clock_rate_row)[static_cast<size_t>(g->offset + j)] = marginal(rate, col + j);
    }
    col += g->size;
  }
  (*clock_rate_row)[7] = marginal(rate, rate);
}

}  // namespace

Status ComputeExtrinsicCovariance(ceres::Problem* problem, CalibrationState* state,
                                  const proto::ObservabilityParams& params, int num_threads,
                                  Matrix7d* covariance, Eigen::MatrixXd* intrinsics_covariance,
                                  std::vector<double>* clock_rate_row,
                                  const VarianceGroupWeights* group_weights) {
  covariance->setZero();
  if (clock_rate_row != nullptr) clock_rate_row->clear();
  // rho, marginalised last when asked for and free.
  const bool with_rate = clock_rate_row != nullptr &&
                         problem->HasParameterBlock(state->clock_rate) &&
                         !problem->IsParameterBlockConstant(state->clock_rate);
  if (intrinsics_covariance != nullptr) intrinsics_covariance->resize(0, 0);
  // The triad errors, marginalised last (before the 7) when asked for
  // and free.
  const IntrinsicsBlocks intrinsics = intrinsics_covariance != nullptr
                                          ? FreeIntrinsicsBlocks(problem, state)
                                          : IntrinsicsBlocks();
  // A constant block (e.g. tau with a zero bound) keeps zero rows and
  // columns.
  const Group groups[] = {{state->imu_from_lidar_rotation, 0, 3},
                          {state->imu_from_lidar_translation, 3, 3},
                          {state->time_offset_s, 6, 1}};
  MarginalOrder order;
  TILTCAL_RETURN_IF_ERROR(OrderForMarginal(problem, groups, intrinsics,
                                           with_rate ? state->clock_rate : nullptr, &order));
  Eigen::MatrixXd marginal;
  TILTCAL_RETURN_IF_ERROR(
      MarginalOfKept(problem, order, params, num_threads, group_weights, &marginal));
  if (intrinsics.size > 0) {
    *intrinsics_covariance = marginal.topLeftCorner(intrinsics.size, intrinsics.size);
  }
  CopyExtrinsicBlocks(marginal, order, intrinsics.size, covariance);
  if (with_rate) CopyClockRateRow(marginal, order, intrinsics.size, clock_rate_row);
  return Status::Ok();
}

VarianceFactor ComputeVarianceFactor(ceres::Problem* problem) {
  VarianceFactor out;
  std::vector<double*> blocks;
  problem->GetParameterBlocks(&blocks);
  int64_t free_parameters = 0;
  for (double* b : blocks) {
    if (!problem->IsParameterBlockConstant(b)) free_parameters += problem->ParameterBlockTangentSize(b);
  }
  const int64_t redundancy = problem->NumResiduals() - free_parameters;
  double cost = 0.0;
  ceres::Problem::EvaluateOptions options;
  options.apply_loss_function = true;
  if (redundancy <= 0 || !problem->Evaluate(options, &cost, nullptr, nullptr, nullptr) ||
      !std::isfinite(cost)) {
    return out;
  }
  out.redundancy = redundancy;
  out.sigma0_squared = 2.0 * cost / static_cast<double>(redundancy);
  return out;
}

Status ComputeVarianceGroupComponents(ceres::Problem* problem, const ImuResidualNoise& imu,
                                      const proto::ObservabilityParams& params, int num_threads,
                                      std::vector<VarianceComponent>* components) {
  std::vector<double*> blocks;
  problem->GetParameterBlocks(&blocks);
  const auto held = [problem](double* b) { return problem->IsParameterBlockConstant(b); };
  blocks.erase(std::remove_if(blocks.begin(), blocks.end(), held), blocks.end());
  TypedJacobian typed;
  const Status evaluated = EvaluateTypedJacobian(problem, blocks, num_threads, &typed);
  if (!evaluated.ok()) return Status::Error("variance components: " + evaluated.message());
  std::vector<VarianceComponentGroup> groups(kNumVarianceGroups);
  for (int k = 0; k < kNumVarianceGroups; ++k) {
    VarianceComponentGroup& g = groups[static_cast<size_t>(k)];
    const ResidualType type = TypeOfGroup(static_cast<VarianceGroup>(k));
    g.square_sum = typed.square_sum[static_cast<size_t>(k)];
    g.estimated = type != kOther;
    const bool low_passed_imu =
        (type == kGyro || type == kAccel) && imu.low_pass_correlation > 1.0;
    if ((type == kGround || low_passed_imu) && params.correlation_batches() > 0) {
      g.correlation = PooledBatchMeansCorrelation(typed.residuals, typed.row_group,
                                                  typed.row_component, k,
                                                  params.correlation_batches());
    }
    if (type == kGround) g.floor = 1.0;
    if (low_passed_imu) {
      g.correlation = std::max(g.correlation, imu.low_pass_correlation);
      g.floor = type == kGyro ? imu.gyro_floor : imu.accel_floor;
    }
  }
  return EstimateVarianceComponents(typed.jacobian, typed.row_group, groups,
                                    params.min_relative_pivot(), components);
}

Matrix7d ScaleDataInformation(const Matrix7d& covariance, const Matrix7d& prior_information,
                              double sigma0_squared) {
  return ScaleDataInformation(Eigen::MatrixXd(covariance), Eigen::MatrixXd(prior_information),
                              sigma0_squared);
}

Eigen::MatrixXd ScaleDataInformation(const Eigen::MatrixXd& covariance,
                                     const Eigen::MatrixXd& prior_information,
                                     double sigma0_squared) {
  // Only the estimated parameters: a held one has zero rows and columns.
  const int size = static_cast<int>(covariance.rows());
  std::vector<int> free;
  for (int i = 0; i < size; ++i) {
    if (covariance(i, i) > 0.0) free.push_back(i);
  }
  const int n = static_cast<int>(free.size());
  Eigen::MatrixXd sub_covariance(n, n), sub_prior(n, n);
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) {
      sub_covariance(r, c) = covariance(free[r], free[c]);
      sub_prior(r, c) = prior_information(free[r], free[c]);
    }
  }
  const Eigen::MatrixXd information = linear_algebra::Inverse(sub_covariance);
  const Eigen::MatrixXd scaled = (information - sub_prior) / sigma0_squared + sub_prior;
  const Eigen::MatrixXd sub_out = linear_algebra::Inverse(scaled);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(size, size);
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) out(free[r], free[c]) = 0.5 * (sub_out(r, c) + sub_out(c, r));
  }
  return out;
}

std::string DescribeDirection(const Eigen::Vector3d& v) {
  int k = 0;
  v.cwiseAbs().maxCoeff(&k);
  char buf[96];
  std::snprintf(buf, sizeof(buf), "%c (%.2f, %.2f, %.2f)", "xyz"[k], v.x(), v.y(), v.z());
  return buf;
}

namespace {

// One 3x3 group of the covariance as the observability report names it:
// its offset in the 7, the rotation of its directions into b, the factor to
// the reported unit and the sigma above which a direction is weak.
struct DirectionGroup {
  const char* what;
  const char* unit;
  int offset;
  Eigen::Matrix3d to_b;
  double scale;
  double threshold;
};

// Eigen-directions of a 3x3 covariance block, largest sigma first.
void AddGroup(const Eigen::Matrix3d& cov_block, const DirectionGroup& group,
              const MotionAxis& motion, proto::CalibrationResult* result) {
  const Eigen::Matrix3d& to_b = group.to_b;
  const int offset = group.offset;
  const double scale = group.scale;
  const double threshold = group.threshold;
  const char* what = group.what;
  const char* unit = group.unit;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(0.5 * (cov_block + cov_block.transpose()));
  for (int i = 2; i >= 0; --i) {
    const double sigma = std::sqrt(std::max(0.0, eig.eigenvalues()[i])) * scale;
    Eigen::Vector3d v = eig.eigenvectors().col(i);
    const Eigen::Vector3d v_b = to_b * v;
    const double cos_axis = std::abs(v_b.dot(motion.axis_b));
    proto::ObservabilityDirection* d = result->add_observability();
    for (int j = 0; j < 7; ++j) d->add_direction(0.0);
    for (int j = 0; j < 3; ++j) d->set_direction(offset + j, v[j]);
    d->set_sigma(sigma);
    d->set_weak(sigma > threshold);
    const double angle_deg = geometry::RadToDeg(std::acos(std::min(1.0, cos_axis)));
    char buf[256];
    std::snprintf(buf, sizeof(buf), "%s along b-%s, %.0f deg from the motion's rotation axis%s: "
                  "sigma %.4g %s%s",
                  what, DescribeDirection(v_b).c_str(), angle_deg,
                  angle_deg < 30.0 ? " (along the rotation axis)"
                                   : (angle_deg > 60.0 ? " (in the plane of rotation)" : ""),
                  sigma, unit, sigma > threshold ? " -- WEAK" : "");
    d->set_description(buf);
  }
}

}  // namespace

void FillCovarianceReport(const Matrix7d& covariance, const Eigen::Matrix3d& c_bl,
                          const MotionAxis& motion, const proto::ObservabilityParams& params,
                          proto::CalibrationResult* result) {
  result->clear_covariance();
  for (int i = 0; i < 7; ++i) {
    for (int j = 0; j < 7; ++j) result->add_covariance(covariance(i, j));
  }
  const double rad_to_deg = geometry::kDegPerRad;
  proto::Vector3* rs = result->mutable_rotation_sigma_deg();
  rs->set_x(std::sqrt(std::max(0.0, covariance(0, 0))) * rad_to_deg);
  rs->set_y(std::sqrt(std::max(0.0, covariance(1, 1))) * rad_to_deg);
  rs->set_z(std::sqrt(std::max(0.0, covariance(2, 2))) * rad_to_deg);
  proto::Vector3* ts = result->mutable_translation_sigma_m();
  ts->set_x(std::sqrt(std::max(0.0, covariance(3, 3))));
  ts->set_y(std::sqrt(std::max(0.0, covariance(4, 4))));
  ts->set_z(std::sqrt(std::max(0.0, covariance(5, 5))));
  result->set_time_offset_sigma_s(std::sqrt(std::max(0.0, covariance(6, 6))));

  result->clear_observability();
  // Marginal covariance of each group is the corresponding block.
  AddGroup(covariance.block<3, 3>(0, 0),
           {"rotation", "deg", 0, c_bl, rad_to_deg, params.weak_rotation_sigma_deg()}, motion,
           result);
  AddGroup(covariance.block<3, 3>(3, 3),
           {"translation", "m", 3, Eigen::Matrix3d::Identity(), 1.0,
            params.weak_translation_sigma_m()},
           motion, result);
  const double tau_sigma = std::sqrt(std::max(0.0, covariance(6, 6)));
  proto::ObservabilityDirection* d = result->add_observability();
  for (int j = 0; j < 7; ++j) d->add_direction(j == 6 ? 1.0 : 0.0);
  d->set_sigma(tau_sigma);
  d->set_weak(tau_sigma > params.weak_time_offset_sigma_s());
  char buf[128];
  if (covariance(6, 6) == 0.0) {
    std::snprintf(buf, sizeof(buf), "time offset: held, not estimated (time_offset_bound_s 0)");
  } else {
    std::snprintf(buf, sizeof(buf), "time offset: sigma %.4g s%s", tau_sigma,
                  tau_sigma > params.weak_time_offset_sigma_s() ? " -- WEAK" : "");
  }
  d->set_description(buf);
}

void AddClockRateObservability(const proto::TimeOffsetDriftReport& report,
                               const proto::ObservabilityParams& params,
                               proto::CalibrationResult* result) {
  if (!report.estimated() || report.covariance_row_size() != 8) return;
  proto::ObservabilityDirection* d = result->add_observability();
  for (int j = 0; j < 8; ++j) d->add_direction(j == 7 ? 1.0 : 0.0);
  d->set_sigma(report.rate_sigma_ppm() * 1e-6);
  d->set_weak(report.weak());
  const double span_s = report.end_time_s() - report.start_time_s();
  char buf[256];
  std::snprintf(buf, sizeof(buf),
                "clock rate (tau drift): sigma %.3g ppm (%.3g ms over the scans' %.1f s); tau at "
                "the first / last scan: sigma %.3g / %.3g ms (weak above %.3g ms)%s",
                report.rate_sigma_ppm(), report.rate_sigma_ppm() * 1e-3 * span_s, span_s,
                report.time_offset_start_sigma_s() * 1e3, report.time_offset_end_sigma_s() * 1e3,
                params.weak_time_offset_sigma_s() * 1e3, report.weak() ? " -- WEAK" : "");
  d->set_description(buf);
}

}  // namespace tiltcal::calibrate
