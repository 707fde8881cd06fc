#include "common/spline/knot_grid.h"

#include <algorithm>
#include <cmath>

namespace tiltcal::spline {

UniformKnotGrid::UniformKnotGrid(double t0_s, double dt_s, int num_knots)
    : t0_s_(t0_s), dt_s_(dt_s), inv_dt_(1.0 / dt_s), num_knots_(num_knots) {}

int UniformKnotGrid::NumKnotsForDuration(double duration_s, double dt_s) {
  // The 1e-9 guards against T/dt landing just above an integer by rounding
  // (2.0 / 0.1 = 20.000000000000004).
  const int segments = static_cast<int>(std::ceil(duration_s / dt_s - 1e-9));
  return std::max(segments, 1) + 3;
}

UniformKnotGrid UniformKnotGrid::ForDuration(double t0_s, double duration_s, double dt_s) {
  return UniformKnotGrid(t0_s, dt_s, NumKnotsForDuration(duration_s, dt_s));
}

bool UniformKnotGrid::Locate(double t_s, KnotWindow* window) const {
  const double x = (t_s - t0_s_) * inv_dt_;
  if (!(x >= 0.0) || x > static_cast<double>(num_segments())) return false;
  const int s = std::min(static_cast<int>(std::floor(x)), num_segments() - 1);
  window->first_knot = s;
  window->u = x - s;
  return true;
}

}  // namespace tiltcal::spline
