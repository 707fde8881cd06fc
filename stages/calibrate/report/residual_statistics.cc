#include "stages/calibrate/report/residual_statistics.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include "stages/calibrate/report/residual_type.h"
#include "stages/calibrate/residuals/stacked_cost_function.h"

namespace tiltcal::calibrate {
namespace {

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

// The rank-ceil(q n) value of `sorted` (nearest rank, q in (0, 1]).
double NearestRank(const std::vector<double>& sorted, double q) {
  const size_t rank = static_cast<size_t>(std::ceil(q * static_cast<double>(sorted.size())));
  return sorted[std::clamp<size_t>(rank, 1, sorted.size()) - 1];
}

// The time of a residual block: the middle of the spline segment of its
// first parameter block when that is a rotation knot; false otherwise.
bool BlockTime(ceres::Problem* problem, ceres::ResidualBlockId id, const CalibrationState& state,
               double* time_s) {
  std::vector<double*> blocks;
  problem->GetParameterBlocksForResidualBlock(id, &blocks);
  const auto& trajectory = state.trajectory;
  const double* first = trajectory.rotation_knot(0);
  const double* last = trajectory.rotation_knot(trajectory.num_knots() - 1);
  const std::less<const double*> before;
  if (blocks.empty() || before(blocks.front(), first) || before(last, blocks.front())) return false;
  const auto knot = static_cast<double>((blocks.front() - first) / 4);
  *time_s = trajectory.grid().t0_s() + (knot + 0.5) * trajectory.grid().dt_s();
  return true;
}

}  // namespace

void FillTimeSeries(const std::vector<TimedResidual>& values, double start_s, double end_s,
                    int bins, proto::ResidualStatistics* s) {
  bins = std::max(1, bins);
  const double width = (end_s - start_s) / bins;
  std::vector<std::vector<double>> by_bin(static_cast<size_t>(bins));
  for (const TimedResidual& v : values) {
    const double bin = width > 0 ? std::floor((v.time_s - start_s) / width) : 0.0;
    by_bin[static_cast<size_t>(std::clamp(bin, 0.0, bins - 1.0))].push_back(v.value);
  }
  s->set_time_start_s(start_s);
  s->set_time_bin_s(width);
  for (std::vector<double>& bin : by_bin) {
    s->add_time_bin_count(static_cast<int>(bin.size()));
    if (bin.empty()) {
      for (auto* field : {s->mutable_time_bin_rms(), s->mutable_time_bin_p05(),
                          s->mutable_time_bin_median(), s->mutable_time_bin_p95()}) {
        field->Add(0.0f);
      }
      continue;
    }
    double sum_squares = 0.0;
    for (const double v : bin) sum_squares += v * v;
    std::sort(bin.begin(), bin.end());
    s->add_time_bin_rms(static_cast<float>(std::sqrt(sum_squares / bin.size())));
    s->add_time_bin_p05(static_cast<float>(NearestRank(bin, 0.05)));
    s->add_time_bin_median(static_cast<float>(NearestRank(bin, 0.5)));
    s->add_time_bin_p95(static_cast<float>(NearestRank(bin, 0.95)));
  }
}

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

std::vector<proto::ResidualStatistics> ComputeResidualStatistics(
    ceres::Problem* problem, const CalibrationState& state,
    const proto::ResidualTimeSeriesParams& params) {
  const spline::UniformKnotGrid& grid = state.trajectory.grid();
  const double start_s = grid.t0_s();
  const double end_s = grid.t0_s() + grid.num_segments() * grid.dt_s();
  std::vector<ceres::ResidualBlockId> blocks;
  problem->GetResidualBlocks(&blocks);
  std::vector<ceres::ResidualBlockId> by_type[kOther];
  for (ceres::ResidualBlockId id : blocks) {
    const ResidualType type = TypeOf(problem->GetCostFunctionForResidualBlock(id));
    if (type != kOther) by_type[type].push_back(id);
  }
  std::vector<proto::ResidualStatistics> out;
  std::vector<double*> parameters;
  std::vector<double> block_residuals;
  for (int t = 0; t < kOther; ++t) {
    if (by_type[t].empty()) continue;
    // The rows' own residuals, without a loss (a stacked block folds its
    // loss into what Ceres sees).
    std::vector<double> residuals;
    std::vector<TimedResidual> timed;
    for (ceres::ResidualBlockId id : by_type[t]) {
      const ceres::CostFunction* cost = problem->GetCostFunctionForResidualBlock(id);
      problem->GetParameterBlocksForResidualBlock(id, &parameters);
      block_residuals.resize(static_cast<size_t>(cost->num_residuals()));
      const auto* stacked = dynamic_cast<const StackedCostFunction*>(cost);
      const bool ok = stacked != nullptr
                          ? stacked->EvaluateRows(parameters.data(), block_residuals.data())
                          : cost->Evaluate(parameters.data(), block_residuals.data(), nullptr);
      if (!ok) continue;
      residuals.insert(residuals.end(), block_residuals.begin(), block_residuals.end());
      double time_s = 0.0;
      if (BlockTime(problem, id, state, &time_s)) {
        for (const double r : block_residuals) timed.push_back({time_s, r});
      }
    }
    proto::ResidualStatistics s =
        SummariseResiduals(ResidualTypeName(static_cast<ResidualType>(t)), std::move(residuals));
    FillTimeSeries(timed, start_s, end_s, static_cast<int>(params.bins()), &s);
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace tiltcal::calibrate
