#include "stages/calibrate/calibrate.h"

#include <algorithm>
#include <future>
#include <optional>

#include <fmt/format.h>

#include "common/geometry/angles.h"
#include "common/io/atomic_file.h"
#include "common/io/eigen_proto.h"
#include "common/io/imu_stream.h"
#include "common/io/provenance.h"
#include "common/io/record_stream.h"
#include "common/io/rig.h"
#include "common/io/text_proto.h"
#include "common/timing/clock_rate.h"
#include "stages/calibrate/calibration_result.h"
#include "stages/calibrate/init/initialisation.h"
#include "stages/calibrate/outer_loop.h"
#include "stages/calibrate/problem/ground_residuals.h"
#include "stages/calibrate/problem/problem_builder.h"
#include "stages/calibrate/problem/time_offset_drift.h"
#include "stages/calibrate/progress.h"
#include "stages/calibrate/report/imu_vibration.h"
#include "stages/calibrate/report/map_export.h"
#include "stages/calibrate/report/solve_check.h"
#include "stages/calibrate/report/verdict.h"

namespace tiltcal::calibrate {
namespace {

// tiltcal_decode's clock-drift note (a provenance note "clocks: ...") of
// the IMU stream, "" without.
Status ReadClockDriftNote(const std::string& imu_path, std::string* note) {
  note->clear();
  RecordReader reader;
  TILTCAL_RETURN_IF_ERROR(reader.Open(imu_path));
  const std::string prefix = timing::kClockDriftNotePrefix;
  for (const std::string& n : reader.header().provenance().notes()) {
    if (n.rfind(prefix, 0) == 0) *note = n.substr(prefix.size());
  }
  return Status::Ok();
}

}  // namespace

Status ReadCalibrateInputs(const CalibratePaths& paths, const proto::CalibrateParams& params,
                           CalibrateInputs* inputs) {
  *inputs = CalibrateInputs();
  TILTCAL_RETURN_IF_ERROR(LoadRigWithExtrinsic(paths.rig, &inputs->rig));
  TILTCAL_RETURN_IF_ERROR(
      ReadImuReadings(paths.imu, &inputs->imu, &inputs->first_imu_stamp_ns));
  inputs->imu_source = paths.imu;
  TILTCAL_RETURN_IF_ERROR(ReadClockDriftNote(paths.imu, &inputs->clock_drift));
  TILTCAL_RETURN_IF_ERROR(
      ReadLidarScans(paths.scans, inputs->first_imu_stamp_ns, params.scans(), &inputs->scans));
  if (inputs->scans.empty()) return Status::Error(paths.scans + ": no scans");
  if (!paths.ground.empty()) {
    TILTCAL_RETURN_IF_ERROR(ReadAllRecords<proto::GroundPlane>(paths.ground, &inputs->ground));
  }
  if (!paths.gravity.empty()) {
    TILTCAL_RETURN_IF_ERROR(ReadTextProto(paths.gravity, &inputs->gravity));
    if (inputs->gravity.has_gravity_flat()) {
      TILTCAL_RETURN_IF_ERROR(
          ValidateGravityFlat(inputs->gravity.gravity_flat_in_imu(), "gravity_flat_in_imu")
              .WithContext(paths.gravity));
    }
    inputs->has_gravity = true;
  }
  return Status::Ok();
}

namespace {

// The wide-window tau of the initialisation and the scans it leaves out.
void LogCoarseTimeOffset(const InitialisationReport& init, std::ostream* log) {
  const imu::AngularSpeedAlignment& a = init.coarse.alignment;
  Log(log, fmt::format("init: wide-window tau {:.4f} s (r {:.3f}, second peak {:.3f}, gyro/LiDAR "
                       "rate scale {:.3f}){}{}",
                       a.time_offset_s, a.correlation, a.second_peak_correlation, a.scale,
                       init.odometry_rerun ? "; odometry rerun at that tau" : "",
                       init.odometry_without_gyro ? " (measured on the odometry without the gyro)"
                                                  : ""));
  if (!init.coarse.trusted) {
    Log(log, "init: wide-window tau not trusted, the search starts from 0: " +
                 init.coarse.distrust_reason);
  }
  if (init.dropped_scans_outside_imu > 0) {
    Log(log, fmt::format("init: {} scans lie outside the IMU time span at tau {:.4f} s and are "
                         "not used",
                         init.dropped_scans_outside_imu, init.time_offset_center_s));
  }
}

// What the initialisation's checks of the rig rotation found.
void LogRigChecks(const InitialisationReport& init, std::ostream* log) {
  const AccelerationCheck& check = init.acceleration_check;
  Log(log, fmt::format("init: rig rotation axis off by {:.2f} deg; starting C_bl {:.2f} deg from "
                       "the rig's; acceleration yaw check {:.2f} deg ({}, RMS {:.2f} m/s^2)",
                       init.rig_axis_disagreement_deg, init.rig_rotation_correction_deg,
                       check.yaw_error_deg, check.decided ? "decided" : "not decided",
                       check.rms_horizontal_acceleration_mps2));
}

// Initialisation (initialisation.h) with its timings and log lines.
Status Initialise(const CalibrateInputs& inputs, const proto::CalibrateParams& params,
                  CalibrationState* state, InitialisationReport* init,
                  proto::CalibrationResult* result, std::ostream* log) {
  const auto start = Clock::now();
  TILTCAL_RETURN_IF_ERROR(InitialiseState(inputs.imu, inputs.scans,
                                          ToEigen(inputs.rig.imu_from_lidar()), params, state,
                                          init));
  AddTiming("init_imu", init->imu_seconds, result);
  AddTiming("init_rotation_spline", init->rotation_fit_seconds, result);
  AddTiming("init_lidar_odometry", init->odometry_seconds, result);
  AddTiming("init_position_spline", init->position_fit_seconds, result);
  Log(log, fmt::format("init: {} knots, static start {:d}, gyro fit rms {:.3f}, odometry {}/{} "
                       "scans registered",
                       state->trajectory.grid().num_knots(), init->imu.from_static_start ? 1 : 0,
                       init->gyro_fit_rms, init->odometry_registered, init->odometry_scans));
  Log(log, fmt::format("init: hand-eye excitation {:.4f} rad ({} pairs); position fit rms {:.3f}; "
                       "{:.2f} s; C_bl from {}",
                       init->hand_eye.excitation_rad, init->hand_eye.num_pairs,
                       init->position_fit_rms, Seconds(start),
                       init->rotation_from_hand_eye ? "hand-eye" : "the rig"));
  Log(log, fmt::format("init: turning {:.3f} rad RMS per pair about the motion's axis over {:.1f} s, "
                       "{:.2f} rad one way, {:.2f} rad the other",
                       init->turning.rms_about_axis_rad, init->turning.span_s,
                       init->turning.left_rad, init->turning.right_rad));
  if (init->odometry_quality_scans > 0) {
    Log(log, fmt::format("init: odometry registration quality over {} scans: inlier rms {:.1f} mm, "
                         "inliers {:.1f} %",
                         init->odometry_quality_scans, init->odometry_mean_fitness_m * 1e3,
                         init->odometry_mean_inlier_fraction * 100.0));
  }
  LogCoarseTimeOffset(*init, log);
  Log(log, fmt::format("init: rotation-axis alignment {:d} ({:.3f} deg), coarse tau {:.2f} ms",
                       init->axis_alignment_applied ? 1 : 0, init->axis_alignment_deg,
                       init->time_offset_init_s * 1e3));
  LogRigChecks(*init, log);
  const Eigen::Vector3d r = state->ImuFromLidarTranslation();
  Log(log, fmt::format("init: rotation refit rms {:.3f}; r_bl ({:.4f}, {:.4f}, {:.4f}) m from the "
                       "position fit",
                       init->rotation_refit_rms, r.x(), r.y(), r.z()));
  return Status::Ok();
}

// Ground residuals (ground_residuals.h): selected from the params
// (AUTO / ON / OFF), the rig's d_b and the gravity reference; losses must
// outlive the adder.
Status MakeGroundAdder(const CalibrateInputs& inputs, const proto::CalibrateParams& params,
                       const GroundLosses& losses, GroundAdder* ground, std::ostream* log) {
  GroundAdderInputs ground_inputs;
  ground_inputs.planes = &inputs.ground;
  ground_inputs.time_origin_ns = inputs.first_imu_stamp_ns;
  ground_inputs.rig = &inputs.rig;
  ground_inputs.gravity = inputs.has_gravity ? &inputs.gravity : nullptr;
  ground_inputs.params = &params.ground();
  ground_inputs.losses = &losses;
  TILTCAL_RETURN_IF_ERROR(MakeGroundResidualAdder(ground_inputs, ground));
  Log(log, ground->reason);
  return Status::Ok();
}

// The outer rounds' solver and problem: tau bounded about the
// initialisation's, the map planes pinning the gauge, the translation's
// prior at the rig's about the motion's rotation axis.
OuterLoopSetup MakeOuterLoopSetup(const CalibrateInputs& inputs,
                                  const proto::CalibrateParams& params,
                                  const InitialisationReport& init, const GroundAdder& ground) {
  SolverSettings solver_settings;
  solver_settings.max_iterations = static_cast<int>(params.solver().max_iterations());
  solver_settings.num_threads = static_cast<int>(params.num_threads());
  solver_settings.function_tolerance = params.solver().function_tolerance();
  solver_settings.initial_trust_region_radius = params.solver().initial_trust_region_radius();
  OuterLoopSetup setup{inputs, params, ground.add, ProblemOptions(),
                       MakeSolverOptions(solver_settings),
                       init.rotation_axis_b.normalized(),
                       std::find(ground.used.begin(), ground.used.end(), "dist") !=
                           ground.used.end()};
  ProblemOptions& problem_options = setup.problem_options;
  problem_options.time_offset_bound_s = params.time_offset_bound_s();
  problem_options.time_offset_center_s = init.time_offset_center_s;
  problem_options.time_offset_step_bound_s = params.outer_loop().time_offset_step_bound_s();
  problem_options.fix_first_knots = false;  // the fixed map planes pin the gauge
  problem_options.translation_prior_m = ToEigen(inputs.rig.imu_from_lidar()).translation;
  problem_options.translation_prior_sigma_m = params.extrinsic_translation_prior_sigma_m();
  problem_options.translation_prior_axis_b = init.rotation_axis_b;
  return setup;
}

// Clock drift (time_offset_drift.h): t_ref the middle of the scans' stamps;
// tau0 starts at the initialisation's single tau, rho at 0 or, with its
// prior, at decode's rate.
ClockDriftSetup SetUpClockDrift(const CalibrateInputs& inputs,
                                const proto::CalibrateParams& params, CalibrationState* state,
                                ProblemOptions* problem_options, std::ostream* log) {
  ClockDriftSetup drift;
  drift.span = ScanStampSpan(inputs.scans);
  state->time_reference_s = drift.span.reference_s;
  drift.decision = DecideTimeOffsetDrift(params.time_offset_drift(), inputs.clock_drift, drift.span);
  const TimeOffsetDriftDecision& decision = drift.decision;
  problem_options->estimate_clock_rate = decision.estimate;
  problem_options->clock_rate_max_ppm = params.time_offset_drift().max_rate_ppm();
  problem_options->clock_rate_half_length_s = drift.span.half_length_s();
  problem_options->clock_rate_prior = decision.prior_rho;
  problem_options->clock_rate_prior_sigma = decision.prior_sigma;
  if (decision.estimate && decision.prior_sigma > 0.0) state->clock_rate[0] = decision.prior_rho;
  Log(log, std::string("clock drift ") + (decision.estimate ? "estimated" : "not estimated") +
               ": " + decision.reason);
  return drift;
}

// IMU intrinsics (imu_intrinsics.h): ON from the first round; AUTO from
// the round after a score test finds them; OFF never, tested at the end.
void SetUpImuIntrinsics(const proto::ImuIntrinsicsParams& intrinsics,
                        ProblemOptions* problem_options) {
  problem_options->estimate_imu_intrinsics = intrinsics.mode() == proto::ImuIntrinsicsParams::ON;
  problem_options->intrinsics_scale_prior_sigma = intrinsics.scale_prior_ppm() * 1e-6;
  problem_options->intrinsics_misalignment_prior_sigma_rad =
      geometry::DegToRad(intrinsics.misalignment_prior_deg());
}

// The solved problem's report: solver, covariance, IMU intrinsics, verdict
// facts and clock drift. The map sharpness reads the state and the scans
// only: measured on another thread (two or more) while the covariance is
// computed.
void ReportSolve(const SolvedCalibration& solved, bool intrinsics_estimated,
                 proto::CalibrationResult* result, std::ostream* log) {
  const proto::CalibrateParams& params = solved.params;
  FillSolverReport(solved.loop, result);
  std::future<MapSharpnessPair> sharpness =
      std::async(params.num_threads() > 1 ? std::launch::async : std::launch::deferred,
                 MeasureBothMapSharpnesses, std::cref(solved.inputs), std::cref(params),
                 std::cref(*solved.state));
  CovarianceExtras extras;
  FillCovariance(solved, result, &extras);
  FillImuIntrinsics(params.imu_intrinsics(), solved.loop, intrinsics_estimated, *solved.state,
                    extras.intrinsics_covariance, result);
  FillVerdictFacts(solved, sharpness.get(), result);
  AddImuIntrinsicsNote(result, log);
  FillTimeOffsetDrift(solved, extras.clock_rate_row, result, log);
}

// The before/after maps of map_export.h, when their paths are given.
Status WriteMaps(const CalibratePaths& paths, const proto::CalibrateParams& params,
                 const CalibrateInputs& inputs, const CalibrationState& state, std::ostream* log) {
  const std::pair<std::string, Rigid3d> maps[] = {
      {paths.out_map_rig, ToEigen(inputs.rig.imu_from_lidar())},
      {paths.out_map_calibrated,
       Rigid3d{state.ImuFromLidarRotation(), state.ImuFromLidarTranslation()}}};
  for (const auto& [path, imu_from_lidar] : maps) {
    if (path.empty()) continue;
    const std::vector<MapPoint> points =
        BuildMapPoints(state, imu_from_lidar, inputs.scans, params.map_export(),
                       params.association().deskew_node_spacing_s());
    TILTCAL_RETURN_IF_ERROR(WriteMapPcd(path, points));
    Log(log, fmt::format("map {} ({} points)", path, points.size()));
  }
  return Status::Ok();
}

}  // namespace

Status Calibrate(const CalibrateInputs& inputs, const proto::CalibrateParams& params,
                 proto::CalibrationResult* result, CalibrationState* final_state,
                 std::ostream* log) {
  result->Clear();
  const auto total_start = Clock::now();
  std::optional<CalibrationState> new_state;
  TILTCAL_RETURN_IF_ERROR(MakeStateOverImu(inputs.imu, params, &new_state));
  CalibrationState& state = *new_state;
  InitialisationReport init;
  TILTCAL_RETURN_IF_ERROR(Initialise(inputs, params, &state, &init, result, log));
  const GroundLosses ground_losses(params.ground());
  GroundAdder ground;
  TILTCAL_RETURN_IF_ERROR(MakeGroundAdder(inputs, params, ground_losses, &ground, log));
  OuterLoopSetup setup = MakeOuterLoopSetup(inputs, params, init, ground);
  const ClockDriftSetup drift =
      SetUpClockDrift(inputs, params, &state, &setup.problem_options, log);
  result->set_translation_prior_sigma_m(setup.problem_options.translation_prior_sigma_m);
  *result->mutable_translation_prior_axis_b() = ToProto(init.rotation_axis_b.normalized());
  SetUpImuIntrinsics(params.imu_intrinsics(), &setup.problem_options);
  OuterLoop loop;
  TILTCAL_RETURN_IF_ERROR(RunOuterLoop(&setup, &state, &loop, log));
  TILTCAL_RETURN_IF_ERROR(CheckSolveUsable(loop.summary));
  ReportSolve(SolvedCalibration{inputs, params, init, drift, loop, &state},
              setup.problem_options.estimate_imu_intrinsics, result, log);
  loop.problem.reset();
  loop.sample_problem.reset();

  ReexpressInFirstImuFrame(&state);
  FillEstimate(state, ground.used, ground.reason, result);
  FillInitialisationFacts(init, result);
  AddTiming("total", Seconds(total_start), result);
  if (final_state != nullptr) *final_state = state;
  DecideVerdict(params.verdict(), result);
  for (const proto::ObservabilityDirection& d : result->observability()) Log(log, d.description());
  Log(log, fmt::format("done in {:.2f} s, {} LM iterations, {:.3f} s per iteration",
                       Seconds(total_start), loop.total_iterations,
                       result->solver().seconds_per_iteration()));
  return Status::Ok();
}

Status CalibrateSequence(const proto::CalibrateParams& params, CalibrateInputs* inputs,
                         proto::CalibrationResult* result, CalibrationState* final_state,
                         std::ostream* log) {
  proto::CalibrateParams solve = params;
  proto::ImuVibrationReport vibration;
  TILTCAL_RETURN_IF_ERROR(HandleImuVibration(params.imu_vibration(), &inputs->imu,
                                             solve.mutable_imu_noise(), &vibration)
                              .WithContext(inputs->imu_source));
  inputs->imu_decimation = vibration.decimation();
  inputs->imu_low_pass_correlation = LowPassCorrelation(vibration);
  const std::string vibration_note = DescribeImuVibration(vibration);
  if (!vibration_note.empty()) Log(log, vibration_note);
  TILTCAL_RETURN_IF_ERROR(Calibrate(*inputs, solve, result, final_state, log));
  *result->mutable_imu_vibration() = vibration;
  if (!vibration_note.empty()) result->add_verdict_notes(vibration_note);
  return Status::Ok();
}

Status Run(const CalibratePaths& paths, const proto::CalibrateParams& params, std::ostream* log,
           proto::CalibrationResult* written) {
  const auto start = Clock::now();
  TILTCAL_RETURN_IF_ERROR(CheckOutputPath(paths.out));
  CalibrateInputs inputs;
  TILTCAL_RETURN_IF_ERROR(ReadCalibrateInputs(paths, params, &inputs));
  const double read_s = Seconds(start);
  proto::CalibrationResult result;
  // Replaced by the final state (the grid here is a placeholder).
  CalibrationState final_state(
      spline::UniformKnotGrid::ForDuration(0.0, 1.0, params.spline().knot_spacing_s()));
  proto::CalibrateParams used = params;
  if (inputs.rig.has_starting_extrinsic() &&
      !inputs.rig.starting_extrinsic().translation_known()) {
    used.set_extrinsic_translation_prior_sigma_m(params.unknown_translation_prior_sigma_m());
    Log(log, fmt::format("no translation guess: prior sigma {} m at zero",
                         params.unknown_translation_prior_sigma_m()));
  }
  // The provenance keeps imu_noise as given, so that the recorded params
  // rerun to the same result.
  TILTCAL_RETURN_IF_ERROR(CalibrateSequence(used, &inputs, &result, &final_state, log));
  TILTCAL_RETURN_IF_ERROR(WriteMaps(paths, params, inputs, final_state, log));
  proto::PhaseTiming* t = result.add_timings();
  t->set_phase("read_inputs");
  t->set_seconds(read_s);
  std::vector<std::pair<std::string, std::string>> input_paths = {
      {"imu", paths.imu}, {"scans", paths.scans}, {"rig", paths.rig}};
  if (!paths.ground.empty()) input_paths.push_back({"ground", paths.ground});
  if (!paths.gravity.empty()) input_paths.push_back({"gravity", paths.gravity});
  *result.mutable_provenance() =
      MakeProvenance("tiltcal_calibrate", used, input_paths, paths.command_line);
  TILTCAL_RETURN_IF_ERROR(WriteTextProto(paths.out, result));
  if (written != nullptr) *written = std::move(result);
  return Status::Ok();
}

}  // namespace tiltcal::calibrate
