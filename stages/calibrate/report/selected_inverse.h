#ifndef TILTCAL_STAGES_CALIBRATE_REPORT_SELECTED_INVERSE_H_
#define TILTCAL_STAGES_CALIBRATE_REPORT_SELECTED_INVERSE_H_

// The entries of H^{-1} on the sparsity pattern of a sparse symmetric
// positive definite H, without forming H^{-1} (Takahashi's recursion).
//
// H is scaled to a unit diagonal (S H S, S = diag(H)^{-1/2}) and factored as
// P S H S P^T = L D L^T (sparse, AMD order). With Z = (P S H S P^T)^{-1} and L
// unit lower triangular, Z = D^{-1} L^{-1} + (I - L^T) Z gives, column j from
// the last to the first, over the rows k > j of L's column j:
//   Z_ij = -sum_k Z_ik L_kj      (i > j, L_ij != 0)
//   Z_jj = 1/d_j - sum_k L_kj Z_kj
// Every Z_ik needed lies on L's pattern (the rows of a column of L form a
// clique in it), which holds H's. The cost is sum_j |L_j|^2: linear in the
// size for a banded H such as a spline's.
// Used for traces tr(H^{-1} B) = sum_ij (H^{-1})_ij B_ij with B's pattern
// inside H's (variance_components.h).
//
// Rank: a pivot of the scaled LDL^T below min_relative_pivot is an error
// (marginal_covariance.h's test).

#include <Eigen/SparseCore>

#include "common/status.h"

namespace tiltcal::calibrate {

// h: both triangles stored. *inverse: the same pattern as h, (H^{-1})_ij.
Status InverseOnPattern(const Eigen::SparseMatrix<double>& h, double min_relative_pivot,
                        Eigen::SparseMatrix<double>* inverse);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_REPORT_SELECTED_INVERSE_H_
