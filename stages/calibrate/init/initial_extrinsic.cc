#include "stages/calibrate/init/initial_extrinsic.h"

#include <cmath>
#include <filesystem>
#include <optional>
#include <ostream>
#include <vector>

#include <fmt/format.h>

#include "common/geometry/angles.h"
#include "common/io/eigen_proto.h"
#include "common/io/imu_stream.h"
#include "common/io/rig.h"
#include "common/io/text_proto.h"
#include "common/io/tf_static_extrinsic.h"
#include "stages/calibrate/init/rotation_from_motion.h"
#include "stages/calibrate/problem/lidar_scans.h"
#include "stages/calibrate/report/imu_vibration.h"

namespace tiltcal::calibrate {
namespace {

void Log(std::ostream* log, const std::string& line) {
  if (log != nullptr) *log << "tiltcal_initial_extrinsic: " << line << "\n" << std::flush;
}

const char* SourceName(proto::StartingExtrinsic::Source source) {
  switch (source) {
    case proto::StartingExtrinsic::RIG:
      return "the rig's imu_from_lidar";
    case proto::StartingExtrinsic::TF_STATIC:
      return "the bag's /tf_static";
    default:
      return "no guess";
  }
}

// The guess the search starts from (rotation_search.start_from).
std::optional<Rigid3d> ChooseGuess(const proto::Rig& rig, const std::optional<Rigid3d>& tf_static,
                                   const proto::RotationSearchParams& params,
                                   proto::StartingExtrinsic* start) {
  if (params.start_from() == proto::RotationSearchParams::AUTO) {
    if (rig.has_imu_from_lidar()) {
      start->set_guess_source(proto::StartingExtrinsic::RIG);
      return ToEigen(rig.imu_from_lidar());
    }
    if (tf_static) {
      start->set_guess_source(proto::StartingExtrinsic::TF_STATIC);
      return tf_static;
    }
  }
  start->set_guess_source(proto::StartingExtrinsic::NONE);
  return std::nullopt;
}

// rig.gravity_reference is relative to the rig's folder: the same place
// seen from the sequence rig's folder.
std::string GravityReferenceFrom(const std::string& rig_path, const std::string& out_path,
                                 const std::string& reference) {
  namespace fs = std::filesystem;
  if (reference.empty() || fs::path(reference).is_absolute()) return reference;
  const fs::path target =
      (fs::absolute(fs::path(rig_path)).parent_path() / reference).lexically_normal();
  const fs::path from = fs::absolute(fs::path(out_path)).parent_path().lexically_normal();
  const fs::path relative = target.lexically_relative(from);
  return relative.empty() ? target.string() : relative.string();
}

}  // namespace

Status FindSequenceRig(const InitialExtrinsicPaths& paths, const proto::CalibrateParams& params,
                       std::ostream* log, proto::Rig* sequence_rig) {
  proto::Rig rig;
  TILTCAL_RETURN_IF_ERROR(LoadRig(paths.rig, &rig));
  std::vector<imu::ImuReading> imu;
  int64_t first_imu_stamp_ns = 0;
  TILTCAL_RETURN_IF_ERROR(ReadImuReadings(paths.imu, &imu, &first_imu_stamp_ns));
  // The readings the calibration will use (imu_vibration.h): vibration
  // would otherwise swamp the accelerations that decide the rotation about
  // the motion's axis.
  proto::CalibrateParams used = params;
  proto::ImuVibrationReport vibration;
  TILTCAL_RETURN_IF_ERROR(
      HandleImuVibration(params.imu_vibration(), &imu, used.mutable_imu_noise(), &vibration)
          .WithContext(paths.imu));
  if (vibration.filtered()) Log(log, DescribeImuVibration(vibration));
  std::vector<LidarScan> scans;
  TILTCAL_RETURN_IF_ERROR(ReadLidarScans(paths.scans, first_imu_stamp_ns, params.scans(), &scans));
  if (scans.empty()) return Status::Error(paths.scans + ": no scans");
  std::optional<Rigid3d> tf_static;
  TILTCAL_RETURN_IF_ERROR(ReadTfStaticExtrinsic(paths.imu, &tf_static));

  proto::StartingExtrinsic start;
  const std::optional<Rigid3d> guess = ChooseGuess(rig, tf_static, params.rotation_search(), &start);
  if (tf_static) *start.mutable_tf_static() = ToProto(*tf_static);
  if (guess) *start.mutable_guess() = ToProto(*guess);
  start.set_translation_known(guess.has_value());
  const Eigen::Vector3d translation = guess ? guess->translation : Eigen::Vector3d::Zero();

  RotationFromMotion found;
  const Status status = FindImuFromLidarRotation(
      imu, scans, guess ? std::optional<Eigen::Quaterniond>(guess->rotation) : std::nullopt,
      translation, used, &found);
  if (!status.ok()) {
    const std::string message =
        "cannot find the extrinsic rotation from the motion: " + status.message();
    return status.not_determined() ? Status::NotDetermined(message) : Status::Error(message);
  }
  const double change_deg =
      guess ? geometry::RadToDeg(
                  Eigen::AngleAxisd(found.imu_from_lidar * guess->rotation.conjugate()).angle())
            : 0.0;
  start.set_rotation_change_deg(change_deg);
  const std::string about_axis =
      found.rounds.back().from_hand_eye
          ? "hand-eye (the motion turns about several axes)"
          : (found.about_axis_decided ? "the rotation axes and the accelerations"
                                      : "the rotation axes; about the axis the guess's "
                                        "(accelerations too small to check it)");
  start.set_summary(
      guess ? fmt::format("started from {}; the motion ({}, {} rounds) turned it by {:.2f} deg",
                          SourceName(start.guess_source()), about_axis, found.rounds.size(),
                          change_deg)
            : fmt::format("no guess: the rotation from the motion ({}, {} rounds); the "
                          "translation from the calibration alone",
                          about_axis, found.rounds.size()));
  Log(log, start.summary());
  Log(log, fmt::format("C_bl (w x y z) {:.6f} {:.6f} {:.6f} {:.6f}; turning {:.3f} rad RMS per "
                       "pair; coarse tau {:.4f} s; {:.2f} s",
                       found.imu_from_lidar.w(), found.imu_from_lidar.x(),
                       found.imu_from_lidar.y(), found.imu_from_lidar.z(),
                       found.turning.rms_about_axis_rad, found.time_offset_s, found.seconds));

  *sequence_rig = rig;
  *sequence_rig->mutable_imu_from_lidar() = ToProto(Rigid3d{found.imu_from_lidar, translation});
  *sequence_rig->mutable_starting_extrinsic() = start;
  sequence_rig->set_gravity_reference(
      GravityReferenceFrom(paths.rig, paths.out, rig.gravity_reference()));
  return Status::Ok();
}

Status RunInitialExtrinsic(const InitialExtrinsicPaths& paths,
                           const proto::CalibrateParams& params, std::ostream* log,
                           proto::Rig* sequence_rig) {
  TILTCAL_RETURN_IF_ERROR(FindSequenceRig(paths, params, log, sequence_rig));
  return WriteTextProto(paths.out, *sequence_rig);
}

}  // namespace tiltcal::calibrate
