#include "stages/calibrate/report/variance_components.h"

#include <algorithm>

#include "stages/calibrate/report/selected_inverse.h"

namespace tiltcal::calibrate {

Status EstimateVarianceComponents(const Eigen::SparseMatrix<double, Eigen::RowMajor>& jacobian,
                                  const std::vector<int>& row_group,
                                  const std::vector<VarianceComponentGroup>& groups,
                                  double min_relative_pivot,
                                  std::vector<VarianceComponent>* components) {
  const size_t num_groups = groups.size();
  if (row_group.size() != static_cast<size_t>(jacobian.rows())) {
    return Status::Error("variance components: one group per row expected");
  }
  components->assign(num_groups, VarianceComponent());
  // J_k: J with the other groups' rows zero; its normal matrix J_k^T J_k.
  std::vector<Eigen::SparseMatrix<double>> normal(num_groups);
  for (size_t k = 0; k < num_groups; ++k) {
    Eigen::SparseMatrix<double, Eigen::RowMajor> j_k = jacobian;
    for (int r = 0; r < j_k.outerSize(); ++r) {
      const int g = row_group[static_cast<size_t>(r)];
      if (g < 0 || static_cast<size_t>(g) >= num_groups) {
        return Status::Error("variance components: a row's group is out of range");
      }
      if (static_cast<size_t>(g) == k) {
        ++(*components)[k].rows;
        continue;
      }
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(j_k, r); it; ++it) {
        it.valueRef() = 0.0;
      }
    }
    j_k.prune(0.0);
    const Eigen::SparseMatrix<double> j_k_columns = j_k;
    normal[k] = j_k_columns.transpose() * j_k_columns;
  }
  Eigen::SparseMatrix<double> h(jacobian.cols(), jacobian.cols());
  for (const Eigen::SparseMatrix<double>& n_k : normal) h += n_k;
  Eigen::SparseMatrix<double> inverse;
  TILTCAL_RETURN_IF_ERROR(InverseOnPattern(h, min_relative_pivot, &inverse));
  for (size_t k = 0; k < num_groups; ++k) {
    VarianceComponent& c = (*components)[k];
    c.redundancy = static_cast<double>(c.rows) - inverse.cwiseProduct(normal[k]).sum();
    if (!groups[k].estimated || !(c.redundancy > 0.0) || !(groups[k].square_sum > 0.0)) continue;
    c.sigma0_squared = groups[k].square_sum / c.redundancy;
    c.correlation = std::max(1.0, groups[k].correlation);
    c.floor = groups[k].floor;
    const double inflation = c.sigma0_squared * c.correlation;
    c.weight = 1.0 / std::max(groups[k].floor, inflation);
  }
  return Status::Ok();
}

}  // namespace tiltcal::calibrate
