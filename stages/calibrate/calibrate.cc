#include "stages/calibrate/calibrate.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <future>
#include <memory>
#include <optional>

#include <ceres/solver.h>
#include <fmt/format.h>

#include "common/geometry/angles.h"
#include "common/geometry/translation_prior.h"
#include "common/io/atomic_file.h"
#include "common/io/eigen_proto.h"
#include "common/io/imu_stream.h"
#include "common/io/provenance.h"
#include "common/io/record_stream.h"
#include "common/io/rig.h"
#include "common/io/text_proto.h"
#include "common/timing/clock_rate.h"
#include "stages/calibrate/init/initialisation.h"
#include "stages/calibrate/problem/dense_sample_weight.h"
#include "stages/calibrate/problem/ground_residuals.h"
#include "stages/calibrate/problem/lidar_association.h"
#include "stages/calibrate/problem/problem_builder.h"
#include "stages/calibrate/problem/time_offset_drift.h"
#include "stages/calibrate/report/covariance_report.h"
#include "stages/calibrate/report/imu_intrinsics.h"
#include "stages/calibrate/report/imu_vibration.h"
#include "stages/calibrate/report/map_export.h"
#include "stages/calibrate/report/map_sharpness.h"
#include "stages/calibrate/report/residual_statistics.h"
#include "stages/calibrate/report/solve_check.h"
#include "stages/calibrate/report/verdict.h"

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

