#include "stages/calibrate/report/unit_diagonal.h"

#include <cmath>

namespace tiltcal::calibrate {

int UnitDiagonalScale(const Eigen::SparseMatrix<double>& h, Eigen::VectorXd* scale) {
  const auto n = static_cast<int>(h.cols());
  scale->resize(n);
  for (int c = 0; c < n; ++c) {
    const double d = h.coeff(c, c);
    if (!(d > 0.0)) return c;
    (*scale)[c] = 1.0 / std::sqrt(d);
  }
  return -1;
}

}  // namespace tiltcal::calibrate
