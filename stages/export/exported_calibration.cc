#include "stages/export/exported_calibration.h"

#include <cctype>
#include <cmath>

#include <fmt/format.h>

#include "common/timing/clock_rate.h"

namespace tiltcal::exporter {
namespace {

bool AllFinite(const proto::CalibrationResult& c) {
  const auto& q = c.imu_from_lidar().rotation();
  const auto& t = c.imu_from_lidar().translation();
  for (double v : {q.w(), q.x(), q.y(), q.z(), t.x(), t.y(), t.z(), c.time_offset_s()}) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

std::string VerdictName(proto::CalibrationResult::Verdict verdict) {
  switch (verdict) {
    case proto::CalibrationResult::OK:
      return "OK";
    case proto::CalibrationResult::WEAK:
      return "WEAK";
    case proto::CalibrationResult::SUSPECT:
      return "SUSPECT";
    default:
      return "UNSET";
  }
}

}  // namespace

Status CheckFrameName(const std::string& flag, const std::string& name) {
  if (name.empty()) return Status::Error(fmt::format("--{} is empty", flag));
  for (const char c : name) {
    const bool allowed = std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '/' ||
                         c == '-' || c == '.';
    if (!allowed) {
      return Status::Error(fmt::format(
          "--{}=\"{}\" has the character '{}' (a frame name is letters, digits, _ / - .)", flag,
          name, c));
    }
  }
  return Status::Ok();
}

Status MakeExportedCalibration(const proto::CalibrationResult& calibration,
                               const std::string& source, const std::string& imu_frame,
                               const std::string& lidar_frame, ExportedCalibration* exported) {
  if (!calibration.has_imu_from_lidar()) {
    return Status::Error(source + ": no imu_from_lidar (not a calibration.txtpb?)");
  }
  const auto& q = calibration.imu_from_lidar().rotation();
  if (!(std::isfinite(q.w()) && std::isfinite(q.x()) && std::isfinite(q.y()) &&
        std::isfinite(q.z()))) {
    return Status::Error(source + ": imu_from_lidar.rotation is not finite (NaN or infinite)");
  }
  if (!HasValidRotation(calibration.imu_from_lidar())) {
    return Status::Error(source + ": imu_from_lidar.rotation is missing or of zero norm");
  }
  if (!AllFinite(calibration)) {
    return Status::Error(source + ": imu_from_lidar or time_offset_s is NaN or infinite");
  }
  TILTCAL_RETURN_IF_ERROR(CheckFrameName("imu_frame", imu_frame));
  TILTCAL_RETURN_IF_ERROR(CheckFrameName("lidar_frame", lidar_frame));
  ExportedCalibration e;
  e.source = source;
  e.imu_from_lidar = ToEigen(calibration.imu_from_lidar());  // quaternion normalised
  // q and -q are the same rotation; w >= 0 reads better.
  if (e.imu_from_lidar.rotation.w() < 0) e.imu_from_lidar.rotation.coeffs() *= -1.0;
  e.lidar_from_imu = e.imu_from_lidar.inverse();
  e.time_offset_s = calibration.time_offset_s();
  if (calibration.has_rotation_sigma_deg() && calibration.has_translation_sigma_m()) {
    ExportedSigma sigma;
    sigma.rotation_deg = ToEigen(calibration.rotation_sigma_deg());
    sigma.translation_m = ToEigen(calibration.translation_sigma_m());
    sigma.time_offset_s = calibration.time_offset_sigma_s();
    e.sigma = sigma;
  }
  e.verdict = VerdictName(calibration.verdict());
  e.verdict_reasons.assign(calibration.verdict_reasons().begin(),
                           calibration.verdict_reasons().end());
  const proto::TimeOffsetDriftReport& drift = calibration.time_offset_drift();
  if (drift.estimated()) {
    e.clock_drift_advice = timing::DescribeDriftAdvice(
        drift.rate_ppm(), drift.end_time_s() - drift.start_time_s(), drift.time_offset_start_s(),
        drift.time_offset_end_s());
  } else if (!calibration.clock_drift().empty()) {
    e.clock_drift_advice = "tiltcal_decode: " + calibration.clock_drift();
  }
  e.imu_frame = imu_frame;
  e.lidar_frame = lidar_frame;
  *exported = std::move(e);
  return Status::Ok();
}

}  // namespace tiltcal::exporter
