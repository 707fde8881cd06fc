#include "stages/verify/verify.h"

#include <filesystem>
#include <utility>

#include <fmt/format.h>

#include "common/calibration/calibration_checks.h"
#include "common/io/atomic_file.h"
#include "common/io/eigen_proto.h"
#include "common/io/provenance.h"
#include "common/io/text_proto.h"
#include "stages/calibrate/calibrate.h"
#include "stages/calibrate/init/initial_extrinsic.h"
#include "stages/calibrate/report/map_sharpness.h"
#include "stages/verify/reference_comparison.h"

namespace tiltcal::verify {
namespace {

// The folder's name ("out/run1/" -> "run1").
std::string SequenceName(const std::string& dir) {
  std::filesystem::path path = std::filesystem::path(dir).lexically_normal();
  if (path.filename().empty()) path = path.parent_path();
  return path.filename().string();
}

// The sequence's own files: its decode outputs, ground, gravity and the rig
// with its starting extrinsic (tiltcal_initial_extrinsic).
calibrate::CalibratePaths SequencePaths(const std::string& dir) {
  calibrate::CalibratePaths p;
  p.imu = dir + "/imu.binpb";
  p.scans = dir + "/scans.binpb.lz4";
  if (std::filesystem::exists(dir + "/ground.binpb")) p.ground = dir + "/ground.binpb";
  if (std::filesystem::exists(dir + "/gravity.txtpb")) p.gravity = dir + "/gravity.txtpb";
  p.rig = dir + "/rig.txtpb";
  return p;
}

// The map of the scans on the final trajectory with the estimate and with the
// reference's extrinsic (same trajectory and tau), and a reason line.
void MeasureMaps(const calibrate::CalibrateInputs& inputs,
                 const proto::CalibrateParams& calibrate_params,
                 const calibrate::CalibrationState& state, const Rigid3d& reference,
                 proto::SequenceVerification* out) {
  const double spacing_s = calibrate_params.association().deskew_node_spacing_s();
  calibrate::MapSharpnessComparison compared = calibrate::CompareMapSharpness(
      state, reference.rotation, reference.translation, inputs.scans, calibrate_params.map(),
      spacing_s);
  *out->mutable_map_sharpness_estimate() = std::move(compared.state);
  *out->mutable_map_sharpness_reference() = std::move(compared.other);
  const proto::MapSharpness& e = out->map_sharpness_estimate();
  const proto::MapSharpness& r = out->map_sharpness_reference();
  out->add_reasons(fmt::format(
      "map: over the {} voxels planar in both maps, median surfel thickness {:.2f} mm with the "
      "estimate ({} planar surfels), {:.2f} mm with the reference ({}), ratio reference / "
      "estimate {:.3f}",
      e.common_surfels(), 1e3 * e.median_thickness_m(), e.planar_surfels(),
      1e3 * r.median_thickness_m(), r.planar_surfels(),
      e.median_thickness_m() > 0.0 ? r.median_thickness_m() / e.median_thickness_m() : 0.0));
}

Status VerifySequence(const std::string& dir, const VerifyPaths& paths,
                      const proto::VerifyParams& params,
                      const proto::CalibrateParams& calibrate_params,
                      const proto::CalibrationResult& reference, std::ostream* log,
                      proto::SequenceVerification* out) {
  out->set_name(SequenceName(dir));
  if (log != nullptr) *log << "tiltcal_verify: " << out->name() << ": calibrating\n";
  const calibrate::CalibratePaths sequence = SequencePaths(dir);
  if (!std::filesystem::exists(sequence.rig)) {
    // The pipeline's tiltcal_initial_extrinsic failed: the same search says why.
    proto::Rig unused;
    const Status start = calibrate::FindSequenceRig(
        {sequence.imu, sequence.scans, paths.rig, sequence.rig}, calibrate_params, nullptr,
        &unused);
    if (start.ok()) {
      return Status::Error(sequence.rig +
                           ": missing (tiltcal_initial_extrinsic writes it; run make first)");
    }
    if (!start.not_determined()) return start.WithContext(dir);
    out->set_verdict(proto::VerifyResult::CANNOT_TELL);
    out->add_reasons("cannot tell: the sequence cannot be calibrated: " + start.message());
    return Status::Ok();
  }
  calibrate::CalibrateInputs inputs;
  TILTCAL_RETURN_IF_ERROR(
      calibrate::ReadCalibrateInputs(sequence, calibrate_params, &inputs).WithContext(dir));
  proto::CalibrationResult estimate;
  calibrate::CalibrationState state(
      spline::UniformKnotGrid::ForDuration(0.0, 1.0, calibrate_params.spline().knot_spacing_s()));
  const Status calibrated =
      calibrate::CalibrateSequence(calibrate_params, &inputs, &estimate, &state, nullptr);
  if (!calibrated.ok()) {
    if (!calibrated.not_determined()) return calibrated.WithContext(dir);
    out->set_verdict(proto::VerifyResult::CANNOT_TELL);
    out->add_reasons("cannot tell: the sequence cannot be calibrated: " + calibrated.message());
    return Status::Ok();
  }
  CompareWithReference(estimate, reference, params, out);
  MeasureMaps(inputs, calibrate_params, state, ToEigen(reference.imu_from_lidar()), out);
  return Status::Ok();
}

}  // namespace

std::string FormatTable(const proto::VerifyResult& result) {
  std::string out = fmt::format("{:<16} {:<11} {:>18} {:>24} {:>24} {:>18} {:>15}\n", "sequence",
                                "verdict", "chi2 / limit (dof)", "rotation deg (sigma)",
                                "translation mm (sigma)", "tau ms (sigma)", "map mm est/ref");
  for (const proto::SequenceVerification& s : result.sequences()) {
    const std::string verdict = proto::VerifyResult::Verdict_Name(s.verdict());
    if (s.dof() == 0) {
      out += fmt::format("{:<16} {:<11} {}\n", s.name(), verdict,
                         s.reasons_size() > 0 ? s.reasons(0) : "");
      continue;
    }
    out += fmt::format(
        "{:<16} {:<11} {:>18} {:>24} {:>24} {:>18} {:>15}\n", s.name(), verdict,
        fmt::format("{:.1f} / {:.1f} ({})", s.chi2(), s.limit(), s.dof()),
        fmt::format("{:.3f} ({:.1f})", ToEigen(s.rotation_difference_deg()).norm(),
                    s.rotation_difference_sigma()),
        fmt::format("{:.1f} ({:.1f})", 1e3 * ToEigen(s.translation_difference_m()).norm(),
                    s.translation_difference_sigma()),
        fmt::format("{:+.3f} ({:.1f})", 1e3 * s.time_offset_difference_s(),
                    s.time_offset_difference_sigma()),
        fmt::format("{:.2f}/{:.2f}", 1e3 * s.map_sharpness_estimate().median_thickness_m(),
                    1e3 * s.map_sharpness_reference().median_thickness_m()));
  }
  for (const proto::SequenceVerification& s : result.sequences()) {
    out += fmt::format("{} {}:\n", s.name(), proto::VerifyResult::Verdict_Name(s.verdict()));
    for (const std::string& r : s.reasons()) out += "  - " + r + "\n";
  }
  out += fmt::format("tiltcal_verify: {} against {}\n",
                     proto::VerifyResult::Verdict_Name(result.verdict()), result.reference());
  for (const std::string& r : result.verdict_reasons()) out += "  - " + r + "\n";
  return out;
}

Status Run(const VerifyPaths& paths, const proto::VerifyParams& params,
           const proto::CalibrateParams& calibrate_params, std::ostream* log, std::ostream* table,
           proto::VerifyResult* result) {
  if (paths.sequence_dirs.empty()) return Status::Error("no sequence folder given");
  TILTCAL_RETURN_IF_ERROR(calibration::ValidateSequenceInputParams(params.input()));
  TILTCAL_RETURN_IF_ERROR(CheckOutputPath(paths.out));
  proto::CalibrationResult reference;
  TILTCAL_RETURN_IF_ERROR(ReadTextProto(paths.reference, &reference));
  const std::string refused = calibration::ReasonRefused(reference, 6, params.input());
  if (!refused.empty()) return Status::Error(paths.reference + ": " + refused);
  proto::VerifyResult& out = *result;
  out.Clear();
  out.set_reference(paths.reference);
  *out.mutable_reference_imu_from_lidar() = reference.imu_from_lidar();
  out.set_reference_time_offset_s(reference.time_offset_s());
  std::vector<InputPath> inputs = {{"reference", paths.reference}, {"rig", paths.rig}};
  if (!paths.params.empty()) inputs.push_back({"params", paths.params});
  if (!paths.calibrate_params.empty()) {
    inputs.push_back({"calibrate_params", paths.calibrate_params});
  }
  for (const std::string& dir : paths.sequence_dirs) {
    TILTCAL_RETURN_IF_ERROR(VerifySequence(dir, paths, params, calibrate_params, reference, log,
                                           out.add_sequences()));
    const calibrate::CalibratePaths sequence = SequencePaths(dir);
    if (std::filesystem::exists(sequence.rig)) inputs.push_back({"sequence_rig", sequence.rig});
    inputs.push_back({"imu", sequence.imu});
    inputs.push_back({"scans", sequence.scans});
    if (!sequence.ground.empty()) inputs.push_back({"ground", sequence.ground});
    if (!sequence.gravity.empty()) inputs.push_back({"gravity", sequence.gravity});
  }
  DecideDatasetVerdict(&out);
  *out.mutable_provenance() = MakeProvenance("tiltcal_verify", params, inputs, paths.command_line);
  TILTCAL_RETURN_IF_ERROR(WriteTextProto(paths.out, out));
  if (table != nullptr) *table << FormatTable(out);
  return Status::Ok();
}

}  // namespace tiltcal::verify
