#include "stages/gravity/gravity_reference.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include <Eigen/Core>

#include "common/geometry/angles.h"
#include "common/io/eigen_proto.h"
#include "common/io/provenance.h"
#include "common/io/text_proto.h"

namespace tiltcal::gravity {
namespace {

using geometry::AngleBetweenDeg;
using geometry::kDegPerRad;

std::string FormatVector(const Eigen::Vector3d& v) {
  return fmt::format("({:.6g}, {:.6g}, {:.6g})", v.x(), v.y(), v.z());
}

// A g_a that is not a gravity: non-finite, or a norm outside the params'
// range (a zero vector is no estimate, left out by ReasonNotUsable).
Status CheckGravity(const FlatCalibration& c, const proto::FlatCalibrationsParams& params) {
  const Eigen::Vector3d g = ToEigen(c.result.gravity_in_world());
  if (!g.allFinite()) {
    return Status::Error(fmt::format("{}: gravity_in_world {} is not finite", c.path,
                                     FormatVector(g)));
  }
  const double norm = g.norm();
  if (norm != 0.0 &&
      !(norm >= params.min_gravity_norm_mps2() && norm <= params.max_gravity_norm_mps2())) {
    return Status::Error(fmt::format(
        "{}: gravity_in_world {} has norm {:.6g} m/s^2, outside "
        "flat_calibrations.min_gravity_norm_mps2 {:g} to max_gravity_norm_mps2 {:g}",
        c.path, FormatVector(g), norm, params.min_gravity_norm_mps2(),
        params.max_gravity_norm_mps2()));
  }
  return Status::Ok();
}

// Why a calibration cannot give g_f ("" when it can).
std::string ReasonNotUsable(const proto::CalibrationResult& c,
                            const proto::FlatCalibrationsParams& params) {
  if (ToEigen(c.gravity_in_world()).norm() == 0.0) return "no gravity estimate";
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

// Unit vectors u_i within theta of one direction m have |sum u_i| >= n cos
// theta (each u_i . m >= cos theta). So a mean resultant length |sum u_i| / n
// below cos(max_angle_from_combined_deg) means no direction lies within that
// angle of every used g_a, also when their mean direction does not exist
// (opposite g_a): an error with the two g_a furthest apart.
Status CheckCommonDirection(const std::vector<FlatCalibration>& calibrations,
                            const proto::GravityReference& out,
                            const proto::FlatCalibrationsParams& params) {
  std::vector<size_t> used;
  Eigen::Vector3d direction_sum = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < calibrations.size(); ++i) {
    if (!out.flat_calibrations(static_cast<int>(i)).used()) continue;
    used.push_back(i);
    direction_sum += ToEigen(calibrations[i].result.gravity_in_world()).normalized();
  }
  const double resultant = direction_sum.norm() / static_cast<double>(used.size());
  // 1e-12: the rounding of the sum, so that equal g_a pass a limit of 0 deg.
  const double limit = std::cos(params.max_angle_from_combined_deg() / kDegPerRad) - 1e-12;
  if (resultant >= limit) return Status::Ok();
  double widest_deg = -1.0;
  std::string pair;
  for (size_t a = 0; a < used.size(); ++a) {
    for (size_t b = a + 1; b < used.size(); ++b) {
      const FlatCalibration& ca = calibrations[used[a]];
      const FlatCalibration& cb = calibrations[used[b]];
      const Eigen::Vector3d ga = ToEigen(ca.result.gravity_in_world());
      const Eigen::Vector3d gb = ToEigen(cb.result.gravity_in_world());
      if (AngleBetweenDeg(ga, gb) > widest_deg) {
        widest_deg = AngleBetweenDeg(ga, gb);
        pair = fmt::format("{} g_a {} and {} g_a {}", ca.path, FormatVector(ga), cb.path,
                           FormatVector(gb));
      }
    }
  }
  return Status::Error(fmt::format(
      "the flat calibrations disagree about gravity: no direction lies within "
      "flat_calibrations.max_angle_from_combined_deg ({:g} deg) of all of them (mean resultant "
      "length of their directions {:.6f} < cos {:g} deg); largest angle {:.3f} deg between {} "
      "(did the IMU move on the vehicle, or did a run not start on level ground?)",
      params.max_angle_from_combined_deg(), resultant, params.max_angle_from_combined_deg(),
      widest_deg, pair));
}

}  // namespace

Status ValidateFlatCalibrationsParams(const proto::FlatCalibrationsParams& params) {
  if (!(params.min_gravity_norm_mps2() < params.max_gravity_norm_mps2())) {
    return Status::Error(fmt::format(
        "field flat_calibrations.min_gravity_norm_mps2 = {:g} is not below "
        "flat_calibrations.max_gravity_norm_mps2 = {:g}",
        params.min_gravity_norm_mps2(), params.max_gravity_norm_mps2()));
  }
  return Status::Ok();
}

Status CombineFlatCalibrations(const std::vector<FlatCalibration>& calibrations,
                               const proto::FlatCalibrationsParams& params,
                               proto::GravityReference* out) {
  TILTCAL_RETURN_IF_ERROR(ValidateFlatCalibrationsParams(params));
  Eigen::Vector3d direction_sum = Eigen::Vector3d::Zero();
  double norm_sum = 0.0;
  int used = 0;
  std::string reasons;
  for (const FlatCalibration& c : calibrations) {
    TILTCAL_RETURN_IF_ERROR(CheckGravity(c, params));
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
    entry.set_angle_from_combined_deg(AngleBetweenDeg(ToEigen(entry.gravity_in_imu()), g_f));
    max_angle_deg = std::max(max_angle_deg, entry.angle_from_combined_deg());
    if (entry.angle_from_combined_deg() > params.max_angle_from_combined_deg()) {
      far += fmt::format("; {}: {:.3f} deg (g_a {})", entry.calibration(),
                         entry.angle_from_combined_deg(),
                         FormatVector(ToEigen(entry.gravity_in_imu())));
    }
  }
  if (!far.empty()) {
    return Status::Error(fmt::format(
        "the flat calibrations disagree about gravity by more than "
        "flat_calibrations.max_angle_from_combined_deg ({:g} deg) from their mean {}{} (did the "
        "IMU move on the vehicle, or did a run not start on level ground?)",
        params.max_angle_from_combined_deg(), FormatVector(g_f), far));
  }
  // Every used g_a within the angle of g_f passes this; it fails when g_f
  // does not exist (a zero sum of directions measures every angle as 0).
  TILTCAL_RETURN_IF_ERROR(CheckCommonDirection(calibrations, *out, params));
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
