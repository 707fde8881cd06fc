#include "stages/calibrate/problem/problem_builder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "common/spline/so3_spline.h"
#include "stages/calibrate/problem/time_offset_drift.h"
#include "stages/calibrate/residuals/accel_cost_function.h"
#include "stages/calibrate/residuals/bias_random_walk_cost_function.h"
#include "stages/calibrate/residuals/drifting_time_offset_cost_function.h"
#include "stages/calibrate/residuals/gyro_cost_function.h"
#include "stages/calibrate/residuals/interval_manifold.h"
#include "stages/calibrate/residuals/point_to_plane_cost_function.h"
#include "stages/calibrate/residuals/stacked_cost_function.h"
#include "stages/calibrate/residuals/triad_errors_prior_cost_function.h"

namespace tiltcal::calibrate {
namespace {

// r = W (t - t_prior)  (3), W = I / sigma or a a^T / sigma (prior along a only).
class TranslationPriorCost final : public ceres::SizedCostFunction<3, 3> {
 public:
  TranslationPriorCost(const Eigen::Vector3d& prior, double sigma, const Eigen::Vector3d& axis)
      : prior_(prior) {
    weight_ = axis.norm() > 0.0 ? Eigen::Matrix3d(axis.normalized() * axis.normalized().transpose())
                                : Eigen::Matrix3d::Identity();
    weight_ /= sigma;
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    Eigen::Map<Eigen::Vector3d> r(residuals);
    r = weight_ * (Eigen::Map<const Eigen::Vector3d>(parameters[0]) - prior_);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> j(jacobians[0]);
      j = weight_;
    }
    return true;
  }

 private:
  Eigen::Vector3d prior_;
  Eigen::Matrix3d weight_;
};

// r = (x - prior) / sigma (1), for a scalar block (the clock rate rho).
class ScalarPriorCost final : public ceres::SizedCostFunction<1, 1> {
 public:
  ScalarPriorCost(double prior, double sigma) : prior_(prior), inv_sigma_(1.0 / sigma) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    residuals[0] = (parameters[0][0] - prior_) * inv_sigma_;
    if (jacobians != nullptr && jacobians[0] != nullptr) jacobians[0][0] = inv_sigma_;
    return true;
  }

 private:
  double prior_;
  double inv_sigma_;
};

}  // namespace

CalibrationProblem::CalibrationProblem(CalibrationState* state,
                                       const proto::ImuNoiseParams& imu_noise,
                                       const proto::LidarResidualParams& lidar,
                                       const ProblemOptions& options)
    : state_(state), imu_noise_(imu_noise), lidar_(lidar), options_(options) {
  if (lidar_.cauchy_scale() > 0.0) {
    lidar_loss_ = std::make_unique<ceres::CauchyLoss>(lidar_.cauchy_scale());
  }
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  problem_ = std::make_unique<ceres::Problem>(problem_options);
  ceres::Problem& p = *problem_;

  AddStateBlocks();
  BoundTimeOffset();
  AddClockRate();
  if (!options_.estimate_extrinsic) {
    p.SetParameterBlockConstant(state_->imu_from_lidar_rotation);
    p.SetParameterBlockConstant(state_->imu_from_lidar_translation);
  }
  if (!options_.estimate_gravity) p.SetParameterBlockConstant(state_->gravity_direction);
  HoldOrTieBiases();
  HoldOrPriorImuIntrinsics();
  AddTranslationPrior();
  counts_.knots = state_->trajectory.num_knots();
  rotation_used_.assign(state_->trajectory.num_knots(), 0);
  position_used_.assign(state_->trajectory.num_knots(), 0);
}

void CalibrationProblem::AddStateBlocks() {
  ceres::Problem& p = *problem_;
  spline::SplineTrajectory& traj = state_->trajectory;
  for (int i = 0; i < traj.num_knots(); ++i) {
    p.AddParameterBlock(traj.rotation_knot(i), 4, &quaternion_manifold_);
    p.AddParameterBlock(traj.position_knot(i), 3);
  }
  // Gauge: the first knots.
  if (options_.fix_first_knots) {
    p.SetParameterBlockConstant(traj.rotation_knot(0));
    p.SetParameterBlockConstant(traj.position_knot(0));
  }

  p.AddParameterBlock(state_->imu_from_lidar_rotation, 4, &quaternion_manifold_);
  p.AddParameterBlock(state_->imu_from_lidar_translation, 3);
  p.AddParameterBlock(state_->time_offset_s, 1);
  p.AddParameterBlock(state_->gravity_direction, 3, &sphere_manifold_);
  for (double* b : state_->BiasBlocks()) p.AddParameterBlock(b, 3);
  p.AddParameterBlock(state_->gyro_triad_errors.data(), 9, &lower_triangular_manifold_);
  p.AddParameterBlock(state_->accel_triad_errors.data(), 9, &lower_triangular_manifold_);
}

