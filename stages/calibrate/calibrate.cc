#include "stages/calibrate/calibrate.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <memory>

#include <ceres/solver.h>

#include "common/io/eigen_proto.h"
#include "common/io/imu_stream.h"
#include "common/io/provenance.h"
#include "common/io/record_stream.h"
#include "common/io/static_detection_params.h"
#include "common/io/text_proto.h"
#include "stages/calibrate/covariance_report.h"
#include "stages/calibrate/ground_residuals.h"
#include "stages/calibrate/initialisation.h"
#include "stages/calibrate/lidar_association.h"
#include "stages/calibrate/problem_builder.h"

namespace tiltcal::calibrate {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// CPU time of the process (all threads), s.
double CpuSeconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

void AddTiming(const std::string& phase, double seconds, proto::CalibrationResult* result) {
  proto::PhaseTiming* t = result->add_timings();
  t->set_phase(phase);
  t->set_seconds(seconds);
}

void Log(std::ostream* log, const std::string& line) {
  if (log != nullptr) *log << "tiltcal_calibrate: " << line << "\n" << std::flush;
}

std::string Format(const char* fmt, double a = 0, double b = 0, double c = 0, double d = 0,
                   double e = 0) {
  char buf[512];
  std::snprintf(buf, sizeof(buf), fmt, a, b, c, d, e);
  return buf;
}

InitialisationOptions MakeInitialisationOptions(const proto::CalibrateParams& params) {
  InitialisationOptions o;
  o.imu.gravity_norm_mps2 = params.gravity_norm_mps2();
  o.gyro_sigma_radps = params.gyro_sigma_radps();
  o.accel_sigma_mps2 = params.accel_sigma_mps2();
  o.accel_bias_random_walk = params.accel_bias_random_walk_mps3_sqrthz();
  o.solver_iterations = static_cast<int>(params.init_solver_iterations());
  o.num_threads = static_cast<int>(params.num_threads());
  o.odometry.method = params.odometry_method() == proto::CalibrateParams::NDT
                          ? RegistrationMethod::kNdt
                          : RegistrationMethod::kGicp;
  o.odometry.scan_voxel_m = params.odometry_scan_voxel_m();
  o.odometry.map_voxel_m = params.odometry_map_voxel_m();
  o.odometry.min_range_m = params.lidar_min_range_m();
  o.odometry.max_range_m = params.lidar_max_range_m();
  o.hand_eye.min_excitation_rad = params.hand_eye_min_excitation_rad();
  o.time_offset_search_s = params.time_offset_bound_s();
  o.imu.static_detection = ToStaticDetectionOptions(params.static_detection());
  o.imu.fallback_window_s = params.init_fallback_window_s();
  o.odometry.max_iterations = static_cast<int>(params.odometry_max_iterations());
  o.odometry.keyframe_distance_m = params.odometry_keyframe_distance_m();
  o.odometry.keyframe_angle_deg = params.odometry_keyframe_angle_deg();
  o.odometry.local_map_keyframes = static_cast<int>(params.odometry_local_map_keyframes());
  o.odometry.max_correspondence_m = params.odometry_max_correspondence_m();
  o.odometry.gicp_neighbours = static_cast<int>(params.odometry_gicp_neighbours());
  o.odometry.ndt_resolution_m = params.odometry_ndt_resolution_m();
  o.hand_eye.min_pairs = static_cast<int>(params.hand_eye_min_pairs());
  o.hand_eye_pair_step = static_cast<int>(params.hand_eye_pair_step());
  o.odometry_scan_step = static_cast<int>(std::max(1u, params.odometry_scan_step()));
  o.hand_eye.consistent_angle_deg = params.hand_eye_consistent_angle_deg();
  o.odometry_rotation_sigma_rad = params.init_odometry_rotation_sigma_deg() * M_PI / 180.0;
  o.translation_prior_sigma_m = params.extrinsic_translation_prior_sigma_m();
  return o;
}

AssociationStageOptions MakeAssociationOptions(const proto::CalibrateParams& params) {
  AssociationStageOptions o;
  o.map.voxel_size_m = params.map_voxel_m();
  o.map.min_points = static_cast<int>(params.surfel_min_points());
  o.map.max_eigen_ratio = params.surfel_max_planarity();
  o.map.max_thickness_m = params.surfel_max_thickness_m();
  o.map.min_spread_ratio = params.surfel_min_spread_ratio();
  o.map.max_normal_sigma_rad = params.surfel_max_normal_sigma_deg() * M_PI / 180.0;
  o.map.inlier_distance_m = params.surfel_inlier_distance_m();
  o.map.min_inlier_fraction = params.surfel_min_inlier_fraction();
  o.map.sample_points_per_voxel = static_cast<int>(params.surfel_sample_points());
  o.max_distance_m = params.association_max_distance_m();
  o.association_stride = static_cast<int>(params.lidar_point_stride());
  o.max_points_per_surfel_per_scan = static_cast<int>(params.lidar_max_points_per_surfel_per_scan());
  o.max_residuals_per_scan = static_cast<int>(params.lidar_max_residuals_per_scan());
  return o;
}

ProblemOptions MakeProblemOptions(const proto::CalibrateParams& params) {
  ProblemOptions o;
  o.gyro_sigma_radps = params.gyro_sigma_radps();
  o.accel_sigma_mps2 = params.accel_sigma_mps2();
  o.gyro_bias_random_walk = params.gyro_bias_random_walk_radps2_sqrthz();
  o.accel_bias_random_walk = params.accel_bias_random_walk_mps3_sqrthz();
  o.lidar_sigma_m = params.lidar_sigma_m();
  o.lidar_cauchy_scale = params.lidar_cauchy_scale();
  o.time_offset_bound_s = params.time_offset_bound_s();
  o.time_offset_step_bound_s = params.time_offset_step_bound_s();
  o.fix_first_knots = false;  // the fixed map planes pin the gauge
  o.translation_prior_sigma_m = params.extrinsic_translation_prior_sigma_m();
  return o;
}

Status CheckParams(const proto::CalibrateParams& params) {
  if (params.gyro_sigma_radps() <= 0 || params.accel_sigma_mps2() <= 0 ||
      params.lidar_sigma_m() <= 0) {
    return Status::Error("params: gyro_sigma_radps, accel_sigma_mps2 and lidar_sigma_m must be > 0");
  }
  if (params.map_voxel_m() <= 0 || params.association_max_distance_m() <= 0) {
    return Status::Error("params: map_voxel_m and association_max_distance_m must be > 0");
  }
  if (params.lidar_max_range_m() <= params.lidar_min_range_m()) {
    return Status::Error("params: lidar_max_range_m must exceed lidar_min_range_m");
  }
  return Status::Ok();
}

}  // namespace

