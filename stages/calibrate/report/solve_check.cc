#include "stages/calibrate/report/solve_check.h"

#include <cmath>

#include <fmt/format.h>

namespace tiltcal::calibrate {

Status CheckSolveUsable(const ceres::Solver::Summary& summary) {
  if (summary.termination_type == ceres::FAILURE || !std::isfinite(summary.final_cost)) {
    return Status::Error(fmt::format("the solve failed (termination {}, final cost {}): {}",
                                     ceres::TerminationTypeToString(summary.termination_type),
                                     summary.final_cost, summary.message));
  }
  return Status::Ok();
}

}  // namespace tiltcal::calibrate
