#ifndef TILTCAL_STAGES_CALIBRATE_REPORT_UNIT_DIAGONAL_H_
#define TILTCAL_STAGES_CALIBRATE_REPORT_UNIT_DIAGONAL_H_

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace tiltcal::calibrate {

// The scaling S = diag(H)^{-1/2} of a symmetric information matrix H, so
// that S H S has a unit diagonal (each parameter in units of its own
// conditional sigma): the pivots of its factorisation are then relative
// and comparable with one threshold. Returns the index of the first column
// whose diagonal entry is not > 0 (a parameter without information), or -1
// with `scale` filled.
int UnitDiagonalScale(const Eigen::SparseMatrix<double>& h, Eigen::VectorXd* scale);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_REPORT_UNIT_DIAGONAL_H_
