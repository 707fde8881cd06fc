#ifndef TILTCAL_STAGES_CALIBRATE_RESIDUALS_GROUND_COST_FUNCTIONS_H_
#define TILTCAL_STAGES_CALIBRATE_RESIDUALS_GROUND_COST_FUNCTIONS_H_

// Ground-plane residuals of the calibrator (docs/design.md §8, paper "Proposed
// Method"), one scan k at a time. The scan's ground plane (n_l, d_l) is in
// the LiDAR frame l at the scan stamp t_k (LiDAR clock): unit normal n_l
// pointing up, d_l > 0 the LiDAR's distance to the plane, ground points
// satisfy n_l^T p_l + d_l = 0. The spline is evaluated at the IMU time
// t = t_k + tau. With n_g the unit gravity direction in the world frame a
// (pointing DOWN, g_a = |g_a| n_g):
//
//   g~_b = -C_ab(t)^T n_g           gravity-up in the IMU frame (unit)
//   g~_f = -g_f / |g_f|             gravity-up in the IMU frame on flat ground
//
//   flat:  e_flat = n_l - C_bl^T g~_b                       (3, level ground only)
//   dist:  e_dist = d_l - d_b - n_l^T C_bl^T r_b^{lb}        (1, any plane)
//   incl:  e_incl = g~_b^T (g~_f - C_bl n_l)                 (1, any plane)
//   up:    e_up   = C_bl n_l - g~_f                          (3, any plane, rigid vehicle)
//
// (The paper writes g~_b = C_ab g~_a; with C_ab mapping b to a the correct
// form is C_ab^T, as here. The paper's e_incl carries the opposite sign, which
// changes nothing in a least-squares cost.)
//
// Weighting: every residual is multiplied by a square-root information W:
//   flat: r = W e_flat                   W 3x3, in the LiDAR frame l;
//   up:   r = W C_bl^T e_up = W (n_l - C_bl^T g~_f)
//                                        W 3x3, also in l: e_up resolved in the
//                                        LiDAR frame, where the plane fit's
//                                        covariance lives; for W = I/sigma the
//                                        cost equals |e_up|^2 / sigma^2;
//   dist, incl: r = w e                  w scalar.
// Robust losses are applied by the problem builder (ground_residuals.h).
//
// Jacobian conventions (as in the other cost functions of stages/calibrate):
// quaternion blocks (x, y, z, w) live on spline::RightQuaternionManifold;
// tangent Jacobians are taken for right perturbations (C <- C Exp(delta)) and
// written as J_t * MinusJacobian(q) (jacobian_writer.h). The gravity
// direction n_g lives on ceres::SphereManifold<3>; its Jacobian is the
// ambient d r / d n_g (n_g treated as unit, like AccelCostFunction). With
// C = C_ab(t) <- C Exp(eps), Q = C_bl <- Q Exp(delta):
//   d g~_b / d eps  = [g~_b]_x,   d g~_b / d n_g = -C^T,   d g~_b / dt = g~_b x omega_b,
//   d (Q^T v) / d delta = [Q^T v]_x,   d (Q n) / d delta = -Q [n]_x,
// and d eps / d delta_i (knot i) = So3SplineSample::rotation_jacobian[i].
//
// Time offset: as PointToPlaneCostFunction, the knot window (segment s) is
// frozen at construction from the current tau, and inside Evaluate
//   u = (t_k + tau - t_s) / dt,
// which may leave [0, 1) slightly (the segment polynomial is extended; the
// problem builder bounds tau and re-bins at every outer iteration).
//
// No heap allocation in Evaluate; all fixed-size Eigen types.

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

namespace tiltcal::calibrate {

// e_flat = n_l - C_bl^T g~_b,  r = W e_flat  (3).
// Parameter blocks, in order:
//   0..3  rotation knots s..s+3: unit quaternions (x, y, z, w),
//         spline::RightQuaternionManifold;
//   4     gravity direction n_g: 3 doubles, unit, frame a, down, SphereManifold<3>;
//   5     C_bl: unit quaternion (x, y, z, w), RightQuaternionManifold;
//   6     tau: 1 double, s (t_imu = t_lidar + tau).
// Jacobians (before W):
//   d e / d eps   = -C_bl^T [g~_b]_x
//   d e / d n_g   =  C_bl^T C_ab^T
//   d e / d delta =  -[C_bl^T g~_b]_x
//   d e / d tau   = -C_bl^T (g~_b x omega_b)
class FlatGroundCostFunction final : public ceres::SizedCostFunction<3, 4, 4, 4, 4, 3, 4, 1> {
 public:
  // segment_start_s: t0 + s dt of the frozen window; scan_time_s: t_k on the
  // LiDAR clock (same clock and origin as the grid); normal_lidar: n_l (unit);
  // sqrt_information: W, 3x3, LiDAR frame.
  FlatGroundCostFunction(double segment_start_s, double inv_dt, double scan_time_s,
                         const Eigen::Vector3d& normal_lidar,
                         const Eigen::Matrix3d& sqrt_information);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  double NormalizedTime(double tau_s) const { return (time_in_segment_s_ + tau_s) * inv_dt_; }

