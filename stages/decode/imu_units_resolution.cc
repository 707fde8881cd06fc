#include "stages/decode/imu_units_resolution.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <fmt/format.h>

#include "common/geometry/angles.h"
#include "common/imu/imu_units.h"
#include "common/imu/static_detection.h"
#include "common/io/eigen_proto.h"
#include "common/io/static_detection_params.h"

namespace tiltcal::decode {

namespace {

using geometry::kDegPerRad;

std::string SamplesText(size_t num_samples, bool from_static_samples) {
  return from_static_samples ? fmt::format("over {} static samples", num_samples)
                             : fmt::format("over all {} samples (no static interval)", num_samples);
}

std::string AccelEvidenceText(const imu::AccelUnitEvidence& e) {
  return fmt::format("median |f| {:.4f} {}", e.median_norm,
                     SamplesText(e.num_samples, e.from_static_samples));
}

std::string GyroEvidenceText(const imu::GyroRateEvidence& e, double bound_radps) {
  return fmt::format("|ω| at percentile {:g} is {:.4g}, {} {:g} rad/s, the fastest turn of a "
                     "ground vehicle",
                     e.percentile, e.rate_at_percentile,
                     e.rate_at_percentile > bound_radps ? "above" : "at most", bound_radps);
}

std::string ConversionText(double factor, const char* si_unit, const char* factor_text) {
  return factor == 1.0 ? std::string("written as published")
                       : fmt::format("converted to {} (× {})", si_unit, factor_text);
}

imu::AccelUnit FromProto(proto::AccelUnit::Unit unit) {
  return unit == proto::AccelUnit::G ? imu::AccelUnit::kStandardGravity
                                     : imu::AccelUnit::kMetresPerSecond2;
}

imu::GyroUnit FromProto(proto::GyroUnit::Unit unit) {
  return unit == proto::GyroUnit::DEGPS ? imu::GyroUnit::kDegreesPerSecond
                                        : imu::GyroUnit::kRadiansPerSecond;
}

// The gyro's unit from the rig's statement and the rates.
Status ResolveGyroUnit(const std::vector<imu::ImuReading>& published, const proto::Rig& rig,
                       const ImuUnitsSources& sources, const proto::ImuUnitsParams& params,
                       ImuUnitsResolution* resolution) {
  const double bound = params.max_vehicle_turn_rate_radps();
  const imu::GyroRateEvidence evidence =
      imu::DetectGyroUnitFromRates(published, params.gyro_rate_percentile(), bound);
  const std::string evidence_text = GyroEvidenceText(evidence, bound);
  if (!evidence.unit) {
    return Status::Error(fmt::format(
        "{}: the gyro fits neither rad/s nor deg/s: {}, and even {:.4g} deg/s is {:.4g} rad/s "
        "(imu_units.max_vehicle_turn_rate_radps of the decode params)",
        sources.bag, evidence_text, evidence.rate_at_percentile,
        evidence.rate_at_percentile * imu::kRadiansPerDegree));
  }
  const proto::GyroUnit::Unit stated = rig.imu_gyro_unit();
  imu::GyroUnit unit = *evidence.unit;
  std::string how;
  if (stated == proto::GyroUnit::AUTO) {
    how = unit == imu::GyroUnit::kDegreesPerSecond
              ? "detected: " + evidence_text
              : fmt::format("assumed: {} (a gyro in deg/s would mean turns never faster "
                            "than {:.4g} deg/s; the calibration checks the gyro against the "
                            "LiDAR odometry)",
                            evidence_text, evidence.rate_at_percentile);
  } else {
    const bool contradicted =
        stated == proto::GyroUnit::RADPS && unit == imu::GyroUnit::kDegreesPerSecond;
    if (contradicted) {
      return Status::Error(fmt::format(
          "{}: imu_gyro_unit is RADPS but the gyro of {} reads in deg/s: {}", sources.rig_path,
          sources.bag, evidence_text));
    }
    unit = FromProto(stated);
    how = fmt::format("stated by the rig (imu_gyro_unit: {}); {}",
                      proto::GyroUnit::Unit_Name(stated), evidence_text);
  }
  resolution->gyro_to_si = imu::ToSiFactor(unit);
  resolution->notes.push_back(fmt::format("gyro in {}, {}; {}", imu::UnitName(unit), how,
                                          ConversionText(resolution->gyro_to_si, "rad/s",
                                                         "π/180")));
  return Status::Ok();
}

imu::UnitBand AccelBand(const proto::ImuUnitsParams& params) {
  imu::UnitBand band;
  band.min_ratio = params.accel_norm_ratio_min();
  band.max_ratio = params.accel_norm_ratio_max();
  return band;
}

// The accelerometer's unit from the rig's statement and the specific force.
Status ResolveAccelUnit(const std::vector<imu::ImuReading>& published,
                        const std::vector<imu::StaticInterval>& static_intervals,
                        const proto::Rig& rig, const ImuUnitsSources& sources,
                        const proto::ImuUnitsParams& params, ImuUnitsResolution* resolution) {
  const imu::UnitBand band = AccelBand(params);
  const imu::AccelUnitEvidence evidence = imu::DetectAccelUnit(published, static_intervals, band);
  const std::string evidence_text = AccelEvidenceText(evidence);
  if (!evidence.unit) {
    return Status::Error(fmt::format(
        "{}: the accelerometer fits neither m/s² nor g: {}, while one g is 9.81 in m/s² and 1 "
        "in g (accepted: {:g} to {:g} times that, imu_units.accel_norm_ratio_min/max of the "
        "decode params)",
        sources.bag, evidence_text, band.min_ratio, band.max_ratio));
  }
  const proto::AccelUnit::Unit stated = rig.imu_accel_unit();
  const imu::AccelUnit unit = *evidence.unit;
  std::string how = "detected: " + evidence_text;
  if (stated != proto::AccelUnit::AUTO) {
    if (FromProto(stated) != unit) {
      return Status::Error(fmt::format("{}: imu_accel_unit is {} but the accelerometer of {} "
                                       "reads in {}: {} (one g is 9.81 in m/s², 1 in g)",
                                       sources.rig_path, proto::AccelUnit::Unit_Name(stated),
                                       sources.bag, imu::UnitName(unit), evidence_text));
    }
    how = fmt::format("stated by the rig (imu_accel_unit: {}) and consistent with {}",
                      proto::AccelUnit::Unit_Name(stated), evidence_text);
  }
  resolution->accel_to_si = imu::ToSiFactor(unit);
  resolution->notes.push_back(fmt::format("accelerometer in {}, {}; {}", imu::UnitName(unit), how,
                                          ConversionText(resolution->accel_to_si, "m/s²",
                                                         "9.80665")));
  return Status::Ok();
}

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double cosine = a.normalized().dot(b.normalized());
  return std::acos(std::clamp(cosine, -1.0, 1.0)) * kDegPerRad;
}

// The sign of the specific force: its mean at rest must point up. Up in the
// IMU frame comes from the rig: −g_f when gravity_flat_in_imu is given (a
// measurement: a contradiction is an error), else the LiDAR's +z through
// imu_from_lidar (an assumption, as a LiDAR may be mounted upside down, and
// the rig's rotation may be what is wrong: a warning). An IMU's own +z says
// nothing: drivers publish in z-up (FLU) and z-down (FRD) frames alike.
Status CheckForceSign(const std::vector<imu::ImuReading>& published,
                      const std::vector<imu::StaticInterval>& static_intervals,
                      const proto::Rig& rig, const ImuUnitsSources& sources,
                      const proto::ImuUnitsParams& params, ImuUnitsResolution* resolution) {
  if (sources.rig_path.empty()) {
    resolution->notes.push_back(
        "accelerometer sign not checked: without a rig nothing says which way is up in the IMU "
        "frame");
    return Status::Ok();
  }
  const imu::RestForce rest = imu::MeanRestForce(published, static_intervals);
  const Eigen::Vector3d mean_mps2 = rest.mean * resolution->accel_to_si;
  const std::string samples = SamplesText(rest.num_samples, rest.from_static_samples);
  const double min_norm_mps2 = params.accel_norm_ratio_min() * imu::kStandardGravityMps2;
  if (mean_mps2.norm() < min_norm_mps2) {
    resolution->notes.push_back(fmt::format(
        "accelerometer sign not checked: the mean specific force {} is {:.3g} m/s², less than "
        "{:.3g} (no clear direction at rest)",
        samples, mean_mps2.norm(), min_norm_mps2));
    return Status::Ok();
  }
  const double max_angle_deg = params.max_rest_force_angle_from_up_deg();
  const std::string force_text = fmt::format(
      "the mean specific force {}, ({:.3f}, {:.3f}, {:.3f}) m/s² in the IMU frame,", samples,
      mean_mps2.x(), mean_mps2.y(), mean_mps2.z());
  const bool have_gravity_flat =
      rig.has_gravity_flat_in_imu() && ToEigen(rig.gravity_flat_in_imu()).norm() > 0.0;
  if (have_gravity_flat) {
    const double angle_deg = AngleDeg(mean_mps2, -ToEigen(rig.gravity_flat_in_imu()));
    if (angle_deg > max_angle_deg) {
      return Status::Error(fmt::format(
          "{}: {} points {:.1f} deg from up (−gravity_flat_in_imu of the rig; more than {:g}): "
          "the accelerometer of {} publishes gravity instead of specific force (sign-flipped), "
          "or gravity_flat_in_imu has the wrong sign (g_f points down: it is minus the mean "
          "accelerometer reading at rest on flat ground)",
          sources.rig_path, force_text, angle_deg, max_angle_deg, sources.bag));
    }
    resolution->notes.push_back(fmt::format(
        "accelerometer sign checked: {} points {:.1f} deg from up (−gravity_flat_in_imu of the "
        "rig)",
        force_text, angle_deg));
    return Status::Ok();
  }
  const Eigen::Vector3d lidar_up_in_imu =
      ToEigen(rig.imu_from_lidar().rotation()) * Eigen::Vector3d::UnitZ();
  const double angle_deg = AngleDeg(mean_mps2, lidar_up_in_imu);
  if (angle_deg > max_angle_deg) {
    const std::string warning = fmt::format(
        "{} points {:.1f} deg from the LiDAR's +z (through imu_from_lidar of the rig; more than "
        "{:g}): the accelerometer publishes gravity instead of specific force (sign-flipped), "
        "or the rig's rotation is wrong (an IMU mounted upside down and not declared), or the "
        "LiDAR is mounted upside down; imu.binpb keeps the published sign",
        force_text, angle_deg, max_angle_deg);
    resolution->notes.push_back(warning);
    resolution->warnings.push_back(warning);
    return Status::Ok();
  }
  resolution->notes.push_back(fmt::format(
      "accelerometer sign checked: {} points {:.1f} deg from the LiDAR's +z (through "
      "imu_from_lidar of the rig, the LiDAR taken as mounted upright)",
      force_text, angle_deg));
  return Status::Ok();
}

}  // namespace

