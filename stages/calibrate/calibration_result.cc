#include "stages/calibrate/calibration_result.h"

#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "common/geometry/angles.h"
#include "common/geometry/translation_prior.h"
#include "common/io/eigen_proto.h"
#include "stages/calibrate/problem/problem_builder.h"
#include "stages/calibrate/progress.h"
#include "stages/calibrate/report/covariance_report.h"
#include "stages/calibrate/report/imu_static_noise.h"
#include "stages/calibrate/report/map_sharpness.h"
#include "stages/calibrate/report/residual_statistics.h"

namespace tiltcal::calibrate {
namespace {

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

// The covariance (and rho's row, when the drift is estimated) with the data's
// information divided by one variance factor, the priors' kept
// (ScaleDataInformation): the translation prior and rho's.
void ScaleByOneFactor(double sigma0_squared, double clock_rate_prior_sigma,
                      const proto::CalibrationResult& result, Matrix7d* cov,
                      std::vector<double>* clock_rate_row) {
  Matrix7d prior_information = Matrix7d::Zero();
  prior_information.block<3, 3>(3, 3) = geometry::TranslationPriorInformation(
      result.translation_prior_sigma_m(), ToEigen(result.translation_prior_axis_b()));
  if (clock_rate_row->size() != 8) {
    *cov = ScaleDataInformation(*cov, prior_information, sigma0_squared);
    return;
  }
  // The 7 and rho together; rho's prior (decode's rate) kept unscaled.
  Eigen::MatrixXd full = Eigen::MatrixXd::Zero(8, 8);
  full.topLeftCorner<7, 7>() = *cov;
  for (int j = 0; j < 8; ++j) {
    full(7, j) = full(j, 7) = (*clock_rate_row)[static_cast<size_t>(j)];
  }
  Eigen::MatrixXd prior_full = Eigen::MatrixXd::Zero(8, 8);
  prior_full.topLeftCorner<7, 7>() = prior_information;
  if (clock_rate_prior_sigma > 0.0) {
    prior_full(7, 7) = 1.0 / (clock_rate_prior_sigma * clock_rate_prior_sigma);
  }
  full = ScaleDataInformation(full, prior_full, sigma0_squared);
  *cov = full.topLeftCorner<7, 7>();
  for (int j = 0; j < 8; ++j) (*clock_rate_row)[static_cast<size_t>(j)] = full(7, j);
}

// The variance components per variance group of the default sample's
// problem into the result, and their weights.
Status FillVarianceComponents(const SolvedCalibration& solved, proto::CalibrationResult* result,
                              VarianceGroupWeights* weights) {
  ImuResidualNoise imu;
  imu.low_pass_correlation = solved.inputs.imu_low_pass_correlation;
  if (imu.low_pass_correlation > 1.0) {
    // Low-passed readings whose noise was not measured at rest (no static
    // start) keep the model's sigma as their floor: their residuals
    // understate it.
    imu.gyro_floor = 1.0;
    imu.accel_floor = 1.0;
    if (solved.init.imu.from_static_start) {
      const ImuStaticNoise at_rest = MeasureImuStaticNoise(
          solved.inputs.imu, solved.init.imu.averaging_begin_s, solved.init.imu.averaging_end_s,
          solved.params.imu_noise().gyro_sigma_radps(),
          solved.params.imu_noise().accel_sigma_mps2(), imu.low_pass_correlation);
      if (at_rest.samples >= kMinStaticNoiseSamples) {
        imu.gyro_floor = at_rest.gyro_factor;
        imu.accel_floor = at_rest.accel_factor;
      }
    }
  }
  std::vector<VarianceComponent> components;
  TILTCAL_RETURN_IF_ERROR(ComputeVarianceGroupComponents(
      ReportProblem(solved.loop)->problem(), imu,
      solved.params.observability(), static_cast<int>(solved.params.num_threads()),
      &components));
  result->clear_variance_components();
  for (int k = 0; k < kNumVarianceGroups; ++k) {
    const VarianceComponent& c = components[static_cast<size_t>(k)];
    (*weights)[static_cast<size_t>(k)] = c.weight;
    if (c.rows == 0) continue;
    proto::VarianceComponentReport* r = result->add_variance_components();
    r->set_type(VarianceGroupName(static_cast<VarianceGroup>(k)));
    r->set_rows(c.rows);
    r->set_redundancy(c.redundancy);
    r->set_variance_factor(c.sigma0_squared);
    r->set_correlation(c.correlation);
    r->set_floor(c.floor);
    r->set_weight(c.weight);
  }
  return Status::Ok();
}

}  // namespace

void FillCovariance(const SolvedCalibration& solved, proto::CalibrationResult* result,
                    CovarianceExtras* extras) {
  const CalibrateInputs& inputs = solved.inputs;
  const proto::CalibrateParams& params = solved.params;
  const proto::ObservabilityParams& observability = params.observability();
  CalibrationProblem* problem = solved.loop.problem.get();
  CalibrationProblem* noise_problem = ReportProblem(solved.loop);
  CalibrationState* state = solved.state;
  Eigen::MatrixXd* intrinsics_covariance = &extras->intrinsics_covariance;
  std::vector<double>* clock_rate_row = &extras->clock_rate_row;
  const auto start = Clock::now();
  intrinsics_covariance->resize(0, 0);
  clock_rate_row->clear();
  if (observability.compute_covariance()) {
    const bool per_type = observability.scale_by_variance_factor() &&
                          observability.variance_factors() == proto::ObservabilityParams::PER_TYPE;
    VarianceGroupWeights weights;
    weights.fill(1.0);
    Status cs = per_type ? FillVarianceComponents(solved, result, &weights) : Status::Ok();
    Matrix7d cov;
    if (cs.ok()) {
      cs = ComputeExtrinsicCovariance(
          problem->problem(), state, observability, static_cast<int>(params.num_threads()), &cov,
          intrinsics_covariance,
          ClockRateInProblem(*state, *problem->problem()) ? clock_rate_row : nullptr,
          per_type ? &weights : nullptr);
    }
    if (cs.ok()) {
      const VarianceFactor factor = ComputeVarianceFactor(noise_problem->problem());
      result->set_variance_factor(factor.sigma0_squared);
      result->set_redundancy(factor.redundancy);
      // Low-passed IMU readings (imu_vibration.h) are not white: their
      // residuals' RMS says nothing of their noise, so a factor below 1
      // must not shrink the covariance on their account.
      const bool shrink_allowed = inputs.imu_decimation == 1 || factor.sigma0_squared > 1.0;
      if (per_type) {
        result->set_covariance_scaled_by_variance_factor(true);
      } else if (observability.scale_by_variance_factor() && factor.redundancy > 0 &&
                 shrink_allowed) {
        ScaleByOneFactor(factor.sigma0_squared, solved.drift.decision.prior_sigma, *result, &cov,
                         clock_rate_row);
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
                           observability, result);
    } else {
      clock_rate_row->clear();
      proto::ObservabilityDirection* d = result->add_observability();
      d->set_weak(true);
      d->set_description(cs.message());
    }
  }
  AddTiming("covariance", Seconds(start), result);
}

void FillTimeOffsetDrift(const SolvedCalibration& solved,
                         const std::vector<double>& clock_rate_row,
                         proto::CalibrationResult* result, std::ostream* log) {
  const proto::CalibrateParams& params = solved.params;
  const CalibrationState& state = *solved.state;
  const CalibrationProblem& problem = *solved.loop.problem;
  const double sigma_tau = result->time_offset_sigma_s();
  proto::TimeOffsetDriftReport* report = result->mutable_time_offset_drift();
  const TimeOffsetDriftEstimate estimate{state.time_offset_s[0],
                                         state.clock_rate[0],
                                         {problem.clock_rate_lower(), problem.clock_rate_upper()},
                                         clock_rate_row, sigma_tau * sigma_tau};
  FillTimeOffsetDriftReport(params.time_offset_drift(), solved.drift.decision, solved.drift.span,
                            estimate, params.observability().weak_time_offset_sigma_s(), report);
  AddClockRateObservability(*report, params.observability(), result);
  const std::string note = DescribeTimeOffsetDrift(*report);
  if (note.empty()) return;
  result->add_verdict_notes(note);
  Log(log, note);
}

MapSharpnessPair MeasureBothMapSharpnesses(const CalibrateInputs& inputs,
                                           const proto::CalibrateParams& params,
                                           const CalibrationState& state) {
  const auto start = Clock::now();
  const Rigid3d rig = ToEigen(inputs.rig.imu_from_lidar());
  const double spacing_s = params.association().deskew_node_spacing_s();
  MapSharpnessComparison compared = CompareMapSharpness(
      state, rig.rotation, rig.translation, inputs.scans, params.map(), spacing_s);
  MapSharpnessPair out;
  out.estimate = std::move(compared.state);
  out.rig = std::move(compared.other);
  out.seconds = Seconds(start);
  return out;
}

void FillVerdictFacts(const SolvedCalibration& solved, MapSharpnessPair sharpness,
                      proto::CalibrationResult* result) {
  const CalibrateInputs& inputs = solved.inputs;
  const proto::CalibrateParams& params = solved.params;
  const InitialisationReport& init = solved.init;
  CalibrationProblem* problem = ReportProblem(solved.loop);
  const CalibrationState& state = *solved.state;
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

}  // namespace tiltcal::calibrate
