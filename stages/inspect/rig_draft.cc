#include "stages/inspect/rig_draft.h"

#include <google/protobuf/text_format.h>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "common/io/atomic_file.h"
#include "common/io/eigen_proto.h"
#include "common/io/text_proto.h"
#include "stages/inspect/bag_survey.h"
#include "stages/inspect/check.h"
#include "tiltcal/proto/rig.pb.h"

namespace tiltcal::inspect {

namespace {

// A text-format string literal (quotes and escapes as TextFormat writes them).
std::string Quoted(const std::string& value) {
  proto::Rig rig;
  rig.set_imu_topic(value);
  std::string text;
  google::protobuf::TextFormat::Printer printer;
  printer.SetSingleLineMode(true);
  printer.PrintToString(rig, &text);
  // "imu_topic: \"...\" "
  const size_t start = text.find('"');
  const size_t end = text.rfind('"');
  return text.substr(start, end - start + 1);
}

// A comment line's text: control characters shown as '?', so a frame id
// cannot end the comment.
std::string Printable(const std::string& value) {
  std::string out = value;
  for (char& c : out) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  return out;
}

std::string AccelUnitLines(const ImuFindings& imu) {
  if (!imu.accel.unit) {
    return fmt::format(
        "# IMU accelerometer unit: not detected (median |f| {:.4g} fits neither m/s² nor g);\n"
        "# tiltcal_decode decides it (AUTO) or refuses the data.\n",
        imu.accel.median_norm);
  }
  const bool g = *imu.accel.unit == imu::AccelUnit::kStandardGravity;
  return fmt::format("# IMU accelerometer in {}: median |f| {:.4g} over {} samples{}.\n"
                     "imu_accel_unit: {}\n",
                     imu::UnitName(*imu.accel.unit), imu.accel.median_norm,
                     imu.accel.num_samples, imu.accel.from_static_samples ? " at rest" : "",
                     g ? "G" : "MPS2");
}

std::string GyroUnitLines(const ImuFindings& imu) {
  const bool degrees = imu.gyro_unit == imu::GyroUnit::kDegreesPerSecond;
  return fmt::format(
      "# IMU gyro in {}: {:g}th percentile |ω| {:.4g} as published{}.\n"
      "imu_gyro_unit: {}\n",
      imu::UnitName(imu.gyro_unit), imu.gyro.percentile, imu.gyro.rate_at_percentile,
      degrees ? " (faster than a ground vehicle turns in rad/s)" : "", degrees ? "DEGPS" : "RADPS");
}

std::string ExtrinsicLines(const bag::StaticTransforms& tf) {
  if (!tf.found) {
    return "# imu_from_lidar: not in the bag (" + Printable(tf.summary) +
           ").\n"
           "# Optional: without it, tiltcal_initial_extrinsic finds the rotation from the\n"
           "# motion and the calibration the translation. If you know the mounting (the\n"
           "# vehicle's URDF, a drawing, a tape measure; p_imu = R p_lidar + t, quaternion\n"
           "# w x y z, metres), put it in and remove the '#':\n"
           "# imu_from_lidar { rotation { w: 1 x: 0 y: 0 z: 0 } translation { x: 0 y: 0 z: 0 } }\n";
  }
  const geometry::FrameChain& c = tf.imu_from_lidar;
  Eigen::Quaterniond q = c.target_from_source_rotation;
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const proto::Rigid3 rigid = ToProto(Rigid3d{q, c.target_from_source_translation});
  std::string body;
  google::protobuf::TextFormat::Printer printer;
  printer.SetInitialIndentLevel(1);
  printer.PrintToString(rigid, &body);
  std::string chain;
  for (const std::string& frame : c.frames) chain += (chain.empty() ? "" : " <- ") + frame;
  return "# From the bag's /tf_static, along " + Printable(chain) +
         "\n"
         "# (C_bl, r_b^{lb}: p_imu = C_bl p_lidar + r_b^{lb}, metres). The calibration starts\n"
         "# from it (its rotation corrected from the motion by any angle) and estimates the\n"
         "# extrinsic; a URDF is often off by degrees and centimetres. Optional: delete it\n"
         "# and the bag's /tf_static is still the start.\n"
         "imu_from_lidar {\n" +
         body + "}\n";
}

}  // namespace

Status DraftRigText(const CheckFindings& f, std::string* text) {
  if (f.imu_topic.empty() || f.lidar_topic.empty()) {
    return Status::Error(fmt::format("{}: cannot draft a rig: {}", f.bag,
                                     fmt::join(f.problems, "; ")));
  }
  std::string out = "# rig.txtpb drafted by tiltcal_inspect rig from " + Printable(f.bag) + " (" +
                    f.format + ").\n# Read every line before you use it.\n\n";
  out += "# IMU frame '" + Printable(f.tf_static.imu_frame_id) + "'.\n";
  out += "imu_topic: " + Quoted(f.imu_topic) + "\n";
  out += "# LiDAR frame '" + Printable(f.tf_static.lidar_frame_id) + "'.\n";
  out += "lidar_topic: " + Quoted(f.lidar_topic) + "\n\n";
  if (f.imu.stamps.count >= 2) {
    out += AccelUnitLines(f.imu) + GyroUnitLines(f.imu) + "\n";
  }
  out += ExtrinsicLines(f.tf_static) + "\n";
  out +=
      "# The IMU's height above the ground plane, metres: with the vehicle on level\n"
      "# ground, measure from the ground to the IMU's origin with a tape measure;\n"
      "# then remove the '#' and put the value in.\n"
      "# imu_height_m: 0.0\n";
  *text = out;
  return Status::Ok();
}

Status RunRigDraft(const RigDraftPaths& paths, const proto::CheckParams& params,
                   std::ostream& out, std::ostream& log) {
  TILTCAL_RETURN_IF_ERROR(CheckParamsAreValid(params));
  if (!paths.out.empty()) TILTCAL_RETURN_IF_ERROR(CheckOutputPath(paths.out));
  BagSurveyOptions options;
  options.max_sampled_scans = params.lidar().max_sampled_scans();
  options.point_stride = params.lidar().point_stride();
  BagSurvey survey;
  TILTCAL_RETURN_IF_ERROR(SurveyBag(paths.bag, options, &survey));
  const CheckFindings findings = AnalyseSurvey(survey, nullptr, params);
  std::string text;
  TILTCAL_RETURN_IF_ERROR(DraftRigText(findings, &text));
  // The draft must parse as a Rig: a failure here is a bug, never a file.
  proto::Rig parsed;
  TILTCAL_RETURN_IF_ERROR(ParseTextProto(text, "the drafted rig", &parsed));
  if (paths.out.empty()) {
    out << text;
  } else {
    TILTCAL_RETURN_IF_ERROR(WriteFileAtomically(paths.out, text));
  }
  log << fmt::format("tiltcal_inspect rig: {}; imu_from_lidar {}; fill in imu_height_m\n",
                     paths.out.empty() ? "the rig on standard output" : "wrote " + paths.out,
                     findings.tf_static.found ? "from /tf_static" : "left to the motion (optional)");
  return Status::Ok();
}

}  // namespace tiltcal::inspect