Status ResolveImuUnits(const std::vector<imu::ImuReading>& published, const proto::Rig& rig,
                       const ImuUnitsSources& sources, const proto::ImuUnitsParams& params,
                       ImuUnitsResolution* resolution) {
  *resolution = ImuUnitsResolution();
  TILTCAL_RETURN_IF_ERROR(ResolveGyroUnit(published, rig, sources, params, resolution));
  // Still intervals on the readings in SI (the bounds of the static detection
  // are in rad/s and m/s²): the gyro as resolved, the accelerometer in the
  // unit its median norm over all samples points to, so that the same motion
  // in other units gives the same intervals.
  const imu::AccelUnitEvidence overall = imu::DetectAccelUnit(published, {}, AccelBand(params));
  const double accel_guess_to_si = overall.unit ? imu::ToSiFactor(*overall.unit) : 1.0;
  std::vector<imu::ImuReading> si = published;
  for (imu::ImuReading& r : si) {
    r.angular_velocity_radps *= resolution->gyro_to_si;
    r.linear_acceleration_mps2 *= accel_guess_to_si;
  }
  const std::vector<imu::StaticInterval> static_intervals =
      imu::DetectStaticIntervals(si, ToStaticDetectionOptions(params.static_detection()));
  TILTCAL_RETURN_IF_ERROR(
      ResolveAccelUnit(published, static_intervals, rig, sources, params, resolution));
  return CheckForceSign(published, static_intervals, rig, sources, params, resolution);
}

}  // namespace tiltcal::decode
