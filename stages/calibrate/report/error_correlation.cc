#include "stages/calibrate/report/error_correlation.h"

#include <map>

namespace tiltcal::calibrate {

BatchMeansVariances BatchMeans(const std::vector<double>& series, int num_batches) {
  BatchMeansVariances out;
  if (num_batches < 2) return out;
  const size_t b = static_cast<size_t>(num_batches);
  const size_t length = series.size() / b;
  if (length < 2) return out;
  const size_t used = b * length;
  double mean = 0.0;
  for (size_t n = 0; n < used; ++n) mean += series[n];
  mean /= static_cast<double>(used);
  double values = 0.0;
  double batch_means = 0.0;
  for (size_t i = 0; i < b; ++i) {
    double batch_sum = 0.0;
    for (size_t n = i * length; n < (i + 1) * length; ++n) {
      const double d = series[n] - mean;
      values += d * d;
      batch_sum += d;
    }
    const double batch_mean = batch_sum / static_cast<double>(length);
    batch_means += batch_mean * batch_mean;
  }
  out.batch_means = static_cast<double>(length) * batch_means / static_cast<double>(b - 1);
  out.values = values / static_cast<double>(used - 1);
  return out;
}

double PooledBatchMeansCorrelation(const Eigen::VectorXd& residuals,
                                   const std::vector<int>& row_group,
                                   const std::vector<int>& row_component, int group,
                                   int num_batches) {
  std::map<int, std::vector<double>> series;
  for (size_t r = 0; r < row_group.size(); ++r) {
    if (row_group[r] != group) continue;
    series[row_component[r]].push_back(residuals[static_cast<Eigen::Index>(r)]);
  }
  double batch_means = 0.0;
  double values = 0.0;
  for (const auto& [component, values_of_component] : series) {
    const BatchMeansVariances v = BatchMeans(values_of_component, num_batches);
    batch_means += v.batch_means;
    values += v.values;
  }
  return values > 0.0 ? batch_means / values : 1.0;
}

}  // namespace tiltcal::calibrate
