#include "stages/calibrate/init/initialisation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <memory>
#include <optional>

#include <fmt/format.h>

#include "common/geometry/angles.h"
#include "common/imu/gyro_integrator.h"
#include "common/io/static_detection_params.h"
#include "common/spline/linear_interpolation.h"
#include "common/spline/so3_spline.h"
#include "stages/calibrate/init/coarse_time_offset.h"
#include "stages/calibrate/init/init_odometry.h"
#include "stages/calibrate/init/rig_rotation_check.h"
#include "stages/calibrate/problem/problem_builder.h"
#include "stages/calibrate/report/covariance_report.h"
#include "stages/calibrate/residuals/lidar_position_sample_cost_function.h"
#include "stages/calibrate/residuals/orientation_sample_cost_function.h"

namespace tiltcal::calibrate {
namespace {

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The initial fits hold the extrinsic, tau (at the state's value), gravity
// and the biases unless told otherwise.
ProblemOptions FitOptions(const proto::CalibrateParams& params, const CalibrationState& state) {
  ProblemOptions p;
  p.time_offset_bound_s = params.time_offset_bound_s();
  p.time_offset_center_s = state.time_offset_s[0];
  p.time_offset_step_bound_s = params.outer_loop().time_offset_step_bound_s();
  p.estimate_extrinsic = false;
  p.estimate_time_offset = false;
  p.estimate_gravity = false;
  p.estimate_biases = false;
  return p;
}

// The IMU noise of the initial fits: the gyro bias segments stay untied (the
// gyro fit holds them, the position fit has no gyro residual).
proto::ImuNoiseParams FitImuNoise(const proto::CalibrateParams& params) {
  proto::ImuNoiseParams noise = params.imu_noise();
  noise.set_gyro_bias_random_walk_radps2_sqrthz(0.0);
  return noise;
}

imu::ImuInitialisationOptions ImuInitialisationOptionsFrom(const proto::CalibrateParams& params) {
  imu::ImuInitialisationOptions options;
  options.static_detection = ToStaticDetectionOptions(params.static_detection());
  options.gravity_norm_mps2 = params.gravity_norm_mps2();
  options.fallback_window_s = params.init().fallback_window_s();
  return options;
}

double RmsResidual(const ceres::Solver::Summary& summary) {
  return summary.num_residuals > 0 ? std::sqrt(2.0 * summary.final_cost / summary.num_residuals)
                                   : 0.0;
}

// LM on one of the initial fits; returns the RMS weighted residual.
double SolveFit(const proto::CalibrateParams& params, ceres::Problem* problem) {
  SolverSettings settings;
  settings.max_iterations = static_cast<int>(params.init().solver_iterations());
  settings.num_threads = static_cast<int>(params.num_threads());
  settings.function_tolerance = params.init().function_tolerance();
  settings.initial_trust_region_radius = params.init().solver_initial_trust_region_radius();
  const ceres::Solver::Options solver = MakeSolverOptions(settings);
  ceres::Solver::Summary summary;
  ceres::Solve(solver, problem, &summary);
  return RmsResidual(summary);
}

}  // namespace

Eigen::Quaterniond AlignRotationAxes(const std::vector<RotationPair>& pairs,
                                     const Eigen::Quaterniond& imu_from_lidar) {
  Eigen::Vector3d a_b, a_l;
  if (!MatchedPrincipalAxes(pairs, &a_b, &a_l)) return imu_from_lidar;
  const Eigen::Vector3d mapped = imu_from_lidar * a_l;
  return (Eigen::Quaterniond::FromTwoVectors(mapped, a_b) * imu_from_lidar).normalized();
}

double SearchTimeOffset(const CalibrationState& state, const std::vector<double>& scan_times_s,
                        const std::vector<Eigen::Quaterniond>& lidar_rotations, double center_s,
                        double bound_s, double step_s) {
  const Eigen::Quaterniond c_bl = state.ImuFromLidarRotation();
  const spline::SplineTrajectory& traj = state.trajectory;
  // b-frame rotation vectors of consecutive LiDAR poses.
  std::vector<Eigen::Vector3d> phi_l;
  std::vector<std::pair<double, double>> spans;
  for (size_t k = 0; k + 1 < scan_times_s.size(); ++k) {
    const Eigen::AngleAxisd d(lidar_rotations[k].conjugate() * lidar_rotations[k + 1]);
    phi_l.push_back(c_bl * (d.angle() * d.axis()));
    spans.emplace_back(scan_times_s[k], scan_times_s[k + 1]);
  }
  auto cost = [&](double tau) {
    double sum = 0.0;
    spline::So3SplineSample r0, r1;
    for (size_t k = 0; k < phi_l.size(); ++k) {
      if (!traj.Evaluate(spans[k].first + tau, spline::kSo3Rotation, &r0, nullptr) ||
          !traj.Evaluate(spans[k].second + tau, spline::kSo3Rotation, &r1, nullptr)) {
        sum += phi_l[k].squaredNorm();  // same penalty for every tau: skip-like
        continue;
      }
      const Eigen::AngleAxisd d(Eigen::Quaterniond(r0.rotation.transpose() * r1.rotation));
      sum += (d.angle() * d.axis() - phi_l[k]).squaredNorm();
    }
    return sum;
  };
  if (phi_l.empty() || step_s <= 0.0) return center_s;
  const int n = static_cast<int>(std::floor(bound_s / step_s));
  int best = 0;
  double best_cost = cost(center_s);
  std::vector<double> costs(2 * n + 1);
  for (int i = -n; i <= n; ++i) {
    costs[i + n] = cost(center_s + i * step_s);
    if (costs[i + n] < best_cost) {
      best_cost = costs[i + n];
      best = i;
    }
  }
  double tau = center_s + best * step_s;
  // Parabola through the neighbours.
  if (best > -n && best < n) {
    const double c0 = costs[best + n - 1], c1 = costs[best + n], c2 = costs[best + n + 1];
    const double den = c0 - 2.0 * c1 + c2;
    if (den > 0.0) tau += 0.5 * step_s * (c0 - c2) / den;
  }
  return tau;
}

double FitRotationSplineToGyro(const std::vector<imu::ImuReading>& imu_samples,
                               const proto::CalibrateParams& params, CalibrationState* state) {
  spline::SplineTrajectory& traj = state->trajectory;
  const spline::UniformKnotGrid& grid = traj.grid();
  const imu::GyroIntegrator integrator(imu_samples, state->GyroBias());
  // Knot i sits (approximately) at t0 + (i - 1) dt for a cubic B-spline.
  for (int i = 0; i < traj.num_knots(); ++i) {
    traj.SetRotationKnot(i, integrator.Rotation(grid.t0_s() + (i - 1) * grid.dt_s()));
  }
  CalibrationProblem problem(state, FitImuNoise(params), params.lidar(), FitOptions(params, *state));
  problem.AddImuResiduals(imu_samples, /*gyro=*/true, /*accel=*/false);
  problem.RemoveUnusedKnots();
  return SolveFit(params, problem.problem());
}

double RefineRotationSpline(const std::vector<double>& times_s,
                            const std::vector<Eigen::Quaterniond>& orientations_a_from_b,
                            const std::vector<imu::ImuReading>& imu_samples,
                            const proto::CalibrateParams& params, CalibrationState* state) {
  spline::SplineTrajectory& traj = state->trajectory;
  const spline::UniformKnotGrid& grid = traj.grid();
  CalibrationProblem problem(state, FitImuNoise(params), params.lidar(), FitOptions(params, *state));
  problem.AddImuResiduals(imu_samples, /*gyro=*/true, /*accel=*/false);
  const double sigma = geometry::DegToRad(params.init().odometry_rotation_sigma_deg());
  Status status = problem.AddExtraResiduals([&](CalibrationState* s, ceres::Problem* p, int* added) {
    for (size_t k = 0; k < times_s.size(); ++k) {
      spline::KnotWindow w;
      if (!grid.Locate(times_s[k], &w)) continue;
      const int f = w.first_knot;
      p->AddResidualBlock(
          new OrientationSampleCostFunction(w, grid.inv_dt(), orientations_a_from_b[k], sigma),
          nullptr, s->trajectory.rotation_knot(f), s->trajectory.rotation_knot(f + 1),
          s->trajectory.rotation_knot(f + 2), s->trajectory.rotation_knot(f + 3));
      ++*added;
    }
    return Status::Ok();
  });
  (void)status;
  problem.RemoveUnusedKnots();
  return SolveFit(params, problem.problem());
}

double FitPositionSpline(const std::vector<double>& times_s,
                         const std::vector<Eigen::Vector3d>& lidar_positions_a,
                         const std::vector<imu::ImuReading>& imu_samples,
                         const proto::CalibrateParams& params,
                         const Eigen::Vector3d& translation_prior_axis_b, CalibrationState* state) {
  spline::SplineTrajectory& traj = state->trajectory;
  const spline::UniformKnotGrid& grid = traj.grid();
  // C_ab at the sample times (held) and the IMU positions they imply with
  // the current r_b^{lb}, for the starting knots.
  std::vector<double> times;
  std::vector<Eigen::Matrix3d> rotations;
  std::vector<Eigen::Vector3d> lidar_positions, imu_positions;
  const Eigen::Vector3d r_bl = state->ImuFromLidarTranslation();
  for (size_t k = 0; k < times_s.size(); ++k) {
    spline::So3SplineSample rot;
    if (!traj.Evaluate(times_s[k], spline::kSo3Rotation, &rot, nullptr)) continue;
    times.push_back(times_s[k]);
    rotations.push_back(rot.rotation);
    lidar_positions.push_back(lidar_positions_a[k]);
    imu_positions.push_back(lidar_positions_a[k] - rot.rotation * r_bl);
  }
  if (times.empty()) return 0.0;
  for (int i = 0; i < traj.num_knots(); ++i) {
    const double knot_time_s = grid.t0_s() + (i - 1) * grid.dt_s();
    traj.SetPositionKnot(i, spline::InterpolateLinearly(times, imu_positions, knot_time_s));
  }
  // The accelerometer bias and g_a are estimated with the positions: with
  // the bias held at 0, its double integral (~ b t^2 / 2, metres within
  // seconds) would bend the positions away from the odometry's. So is the
  // lever arm r_b^{lb} (prior at its current value): a wrong one makes the
  // IMU positions p_l - C_ab r_b^{lb} swing with the heading, which the
  // accelerometer contradicts.
  ProblemOptions fit = FitOptions(params, *state);
  fit.estimate_biases = true;
  fit.estimate_gravity = true;
  fit.fix_first_knots = false;  // the position samples pin the gauge
  fit.translation_prior_sigma_m = params.extrinsic_translation_prior_sigma_m();
  fit.estimate_extrinsic = fit.translation_prior_sigma_m > 0.0;
  fit.translation_prior_m = r_bl;
  fit.translation_prior_axis_b = translation_prior_axis_b;
  CalibrationProblem problem(state, FitImuNoise(params), params.lidar(), fit);
  problem.SetRotationKnotsConstant();
  problem.AddImuResiduals(imu_samples, /*gyro=*/false, /*accel=*/true);
  const double sigma = params.init().odometry_position_sigma_m();
  Status status = problem.AddExtraResiduals(
      [&](CalibrationState* s, ceres::Problem* p, int* added) {
        for (size_t k = 0; k < times.size(); ++k) {
          spline::KnotWindow w;
          if (!grid.Locate(times[k], &w)) continue;
          const int f = w.first_knot;
          p->AddResidualBlock(
              new LidarPositionSampleCostFunction(w.u, grid.inv_dt(), rotations[k],
                                                  lidar_positions[k], sigma),
              nullptr,
              {s->trajectory.position_knot(f), s->trajectory.position_knot(f + 1),
               s->trajectory.position_knot(f + 2), s->trajectory.position_knot(f + 3),
               s->imu_from_lidar_translation});
          ++*added;
        }
        return Status::Ok();
      });
  (void)status;
  problem.RemoveUnusedKnots();  // C_bl and tau: no residual here uses them
  return SolveFit(params, problem.problem());
}

namespace {

// Step 4: an error when the motion turned too little to decide the rotation
// (MissingTurning); else C_bl from the rig, or hand-eye when excited; without
// excitation the rig's C_bl aligned to the motion's rotation axis. The rig's
// C_bl maps the LiDAR's rotation axis within max_axis_alignment_deg of the
// IMU's, or hand-eye replaces it; otherwise (planar motion: the rotation
// about the axis is not determined) it is an error with the angle.
Status InitialExtrinsicRotation(const OdometryRun& run, const std::vector<LidarScan>& scans,
                                const Eigen::Quaterniond& measured_imu_from_lidar,
                                const proto::CalibrateParams& params,
                                InitialisationReport* report, Eigen::Quaterniond* c_bl) {
  const int pair_step = std::max(1, static_cast<int>(params.hand_eye().pair_step()));
  const std::vector<RotationPair> pairs =
      MakeRotationPairs(run.imu_used, run.lidar_used, pair_step);
  std::vector<std::pair<double, double>> pair_times_s;
  for (size_t k = 0; k + pair_step < run.used.size(); k += pair_step) {
    pair_times_s.emplace_back(scans[run.scan_of_pose[run.used[k]]].stamp_s,
                              scans[run.scan_of_pose[run.used[k + pair_step]]].stamp_s);
  }
  report->turning = MeasureTurning(pairs, pair_times_s);
  // Without turning, the motion's axis is noise: neither hand-eye, nor the
  // axis alignment, nor a check of the rig can use it.
  const std::string missing = MissingTurning(report->turning, params.init());
  if (!missing.empty()) return Status::NotDetermined(missing);
  report->hand_eye = EstimateHandEyeRotation(pairs, params.hand_eye());
  Eigen::Quaterniond c_bl_init = ChooseInitialRotation(measured_imu_from_lidar, report->hand_eye);
  report->rotation_from_hand_eye = report->hand_eye.excited;
  report->rig_axis_disagreement_deg = RotationAxisDisagreementDeg(pairs, measured_imu_from_lidar);
  const double max_deg = params.init().max_axis_alignment_deg();
  if (!report->rotation_from_hand_eye && report->rig_axis_disagreement_deg > max_deg) {
    return Status::Error(fmt::format(
        "the rig's imu_from_lidar rotation maps the LiDAR's rotation axis {:.1f} deg away from "
        "the IMU's (180: one of them is upside down; at most init.max_axis_alignment_deg = {} "
        "is corrected), and the motion (hand-eye excitation {:.4f} rad) does not determine "
        "the rotation: fix imu_from_lidar.rotation in the rig",
        report->rig_axis_disagreement_deg, max_deg, report->hand_eye.excitation_rad));
  }
  if (!report->rotation_from_hand_eye && params.init().align_rotation_axis()) {
    // Planar motion: the rotation axis is still seen by both sensors.
    const Eigen::Quaterniond aligned = AlignRotationAxes(pairs, c_bl_init);
    const double correction_deg =
        geometry::RadToDeg(Eigen::AngleAxisd(aligned * c_bl_init.conjugate()).angle());
    if (correction_deg <= max_deg) {
      c_bl_init = aligned;
      report->axis_alignment_deg = correction_deg;
      report->axis_alignment_applied = true;
    }
  }
  report->rig_rotation_correction_deg =
      geometry::RadToDeg(
          Eigen::AngleAxisd(c_bl_init * measured_imu_from_lidar.conjugate()).angle());
  *c_bl = c_bl_init;
  return Status::Ok();
}

// Step 4c: the rotation spline refitted to the gyro and the odometry's
// orientations carried to b, C_ab(t_k + tau) = C_ab(t_f + tau) C_bl
// C_{l0 lk} C_bl^T (f: the first registered scan). Returns the anchor
// C_ab(t_f + tau) (identity when no scan is inside the spline).
Eigen::Quaterniond RefineHeading(const OdometryRun& run, const std::vector<LidarScan>& scans,
                                 const std::vector<imu::ImuReading>& imu_samples,
                                 const Eigen::Quaterniond& c_bl_init,
                                 const proto::CalibrateParams& params, CalibrationState* state,
                                 InitialisationReport* report) {
  const Eigen::Quaterniond c_bl_q = c_bl_init.normalized();
  Eigen::Quaterniond anchor = Eigen::Quaterniond::Identity();
  std::vector<double> times;
  std::vector<Eigen::Quaterniond> orientations;
  bool have_anchor = false;
  for (const size_t i : run.used) {
    const double t_imu = scans[run.scan_of_pose[i]].stamp_s + state->time_offset_s[0];
    spline::So3SplineSample rot;
    if (!state->trajectory.Evaluate(t_imu, spline::kSo3Rotation, &rot, nullptr)) continue;
    if (!have_anchor) {
      anchor = Eigen::Quaterniond(rot.rotation);
      have_anchor = true;
    }
    times.push_back(t_imu);
    orientations.push_back(anchor * c_bl_q *
                           Eigen::Quaterniond(run.poses[i].l0_from_lidar.rotation()) *
                           c_bl_q.conjugate());
  }
  if (params.init().odometry_rotation_sigma_deg() > 0.0 && times.size() >= 2) {
    report->rotation_refit_rms =
        RefineRotationSpline(times, orientations, imu_samples, params, state);
  }
  return anchor;
}

// Scans whose sweep at t_l + tau is not inside the IMU's spline.
int CountScansOutsideImu(const std::vector<LidarScan>& scans, const CalibrationState& state) {
  const spline::UniformKnotGrid& grid = state.trajectory.grid();
  spline::KnotWindow w;
  int outside = 0;
  for (const LidarScan& scan : scans) {
    const double t = scan.stamp_s + state.time_offset_s[0];
    if (!grid.Locate(t + scan.min_time_s, &w) || !grid.Locate(t + scan.max_time_s, &w)) {
      ++outside;
    }
  }
  return outside;
}

// Step 4d: the acceleration check of the starting C_bl about the motion's
// axis (rig_rotation_check.h); a yaw error beyond max_rig_rotation_error_deg
// is an error.
Status CheckRigYaw(const OdometryRun& run, const std::vector<LidarScan>& scans,
                   const std::vector<imu::ImuReading>& imu_samples, const Eigen::Vector3d& axis_b,
                   const proto::CalibrateParams& params, const CalibrationState& state,
                   InitialisationReport* report) {
  std::vector<double> times;
  std::vector<Eigen::Vector3d> positions;
  for (const size_t i : run.used) {
    times.push_back(scans[run.scan_of_pose[i]].stamp_s);
    positions.push_back(run.poses[i].l0_from_lidar.translation());
  }
  report->acceleration_check =
      CheckRigYawByAccelerations(state, imu_samples, times, positions, axis_b, params.init());
  const AccelerationCheck& check = report->acceleration_check;
  const double max_deg = params.init().max_rig_rotation_error_deg();
  if (!check.decided || std::abs(check.yaw_error_deg) <= max_deg) return Status::Ok();
  return Status::Error(fmt::format(
      "the LiDAR's accelerations mapped into the IMU frame by the {} C_bl are turned by {:.1f} "
      "deg about the motion's rotation axis ({:.3f}, {:.3f}, {:.3f}) against the "
      "accelerometer's (RMS horizontal acceleration {:.2f} m/s^2, {} samples; at most "
      "init.max_rig_rotation_error_deg = {}): the rig's imu_from_lidar rotation is off by about "
      "that angle about this axis; fix it in the rig",
      report->rotation_from_hand_eye ? "hand-eye" : "rig's", check.yaw_error_deg, axis_b.x(),
      axis_b.y(), axis_b.z(), check.rms_horizontal_acceleration_mps2, check.samples, max_deg));
}

// 99th percentile of |omega_m - b_g|, in the file's unit.
double GyroSpeedPercentile99(const std::vector<imu::ImuReading>& imu_samples,
                             const Eigen::Vector3d& gyro_bias) {
  std::vector<double> speeds;
  for (const imu::TimedValue& v : GyroAngularSpeeds(imu_samples, gyro_bias)) {
    speeds.push_back(v.value);
  }
  if (speeds.empty()) return 0.0;
  const size_t k = std::min(speeds.size() - 1, static_cast<size_t>(0.99 * speeds.size()));
  std::nth_element(speeds.begin(), speeds.begin() + k, speeds.end());
  return speeds[k];
}

// Step 3 with 3b: the odometry at tau = 0, the coarse tau and, when it is
// beyond time_offset_bound_s, the odometry again at the coarse tau (its
// deskew and gyro prior then come from the right instants).
Status OdometryAndCoarseTau(const std::vector<LidarScan>& scans,
                            const std::vector<imu::ImuReading>& imu_samples,
                            const proto::CalibrateParams& params, CalibrationState* state,
                            InitialisationReport* report, OdometryRun* run) {
  auto start = std::chrono::steady_clock::now();
  *run = RunOdometry(scans, *state, params, /*gyro_aided=*/true, report);
  report->odometry_seconds = Seconds(start);
  if (run->poses.size() < 2) {
    return Status::Error("too few scans inside the IMU time range for the LiDAR odometry (" +
                         std::to_string(run->poses.size()) + ")");
  }
  TILTCAL_RETURN_IF_ERROR(EstimateCoarseTau(*run, scans, imu_samples, params, *state, report));
  const proto::InitParams& init = params.init();
  const double scale = report->coarse.alignment.scale;
  if (init.coarse_time_offset_window_s() > 0.0 &&
      (!report->coarse.trusted || scale < init.min_gyro_to_lidar_rate_scale() ||
       scale > init.max_gyro_to_lidar_rate_scale() ||
       GyroSpeedPercentile99(imu_samples, state->GyroBias()) >
           init.max_plausible_gyro_speed_radps())) {
    // The gyro may have misled the odometry (deskew and prior from a gyro in
    // another unit, or from instants far off): the LiDAR alone decides.
    start = std::chrono::steady_clock::now();
    const OdometryRun lidar_only = RunOdometry(scans, *state, params, false, report);
    report->odometry_without_gyro = true;
    report->odometry_seconds += Seconds(start);
    TILTCAL_RETURN_IF_ERROR(
        EstimateCoarseTau(lidar_only, scans, imu_samples, params, *state, report));
    if (report->coarse.trusted) {
      TILTCAL_RETURN_IF_ERROR(CheckGyroToLidarRateScale(report->coarse.alignment.scale, init));
    }
  }
  if (std::abs(report->time_offset_center_s) > params.time_offset_bound_s() ||
      report->odometry_without_gyro) {
    start = std::chrono::steady_clock::now();
    state->time_offset_s[0] = report->time_offset_center_s;
    *run = RunOdometry(scans, *state, params, /*gyro_aided=*/true, report);
    report->odometry_rerun = true;
    report->odometry_seconds += Seconds(start);
    if (run->poses.size() < 2) {
      return Status::Error(fmt::format(
          "too few scans inside the IMU time range at the coarse time offset {:.3f} s ({})",
          report->time_offset_center_s, run->poses.size()));
    }
    // The first odometry's gyro prior came from instants tau off, which
    // drags its rotations; the rerun's speeds give the better tau.
    const InitialisationReport first = *report;
    TILTCAL_RETURN_IF_ERROR(EstimateCoarseTau(*run, scans, imu_samples, params, *state, report));
    if (!report->coarse.trusted) {
      report->coarse = first.coarse;
      report->time_offset_center_s = first.time_offset_center_s;
    }
  }
  state->time_offset_s[0] = report->time_offset_center_s;
  report->dropped_scans_outside_imu = CountScansOutsideImu(scans, *state);
  return Status::Ok();
}

}  // namespace

Status MakeStateOverImu(const std::vector<imu::ImuReading>& imu_samples,
                        const proto::CalibrateParams& params,
                        std::optional<CalibrationState>* state) {
  if (imu_samples.size() < 10) return Status::Error("too few IMU samples");
  // Grid over the IMU samples (IMU clock, t0 = first sample = 0).
  const double t0 = imu_samples.front().time_s;
  const double duration = imu_samples.back().time_s - t0;
  if (!(duration <= params.spline().max_duration_s())) {
    return Status::Error(fmt::format(
        "imu: the stamps span {} s, more than spline.max_duration_s = {} s (a stamp far from "
        "its neighbours?)",
        duration, params.spline().max_duration_s()));
  }
  state->emplace(
      spline::UniformKnotGrid::ForDuration(t0, duration, params.spline().knot_spacing_s()));
  (*state)->gravity_norm_mps2 = params.gravity_norm_mps2();
  return (*state)->SetBiasSegments(params.imu_noise().gyro_bias_segment_s(),
                                   params.imu_noise().accel_bias_segment_s());
}

Status InitialiseImuAndRotationSpline(const std::vector<imu::ImuReading>& imu_samples,
                                      const proto::CalibrateParams& params,
                                      CalibrationState* state, InitialisationReport* report) {
  // 1. IMU: gyro bias, gravity.
  auto start = std::chrono::steady_clock::now();
  TILTCAL_RETURN_IF_ERROR(
      imu::InitialiseImu(imu_samples, ImuInitialisationOptionsFrom(params), &report->imu));
  state->SetGyroBias(report->imu.gyro_bias_radps);
  state->SetAccelBias(Eigen::Vector3d::Zero());
  state->SetGravityDirection(report->imu.gravity_in_world_mps2);
  state->time_offset_s[0] = 0.0;
  report->imu_seconds = Seconds(start);

  const MotionAxis axis = PrincipalRotationAxis(imu_samples, report->imu.gyro_bias_radps);
  report->rotation_axis_b = axis.axis_b;
  report->rotation_axis_fraction = axis.fraction;

  // 2. Rotation spline from the gyro.
  start = std::chrono::steady_clock::now();
  report->gyro_fit_rms = FitRotationSplineToGyro(imu_samples, params, state);
  report->rotation_fit_seconds = Seconds(start);
  return Status::Ok();
}

Status InitialiseState(const std::vector<imu::ImuReading>& imu_samples,
                       const std::vector<LidarScan>& scans, const Rigid3d& measured_imu_from_lidar,
                       const proto::CalibrateParams& params, CalibrationState* state,
                       InitialisationReport* report) {
  *report = InitialisationReport();
  state->SetImuFromLidarRotation(measured_imu_from_lidar.rotation);
  state->SetImuFromLidarTranslation(measured_imu_from_lidar.translation);
  // 1. and 2.
  TILTCAL_RETURN_IF_ERROR(InitialiseImuAndRotationSpline(imu_samples, params, state, report));
  const MotionAxis axis{report->rotation_axis_b, report->rotation_axis_fraction};

  // 3. Odometry and the wide-window tau.
  OdometryRun run;
  TILTCAL_RETURN_IF_ERROR(OdometryAndCoarseTau(scans, imu_samples, params, state, report, &run));

  // 4. Extrinsic rotation.
  Eigen::Quaterniond c_bl_init;
  TILTCAL_RETURN_IF_ERROR(
      InitialExtrinsicRotation(run, scans, measured_imu_from_lidar.rotation, params, report,
                               &c_bl_init));
  state->SetImuFromLidarRotation(c_bl_init);

  // 4b. Tau from consecutive odometry rotations against the gyro spline,
  // within time_offset_bound_s of the coarse tau.
  report->time_offset_init_s = report->time_offset_center_s;
  if (params.time_offset_bound_s() > 0.0) {
    std::vector<double> times_used;
    for (const size_t i : run.used) times_used.push_back(scans[run.scan_of_pose[i]].stamp_s);
    report->time_offset_init_s = SearchTimeOffset(
        *state, times_used, run.lidar_used, report->time_offset_center_s,
        params.time_offset_bound_s(), params.init().time_offset_search_step_s());
  }
  state->time_offset_s[0] = report->time_offset_init_s;

  // 4c. Heading; 4d. the starting C_bl against the accelerations.
  auto start = std::chrono::steady_clock::now();
  const Eigen::Quaterniond anchor =
      RefineHeading(run, scans, imu_samples, c_bl_init, params, state, report);
  report->rotation_fit_seconds += Seconds(start);
  TILTCAL_RETURN_IF_ERROR(
      CheckRigYaw(run, scans, imu_samples, axis.axis_b, params, *state, report));

  // 5. Position spline (and lever arm) from the odometry's LiDAR positions,
  // p_l(t_k) = C_ab(t_f + tau) C_bl r_{l0}^{lk l0} (the LiDAR at the first
  // registered scan as origin), and the accelerometer.
  start = std::chrono::steady_clock::now();
  const Eigen::Matrix3d c_bl_m = c_bl_init.toRotationMatrix();
  std::vector<double> times;
  std::vector<Eigen::Vector3d> positions;
  for (const size_t i : run.used) {
    times.push_back(scans[run.scan_of_pose[i]].stamp_s + state->time_offset_s[0]);
    positions.push_back(anchor * (c_bl_m * run.poses[i].l0_from_lidar.translation()));
  }
  report->position_fit_rms =
      FitPositionSpline(times, positions, imu_samples, params, axis.axis_b, state);
  report->position_fit_seconds = Seconds(start);
  return Status::Ok();
}

}  // namespace tiltcal::calibrate