// The initialisation's findings for the verdict (CalibrationResult 80-89)
// and its odometry's counts and registration quality (111-115).
void FillInitialisationFacts(const InitialisationReport& init, proto::CalibrationResult* result) {
  result->set_odometry_scans(init.odometry_scans);
  result->set_odometry_registered_scans(init.odometry_registered);
  result->set_odometry_quality_scans(init.odometry_quality_scans);
  result->set_odometry_mean_fitness_m(init.odometry_mean_fitness_m);
  result->set_odometry_mean_inlier_fraction(init.odometry_mean_inlier_fraction);
  result->set_coarse_time_offset_s(init.coarse.alignment.time_offset_s);
  result->set_coarse_time_offset_correlation(init.coarse.alignment.correlation);
  result->set_coarse_time_offset_second_peak_correlation(
      init.coarse.alignment.second_peak_correlation);
  result->set_coarse_time_offset_trusted(init.coarse.trusted);
  result->set_gyro_to_lidar_rate_scale(init.coarse.alignment.scale);
  result->set_rig_rotation_correction_deg(init.rig_rotation_correction_deg);
  result->set_dropped_scans_outside_imu(init.dropped_scans_outside_imu);
  result->set_rig_rotation_axis_disagreement_deg(init.rig_axis_disagreement_deg);
  result->set_rig_yaw_error_from_accelerations_deg(init.acceleration_check.yaw_error_deg);
  result->set_acceleration_check_decided(init.acceleration_check.decided);
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

// The outer iterations' running totals and the last round's problem.
struct OuterLoop {
  std::unique_ptr<CalibrationProblem> problem;
  // The last round drawn with AssociationParams `association`, kept when the
  // final round (OuterLoopParams.final_association) solves a denser sample:
  // the variance factor, the residual statistics and the intrinsics' score
  // test read it at the final estimate (ReportProblem); the final problem's
  // residuals are down-weighted (dense_sample_weight.h), so their RMS says
  // nothing of the noise.
  std::unique_ptr<CalibrationProblem> sample_problem;
  ceres::Solver::Summary summary;
  std::vector<LidarPointResidual> lidar;
  double map_s = 0, assoc_s = 0, build_s = 0, solve_s = 0, solve_cpu_s = 0;
  int total_iterations = 0;
  double first_initial_cost = -1.0;
  bool converged = false;
  std::string termination;
  int rounds = 0;
  // The trust-region radius the last solve ended with (0: no solve yet).
  double last_trust_region_radius = 0.0;
  // How far the last round moved C_bl (deg), r_b^{lb} (m) and tau (s).
  double moved_deg = 0.0, moved_m = 0.0, moved_s = 0.0;
  // The last score test of the IMU intrinsics (imu_intrinsics.h), the
  // round after which it ran (0: none) and whether it found them.
  ImuIntrinsicsScore intrinsics_score;
  int intrinsics_score_round = 0;
  bool intrinsics_found = false;
};

// The problem the covariance and the verdict read (see OuterLoop).
CalibrationProblem* ReportProblem(const OuterLoop& loop) {
  return loop.sample_problem ? loop.sample_problem.get() : loop.problem.get();
}

// What every outer round uses and does not change.
struct OuterLoopSetup {
  const CalibrateInputs& inputs;
  const proto::CalibrateParams& params;
  const ExtraResidualAdder& ground_adder;
  ProblemOptions problem_options;
  ceres::Solver::Options solver_options;
  // Motion's principal rotation axis (unit, frame b) and whether the distance
  // residual observes the translation along it.
  Eigen::Vector3d axis_b;
  bool translation_along_axis_observed;
};

// One round: surfel map + association with the current state, problem
// build, LM solve. `association` draws the LiDAR sample; with
// reference_lidar_residuals > 0 it stands for a sample of that size
// (dense_sample_weight.h). Sets *settled when the round moved the extrinsic
// by less than the OuterLoopParams stop thresholds (from the second round
// on).
Status RunOuterRound(const OuterLoopSetup& setup, const proto::AssociationParams& association,
                     size_t reference_lidar_residuals, CalibrationState* state, OuterLoop* loop,
                     bool* settled, std::ostream* log) {
  const proto::CalibrateParams& params = setup.params;
  const int round = loop->rounds + 1;
  const Eigen::Quaterniond rotation_before = state->ImuFromLidarRotation();
  const Eigen::Vector3d translation_before = state->ImuFromLidarTranslation();
  const double tau_before = state->time_offset_s[0];
  const double rho_before = state->clock_rate[0];
  AssociationStageSummary assoc;
  BuildMapAndAssociate(*state, setup.inputs.scans, params.map(), association,
                       static_cast<int>(params.num_threads()), &loop->lidar, &assoc);
  loop->map_s += assoc.map_seconds;
  loop->assoc_s += assoc.associate_seconds;
  if (loop->lidar.empty()) {
    return Status::Error("no LiDAR point could be associated with a planar surfel (" +
                         std::to_string(assoc.map.num_surfels) + " surfels in the map)");
  }
  auto start = Clock::now();
  loop->problem.reset();
  const proto::LidarResidualParams lidar = DenseSampleLidarParams(
      params.lidar(), loop->lidar.size(), reference_lidar_residuals,
      params.outer_loop().final_lidar_information_exponent());
  loop->problem = std::make_unique<CalibrationProblem>(state, params.imu_noise(), lidar,
                                                       setup.problem_options);
  loop->problem->AddImuResiduals(setup.inputs.imu, true, true);
  loop->problem->AddLidarResiduals(loop->lidar);
  TILTCAL_RETURN_IF_ERROR(loop->problem->AddExtraResiduals(setup.ground_adder));
  loop->problem->RemoveUnusedKnots();
  loop->build_s += Seconds(start);
  start = Clock::now();
  const double cpu_start = CpuSeconds();
  ceres::Solver::Options solver_options = setup.solver_options;
  if (params.solver().warm_start_trust_region() && loop->last_trust_region_radius > 0.0) {
    solver_options.initial_trust_region_radius =
        std::clamp(loop->last_trust_region_radius, solver_options.initial_trust_region_radius,
                   solver_options.max_trust_region_radius);
  }
  ceres::Solve(solver_options, loop->problem->problem(), &loop->summary);
  if (!loop->summary.iterations.empty()) {
    loop->last_trust_region_radius = loop->summary.iterations.back().trust_region_radius;
  }
  const double solve_seconds = Seconds(start);
  loop->solve_cpu_s += CpuSeconds() - cpu_start;
  loop->solve_s += solve_seconds;
  const ceres::Solver::Summary& summary = loop->summary;
  loop->total_iterations += static_cast<int>(summary.iterations.size()) - 1;
  if (loop->first_initial_cost < 0) loop->first_initial_cost = summary.initial_cost;
  loop->converged = summary.termination_type == ceres::CONVERGENCE;
  loop->termination = ceres::TerminationTypeToString(summary.termination_type);
  const Eigen::Vector3d r = state->ImuFromLidarTranslation();
  Log(log, fmt::format("outer {}: {} surfels, {} lidar residuals, cost {:.4g} -> {:.4g}", round,
                       assoc.map.num_surfels, assoc.residuals, summary.initial_cost,
                       summary.final_cost));
  const Eigen::Quaterniond q = state->ImuFromLidarRotation();
  Log(log, fmt::format("outer {}: {} LM iterations in {:.2f} s; tau {:.3f} ms; r_bl ({:.4f}, "
                       "{:.4f}, {:.4f}) m; q_bl (w {:.7f}, x {:.7f}, y {:.7f}, z {:.7f})",
                       round, static_cast<int>(summary.iterations.size()) - 1, solve_seconds,
                       state->time_offset_s[0] * 1e3, r.x(), r.y(), r.z(), q.w(), q.x(), q.y(),
                       q.z()));
  loop->rounds = round;
  loop->moved_deg =
      geometry::RadToDeg(
          Eigen::AngleAxisd(rotation_before.conjugate() * state->ImuFromLidarRotation()).angle());
  // Without the distance residual the translation along the motion's
  // rotation axis is held only by its prior (planar motion): it wanders by
  // millimetres per round and takes no part in the stop test.
  Eigen::Vector3d moved_b = state->ImuFromLidarTranslation() - translation_before;
  if (!setup.translation_along_axis_observed) {
    moved_b -= setup.axis_b * setup.axis_b.dot(moved_b);
  }
  loop->moved_m = moved_b.norm();
  loop->moved_s = std::abs(state->time_offset_s[0] - tau_before);
  if (setup.problem_options.estimate_clock_rate) {
    // tau at the scans' ends moved by the rate's change times the half span.
    const double rho_moved = std::abs(state->clock_rate[0] - rho_before);
    loop->moved_s =
        std::max(loop->moved_s, rho_moved * setup.problem_options.clock_rate_half_length_s);
    Log(log, fmt::format("outer {}: clock rate {:+.2f} ppm (LiDAR against IMU), moved {:.2f} ppm",
                         round, -state->clock_rate[0] * 1e6, rho_moved * 1e6));
  }
  const proto::OuterLoopParams& stop = params.outer_loop();
  *settled = round >= 2 && loop->moved_deg < stop.stop_rotation_deg() &&
             loop->moved_m < stop.stop_translation_m() &&
             loop->moved_s < stop.stop_time_offset_s();
  Log(log, fmt::format("outer {}: extrinsic moved {:.4f} deg, {:.2f} mm, tau {:.3f} ms{}", round,
                       loop->moved_deg, loop->moved_m * 1e3, loop->moved_s * 1e3,
                       *settled ? ": stop" : ""));
  return Status::Ok();
}

// Timings, problem size and solver report of the outer loop.
void FillSolverReport(const OuterLoop& loop, proto::CalibrationResult* result) {
  AddTiming("map", loop.map_s, result);
  AddTiming("association", loop.assoc_s, result);
  AddTiming("problem_build", loop.build_s, result);
  AddTiming("solve", loop.solve_s, result);
  // CPU time of the solves summed over threads (on a loaded machine the
  // steadier figure; wall ~ cpu / threads on idle cores).
  AddTiming("solve_cpu", loop.solve_cpu_s, result);

  const ProblemCounts counts = loop.problem->counts();
  proto::ProblemSize* size = result->mutable_problem_size();
  size->set_knots(counts.knots);
  size->set_gyro_residuals(counts.gyro_residuals);
  size->set_accel_residuals(counts.accel_residuals);
  size->set_lidar_residuals(counts.lidar_residuals);
  size->set_ground_residuals(counts.ground_residuals);
  size->set_parameters(counts.free_parameters);

  proto::SolverReport* solver = result->mutable_solver();
  solver->set_converged(loop.converged);
  solver->set_termination(loop.termination);
  solver->set_iterations(loop.total_iterations);
  solver->set_initial_cost(loop.first_initial_cost);
  solver->set_final_cost(loop.summary.final_cost);
  solver->set_seconds_per_iteration(
      loop.total_iterations > 0 ? loop.solve_s / loop.total_iterations : 0.0);
  solver->set_brief_report(loop.summary.BriefReport());
  solver->set_outer_iterations(loop.rounds);
  solver->set_last_outer_rotation_change_deg(loop.moved_deg);
  solver->set_last_outer_translation_change_m(loop.moved_m);
  solver->set_last_outer_time_offset_change_s(loop.moved_s);
}

// The score test of the IMU intrinsics on the last round's problem (they
// are held there), logged with what it points to.
Status TestImuIntrinsics(const proto::CalibrateParams& params, CalibrationState* state,
                         OuterLoop* loop, std::ostream* log) {
  const proto::ImuIntrinsicsParams& intrinsics = params.imu_intrinsics();
  TILTCAL_RETURN_IF_ERROR(ScoreTestImuIntrinsics(ReportProblem(*loop)->problem(), state, intrinsics,
                                                 static_cast<int>(params.num_threads()),
                                                 &loop->intrinsics_score));
  const ImuIntrinsicsScore& score = loop->intrinsics_score;
  loop->intrinsics_score_round = loop->rounds;
  loop->intrinsics_found = score.chi2 > intrinsics.min_score_chi2();
  const proto::ImuTriadEstimate gyro = DescribeTriad(score.gyro_triad_errors, {}, {});
  Log(log, fmt::format("outer {}: IMU intrinsics score {:.1f} over {} (variance factor {:.2f}, "
                       "limit {:.1f}): {}; they point to gyro scale ({:.0f}, {:.0f}, {:.0f}) ppm",
                       loop->rounds, score.chi2, score.dof, score.sigma0_squared,
                       intrinsics.min_score_chi2(),
                       loop->intrinsics_found ? "found" : "not found", gyro.scale_ppm().x(),
                       gyro.scale_ppm().y(), gyro.scale_ppm().z()));
  return Status::Ok();
}

// The IMU intrinsics' report: estimated values with the sigmas of their
// marginal covariance (12x12, may be empty), or the score test's one-step
// values.
void FillImuIntrinsics(const proto::ImuIntrinsicsParams& params, const OuterLoop& loop,
                       bool estimated, const CalibrationState& state,
                       const Eigen::MatrixXd& covariance, proto::CalibrationResult* result) {
  proto::ImuIntrinsicsReport* report = result->mutable_imu_intrinsics();
  report->set_mode(proto::ImuIntrinsicsParams::Mode_Name(params.mode()));
  report->set_estimated(estimated);
  report->set_score_round(loop.intrinsics_score_round);
  if (loop.intrinsics_score_round > 0) {
    report->set_score_chi2(loop.intrinsics_score.chi2);
    report->set_score_dof(loop.intrinsics_score.dof);
    report->set_found(loop.intrinsics_found);
  }
  if (estimated) {
    const bool has_covariance = covariance.rows() == 12;
    *report->mutable_gyro() =
        DescribeTriad(state.gyro_triad_errors, GyroErrorEntries(),
                      has_covariance ? Eigen::MatrixXd(covariance.topLeftCorner(6, 6))
                                     : Eigen::MatrixXd());
    *report->mutable_accel() =
        DescribeTriad(state.accel_triad_errors, AccelErrorEntries(),
                      has_covariance ? Eigen::MatrixXd(covariance.bottomRightCorner(6, 6))
                                     : Eigen::MatrixXd());
    for (std::string& name : UndeterminedIntrinsics(covariance, params)) {
      report->add_undetermined(std::move(name));
    }
  } else if (loop.intrinsics_score_round > 0) {
    *report->mutable_gyro() = DescribeTriad(loop.intrinsics_score.gyro_triad_errors, {}, {});
    *report->mutable_accel() = DescribeTriad(loop.intrinsics_score.accel_triad_errors, {}, {});
  }
}

// The estimated IMU intrinsics as a verdict note (and on stderr): values,
// sigmas and what the motion left at the prior.
void AddImuIntrinsicsNote(proto::CalibrationResult* result, std::ostream* log) {
  const proto::ImuIntrinsicsReport& k = result->imu_intrinsics();
  if (!k.estimated()) return;
  auto triad = [](const proto::ImuTriadEstimate& t) {
    return fmt::format("scale ({:.0f}, {:.0f}, {:.0f}) +- ({:.0f}, {:.0f}, {:.0f}) ppm, "
                       "misalignment ({:.3f}, {:.3f}, {:.3f}) +- ({:.3f}, {:.3f}, {:.3f}) deg",
                       t.scale_ppm().x(), t.scale_ppm().y(), t.scale_ppm().z(),
                       t.scale_sigma_ppm().x(), t.scale_sigma_ppm().y(), t.scale_sigma_ppm().z(),
                       t.misalignment_deg().x(), t.misalignment_deg().y(),
                       t.misalignment_deg().z(), t.misalignment_sigma_deg().x(),
                       t.misalignment_sigma_deg().y(), t.misalignment_sigma_deg().z());
  };
  std::string line = "IMU intrinsics estimated (imu_intrinsics.mode " + k.mode();
  if (k.score_round() > 0) {
    line += fmt::format(": score {:.0f} over {} after round {}", k.score_chi2(), k.score_dof(),
                        k.score_round());
  }
  line += "): gyroscope " + triad(k.gyro()) + "; accelerometer " + triad(k.accel());
  if (k.undetermined_size() > 0) {
    line += "; not determined by this motion (held near the prior): ";
    for (int i = 0; i < k.undetermined_size(); ++i) {
      line += (i > 0 ? ", " : "") + k.undetermined(i);
    }
  }
  result->add_verdict_notes(line);
  Log(log, line);
}

// The clock drift's report (time_offset_drift.h) from the last problem and
// the covariance's rho row, its observability entry, and, when rho was
// estimated, its verdict note (also on stderr).
void FillTimeOffsetDrift(const proto::CalibrateParams& params,
                         const TimeOffsetDriftDecision& decision, const ScanTimeSpan& span,
                         const CalibrationState& state, const CalibrationProblem& problem,
                         const std::vector<double>& clock_rate_row,
                         proto::CalibrationResult* result, std::ostream* log) {
  const double sigma_tau = result->time_offset_sigma_s();
  proto::TimeOffsetDriftReport* report = result->mutable_time_offset_drift();
  FillTimeOffsetDriftReport(params.time_offset_drift(), decision, span, state.time_offset_s[0],
                            state.clock_rate[0],
                            {problem.clock_rate_lower(), problem.clock_rate_upper()},
                            clock_rate_row, sigma_tau * sigma_tau,
                            params.observability().weak_time_offset_sigma_s(), report);
  AddClockRateObservability(*report, params.observability(), result);
  const std::string note = DescribeTimeOffsetDrift(*report);
  if (note.empty()) return;
  result->add_verdict_notes(note);
  Log(log, note);
}

// Covariance and observability on the last problem (the extrinsic and tau do
// not depend on the world gauge).
// *intrinsics_covariance: that of the IMU intrinsics when they are estimated
// (covariance_report.h), else empty.
// *clock_rate_row: rho's row of the covariance (covariance_report.h), scaled
// as the 7x7 (its prior of sigma clock_rate_prior_sigma, 0 = none, kept like
// the translation's), when the drift is estimated; else empty.
// The information is `problem`'s, the variance factor `noise_problem`'s (the
// residuals of the default sample: ReportProblem).
void FillCovariance(const CalibrateInputs& inputs, const proto::CalibrateParams& params,
                    CalibrationProblem* problem, CalibrationProblem* noise_problem,
                    CalibrationState* state, double clock_rate_prior_sigma,
                    proto::CalibrationResult* result, Eigen::MatrixXd* intrinsics_covariance,
                    std::vector<double>* clock_rate_row) {
  const auto start = Clock::now();
  intrinsics_covariance->resize(0, 0);
  clock_rate_row->clear();
  if (params.observability().compute_covariance()) {
    Matrix7d cov;
    Status cs = ComputeExtrinsicCovariance(
        problem->problem(), state, params.observability(), static_cast<int>(params.num_threads()),
        &cov, intrinsics_covariance,
        ClockRateInProblem(*state, *problem->problem()) ? clock_rate_row : nullptr);
    if (cs.ok()) {
      const VarianceFactor factor = ComputeVarianceFactor(noise_problem->problem());
      result->set_variance_factor(factor.sigma0_squared);
      result->set_redundancy(factor.redundancy);
      // Low-passed IMU readings (imu_vibration.h) are not white: their
      // residuals' RMS says nothing of their noise, so a factor below 1
      // must not shrink the covariance on their account.
      const bool shrink_allowed = inputs.imu_decimation == 1 || factor.sigma0_squared > 1.0;
      if (params.observability().scale_by_variance_factor() && factor.redundancy > 0 &&
          shrink_allowed) {
        Matrix7d prior_information = Matrix7d::Zero();
        prior_information.block<3, 3>(3, 3) = geometry::TranslationPriorInformation(
            result->translation_prior_sigma_m(), ToEigen(result->translation_prior_axis_b()));
        if (clock_rate_row->size() == 8) {
          // The 7 and rho together; rho's prior (decode's rate) kept unscaled.
          Eigen::MatrixXd full = Eigen::MatrixXd::Zero(8, 8);
          full.topLeftCorner<7, 7>() = cov;
          for (int j = 0; j < 8; ++j) {
            full(7, j) = full(j, 7) = (*clock_rate_row)[static_cast<size_t>(j)];
          }
          Eigen::MatrixXd prior_full = Eigen::MatrixXd::Zero(8, 8);
          prior_full.topLeftCorner<7, 7>() = prior_information;
          if (clock_rate_prior_sigma > 0.0) {
            prior_full(7, 7) = 1.0 / (clock_rate_prior_sigma * clock_rate_prior_sigma);
          }
          full = ScaleDataInformation(full, prior_full, factor.sigma0_squared);
          cov = full.topLeftCorner<7, 7>();
          for (int j = 0; j < 8; ++j) (*clock_rate_row)[static_cast<size_t>(j)] = full(7, j);
        } else {
          cov = ScaleDataInformation(cov, prior_information, factor.sigma0_squared);
        }
        result->set_covariance_scaled_by_variance_factor(true);
      }
      // A covariance that is not finite is no covariance (SUSPECT), never
      // NaN sigmas next to an OK verdict.
      if (!cov.allFinite()) cs = Status::Error("covariance: not finite");
      for (const double c : *clock_rate_row) {
        if (!std::isfinite(c)) cs = Status::Error("covariance: the clock rate's is not finite");
      }
    }
    if (cs.ok()) {
      const MotionAxis motion = PrincipalRotationAxis(inputs.imu, state->GyroBias());
      *result->mutable_motion_rotation_axis_b() = ToProto(motion.axis_b);
      FillCovarianceReport(cov, state->ImuFromLidarRotation().toRotationMatrix(), motion,
                           params.observability(), result);
    } else {
      clock_rate_row->clear();
      proto::ObservabilityDirection* d = result->add_observability();
      d->set_weak(true);
      d->set_description(cs.message());
    }
  }
  AddTiming("covariance", Seconds(start), result);
}

// The estimate (state already in the gauge C_ab(t0) = 1, r_a^{ba}(t0) = 0)
// and the ground residuals used.
void FillEstimate(const CalibrationState& state, const std::vector<std::string>& ground_used,
                  const std::string& ground_reason, proto::CalibrationResult* result) {
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
}

// The map sharpness with the estimate and with the rig's extrinsic.
struct MapSharpnessPair {
  proto::MapSharpness estimate;
  proto::MapSharpness rig;
  double seconds = 0.0;  // of both measurements, on whichever thread ran them
};

MapSharpnessPair MeasureBothMapSharpnesses(const CalibrateInputs& inputs,
                                           const proto::CalibrateParams& params,
                                           const CalibrationState& state) {
  const auto start = Clock::now();
  const Rigid3d rig = ToEigen(inputs.rig.imu_from_lidar());
  const double spacing_s = params.association().deskew_node_spacing_s();
  MapSharpnessPair out;
  out.estimate = MeasureMapSharpness(state, inputs.scans, params.map(), spacing_s);
  CalibrationState with_rig = state;
  with_rig.SetImuFromLidarRotation(rig.rotation);
  with_rig.SetImuFromLidarTranslation(rig.translation);
  out.rig = MeasureMapSharpness(with_rig, inputs.scans, params.map(), spacing_s);
  out.seconds = Seconds(start);
  return out;
}

// The sequence rig's starting extrinsic (initial_extrinsic.h) against the
// estimate, and the bag's /tf_static against it, as verdict notes.
void FillStartingExtrinsicNotes(const proto::Rig& rig, const CalibrationState& state,
                                proto::CalibrationResult* result) {
  result->clear_verdict_notes();
  if (!rig.has_starting_extrinsic()) return;
  const proto::StartingExtrinsic& start = rig.starting_extrinsic();
  *result->mutable_starting_extrinsic() = start;
  const Eigen::Quaterniond c_bl = state.ImuFromLidarRotation();
  const Eigen::Vector3d r_bl = state.ImuFromLidarTranslation();
  auto rotation_deg = [&](const Rigid3d& t) {
    return geometry::RadToDeg(Eigen::AngleAxisd(t.rotation.conjugate() * c_bl).angle());
  };
  std::string line = "starting extrinsic: " + start.summary();
  if (start.has_guess()) {
    const Rigid3d guess = ToEigen(start.guess());
    result->set_rotation_from_guess_deg(rotation_deg(guess));
    result->set_translation_from_guess_m((r_bl - guess.translation).norm());
    line += fmt::format("; the estimate is {:.2f} deg and {:.3f} m from that guess",
                        result->rotation_from_guess_deg(), result->translation_from_guess_m());
  }
  result->add_verdict_notes(line);
  if (start.has_tf_static()) {
    const Rigid3d tf = ToEigen(start.tf_static());
    result->add_verdict_notes(fmt::format(
        "the bag's /tf_static (the vehicle's URDF) differs from the estimate by {:.2f} deg and "
        "{:.1f} cm",
        rotation_deg(tf), (r_bl - tf.translation).norm() * 100.0));
  }
}

// What the verdict is decided from besides the estimate and the covariance:
// residual statistics and tau bounds of the last problem, the map sharpness
// with the estimate and with the rig's extrinsic (same trajectory and tau,
// measured by MeasureBothMapSharpnesses),
// the move from the rig, hand-eye and static start.
void FillVerdictFacts(const CalibrateInputs& inputs, const proto::CalibrateParams& params,
                      const InitialisationReport& init, CalibrationProblem* problem,
                      const CalibrationState& state, MapSharpnessPair sharpness,
                      proto::CalibrationResult* result) {
  const auto start = Clock::now();
  result->clear_residual_statistics();
  for (proto::ResidualStatistics& s :
       ComputeResidualStatistics(problem->problem(), state, params.residual_time_series())) {
    *result->add_residual_statistics() = std::move(s);
  }
  result->set_time_offset_lower_bound_s(problem->time_offset_lower_s());
  result->set_time_offset_upper_bound_s(problem->time_offset_upper_s());

  *result->mutable_map_sharpness_estimate() = std::move(sharpness.estimate);
  *result->mutable_map_sharpness_rig() = std::move(sharpness.rig);
  const Rigid3d rig = ToEigen(inputs.rig.imu_from_lidar());

  const Eigen::Quaterniond c_bl = state.ImuFromLidarRotation();
  *result->mutable_rig_imu_from_lidar() = ToProto(rig);
  result->set_rotation_from_rig_deg(
      geometry::RadToDeg(Eigen::AngleAxisd(rig.rotation.conjugate() * c_bl).angle()));
  result->set_translation_from_rig_m((state.ImuFromLidarTranslation() - rig.translation).norm());
  result->set_hand_eye_used(init.rotation_from_hand_eye);
  if (init.rotation_from_hand_eye) {
    result->set_hand_eye_disagreement_deg(
        geometry::RadToDeg(
            Eigen::AngleAxisd(init.hand_eye.imu_from_lidar_rotation.conjugate() * c_bl).angle()));
  }
  result->set_static_start(init.imu.from_static_start);
  result->set_static_samples(init.imu.num_samples_averaged * inputs.imu_decimation);
  result->set_clock_drift(inputs.clock_drift);
  FillStartingExtrinsicNotes(inputs.rig, state, result);
  AddTiming("verdict_facts", Seconds(start), result);
  AddTiming("map_sharpness", sharpness.seconds, result);
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

  // Ground residuals (ground_residuals.h): selected from the params
  // (AUTO / ON / OFF), the rig's d_b and the gravity reference.
  std::vector<std::string> ground_used;
  std::string ground_reason;
  const GroundLosses ground_losses(params.ground());
  ExtraResidualAdder ground_adder;
  TILTCAL_RETURN_IF_ERROR(MakeGroundResidualAdder(
      inputs.ground, inputs.first_imu_stamp_ns, inputs.rig,
      inputs.has_gravity ? &inputs.gravity : nullptr, params.ground(), &ground_losses, nullptr,
      &ground_adder, &ground_used, &ground_reason));
  Log(log, ground_reason);

  SolverSettings solver_settings;
  solver_settings.max_iterations = static_cast<int>(params.solver().max_iterations());
  solver_settings.num_threads = static_cast<int>(params.num_threads());
  solver_settings.function_tolerance = params.solver().function_tolerance();
  solver_settings.initial_trust_region_radius = params.solver().initial_trust_region_radius();
  OuterLoopSetup setup{inputs, params, ground_adder, ProblemOptions(),
                       MakeSolverOptions(solver_settings),
                       init.rotation_axis_b.normalized(),
                       std::find(ground_used.begin(), ground_used.end(), "dist") !=
                           ground_used.end()};
  ProblemOptions& problem_options = setup.problem_options;
  problem_options.time_offset_bound_s = params.time_offset_bound_s();
  problem_options.time_offset_center_s = init.time_offset_center_s;
  problem_options.time_offset_step_bound_s = params.outer_loop().time_offset_step_bound_s();
  problem_options.fix_first_knots = false;  // the fixed map planes pin the gauge
  problem_options.translation_prior_m = ToEigen(inputs.rig.imu_from_lidar()).translation;
  problem_options.translation_prior_sigma_m = params.extrinsic_translation_prior_sigma_m();
  problem_options.translation_prior_axis_b = init.rotation_axis_b;
  // Clock drift (time_offset_drift.h): t_ref the middle of the scans' stamps;
  // tau0 starts at the initialisation's single tau, rho at 0 or, with its
  // prior, at decode's rate.
  const ScanTimeSpan span = ScanStampSpan(inputs.scans);
  state.time_reference_s = span.reference_s;
  const TimeOffsetDriftDecision drift =
      DecideTimeOffsetDrift(params.time_offset_drift(), inputs.clock_drift, span);
  problem_options.estimate_clock_rate = drift.estimate;
  problem_options.clock_rate_max_ppm = params.time_offset_drift().max_rate_ppm();
  problem_options.clock_rate_half_length_s = span.half_length_s();
  problem_options.clock_rate_prior = drift.prior_rho;
  problem_options.clock_rate_prior_sigma = drift.prior_sigma;
  if (drift.estimate && drift.prior_sigma > 0.0) state.clock_rate[0] = drift.prior_rho;
  Log(log, std::string("clock drift ") + (drift.estimate ? "estimated" : "not estimated") + ": " +
               drift.reason);
  result->set_translation_prior_sigma_m(problem_options.translation_prior_sigma_m);
  *result->mutable_translation_prior_axis_b() = ToProto(init.rotation_axis_b.normalized());
  // IMU intrinsics (imu_intrinsics.h): ON from the first round; AUTO from
  // the round after a score test finds them; OFF never, tested at the end.
  const proto::ImuIntrinsicsParams& intrinsics = params.imu_intrinsics();
  problem_options.estimate_imu_intrinsics = intrinsics.mode() == proto::ImuIntrinsicsParams::ON;
  problem_options.intrinsics_scale_prior_sigma = intrinsics.scale_prior_ppm() * 1e-6;
  problem_options.intrinsics_misalignment_prior_sigma_rad =
      geometry::DegToRad(intrinsics.misalignment_prior_deg());
  OuterLoop loop;
  bool settled = false;
  int max_rounds = static_cast<int>(params.outer_loop().iterations());
  while (loop.rounds < max_rounds && !settled) {
    TILTCAL_RETURN_IF_ERROR(
        RunOuterRound(setup, params.association(), 0, &state, &loop, &settled, log));
    if (intrinsics.mode() == proto::ImuIntrinsicsParams::AUTO &&
        !problem_options.estimate_imu_intrinsics) {
      TILTCAL_RETURN_IF_ERROR(TestImuIntrinsics(params, &state, &loop, log));
      if (loop.intrinsics_found) {
        // At least one round with them.
        problem_options.estimate_imu_intrinsics = true;
        settled = false;
        max_rounds = std::max(max_rounds, loop.rounds + 1);
      }
    }
  }
  if (params.outer_loop().has_final_association()) {
    // The final round: a denser sample, weighted as (n / n_default)^e times
    // the default sample's information (dense_sample_weight.h); the default
    // sample's problem is kept for the variance factor, the residual
    // statistics and the score test.
    Log(log, "final round: the denser association (outer_loop.final_association)");
    const size_t sample_residuals = loop.lidar.size();
    loop.sample_problem = std::move(loop.problem);
    TILTCAL_RETURN_IF_ERROR(RunOuterRound(setup, params.outer_loop().final_association(),
                                          sample_residuals, &state, &loop, &settled, log));
  }
  if (intrinsics.mode() == proto::ImuIntrinsicsParams::OFF) {
    TILTCAL_RETURN_IF_ERROR(TestImuIntrinsics(params, &state, &loop, log));
  }
  TILTCAL_RETURN_IF_ERROR(CheckSolveUsable(loop.summary));
  FillSolverReport(loop, result);
  // The map sharpness reads the state and the scans only: measured on
  // another thread (two or more) while the covariance is computed.
  std::future<MapSharpnessPair> sharpness =
      std::async(params.num_threads() > 1 ? std::launch::async : std::launch::deferred,
                 MeasureBothMapSharpnesses, std::cref(inputs), std::cref(params), std::cref(state));
  Eigen::MatrixXd intrinsics_covariance;
  std::vector<double> clock_rate_row;
  FillCovariance(inputs, params, loop.problem.get(), ReportProblem(loop), &state,
                 problem_options.clock_rate_prior_sigma, result, &intrinsics_covariance,
                 &clock_rate_row);
  FillImuIntrinsics(intrinsics, loop, problem_options.estimate_imu_intrinsics, state,
                    intrinsics_covariance, result);
  FillVerdictFacts(inputs, params, init, ReportProblem(loop), state, sharpness.get(), result);
  AddImuIntrinsicsNote(result, log);
  FillTimeOffsetDrift(params, drift, span, state, *loop.problem, clock_rate_row, result, log);
  loop.problem.reset();
  loop.sample_problem.reset();

  ReexpressInFirstImuFrame(&state);
  FillEstimate(state, ground_used, ground_reason, result);
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
  // The solve weighs filtered readings with the thinned sigmas
  // (imu_vibration.h); the provenance keeps imu_noise as given, so that the
  // recorded params rerun to the same result.
  proto::CalibrateParams solve = used;
  proto::ImuVibrationReport vibration;
  TILTCAL_RETURN_IF_ERROR(HandleImuVibration(params.imu_vibration(), &inputs.imu,
                                             solve.mutable_imu_noise(), &vibration)
                              .WithContext(paths.imu));
  inputs.imu_decimation = vibration.decimation();
  const std::string vibration_note = DescribeImuVibration(vibration);
  if (!vibration_note.empty()) Log(log, vibration_note);
  TILTCAL_RETURN_IF_ERROR(Calibrate(inputs, solve, &result, &final_state, log));
  *result.mutable_imu_vibration() = vibration;
  if (!vibration_note.empty()) result.add_verdict_notes(vibration_note);
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
