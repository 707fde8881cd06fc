#include "common/spline/spline_trajectory.h"

namespace tiltcal::spline {

SplineTrajectory::SplineTrajectory(const UniformKnotGrid& grid)
    : grid_(grid),
      rotation_knots_(4 * grid.num_knots(), 0.0),
      position_knots_(3 * grid.num_knots(), 0.0) {
  for (int i = 0; i < grid.num_knots(); ++i) rotation_knots_[4 * i + 3] = 1.0;  // w = 1
}

void SplineTrajectory::SetRotationKnot(int i, const Eigen::Quaterniond& q) {
  Eigen::Map<Eigen::Quaterniond> knot(rotation_knot(i));
  knot = q.normalized();
}

void SplineTrajectory::SetPositionKnot(int i, const Eigen::Vector3d& p) {
  Eigen::Map<Eigen::Vector3d> knot(position_knot(i));
  knot = p;
}

Eigen::Quaterniond SplineTrajectory::RotationKnot(int i) const {
  return Eigen::Quaterniond(Eigen::Map<const Eigen::Quaterniond>(rotation_knot(i)));
}

Eigen::Vector3d SplineTrajectory::PositionKnot(int i) const {
  return Eigen::Map<const Eigen::Vector3d>(position_knot(i));
}

void SplineTrajectory::RotationKnots(int first_knot, const double* knots[4]) const {
  for (int j = 0; j < 4; ++j) knots[j] = rotation_knot(first_knot + j);
}

void SplineTrajectory::PositionKnots(int first_knot, const double* knots[4]) const {
  for (int j = 0; j < 4; ++j) knots[j] = position_knot(first_knot + j);
}

bool SplineTrajectory::Evaluate(double t_s, int so3_outputs, So3SplineSample* rotation,
                                R3SplineSample* position) const {
  KnotWindow window;
  if (!grid_.Locate(t_s, &window)) return false;
  const double* knots[4];
  if (rotation != nullptr) {
    RotationKnots(window.first_knot, knots);
    EvaluateSo3Spline(knots, window.u, grid_.inv_dt(), so3_outputs, rotation);
  }
  if (position != nullptr) {
    PositionKnots(window.first_knot, knots);
    EvaluateR3Spline(knots, window.u, grid_.inv_dt(), position);
  }
  return true;
}

}  // namespace tiltcal::spline
