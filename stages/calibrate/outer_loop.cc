#include "stages/calibrate/outer_loop.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "common/geometry/angles.h"
#include "stages/calibrate/problem/dense_sample_weight.h"
#include "stages/calibrate/problem/lidar_association.h"
#include "stages/calibrate/progress.h"

namespace tiltcal::calibrate {
namespace {

// The extrinsic, tau and the clock rate before a round, for how far it
// moved them.
struct RoundStart {
  Eigen::Quaterniond rotation;
  Eigen::Vector3d translation;
  double tau = 0.0;
  double rho = 0.0;
};

RoundStart RecordRoundStart(const CalibrationState& state) {
  RoundStart start;
  start.rotation = state.ImuFromLidarRotation();
  start.translation = state.ImuFromLidarTranslation();
  start.tau = state.time_offset_s[0];
  start.rho = state.clock_rate[0];
  return start;
}

// Surfel map and association with the current state into loop->lidar; an
// error when no point found a planar surfel.
Status AssociateLidarPoints(const OuterLoopSetup& setup,
                            const proto::AssociationParams& association,
                            const CalibrationState& state, OuterLoop* loop,
                            AssociationStageSummary* assoc) {
  const proto::CalibrateParams& params = setup.params;
  BuildMapAndAssociate(state, setup.inputs.scans, params.map(), association,
                       static_cast<int>(params.num_threads()), &loop->lidar, assoc);
  loop->map_s += assoc->map_seconds;
  loop->assoc_s += assoc->associate_seconds;
  if (loop->lidar.empty()) {
    return Status::Error("no LiDAR point could be associated with a planar surfel (" +
                         std::to_string(assoc->map.num_surfels) + " surfels in the map)");
  }
  return Status::Ok();
}

// The round's problem: IMU, LiDAR and ground residuals. With
// reference_lidar_residuals > 0 the LiDAR sample stands for one of that size
// (dense_sample_weight.h).
Status BuildRoundProblem(const OuterLoopSetup& setup, size_t reference_lidar_residuals,
                         CalibrationState* state, OuterLoop* loop) {
  const proto::CalibrateParams& params = setup.params;
  const auto start = Clock::now();
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
  return Status::Ok();
}

// LM on the round's problem (from the last solve's trust region when
// SolverParams.warm_start_trust_region), with its totals in *loop; returns
// the solve's wall seconds.
double SolveRoundProblem(const OuterLoopSetup& setup, OuterLoop* loop) {
  const proto::CalibrateParams& params = setup.params;
  const auto start = Clock::now();
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
  return solve_seconds;
}

void LogRoundSolve(int round, const AssociationStageSummary& assoc,
                   const ceres::Solver::Summary& summary, double solve_seconds,
                   const CalibrationState& state, std::ostream* log) {
  const Eigen::Vector3d r = state.ImuFromLidarTranslation();
  Log(log, fmt::format("outer {}: {} surfels, {} lidar residuals, cost {:.4g} -> {:.4g}", round,
                       assoc.map.num_surfels, assoc.residuals, summary.initial_cost,
                       summary.final_cost));
  const Eigen::Quaterniond q = state.ImuFromLidarRotation();
  Log(log, fmt::format("outer {}: {} LM iterations in {:.2f} s; tau {:.3f} ms; r_bl ({:.4f}, "
                       "{:.4f}, {:.4f}) m; q_bl (w {:.7f}, x {:.7f}, y {:.7f}, z {:.7f})",
                       round, static_cast<int>(summary.iterations.size()) - 1, solve_seconds,
                       state.time_offset_s[0] * 1e3, r.x(), r.y(), r.z(), q.w(), q.x(), q.y(),
                       q.z()));
}

// How far the round moved C_bl (deg), r_b^{lb} (m) and tau (s; at the scans'
// ends with the clock rate) into loop->moved_*.
void MeasureRoundMove(const OuterLoopSetup& setup, const RoundStart& before, int round,
                      const CalibrationState& state, OuterLoop* loop, std::ostream* log) {
  loop->moved_deg =
      geometry::RadToDeg(
          Eigen::AngleAxisd(before.rotation.conjugate() * state.ImuFromLidarRotation()).angle());
  // Without the distance residual the translation along the motion's
  // rotation axis is held only by its prior (planar motion): it wanders by
  // millimetres per round and takes no part in the stop test.
  Eigen::Vector3d moved_b = state.ImuFromLidarTranslation() - before.translation;
  if (!setup.translation_along_axis_observed) {
    moved_b -= setup.axis_b * setup.axis_b.dot(moved_b);
  }
  loop->moved_m = moved_b.norm();
  loop->moved_s = std::abs(state.time_offset_s[0] - before.tau);
  if (setup.problem_options.estimate_clock_rate) {
    // tau at the scans' ends moved by the rate's change times the half span.
    const double rho_moved = std::abs(state.clock_rate[0] - before.rho);
    loop->moved_s =
        std::max(loop->moved_s, rho_moved * setup.problem_options.clock_rate_half_length_s);
    Log(log, fmt::format("outer {}: clock rate {:+.2f} ppm (LiDAR against IMU), moved {:.2f} ppm",
                         round, -state.clock_rate[0] * 1e6, rho_moved * 1e6));
  }
}

// One round: surfel map + association with the current state, problem
// build, LM solve. `association` draws the LiDAR sample; with
// reference_lidar_residuals > 0 it stands for a sample of that size
// (dense_sample_weight.h). Sets loop->settled when the round moved the
// extrinsic by less than the OuterLoopParams stop thresholds (from the
// second round on).
Status RunOuterRound(const OuterLoopSetup& setup, const proto::AssociationParams& association,
                     size_t reference_lidar_residuals, CalibrationState* state, OuterLoop* loop,
                     std::ostream* log) {
  const int round = loop->rounds + 1;
  const RoundStart before = RecordRoundStart(*state);
  AssociationStageSummary assoc;
  TILTCAL_RETURN_IF_ERROR(AssociateLidarPoints(setup, association, *state, loop, &assoc));
  TILTCAL_RETURN_IF_ERROR(BuildRoundProblem(setup, reference_lidar_residuals, state, loop));
  const double solve_seconds = SolveRoundProblem(setup, loop);
  LogRoundSolve(round, assoc, loop->summary, solve_seconds, *state, log);
  loop->rounds = round;
  MeasureRoundMove(setup, before, round, *state, loop, log);
  const proto::OuterLoopParams& stop = setup.params.outer_loop();
  loop->settled = round >= 2 && loop->moved_deg < stop.stop_rotation_deg() &&
                  loop->moved_m < stop.stop_translation_m() &&
                  loop->moved_s < stop.stop_time_offset_s();
  Log(log, fmt::format("outer {}: extrinsic moved {:.4f} deg, {:.2f} mm, tau {:.3f} ms{}", round,
                       loop->moved_deg, loop->moved_m * 1e3, loop->moved_s * 1e3,
                       loop->settled ? ": stop" : ""));
  return Status::Ok();
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

}  // namespace

CalibrationProblem* ReportProblem(const OuterLoop& loop) {
  return loop.sample_problem ? loop.sample_problem.get() : loop.problem.get();
}

Status RunOuterLoop(OuterLoopSetup* setup, CalibrationState* state, OuterLoop* loop,
                    std::ostream* log) {
  const proto::CalibrateParams& params = setup->params;
  const proto::ImuIntrinsicsParams& intrinsics = params.imu_intrinsics();
  ProblemOptions& problem_options = setup->problem_options;
  int max_rounds = static_cast<int>(params.outer_loop().iterations());
  while (loop->rounds < max_rounds && !loop->settled) {
    TILTCAL_RETURN_IF_ERROR(RunOuterRound(*setup, params.association(), 0, state, loop, log));
    if (intrinsics.mode() == proto::ImuIntrinsicsParams::AUTO &&
        !problem_options.estimate_imu_intrinsics) {
      TILTCAL_RETURN_IF_ERROR(TestImuIntrinsics(params, state, loop, log));
      if (loop->intrinsics_found) {
        // At least one round with them.
        problem_options.estimate_imu_intrinsics = true;
        loop->settled = false;
        max_rounds = std::max(max_rounds, loop->rounds + 1);
      }
    }
  }
  if (params.outer_loop().has_final_association()) {
    // The final round: a denser sample, weighted as (n / n_default)^e times
    // the default sample's information (dense_sample_weight.h); the default
    // sample's problem is kept for the variance factor, the residual
    // statistics and the score test.
    Log(log, "final round: the denser association (outer_loop.final_association)");
    const size_t sample_residuals = loop->lidar.size();
    loop->sample_problem = std::move(loop->problem);
    TILTCAL_RETURN_IF_ERROR(RunOuterRound(*setup, params.outer_loop().final_association(),
                                          sample_residuals, state, loop, log));
  }
  if (intrinsics.mode() == proto::ImuIntrinsicsParams::OFF) {
    TILTCAL_RETURN_IF_ERROR(TestImuIntrinsics(params, state, loop, log));
  }
  return Status::Ok();
}

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

}  // namespace tiltcal::calibrate
