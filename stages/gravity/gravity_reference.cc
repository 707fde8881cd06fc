#include "stages/gravity/gravity_reference.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include <Eigen/Core>

#include "common/io/eigen_proto.h"
#include "common/io/provenance.h"
#include "common/io/text_proto.h"

namespace tiltcal::gravity {
namespace {

constexpr double kDegPerRad = 180.0 / M_PI;

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * kDegPerRad;
}

// Why a calibration cannot give g_f ("" when it can).
std::string ReasonNotUsable(const proto::CalibrationResult& c,
                            const proto::FlatCalibrationsParams& params) {
  const Eigen::Vector3d g = ToEigen(c.gravity_in_world());
  if (!g.allFinite() || g.norm() < 1.0) return "no gravity estimate";
  if (!c.static_start()) return "did not start still: its g_a is not the gravity at rest";
  const auto& used = c.ground_residuals_used();
  if (std::find(used.begin(), used.end(), "flat") == used.end()) {
    return "not level (it did not use the flat-ground residual)";
  }
  if (c.verdict() == proto::CalibrationResult::SUSPECT && !params.use_suspect()) {
    return "verdict SUSPECT";
  }
  return "";
}

}  // namespace

Status CombineFlatCalibrations(const std::vector<FlatCalibration>& calibrations,
                               const proto::FlatCalibrationsParams& params,
                               proto::GravityReference* out) {
  Eigen::Vector3d direction_sum = Eigen::Vector3d::Zero();
  double norm_sum = 0.0;
  int used = 0;
  std::string reasons;
  for (const FlatCalibration& c : calibrations) {
    proto::FlatCalibrationGravity* entry = out->add_flat_calibrations();
    entry->set_calibration(c.path);
    *entry->mutable_gravity_in_imu() = c.result.gravity_in_world();
    entry->set_reason(ReasonNotUsable(c.result, params));
    entry->set_used(entry->reason().empty());
    if (!entry->used()) {
      reasons += fmt::format("; {}: {}", c.path, entry->reason());
      continue;
    }
    const Eigen::Vector3d g = ToEigen(c.result.gravity_in_world());
    direction_sum += g.normalized();
    norm_sum += g.norm();
    ++used;
  }
  if (used == 0) {
    return Status::Error(fmt::format(
        "no flat-ground calibration gives g_f ({} read{})", calibrations.size(), reasons));
  }
  const Eigen::Vector3d g_f = norm_sum / used * direction_sum.normalized();
  double max_angle_deg = 0.0;
  std::string far;
  for (proto::FlatCalibrationGravity& entry : *out->mutable_flat_calibrations()) {
    if (!entry.used()) continue;
    entry.set_angle_from_combined_deg(AngleDeg(ToEigen(entry.gravity_in_imu()), g_f));
    max_angle_deg = std::max(max_angle_deg, entry.angle_from_combined_deg());
    if (entry.angle_from_combined_deg() > params.max_angle_from_combined_deg()) {
      far += fmt::format("; {}: {:.3f} deg", entry.calibration(), entry.angle_from_combined_deg());
    }
  }
  if (!far.empty()) {
    return Status::Error(fmt::format(
        "the flat calibrations disagree about gravity by more than "
        "flat_calibrations.max_angle_from_combined_deg ({:g} deg) from their mean{} (did the IMU "
        "move on the vehicle, or did a run not start on level ground?)",
        params.max_angle_from_combined_deg(), far));
  }
  *out->mutable_gravity_flat_in_imu() = ToProto(g_f);
  out->set_has_gravity_flat(true);
  out->set_gravity_flat_source(fmt::format("flat calibrations ({} of {})", used,
                                           calibrations.size()));
  out->set_flat_calibrations_max_angle_deg(max_angle_deg);
  return Status::Ok();
}

std::string ResolveGravityReferencePath(const std::string& rig_path,
                                        const std::string& gravity_reference) {
  const std::filesystem::path named =
      std::filesystem::path(rig_path).parent_path() / gravity_reference;
  std::error_code error;
  if (std::filesystem::is_directory(named, error)) {
    return (named / "out" / "gravity_reference.txtpb").string();
  }
  return named.string();
}

Status RunGravityReference(const GravityReferencePaths& paths, const proto::GravityParams& params,
                           std::ostream* log) {
  if (paths.calibrations.empty()) return Status::Error("no calibration given");
  std::vector<FlatCalibration> calibrations(paths.calibrations.size());
  std::vector<InputPath> input_paths;
  for (size_t i = 0; i < paths.calibrations.size(); ++i) {
    calibrations[i].path = paths.calibrations[i];
    TILTCAL_RETURN_IF_ERROR(ReadTextProto(paths.calibrations[i], &calibrations[i].result));
    input_paths.push_back({"calibration", paths.calibrations[i]});
  }
  if (!paths.params.empty()) input_paths.push_back({"params", paths.params});
  proto::GravityReference out;
  TILTCAL_RETURN_IF_ERROR(CombineFlatCalibrations(calibrations, params.flat_calibrations(), &out));
  *out.mutable_provenance() =
      MakeProvenance("tiltcal_gravity_reference", params, input_paths, paths.command_line);
  TILTCAL_RETURN_IF_ERROR(WriteTextProto(paths.out, out));
  if (log != nullptr) {
    const Eigen::Vector3d g_f = ToEigen(out.gravity_flat_in_imu());
    *log << fmt::format(
        "tiltcal_gravity_reference: g_f = ({:.4f}, {:.4f}, {:.4f}) m/s^2 from {}; largest angle "
        "of a calibration from it {:.3f} deg\n",
        g_f.x(), g_f.y(), g_f.z(), out.gravity_flat_source(),
        out.flat_calibrations_max_angle_deg());
    for (const proto::FlatCalibrationGravity& entry : out.flat_calibrations()) {
      if (!entry.used()) {
        *log << "tiltcal_gravity_reference: left out " << entry.calibration() << ": "
             << entry.reason() << "\n";
      }
    }
  }
  return Status::Ok();
}

}  // namespace tiltcal::gravity
