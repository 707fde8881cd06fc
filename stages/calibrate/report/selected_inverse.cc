#include "stages/calibrate/report/selected_inverse.h"

#include <algorithm>
#include <string>
#include <vector>

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>

#include "stages/calibrate/report/unit_diagonal.h"

namespace tiltcal::calibrate {
namespace {

// Z on the pattern of L's strict lower triangle plus the diagonal, by
// column; rows ascending.
class PatternInverse {
 public:
  explicit PatternInverse(const Eigen::SparseMatrix<double>& l)
      : diagonal_(l.cols()), rows_(static_cast<size_t>(l.cols())),
        values_(static_cast<size_t>(l.cols())) {
    for (int c = 0; c < l.outerSize(); ++c) {
      for (Eigen::SparseMatrix<double>::InnerIterator it(l, c); it; ++it) {
        if (it.row() > c) rows_[static_cast<size_t>(c)].push_back(static_cast<int>(it.row()));
      }
      std::sort(rows_[static_cast<size_t>(c)].begin(), rows_[static_cast<size_t>(c)].end());
      values_[static_cast<size_t>(c)].assign(rows_[static_cast<size_t>(c)].size(), 0.0);
    }
  }

  // Z_ij, (i, j) on the pattern (either triangle).
  double& At(int i, int j) {
    if (i == j) return diagonal_[i];
    const int row = std::max(i, j);
    const auto col = static_cast<size_t>(std::min(i, j));
    const std::vector<int>& rows = rows_[col];
    const auto it = std::lower_bound(rows.begin(), rows.end(), row);
    return values_[col][static_cast<size_t>(it - rows.begin())];
  }

  const std::vector<int>& Rows(int j) const { return rows_[static_cast<size_t>(j)]; }

 private:
  Eigen::VectorXd diagonal_;
  std::vector<std::vector<int>> rows_;
  std::vector<std::vector<double>> values_;
};

}  // namespace

Status InverseOnPattern(const Eigen::SparseMatrix<double>& h, double min_relative_pivot,
                        Eigen::SparseMatrix<double>* inverse) {
  const int n = static_cast<int>(h.cols());
  Eigen::VectorXd scale;
  if (const int c = UnitDiagonalScale(h, &scale); c >= 0) {
    return Status::Error("selected inverse: parameter " + std::to_string(c) + " of " +
                         std::to_string(n) + " has no information");
  }
  const Eigen::SparseMatrix<double> scaled = scale.asDiagonal() * h * scale.asDiagonal();
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt(
      scaled);
  if (ldlt.info() != Eigen::Success) {
    return Status::Error("selected inverse: rank deficient (the factorisation met a zero pivot)");
  }
  const Eigen::VectorXd d = ldlt.vectorD();
  if (n > 0 && !(d.minCoeff() > min_relative_pivot)) {
    return Status::Error("selected inverse: rank deficient (a pivot of " +
                         std::to_string(d.minCoeff()) + " of the unit-diagonal matrix)");
  }
  const Eigen::SparseMatrix<double> l = ldlt.matrixL().nestedExpression();
  PatternInverse z(l);
  std::vector<double> l_column;
  for (int j = n - 1; j >= 0; --j) {
    const std::vector<int>& rows = z.Rows(j);
    l_column.assign(rows.size(), 0.0);
    for (Eigen::SparseMatrix<double>::InnerIterator it(l, j); it; ++it) {
      if (it.row() <= j) continue;
      const auto a = std::lower_bound(rows.begin(), rows.end(), it.row()) - rows.begin();
      l_column[static_cast<size_t>(a)] = it.value();
    }
    for (size_t a_i = 0; a_i < rows.size(); ++a_i) {
      double sum = 0.0;
      for (size_t b = 0; b < rows.size(); ++b) sum += z.At(rows[a_i], rows[b]) * l_column[b];
      z.At(rows[a_i], j) = -sum;
    }
    double diagonal = 1.0 / d[j];
    for (size_t b = 0; b < rows.size(); ++b) diagonal -= l_column[b] * z.At(rows[b], j);
    z.At(j, j) = diagonal;
  }
  // Back to H's order and units: H^{-1} = S P^T Z P S.
  const Eigen::VectorXi& perm = ldlt.permutationP().indices();
  *inverse = h;
  for (int c = 0; c < inverse->outerSize(); ++c) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(*inverse, c); it; ++it) {
      const auto r = static_cast<int>(it.row());
      it.valueRef() = z.At(perm[r], perm[c]) * scale[r] * scale[c];
    }
  }
  return Status::Ok();
}

}  // namespace tiltcal::calibrate
