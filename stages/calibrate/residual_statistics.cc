#include "stages/calibrate/residual_statistics.h"

#include <algorithm>
#include <cmath>

#include "stages/calibrate/accel_cost_function.h"
#include "stages/calibrate/ground_cost_functions.h"
#include "stages/calibrate/gyro_cost_function.h"
#include "stages/calibrate/point_to_plane_cost_function.h"

namespace tiltcal::calibrate {
namespace {

enum ResidualType { kGyro = 0, kAccel, kLidar, kGround, kOther };
constexpr const char* kTypeNames[] = {"gyro", "accel", "lidar", "ground"};

ResidualType TypeOf(const ceres::CostFunction* f) {
  if (dynamic_cast<const GyroCostFunction*>(f) != nullptr) return kGyro;
  if (dynamic_cast<const AccelCostFunction*>(f) != nullptr) return kAccel;
  if (dynamic_cast<const PointToPlaneCostFunction*>(f) != nullptr) return kLidar;
  if (dynamic_cast<const FlatGroundCostFunction*>(f) != nullptr ||
      dynamic_cast<const DistanceCostFunction*>(f) != nullptr ||
      dynamic_cast<const InclinationCostFunction*>(f) != nullptr ||
      dynamic_cast<const UpCostFunction*>(f) != nullptr) {
    return kGround;
  }
  return kOther;
}

// 40 bins of 0.25 over [-5, 5): a standard normal fills the middle 24.
constexpr double kHistogramMin = -5.0;
constexpr double kHistogramBinWidth = 0.25;
constexpr int kHistogramBins = 40;

void FillHistogram(const std::vector<double>& values, proto::ResidualStatistics* s) {
  std::vector<int> counts(kHistogramBins, 0);
  int below = 0;
  int above = 0;
  for (const double v : values) {
    const double bin = std::floor((v - kHistogramMin) / kHistogramBinWidth);
    if (bin < 0) {
      ++below;
    } else if (bin >= kHistogramBins) {
      ++above;
    } else {
      ++counts[static_cast<size_t>(bin)];
    }
  }
  s->set_histogram_min(kHistogramMin);
  s->set_histogram_bin_width(kHistogramBinWidth);
  for (const int c : counts) s->add_histogram_counts(c);
  s->set_histogram_below(below);
  s->set_histogram_above(above);
}

}  // namespace

proto::ResidualStatistics SummariseResiduals(const char* type, std::vector<double> values) {
  proto::ResidualStatistics s;
  s.set_type(type);
  s.set_count(static_cast<int>(values.size()));
  if (values.empty()) return s;
  FillHistogram(values, &s);
  double sum_squares = 0.0;
  for (double& v : values) {
    sum_squares += v * v;
    v = std::abs(v);
  }
  s.set_rms(std::sqrt(sum_squares / static_cast<double>(values.size())));
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  s.set_median_abs(*middle);
  return s;
}

std::vector<proto::ResidualStatistics> ComputeResidualStatistics(ceres::Problem* problem) {
  std::vector<ceres::ResidualBlockId> blocks;
  problem->GetResidualBlocks(&blocks);
  std::vector<ceres::ResidualBlockId> by_type[kOther];
  for (ceres::ResidualBlockId id : blocks) {
    const ResidualType type = TypeOf(problem->GetCostFunctionForResidualBlock(id));
    if (type != kOther) by_type[type].push_back(id);
  }
  std::vector<proto::ResidualStatistics> out;
  for (int t = 0; t < kOther; ++t) {
    if (by_type[t].empty()) continue;
    ceres::Problem::EvaluateOptions options;
    options.residual_blocks = by_type[t];
    options.apply_loss_function = false;
    double cost = 0.0;
    std::vector<double> residuals;
    if (!problem->Evaluate(options, &cost, &residuals, nullptr, nullptr)) continue;
    out.push_back(SummariseResiduals(kTypeNames[t], std::move(residuals)));
  }
  return out;
}

}  // namespace tiltcal::calibrate
