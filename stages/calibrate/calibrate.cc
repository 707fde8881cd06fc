#include "stages/calibrate/calibrate.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <memory>

#include <ceres/solver.h>
#include <fmt/format.h>

#include "common/io/eigen_proto.h"
#include "common/io/imu_stream.h"
#include "common/io/provenance.h"
#include "common/io/record_stream.h"
#include "common/io/rig.h"
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

}  // namespace

Status ReadCalibrateInputs(const CalibratePaths& paths, const proto::CalibrateParams& params,
                           CalibrateInputs* inputs) {
  *inputs = CalibrateInputs();
  TILTCAL_RETURN_IF_ERROR(LoadRig(paths.rig, &inputs->rig));
  TILTCAL_RETURN_IF_ERROR(
      ReadImuReadings(paths.imu, &inputs->imu, &inputs->first_imu_stamp_ns));
  TILTCAL_RETURN_IF_ERROR(
      ReadLidarScans(paths.scans, inputs->first_imu_stamp_ns, params.scans(), &inputs->scans));
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

namespace {

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
  Log(log, fmt::format("init: rotation-axis alignment {:d} ({:.3f} deg), coarse tau {:.2f} ms",
                       init->axis_alignment_applied ? 1 : 0, init->axis_alignment_deg,
                       init->time_offset_init_s * 1e3));
  const Eigen::Vector3d r = state->ImuFromLidarTranslation();
  Log(log, fmt::format("init: rotation refit rms {:.3f}; r_bl ({:.4f}, {:.4f}, {:.4f}) m from the "
                       "position fit",
                       init->rotation_refit_rms, r.x(), r.y(), r.z()));
  return Status::Ok();
}

// The outer iterations' running totals and the last round's problem.
struct OuterLoop {
  std::unique_ptr<CalibrationProblem> problem;
  ceres::Solver::Summary summary;
  std::vector<LidarPointResidual> lidar;
  double map_s = 0, assoc_s = 0, build_s = 0, solve_s = 0, solve_cpu_s = 0;
  int total_iterations = 0;
  double first_initial_cost = -1.0;
  bool converged = false;
  std::string termination;
  int rounds = 0;
  // How far the last round moved C_bl (deg), r_b^{lb} (m) and tau (s).
  double moved_deg = 0.0, moved_m = 0.0, moved_s = 0.0;
};

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
// build, LM solve. Sets *settled when the round moved the extrinsic by less
// than the OuterLoopParams stop thresholds (from the second round on).
Status RunOuterRound(const OuterLoopSetup& setup, CalibrationState* state, OuterLoop* loop,
                     bool* settled, std::ostream* log) {
  const proto::CalibrateParams& params = setup.params;
  const int round = loop->rounds + 1;
  const Eigen::Quaterniond rotation_before = state->ImuFromLidarRotation();
  const Eigen::Vector3d translation_before = state->ImuFromLidarTranslation();
  const double tau_before = state->time_offset_s[0];
  AssociationStageSummary assoc;
  BuildMapAndAssociate(*state, setup.inputs.scans, params.map(), params.association(),
                       &loop->lidar, &assoc);
  loop->map_s += assoc.map_seconds;
  loop->assoc_s += assoc.associate_seconds;
  if (loop->lidar.empty()) {
    return Status::Error("no LiDAR point could be associated with a planar surfel (" +
                         std::to_string(assoc.map.num_surfels) + " surfels in the map)");
  }
  auto start = Clock::now();
  loop->problem.reset();
  loop->problem = std::make_unique<CalibrationProblem>(state, params.imu_noise(), params.lidar(),
                                                       setup.problem_options);
  loop->problem->AddImuResiduals(setup.inputs.imu, true, true);
  loop->problem->AddLidarResiduals(loop->lidar);
  TILTCAL_RETURN_IF_ERROR(loop->problem->AddExtraResiduals(setup.ground_adder));
  loop->problem->RemoveUnusedKnots();
  loop->build_s += Seconds(start);
  start = Clock::now();
  const double cpu_start = CpuSeconds();
  ceres::Solve(setup.solver_options, loop->problem->problem(), &loop->summary);
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
  Log(log, fmt::format("outer {}: {} LM iterations in {:.2f} s; tau {:.3f} ms; r_bl ({:.4f}, "
                       "{:.4f}, {:.4f}) m",
                       round, static_cast<int>(summary.iterations.size()) - 1, solve_seconds,
                       state->time_offset_s[0] * 1e3, r.x(), r.y(), r.z()));
  loop->rounds = round;
  loop->moved_deg =
      Eigen::AngleAxisd(rotation_before.conjugate() * state->ImuFromLidarRotation()).angle() *
      180.0 / M_PI;
  // Without the distance residual the translation along the motion's
  // rotation axis is held only by its prior (planar motion): it wanders by
  // millimetres per round and takes no part in the stop test.
  Eigen::Vector3d moved_b = state->ImuFromLidarTranslation() - translation_before;
  if (!setup.translation_along_axis_observed) {
    moved_b -= setup.axis_b * setup.axis_b.dot(moved_b);
  }
  loop->moved_m = moved_b.norm();
  loop->moved_s = std::abs(state->time_offset_s[0] - tau_before);
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

// Covariance and observability on the last problem (the extrinsic and tau do
// not depend on the world gauge).
void FillCovariance(const CalibrateInputs& inputs, const proto::CalibrateParams& params,
                    CalibrationProblem* problem, CalibrationState* state,
                    proto::CalibrationResult* result) {
  const auto start = Clock::now();
  if (params.observability().compute_covariance()) {
    Matrix7d cov;
    const Status cs = ComputeExtrinsicCovariance(problem->problem(), state,
                                                 static_cast<int>(params.num_threads()), &cov);
    if (cs.ok()) {
      FillCovarianceReport(cov, state->ImuFromLidarRotation().toRotationMatrix(),
                           PrincipalRotationAxis(inputs.imu, state->GyroBias()),
                           params.observability(), result);
    } else {
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

}  // namespace

Status Calibrate(const CalibrateInputs& inputs, const proto::CalibrateParams& params,
                 proto::CalibrationResult* result, CalibrationState* final_state,
                 std::ostream* log) {
  result->Clear();
  const auto total_start = Clock::now();
  if (inputs.imu.size() < 10) return Status::Error("too few IMU samples");

  // Grid over the IMU samples (IMU clock, t0 = first sample = 0).
  const double t0 = inputs.imu.front().time_s;
  const double duration = inputs.imu.back().time_s - t0;
  CalibrationState state(
      spline::UniformKnotGrid::ForDuration(t0, duration, params.spline().knot_spacing_s()));
  state.gravity_norm_mps2 = params.gravity_norm_mps2();
  state.SetBiasSegments(params.imu_noise().gyro_bias_segment_s(),
                        params.imu_noise().accel_bias_segment_s());
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

  OuterLoopSetup setup{inputs, params, ground_adder, ProblemOptions(),
                       MakeSolverOptions(static_cast<int>(params.solver().max_iterations()),
                                         static_cast<int>(params.num_threads()),
                                         params.solver().function_tolerance()),
                       init.rotation_axis_b.normalized(),
                       std::find(ground_used.begin(), ground_used.end(), "dist") !=
                           ground_used.end()};
  ProblemOptions& problem_options = setup.problem_options;
  problem_options.time_offset_bound_s = params.time_offset_bound_s();
  problem_options.time_offset_step_bound_s = params.outer_loop().time_offset_step_bound_s();
  problem_options.fix_first_knots = false;  // the fixed map planes pin the gauge
  problem_options.translation_prior_m = ToEigen(inputs.rig.imu_from_lidar()).translation;
  problem_options.translation_prior_sigma_m = params.extrinsic_translation_prior_sigma_m();
  problem_options.translation_prior_axis_b = init.rotation_axis_b;
  OuterLoop loop;
  bool settled = false;
  const int max_rounds = static_cast<int>(params.outer_loop().iterations());
  while (loop.rounds < max_rounds && !settled) {
    TILTCAL_RETURN_IF_ERROR(RunOuterRound(setup, &state, &loop, &settled, log));
  }
  FillSolverReport(loop, result);
  FillCovariance(inputs, params, loop.problem.get(), &state, result);
  loop.problem.reset();

  ReexpressInFirstImuFrame(&state);
  FillEstimate(state, ground_used, ground_reason, result);
  AddTiming("total", Seconds(total_start), result);
  if (final_state != nullptr) *final_state = state;
  for (const proto::ObservabilityDirection& d : result->observability()) Log(log, d.description());
  Log(log, fmt::format("done in {:.2f} s, {} LM iterations, {:.3f} s per iteration",
                       Seconds(total_start), loop.total_iterations,
                       result->solver().seconds_per_iteration()));
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