void CalibrationProblem::BoundTimeOffset() {
  ceres::Problem& p = *problem_;
  // tau bounds around the binning value; tau clamped into them.
  const double bound = std::abs(options_.time_offset_bound_s);
  const double lowest = options_.time_offset_center_s - bound;
  const double highest = options_.time_offset_center_s + bound;
  const double tau_bin = std::clamp(state_->time_offset_s[0], lowest, highest);
  tau_lower_ = std::max(lowest, tau_bin - options_.time_offset_step_bound_s);
  tau_upper_ = std::min(highest, tau_bin + options_.time_offset_step_bound_s);
  state_->time_offset_s[0] = tau_bin;
  if (options_.estimate_time_offset && tau_upper_ > tau_lower_) {
    time_offset_manifold_ = std::make_unique<IntervalManifold>(tau_lower_, tau_upper_);
    p.SetManifold(state_->time_offset_s, time_offset_manifold_.get());
  } else {
    p.SetParameterBlockConstant(state_->time_offset_s);
  }
}

void CalibrationProblem::AddClockRate() {
  ceres::Problem& p = *problem_;
  // rho (only with the drift; see problem_builder.h), clamped into its bounds.
  if (options_.estimate_clock_rate) {
    const ClockRateBounds rho = ClockRateBoundsOfBuild(
        state_->clock_rate[0], options_.clock_rate_max_ppm, options_.time_offset_step_bound_s,
        options_.clock_rate_half_length_s);
    rho_lower_ = rho.lower;
    rho_upper_ = rho.upper;
    state_->clock_rate[0] = std::clamp(state_->clock_rate[0], rho_lower_, rho_upper_);
    p.AddParameterBlock(state_->clock_rate, 1);
    if (rho_upper_ > rho_lower_) {
      clock_rate_manifold_ = std::make_unique<IntervalManifold>(rho_lower_, rho_upper_);
      p.SetManifold(state_->clock_rate, clock_rate_manifold_.get());
      if (options_.clock_rate_prior_sigma > 0.0) {
        p.AddResidualBlock(
            new ScalarPriorCost(options_.clock_rate_prior, options_.clock_rate_prior_sigma),
            nullptr, state_->clock_rate);
        ++counts_.prior_residuals;
      }
    } else {
      p.SetParameterBlockConstant(state_->clock_rate);
    }
  }
}

void CalibrationProblem::HoldOrTieBiases() {
  ceres::Problem& p = *problem_;
  const std::pair<BiasSegments*, double> biases[] = {
      {&state_->gyro_bias, imu_noise_.gyro_bias_random_walk_radps2_sqrthz()},
      {&state_->accel_bias, imu_noise_.accel_bias_random_walk_mps3_sqrthz()}};
  for (const auto& [bias, random_walk] : biases) {
    if (!options_.estimate_biases) {
      for (std::array<double, 3>& b : bias->values) p.SetParameterBlockConstant(b.data());
    } else if (random_walk > 0.0) {
      // Consecutive segments tied by the random walk over one segment.
      for (int i = 0; i + 1 < bias->size(); ++i) {
        p.AddResidualBlock(new BiasRandomWalkCostFunction(random_walk, bias->segment_s), nullptr,
                           bias->values[i].data(), bias->values[i + 1].data());
        ++counts_.prior_residuals;
      }
    }
  }
}

void CalibrationProblem::HoldOrPriorImuIntrinsics() {
  ceres::Problem& p = *problem_;
  for (double* k : {state_->gyro_triad_errors.data(), state_->accel_triad_errors.data()}) {
    if (!options_.estimate_imu_intrinsics) {
      p.SetParameterBlockConstant(k);
      continue;
    }
    p.AddResidualBlock(
        new TriadErrorsPriorCostFunction(options_.intrinsics_scale_prior_sigma,
                                             options_.intrinsics_misalignment_prior_sigma_rad),
        nullptr, k);
    ++counts_.prior_residuals;
  }
}

