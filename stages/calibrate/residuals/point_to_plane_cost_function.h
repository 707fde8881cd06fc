#ifndef TILTCAL_STAGES_CALIBRATE_RESIDUALS_POINT_TO_PLANE_COST_FUNCTION_H_
#define TILTCAL_STAGES_CALIBRATE_RESIDUALS_POINT_TO_PLANE_COST_FUNCTION_H_

// LiDAR point-to-plane residual (docs/design.md §7). A point p_l (LiDAR frame, m)
// measured at LiDAR time t_j is mapped to the world frame a at IMU time
// t = t_j + tau:
//   p_a = C_ab(t) (C_bl p_l + r_b^{lb}) + r_a^{ba}(t)
//   r   = (n_pi^T p_a + d_pi) / sigma          (1, dimensionless)
// against a plane (n_pi unit, d_pi in m) of the map in frame a, held fixed.
//
// Parameter blocks, in order:
//   0..3  rotation knots s..s+3: unit quaternions, 4 doubles (x, y, z, w),
//         spline::RightQuaternionManifold (right perturbation);
//   4..7  position knots s..s+3: 3 doubles each, m;
//   8     C_bl: unit quaternion, 4 doubles (x, y, z, w), RightQuaternionManifold;
//   9     r_b^{lb}: 3 doubles, m;
//   10    tau: 1 double, s (t_imu = t_lidar + tau).
//
// Time offset and the knot window: the window (segment s) is FROZEN at
// construction, chosen by the problem builder from the current tau
// (UniformKnotGrid::Locate(t_j + tau)). Inside Evaluate
//   u = (t_j + tau - t_s) / dt,   t_s = start of segment s,
// and u may leave [0, 1): the segment's cubic polynomial is then extended.
// At the segment boundary the extension matches the true spline in value and
// first two derivatives; it departs from it by O(|du|^3) (times the jump of
// the third derivative). The builder therefore (a) bounds tau
// (CalibrateParams.time_offset_bound_s, a small fraction of dt around the
// value used for binning) and (b) re-bins every point (recomputes s and u)
// at each outer association iteration. No padding knots: the block stays at
// 4 + 4 knots. dr/dtau = n^T (C (omega x x) + r'_a) / sigma with x = C_bl p_l + r_b.
//
// Analytic Jacobians; the Cauchy loss is applied by the problem builder.

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

namespace tiltcal::calibrate {

class PointToPlaneCostFunction final
    : public ceres::SizedCostFunction<1, 4, 4, 4, 4, 3, 3, 3, 3, 4, 3, 1> {
 public:
  // segment_start_s: t0 + s dt of the frozen window (same clock as point_time_s,
  // seconds from the sequence start); point_time_s: t_j on the LiDAR clock.
  PointToPlaneCostFunction(double segment_start_s, double inv_dt, double point_time_s,
                           const Eigen::Vector3d& point_lidar_m,
                           const Eigen::Vector3d& plane_normal_world, double plane_offset_m,
                           double sigma_m);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  // Normalised time u for a given tau (for tests and for re-binning checks).
  double NormalizedTime(double tau_s) const { return (time_in_segment_s_ + tau_s) * inv_dt_; }

 private:
  double time_in_segment_s_;  // t_j - t_s
  double inv_dt_;
  Eigen::Vector3d point_lidar_m_;
  Eigen::Vector3d normal_scaled_;  // n_pi / sigma
  double offset_scaled_;           // d_pi / sigma
};

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_RESIDUALS_POINT_TO_PLANE_COST_FUNCTION_H_