Status ReadCalibrateInputs(const CalibratePaths& paths, const proto::CalibrateParams& params,
                           CalibrateInputs* inputs) {
  *inputs = CalibrateInputs();
  TILTCAL_RETURN_IF_ERROR(ReadTextProto(paths.rig, &inputs->rig));
  if (!HasValidRotation(inputs->rig.imu_from_lidar())) {
    return Status::Error(paths.rig + ": imu_from_lidar.rotation missing or zero");
  }
  TILTCAL_RETURN_IF_ERROR(
      ReadImuReadings(paths.imu, &inputs->imu, &inputs->first_imu_stamp_ns));
  ScanReadOptions scan_options;
  scan_options.min_range_m = params.lidar_min_range_m();
  scan_options.max_range_m = params.lidar_max_range_m();
  scan_options.point_stride = static_cast<int>(params.map_point_stride());
  TILTCAL_RETURN_IF_ERROR(
      ReadLidarScans(paths.scans, inputs->first_imu_stamp_ns, scan_options, &inputs->scans));
  if (inputs->scans.empty()) return Status::Error(paths.scans + ": no scans");
  if (!paths.ground.empty()) {
    TILTCAL_RETURN_IF_ERROR(ReadAllRecords<proto::GroundPlane>(paths.ground, &inputs->ground));
  }
  if (!paths.gravity.empty()) {
    TILTCAL_RETURN_IF_ERROR(ReadTextProto(paths.gravity, &inputs->gravity));
    inputs->has_gravity = true;
  }
  return Status::Ok();
}