void CalibrationProblem::AddTranslationPrior() {
  ceres::Problem& p = *problem_;
  if (options_.translation_prior_sigma_m > 0.0 && options_.estimate_extrinsic) {
    p.AddResidualBlock(new TranslationPriorCost(options_.translation_prior_m,
                                                options_.translation_prior_sigma_m,
                                                options_.translation_prior_axis_b),
                       nullptr, state_->imu_from_lidar_translation);
    ++counts_.prior_residuals;
  }
}

void CalibrationProblem::MarkKnots(int first_knot, bool position) {
  for (int j = 0; j < 4; ++j) {
    rotation_used_[first_knot + j] = 1;
    if (position) position_used_[first_knot + j] = 1;
  }
}

void CalibrationProblem::AddImuResiduals(const std::vector<imu::ImuReading>& samples, bool gyro,
                                         bool accel) {
  spline::SplineTrajectory& traj = state_->trajectory;
  const spline::UniformKnotGrid& grid = traj.grid();
  StackedResidualAdder gyro_rows(nullptr);
  StackedResidualAdder accel_rows(nullptr);
  for (const imu::ImuReading& s : samples) {
    spline::KnotWindow w;
    if (!grid.Locate(s.time_s, &w)) continue;
    const int k = w.first_knot;
    if (gyro) {
      auto* row = new GyroCostFunction(w, grid.inv_dt(), s.angular_velocity_radps,
                                       imu_noise_.gyro_sigma_radps());
      std::vector<double*> blocks = {traj.rotation_knot(k), traj.rotation_knot(k + 1),
                                     traj.rotation_knot(k + 2), traj.rotation_knot(k + 3),
                                     state_->gyro_bias.Block(s.time_s),
                                     state_->gyro_triad_errors.data()};
      gyro_rows.Add(row, std::move(blocks));
      ++counts_.gyro_residuals;
      MarkKnots(k, false);
    }
    if (accel) {
      auto* row = new AccelCostFunction(w, grid.inv_dt(), s.linear_acceleration_mps2,
                                        imu_noise_.accel_sigma_mps2(), state_->gravity_norm_mps2);
      std::vector<double*> blocks = {
          traj.rotation_knot(k), traj.rotation_knot(k + 1), traj.rotation_knot(k + 2),
          traj.rotation_knot(k + 3), traj.position_knot(k), traj.position_knot(k + 1),
          traj.position_knot(k + 2), traj.position_knot(k + 3), state_->gravity_direction,
          state_->accel_bias.Block(s.time_s), state_->accel_triad_errors.data()};
      accel_rows.Add(row, std::move(blocks));
      ++counts_.accel_residuals;
      MarkKnots(k, true);
    }
  }
  gyro_rows.Flush(problem_.get());
  accel_rows.Flush(problem_.get());
}

void CalibrationProblem::AddLidarResiduals(const std::vector<LidarPointResidual>& points) {
  spline::SplineTrajectory& traj = state_->trajectory;
  const spline::UniformKnotGrid& grid = traj.grid();
  StackedResidualAdder rows(lidar_loss_.get());
  const bool drift = ClockRateInProblem(*state_, *problem_);
  for (const LidarPointResidual& r : points) {
    spline::KnotWindow w;
    if (!state_->TimeWindow(r.time_s, &w)) {
      ++counts_.lidar_skipped;
      continue;
    }
    const int k = w.first_knot;
    auto* row = new PointToPlaneCostFunction(grid.SegmentStart(k), grid.inv_dt(), r.time_s,
                                             r.point_lidar_m, r.plane_normal, r.plane_offset_m,
                                             lidar_.sigma_m());
    std::vector<double*> blocks = {
        traj.rotation_knot(k), traj.rotation_knot(k + 1), traj.rotation_knot(k + 2),
        traj.rotation_knot(k + 3), traj.position_knot(k), traj.position_knot(k + 1),
        traj.position_knot(k + 2), traj.position_knot(k + 3), state_->imu_from_lidar_rotation,
        state_->imu_from_lidar_translation, state_->time_offset_s};
    if (drift) {
      // tau(t_j) = tau0 + rho (t_j - t_ref); rho is the last block.
      blocks.push_back(state_->clock_rate);
      rows.Add(new DriftingTimeOffsetCostFunction(row, 10, r.time_s - state_->time_reference_s),
               std::move(blocks));
    } else {
      rows.Add(row, std::move(blocks));
    }
    ++counts_.lidar_residuals;
    MarkKnots(k, true);
  }
  rows.Flush(problem_.get());
}

