#include "stages/calibrate/calibrate_params_validation.h"

#include <string>

#include <fmt/format.h>
#include <google/protobuf/text_format.h>

#include "common/io/params.h"
#include "stages/calibrate/default_params_text.h"
#include "stages/calibrate/problem/bias_segments.h"

namespace tiltcal::calibrate {
namespace {

Status MustBePositive(double value, const std::string& field) {
  if (value > 0.0) return Status::Ok();
  return Status::Error("params: " + field + " must be > 0");
}

}  // namespace

// 0 (one constant bias) or at least kMinBiasSegmentS: a bias is a slowly
// wandering offset, and each segment is a parameter block of the solve.
Status ValidateBiasSegment(double segment_s, const std::string& field) {
  if (segment_s == 0.0 || segment_s >= kMinBiasSegmentS) return Status::Ok();
  return Status::Error(fmt::format("params: {} = {} must be 0 (one constant bias) or at least {} s",
                                   field, segment_s, kMinBiasSegmentS));
}

Status ValidateImuNoiseParams(const proto::ImuNoiseParams& params) {
  TILTCAL_RETURN_IF_ERROR(
      ValidateBiasSegment(params.gyro_bias_segment_s(), "imu_noise.gyro_bias_segment_s"));
  TILTCAL_RETURN_IF_ERROR(
      ValidateBiasSegment(params.accel_bias_segment_s(), "imu_noise.accel_bias_segment_s"));
  TILTCAL_RETURN_IF_ERROR(MustBePositive(params.gyro_sigma_radps(), "imu_noise.gyro_sigma_radps"));
  return MustBePositive(params.accel_sigma_mps2(), "imu_noise.accel_sigma_mps2");
}

Status ValidateLidarScanParams(const proto::LidarScanParams& params) {
  if (params.max_range_m() <= params.min_range_m()) {
    return Status::Error("params: scans.max_range_m must exceed scans.min_range_m");
  }
  return Status::Ok();
}

Status ValidateLidarResidualParams(const proto::LidarResidualParams& params) {
  return MustBePositive(params.sigma_m(), "lidar.sigma_m");
}

Status ValidateInitParams(const proto::InitParams& params) {
  TILTCAL_RETURN_IF_ERROR(
      MustBePositive(params.odometry_position_sigma_m(), "init.odometry_position_sigma_m"));
  return MustBePositive(params.deskew_node_spacing_s(), "init.deskew_node_spacing_s");
}

Status ValidateSurfelMapParams(const proto::SurfelMapParams& params, const std::string& path) {
  return MustBePositive(params.voxel_m(), path + ".voxel_m");
}

Status ValidateLidarOdometryParams(const proto::LidarOdometryParams& params) {
  TILTCAL_RETURN_IF_ERROR(ValidateSurfelMapParams(params.quality_map(), "odometry.quality_map"));
  if (params.method() != proto::LidarOdometryParams::VOXEL_ICP) return Status::Ok();
  if (!params.has_voxel_icp()) {
    return Status::Error("params: odometry.voxel_icp is required with odometry.method VOXEL_ICP");
  }
  const proto::VoxelIcpParams& icp = params.voxel_icp();
  TILTCAL_RETURN_IF_ERROR(
      MustBePositive(icp.max_correspondence_m(), "odometry.voxel_icp.max_correspondence_m"));
  TILTCAL_RETURN_IF_ERROR(MustBePositive(icp.kernel_scale_m(), "odometry.voxel_icp.kernel_scale_m"));
  TILTCAL_RETURN_IF_ERROR(
      MustBePositive(icp.max_plane_thickness_m(), "odometry.voxel_icp.max_plane_thickness_m"));
  if (icp.min_plane_points() > icp.max_points_per_cell()) {
    return Status::Error(
        "params: odometry.voxel_icp.min_plane_points must not exceed max_points_per_cell");
  }
  return Status::Ok();
}

Status ValidateAssociationParams(const proto::AssociationParams& params,
                                 const std::string& name) {
  TILTCAL_RETURN_IF_ERROR(MustBePositive(params.max_distance_m(), name + ".max_distance_m"));
  return MustBePositive(params.deskew_node_spacing_s(), name + ".deskew_node_spacing_s");
}

Status ValidateGroundResidualsParams(const proto::GroundResidualsParams& params) {
  TILTCAL_RETURN_IF_ERROR(MustBePositive(params.flat().sigma(), "ground.flat.sigma"));
  TILTCAL_RETURN_IF_ERROR(MustBePositive(params.dist().sigma(), "ground.dist.sigma"));
  TILTCAL_RETURN_IF_ERROR(MustBePositive(params.incl().sigma(), "ground.incl.sigma"));
  return MustBePositive(params.up().sigma(), "ground.up.sigma");
}

Status ValidateVerdictParams(const proto::VerdictParams& params) {
  TILTCAL_RETURN_IF_ERROR(MustBePositive(params.max_gyro_rms(), "verdict.max_gyro_rms"));
  TILTCAL_RETURN_IF_ERROR(MustBePositive(params.max_accel_rms(), "verdict.max_accel_rms"));
  TILTCAL_RETURN_IF_ERROR(MustBePositive(params.max_lidar_rms(), "verdict.max_lidar_rms"));
  TILTCAL_RETURN_IF_ERROR(MustBePositive(params.max_ground_rms(), "verdict.max_ground_rms"));
  TILTCAL_RETURN_IF_ERROR(
      MustBePositive(params.large_rotation_deg(), "verdict.large_rotation_deg"));
  return MustBePositive(params.large_translation_m(), "verdict.large_translation_m");
}

Status ValidateImuVibrationParams(const proto::ImuVibrationParams& params) {
  if (params.cutoff_hz() * params.filter_span_s() < 1.0) {
    return Status::Error(
        "imu_vibration.filter_span_s must hold at least one period of imu_vibration.cutoff_hz");
  }
  return Status::Ok();
}

// 0 (errors taken as independent) or enough batches for a variance of
// their means (error_correlation.h).
Status ValidateObservabilityParams(const proto::ObservabilityParams& params) {
  const int batches = params.correlation_batches();
  if (batches == 0 || batches >= 4) return Status::Ok();
  return Status::Error(fmt::format(
      "params: observability.correlation_batches = {} must be 0 or at least 4", batches));
}

Status ValidateCalibrateParams(const proto::CalibrateParams& params) {
  TILTCAL_RETURN_IF_ERROR(ValidateImuNoiseParams(params.imu_noise()));
  TILTCAL_RETURN_IF_ERROR(ValidateLidarScanParams(params.scans()));
  TILTCAL_RETURN_IF_ERROR(ValidateLidarResidualParams(params.lidar()));
  TILTCAL_RETURN_IF_ERROR(ValidateInitParams(params.init()));
  TILTCAL_RETURN_IF_ERROR(ValidateLidarOdometryParams(params.odometry()));
  TILTCAL_RETURN_IF_ERROR(ValidateSurfelMapParams(params.map(), "map"));
  TILTCAL_RETURN_IF_ERROR(ValidateAssociationParams(params.association(), "association"));
  if (params.outer_loop().has_final_association()) {
    TILTCAL_RETURN_IF_ERROR(ValidateAssociationParams(params.outer_loop().final_association(),
                                                      "outer_loop.final_association"));
  }
  TILTCAL_RETURN_IF_ERROR(ValidateGroundResidualsParams(params.ground()));
  TILTCAL_RETURN_IF_ERROR(ValidateImuVibrationParams(params.imu_vibration()));
  TILTCAL_RETURN_IF_ERROR(ValidateObservabilityParams(params.observability()));
  return ValidateVerdictParams(params.verdict());
}

Status LoadCalibrateParams(const std::string& path, proto::CalibrateParams* params) {
  TILTCAL_RETURN_IF_ERROR(LoadParamsOrDefaults(path, DefaultParamsText(), params));
  // Optional messages (a params file older than them keeps working): the
  // compiled-in defaults.
  if (!params->has_time_offset_drift()) {
    proto::CalibrateParams defaults;
    if (!google::protobuf::TextFormat::ParseFromString(std::string(DefaultParamsText()),
                                                       &defaults)) {
      return Status::Error("default CalibrateParams: not readable");
    }
    *params->mutable_time_offset_drift() = defaults.time_offset_drift();
  }
  return ValidateCalibrateParams(*params).WithContext(path.empty() ? "default CalibrateParams"
                                                                   : path);
}

}  // namespace tiltcal::calibrate
