#ifndef TILTCAL_STAGES_CALIBRATE_REPORT_SOLVE_CHECK_H_
#define TILTCAL_STAGES_CALIBRATE_REPORT_SOLVE_CHECK_H_

// Whether a Ceres solve left a usable estimate. A solve that failed outright
// (termination FAILURE, e.g. a residual or Jacobian that does not evaluate)
// or ended on a non-finite cost (an input so large its squared residual
// overflows a double) leaves none: an error naming the termination, the
// final cost and Ceres' message, so that the stage writes no result.

#include <ceres/solver.h>

#include "common/status.h"

namespace tiltcal::calibrate {

Status CheckSolveUsable(const ceres::Solver::Summary& summary);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_REPORT_SOLVE_CHECK_H_
