#include "stages/inspect/check.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "common/io/rig.h"
#include "stages/inspect/bag_survey.h"
#include "stages/inspect/check_findings.h"
#include "stages/inspect/check_report.h"
#include "tiltcal/proto/rig.pb.h"

namespace tiltcal::inspect {

Status CheckParamsAreValid(const proto::CheckParams& params) {
  const proto::StaticDetectionParams& s = params.static_detection();
  if (s.hop_s() > s.window_s()) {
    return Status::Error(fmt::format(
        "static_detection.hop_s ({:g}) must not exceed static_detection.window_s ({:g})", s.hop_s(),
        s.window_s()));
  }
  const proto::LidarCheckParams& l = params.lidar();
  if (l.ground_inlier_distance_m() > l.ground_min_depth_m() + l.ground_max_range_m()) {
    return Status::Error("lidar.ground_inlier_distance_m is larger than the ground region");
  }
  if (params.imu().min_rotation_radps() >= params.imu().max_vehicle_turn_rate_radps()) {
    return Status::Error(
        fmt::format(
            "imu.min_rotation_radps ({:g}) must be below imu.max_vehicle_turn_rate_radps ({:g})",
            params.imu().min_rotation_radps(), params.imu().max_vehicle_turn_rate_radps()));
  }
  if (params.imu().gyro_noise_radps() <= 0.0 || params.imu().accel_noise_mps2() <= 0.0) {
    return Status::Error("imu.gyro_noise_radps and imu.accel_noise_mps2 must be positive");
  }
  if (params.imu().vibration_cutoff_hz() * params.imu().vibration_filter_span_s() < 1.0) {
    return Status::Error(
        "imu.vibration_filter_span_s must hold at least one period of imu.vibration_cutoff_hz");
  }
  return Status::Ok();
}

Status RunCheck(const CheckPaths& paths, const proto::CheckParams& params, std::ostream& out) {
  TILTCAL_RETURN_IF_ERROR(CheckParamsAreValid(params));
  proto::Rig rig;
  if (!paths.rig.empty()) TILTCAL_RETURN_IF_ERROR(LoadRig(paths.rig, &rig));
  BagSurveyOptions options;
  options.imu_topic = rig.imu_topic();
  options.lidar_topic = rig.lidar_topic();
  options.max_sampled_scans = params.lidar().max_sampled_scans();
  options.point_stride = params.lidar().point_stride();
  BagSurvey survey;
  TILTCAL_RETURN_IF_ERROR(SurveyBag(paths.bag, options, &survey));
  const CheckFindings findings = AnalyseSurvey(survey, paths.rig.empty() ? nullptr : &rig, params);
  WriteCheckReport(findings, out);
  if (findings.problems.empty()) return Status::Ok();
  return Status::Error(
      fmt::format("{}: cannot be calibrated: {}", paths.bag, fmt::join(findings.problems, "; ")));
}

}  // namespace tiltcal::inspect