Status Calibrate(const CalibrateInputs& inputs, const proto::CalibrateParams& params,
                 proto::CalibrationResult* result, CalibrationState* final_state,
                 std::ostream* log) {
  TILTCAL_RETURN_IF_ERROR(CheckParams(params));
  result->Clear();
  const auto total_start = Clock::now();
  if (inputs.imu.size() < 10) return Status::Error("too few IMU samples");

  // Grid over the IMU samples (IMU clock, t0 = first sample = 0).
  const double t0 = inputs.imu.front().time_s;
  const double duration = inputs.imu.back().time_s - t0;
  const spline::UniformKnotGrid grid =
      spline::UniformKnotGrid::ForDuration(t0, duration, params.knot_spacing_s());
  CalibrationState state(grid);
  state.gravity_norm_mps2 = params.gravity_norm_mps2();
  state.SetBiasSegments(params.gyro_bias_segment_s(), params.accel_bias_segment_s());

  // Initialisation.
  auto start = Clock::now();
  const Rigid3d measured = ToEigen(inputs.rig.imu_from_lidar());
  InitialisationReport init;
  TILTCAL_RETURN_IF_ERROR(InitialiseState(inputs.imu, inputs.scans, measured,
                                          MakeInitialisationOptions(params), &state, &init));
  AddTiming("init_imu", init.imu_seconds, result);
  AddTiming("init_rotation_spline", init.rotation_fit_seconds, result);
  AddTiming("init_lidar_odometry", init.odometry_seconds, result);
  AddTiming("init_position_spline", init.position_fit_seconds, result);
  Log(log, Format("init: %.0f knots, static start %.0f, gyro fit rms %.3f, odometry %.0f/%.0f "
                  "scans registered",
                  grid.num_knots(), init.imu.from_static_start ? 1 : 0, init.gyro_fit_rms,
                  init.odometry_registered, init.odometry_scans));
  Log(log, Format("init: hand-eye excitation %.4f rad (%.0f pairs); position fit rms %.3f; "
                  "%.2f s",
                  init.hand_eye.excitation_rad, init.hand_eye.num_pairs, init.position_fit_rms,
                  Seconds(start)) +
               (init.rotation_from_hand_eye ? "; C_bl from hand-eye" : "; C_bl from the rig"));
  Log(log, Format("init: rotation-axis alignment %.0f (%.3f deg), coarse tau %.2f ms",
                  init.axis_alignment_applied ? 1 : 0, init.axis_alignment_deg,
                  init.time_offset_init_s * 1e3));
  {
    const Eigen::Vector3d r = state.ImuFromLidarTranslation();
    Log(log, Format("init: rotation refit rms %.3f; r_bl (%.4f, %.4f, %.4f) m from the position fit",
                    init.rotation_refit_rms, r.x(), r.y(), r.z()));
  }

  // Ground residuals (issue 6, ground_residuals.h): selected from the params
  // (AUTO / ON / OFF), the rig's d_b and the gravity reference.
  std::vector<std::string> ground_used;
  std::string ground_reason;
  const GroundLosses ground_losses(params);
  ExtraResidualAdder ground_adder;
  TILTCAL_RETURN_IF_ERROR(MakeGroundResidualAdder(
      inputs.ground, inputs.first_imu_stamp_ns, inputs.rig,
      inputs.has_gravity ? &inputs.gravity : nullptr, params, &ground_losses, nullptr,
      &ground_adder, &ground_used, &ground_reason));
  Log(log, ground_reason);

  // Outer iterations.
  const AssociationStageOptions assoc_options = MakeAssociationOptions(params);
  ProblemOptions problem_options = MakeProblemOptions(params);
  problem_options.translation_prior_m = measured.translation;
  problem_options.translation_prior_axis_b = init.rotation_axis_b;
  const ceres::Solver::Options solver_options =
      MakeSolverOptions(static_cast<int>(params.max_solver_iterations()),
                        static_cast<int>(params.num_threads()), params.function_tolerance());
  std::unique_ptr<CalibrationProblem> problem;
  ceres::Solver::Summary summary;
  std::vector<LidarPointResidual> lidar;
  double map_s = 0, assoc_s = 0, build_s = 0, solve_s = 0, solve_cpu_s = 0;
  int total_iterations = 0;
  double first_initial_cost = -1.0;
  bool converged = false;
  std::string termination;
  const int outer = static_cast<int>(params.outer_iterations());
  int outer_done = 0;
  double moved_deg = 0.0, moved_m = 0.0, moved_s = 0.0;
  const Eigen::Vector3d axis_b = init.rotation_axis_b.normalized();
  const bool translation_along_axis_observed =
      std::find(ground_used.begin(), ground_used.end(), "dist") != ground_used.end();
  for (int it = 0; it < outer; ++it) {
    const Eigen::Quaterniond rotation_before = state.ImuFromLidarRotation();
    const Eigen::Vector3d translation_before = state.ImuFromLidarTranslation();
    const double tau_before = state.time_offset_s[0];
    AssociationStageSummary assoc;
    BuildMapAndAssociate(state, inputs.scans, assoc_options, &lidar, &assoc);
    map_s += assoc.map_seconds;
    assoc_s += assoc.associate_seconds;
    if (lidar.empty()) {
      return Status::Error("no LiDAR point could be associated with a planar surfel (" +
                           std::to_string(assoc.map.num_surfels) + " surfels in the map)");
    }
    start = Clock::now();
    problem.reset();
    problem = std::make_unique<CalibrationProblem>(&state, problem_options);
    problem->AddImuResiduals(inputs.imu, true, true);
    problem->AddLidarResiduals(lidar);
    TILTCAL_RETURN_IF_ERROR(problem->AddExtraResiduals(ground_adder));
    problem->RemoveUnusedKnots();
    build_s += Seconds(start);
    start = Clock::now();
    const double cpu_start = CpuSeconds();
    ceres::Solve(solver_options, problem->problem(), &summary);
    const double solve_seconds = Seconds(start);
    solve_cpu_s += CpuSeconds() - cpu_start;
    solve_s += solve_seconds;
    total_iterations += static_cast<int>(summary.iterations.size()) - 1;
    if (first_initial_cost < 0) first_initial_cost = summary.initial_cost;
    converged = summary.termination_type == ceres::CONVERGENCE;
    termination = ceres::TerminationTypeToString(summary.termination_type);
    const Eigen::Vector3d r = state.ImuFromLidarTranslation();
    Log(log, Format("outer %.0f: %.0f surfels, %.0f lidar residuals, cost %.4g -> %.4g", it + 1,
                    assoc.map.num_surfels, assoc.residuals, summary.initial_cost,
                    summary.final_cost));
    Log(log, Format("outer %.0f: %.0f LM iterations in %.2f s; tau %.3f ms; r_bl (%.4f, ", it + 1,
                    static_cast<double>(summary.iterations.size()) - 1, solve_seconds,
                    state.time_offset_s[0] * 1e3, r.x()) +
                 Format("%.4f, %.4f) m", r.y(), r.z()));
    // tau at its per-iteration bound: more outer iterations re-bin and go on.
    outer_done = it + 1;
    moved_deg =
        Eigen::AngleAxisd(rotation_before.conjugate() * state.ImuFromLidarRotation()).angle() *
        180.0 / M_PI;
    // Without the distance residual the translation along the motion's
    // rotation axis is held only by its prior (planar motion): it wanders by
    // millimetres per round and takes no part in the stop test.
    Eigen::Vector3d moved_b = state.ImuFromLidarTranslation() - translation_before;
    if (!translation_along_axis_observed) moved_b -= axis_b * axis_b.dot(moved_b);
    moved_m = moved_b.norm();
    moved_s = std::abs(state.time_offset_s[0] - tau_before);
    const bool settled = it >= 1 && moved_deg < params.outer_stop_rotation_deg() &&
                         moved_m < params.outer_stop_translation_m() &&
                         moved_s < params.outer_stop_time_offset_s();
    Log(log, Format("outer %.0f: extrinsic moved %.4f deg, %.2f mm, tau %.3f ms", it + 1,
                    moved_deg, moved_m * 1e3, moved_s * 1e3) +
                 (settled ? ": stop" : ""));
    if (settled) break;
  }
  AddTiming("map", map_s, result);
  AddTiming("association", assoc_s, result);
  AddTiming("problem_build", build_s, result);
  AddTiming("solve", solve_s, result);
  // CPU time of the solves summed over threads (on a loaded machine the
  // steadier figure; wall ~ cpu / threads on idle cores).
  AddTiming("solve_cpu", solve_cpu_s, result);

  const ProblemCounts counts = problem->counts();
  proto::ProblemSize* size = result->mutable_problem_size();
  size->set_knots(counts.knots);
  size->set_gyro_residuals(counts.gyro_residuals);
  size->set_accel_residuals(counts.accel_residuals);
  size->set_lidar_residuals(counts.lidar_residuals);
  size->set_ground_residuals(counts.ground_residuals);
  size->set_parameters(counts.free_parameters);

  proto::SolverReport* solver = result->mutable_solver();
  solver->set_converged(converged);
  solver->set_termination(termination);
  solver->set_iterations(total_iterations);
  solver->set_initial_cost(first_initial_cost);
  solver->set_final_cost(summary.final_cost);
  solver->set_seconds_per_iteration(total_iterations > 0 ? solve_s / total_iterations : 0.0);
  solver->set_brief_report(summary.BriefReport());
  solver->set_outer_iterations(outer_done);
  solver->set_last_outer_rotation_change_deg(moved_deg);
  solver->set_last_outer_translation_change_m(moved_m);
  solver->set_last_outer_time_offset_change_s(moved_s);

  // Covariance and observability on the last problem (the extrinsic and tau
  // do not depend on the world gauge).
  start = Clock::now();
  if (params.compute_covariance()) {
    Matrix7d cov;
    const Status cs = ComputeExtrinsicCovariance(problem->problem(), &state,
                                                 static_cast<int>(params.num_threads()), &cov);
    if (cs.ok()) {
      ObservabilityThresholds th;
      th.rotation_sigma_deg = params.weak_rotation_sigma_deg();
      th.translation_sigma_m = params.weak_translation_sigma_m();
      th.time_offset_sigma_s = params.weak_time_offset_sigma_s();
      FillCovarianceReport(cov, state.ImuFromLidarRotation().toRotationMatrix(),
                           PrincipalRotationAxis(inputs.imu, state.GyroBias()), th, result);
    } else {
      proto::ObservabilityDirection* d = result->add_observability();
      d->set_weak(true);
      d->set_description(cs.message());
    }
  }
  AddTiming("covariance", Seconds(start), result);
  problem.reset();

  ReexpressInFirstImuFrame(&state);
  Rigid3d extrinsic;
  extrinsic.rotation = state.ImuFromLidarRotation();
  extrinsic.translation = state.ImuFromLidarTranslation();
  *result->mutable_imu_from_lidar() = ToProto(extrinsic);
  result->set_time_offset_s(state.time_offset_s[0]);
  *result->mutable_gravity_in_world() = ToProto(state.GravityInWorld());
  *result->mutable_gyro_bias_radps() = ToProto(state.GyroBias());
  *result->mutable_accel_bias_mps2() = ToProto(state.AccelBias());
  for (int i = 0; i < state.gyro_bias.size(); ++i) {
    *result->add_gyro_bias_segments_radps() = ToProto(state.gyro_bias.Value(i));
  }
  result->set_gyro_bias_segment_s(state.gyro_bias.segment_s);
  for (int i = 0; i < state.accel_bias.size(); ++i) {
    *result->add_accel_bias_segments_mps2() = ToProto(state.accel_bias.Value(i));
  }
  result->set_accel_bias_segment_s(state.accel_bias.segment_s);
  for (const std::string& g : ground_used) result->add_ground_residuals_used(g);
  result->set_ground_residuals_reason(ground_reason);
  AddTiming("total", Seconds(total_start), result);
  if (final_state != nullptr) *final_state = state;
  for (const proto::ObservabilityDirection& d : result->observability()) Log(log, d.description());
  Log(log, Format("done in %.2f s, %.0f LM iterations, %.3f s per iteration",
                  Seconds(total_start), total_iterations, solver->seconds_per_iteration()));
  return Status::Ok();
}

Status Run(const CalibratePaths& paths, const proto::CalibrateParams& params, std::ostream* log) {
  const auto start = Clock::now();
  CalibrateInputs inputs;
  TILTCAL_RETURN_IF_ERROR(ReadCalibrateInputs(paths, params, &inputs));
  const double read_s = Seconds(start);
  proto::CalibrationResult result;
  TILTCAL_RETURN_IF_ERROR(Calibrate(inputs, params, &result, nullptr, log));
  proto::PhaseTiming* t = result.add_timings();
  t->set_phase("read_inputs");
  t->set_seconds(read_s);
  std::vector<std::pair<std::string, std::string>> input_paths = {
      {"imu", paths.imu}, {"scans", paths.scans}, {"rig", paths.rig}};
  if (!paths.ground.empty()) input_paths.push_back({"ground", paths.ground});
  if (!paths.gravity.empty()) input_paths.push_back({"gravity", paths.gravity});
  *result.mutable_provenance() =
      MakeProvenance("tiltcal_calibrate", params, input_paths, paths.command_line);
  return WriteTextProto(paths.out, result);
}

}  // namespace tiltcal::calibrate