 private:
  double time_in_segment_s_;  // t_k - t_s
  double inv_dt_;
  Eigen::Vector3d normal_lidar_;
  Eigen::Matrix3d sqrt_information_;
};

// e_dist = d_l - d_b - n_l^T C_bl^T r_b^{lb},  r = w e_dist  (1).
// Parameter blocks, in order:
//   0     C_bl: unit quaternion (x, y, z, w), RightQuaternionManifold;
//   1     r_b^{lb}: 3 doubles, m.
// No spline and no tau: both heights are distances to the same plane at the
// same instant. Jacobians (before w):
//   d e / d delta = -n_l^T [C_bl^T r_b^{lb}]_x
//   d e / d r     = -(C_bl n_l)^T
class DistanceCostFunction final : public ceres::SizedCostFunction<1, 4, 3> {
 public:
  // lidar_height_m: d_l; imu_height_m: d_b (Rig.imu_height_m); w: 1/m.
  DistanceCostFunction(const Eigen::Vector3d& normal_lidar, double lidar_height_m,
                       double imu_height_m, double sqrt_information);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Vector3d normal_lidar_;
  double height_difference_m_;  // d_l - d_b
  double sqrt_information_;
};

// e_incl = g~_b^T (g~_f - C_bl n_l),  r = w e_incl  (1).
// Parameter blocks: as FlatGroundCostFunction (0..3 knots, 4 n_g, 5 C_bl, 6 tau).
// With m = g~_f - C_bl n_l, Jacobians (before w):
//   d e / d eps   =  m^T [g~_b]_x
//   d e / d n_g   = -m^T C_ab^T
//   d e / d delta =  g~_b^T C_bl [n_l]_x
//   d e / d tau   =  m^T (g~_b x omega_b)
class InclinationCostFunction final
    : public ceres::SizedCostFunction<1, 4, 4, 4, 4, 3, 4, 1> {
 public:
  // gravity_flat_in_imu: g_f (any norm > 0, points down), IMU frame.
  InclinationCostFunction(double segment_start_s, double inv_dt, double scan_time_s,
                          const Eigen::Vector3d& normal_lidar,
                          const Eigen::Vector3d& gravity_flat_in_imu, double sqrt_information);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  double NormalizedTime(double tau_s) const { return (time_in_segment_s_ + tau_s) * inv_dt_; }

 private:
  double time_in_segment_s_;
  double inv_dt_;
  Eigen::Vector3d normal_lidar_;
  Eigen::Vector3d up_flat_;  // g~_f
  double sqrt_information_;
};

// e_up = C_bl n_l - g~_f, evaluated as r = W C_bl^T e_up = W (n_l - C_bl^T g~_f)  (3).
// Parameter blocks, in order:
//   0     C_bl: unit quaternion (x, y, z, w), RightQuaternionManifold.
// Jacobian (before W):  d (C_bl^T e_up) / d delta = -[C_bl^T g~_f]_x.
// No spline, no gravity, no tau: it says the ground normal seen in the IMU
// frame equals the flat-ground gravity-up g~_f, which holds on any plane for
// a rigid vehicle whose wheels are on the plane.
class UpCostFunction final : public ceres::SizedCostFunction<3, 4> {
 public:
  UpCostFunction(const Eigen::Vector3d& normal_lidar, const Eigen::Vector3d& gravity_flat_in_imu,
                 const Eigen::Matrix3d& sqrt_information);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Vector3d normal_lidar_;
  Eigen::Vector3d up_flat_;  // g~_f
  Eigen::Matrix3d sqrt_information_;
};

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_RESIDUALS_GROUND_COST_FUNCTIONS_H_
