#ifndef TILTCAL_COMMON_SPLINE_SPLINE_TRAJECTORY_H_
#define TILTCAL_COMMON_SPLINE_SPLINE_TRAJECTORY_H_

// The IMU trajectory of the calibrator: C_ab(t) as a cumulative cubic SO(3)
// B-spline and r_a^{ba}(t) as a cubic R^3 B-spline on the same uniform knot
// grid (split representation, docs/design.md §6). Owns the knot storage that the
// optimiser uses as parameter blocks:
//   rotation knot i: 4 doubles (x, y, z, w), a unit quaternion, at rotation_knot(i);
//   position knot i: 3 doubles (m), at position_knot(i).
// Knots start at identity / zero.

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/spline/knot_grid.h"
#include "common/spline/r3_spline.h"
#include "common/spline/so3_spline.h"

namespace tiltcal::spline {

class SplineTrajectory {
 public:
  explicit SplineTrajectory(const UniformKnotGrid& grid);

  const UniformKnotGrid& grid() const { return grid_; }
  int num_knots() const { return grid_.num_knots(); }

  double* rotation_knot(int i) { return &rotation_knots_[4 * i]; }
  const double* rotation_knot(int i) const { return &rotation_knots_[4 * i]; }
  double* position_knot(int i) { return &position_knots_[3 * i]; }
  const double* position_knot(int i) const { return &position_knots_[3 * i]; }

  void SetRotationKnot(int i, const Eigen::Quaterniond& q);
  void SetPositionKnot(int i, const Eigen::Vector3d& p);
  Eigen::Quaterniond RotationKnot(int i) const;
  Eigen::Vector3d PositionKnot(int i) const;

  // Pointers to the 4 active knots of a window.
  void RotationKnots(int first_knot, const double* knots[4]) const;
  void PositionKnots(int first_knot, const double* knots[4]) const;

  // Evaluates at time t_s (seconds, same clock as the grid). Returns false
  // when t_s is outside the grid. rotation and/or position may be null;
  // so3_outputs is an OR of So3SplineOutput.
  bool Evaluate(double t_s, int so3_outputs, So3SplineSample* rotation,
                R3SplineSample* position) const;

 private:
  UniformKnotGrid grid_;
  std::vector<double> rotation_knots_;
  std::vector<double> position_knots_;
};

}  // namespace tiltcal::spline

#endif  // TILTCAL_COMMON_SPLINE_SPLINE_TRAJECTORY_H_