Status CalibrationProblem::AddExtraResiduals(const ExtraResidualAdder& adder) {
  if (!adder) return Status::Ok();
  int added = 0;
  TILTCAL_RETURN_IF_ERROR(adder(state_, problem_.get(), &added));
  counts_.ground_residuals += added;
  return Status::Ok();
}

void CalibrationProblem::SetRotationKnotsConstant() {
  for (int i = 0; i < state_->trajectory.num_knots(); ++i) {
    problem_->SetParameterBlockConstant(state_->trajectory.rotation_knot(i));
  }
}

void CalibrationProblem::SetPositionKnotsConstant() {
  for (int i = 0; i < state_->trajectory.num_knots(); ++i) {
    problem_->SetParameterBlockConstant(state_->trajectory.position_knot(i));
  }
}

void CalibrationProblem::RemoveUnusedKnots() {
  spline::SplineTrajectory& traj = state_->trajectory;
  // Held constant rather than removed: Ceres leaves constant blocks out of
  // the solve, while RemoveParameterBlock scans every residual block for each
  // knot (all position knots of the rotation-only fit: quadratic in the
  // duration).
  for (int i = 0; i < traj.num_knots(); ++i) {
    if (!rotation_used_[i]) problem_->SetParameterBlockConstant(traj.rotation_knot(i));
    if (!position_used_[i]) problem_->SetParameterBlockConstant(traj.position_knot(i));
  }
  // The calibration blocks: asked of Ceres (a scan of the residual blocks
  // each; there are a handful), so extra residual sets are accounted for
  // exactly.
  std::vector<ceres::ResidualBlockId> users;
  std::vector<double*> blocks = state_->BiasBlocks();
  for (double* b : {state_->imu_from_lidar_rotation, state_->imu_from_lidar_translation,
                    state_->time_offset_s, state_->gravity_direction,
                    state_->gyro_triad_errors.data(), state_->accel_triad_errors.data()}) {
    blocks.push_back(b);
  }
  if (problem_->HasParameterBlock(state_->clock_rate)) blocks.push_back(state_->clock_rate);
  for (double* block : blocks) {
    users.clear();
    problem_->GetResidualBlocksForParameterBlock(block, &users);
    if (users.empty()) problem_->RemoveParameterBlock(block);
  }
}

const ProblemCounts& CalibrationProblem::counts() {
  std::vector<double*> blocks;
  problem_->GetParameterBlocks(&blocks);
  int free = 0;
  for (double* b : blocks) {
    if (!problem_->IsParameterBlockConstant(b)) free += problem_->ParameterBlockTangentSize(b);
  }
  counts_.free_parameters = free;
  return counts_;
}

bool ClockRateInProblem(const CalibrationState& state, const ceres::Problem& problem) {
  return problem.HasParameterBlock(state.clock_rate);
}

ceres::Solver::Options MakeSolverOptions(const SolverSettings& settings) {
  ceres::Solver::Options options;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.max_num_iterations = std::max(1, settings.max_iterations);
  options.num_threads = std::max(1, settings.num_threads);
  if (settings.function_tolerance > 0.0) options.function_tolerance = settings.function_tolerance;
  // At most Ceres' max_trust_region_radius (1e16), the params' bound.
  if (settings.initial_trust_region_radius > 0.0) {
    options.initial_trust_region_radius = settings.initial_trust_region_radius;
  }
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  return options;
}

void ReexpressInFirstImuFrame(CalibrationState* state) {
  spline::SplineTrajectory& traj = state->trajectory;
  spline::So3SplineSample rot;
  spline::R3SplineSample pos;
  if (!traj.Evaluate(traj.grid().t0_s(), spline::kSo3Rotation, &rot, &pos)) return;
  const Eigen::Quaterniond g(rot.rotation.transpose());
  const Eigen::Vector3d p0 = pos.position;
  for (int i = 0; i < traj.num_knots(); ++i) {
    traj.SetRotationKnot(i, (g * traj.RotationKnot(i)).normalized());
    traj.SetPositionKnot(i, g * (traj.PositionKnot(i) - p0));
  }
  state->SetGravityDirection(g * state->GravityInWorld());
}

}  // namespace tiltcal::calibrate
