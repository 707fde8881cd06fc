#include "stages/export/formats.h"

#include <cmath>

#include <fmt/format.h>

#include "common/geometry/euler_angles.h"
#include "common/io/escaping.h"

namespace tiltcal::exporter {

const std::vector<ExportFormat>& ExportFormats() {
  static const std::vector<ExportFormat> formats = {
      {"fast_lio", "FAST-LIO / FAST-LIVO YAML: extrinsic_T, extrinsic_R (LiDAR in IMU frame)",
       &WriteFastLio},
      {"lio_sam", "LIO-SAM YAML: extrinsicTrans, extrinsicRot, extrinsicRPY", &WriteLioSam},
      {"urdf", "URDF fixed <joint>: IMU link parent, LiDAR link child (xyz, rpy)", &WriteUrdf},
      {"tf_ros1", "ROS 1 static_transform_publisher arguments", &WriteTfRos1},
      {"tf_ros2", "ROS 2 static_transform_publisher arguments", &WriteTfRos2},
      {"kalibr", "Kalibr-style YAML: T_imu_lidar, T_lidar_imu (4x4), timeshift_lidar_imu",
       &WriteKalibr},
      {"matrix", "plain 4x4 in both directions, quaternion + translation", &WriteMatrix},
      {"json", "everything as one JSON object", &WriteJson},
  };
  return formats;
}

const ExportFormat* FindExportFormat(const std::string& name) {
  for (const ExportFormat& format : ExportFormats()) {
    if (format.name == name) return &format;
  }
  return nullptr;
}

std::string ExportFormatNames() {
  std::string names;
  for (const ExportFormat& format : ExportFormats()) {
    names += (names.empty() ? "" : ", ") + format.name;
  }
  return names;
}

std::string Num(double value) {
  std::string text = fmt::format("{:.9f}", value);
  if (text.find_first_not_of("-0.") == std::string::npos && text[0] == '-') text.erase(0, 1);
  return text;
}

Eigen::Vector3d RollPitchYaw(const Eigen::Quaterniond& rotation) {
  return geometry::Euler123FromRotation(rotation.toRotationMatrix());
}

Eigen::Matrix4d Homogeneous(const Rigid3d& transform) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = transform.rotation.toRotationMatrix();
  m.topRightCorner<3, 1>() = transform.translation;
  return m;
}

std::string HeaderText(const ExportedCalibration& c) {
  std::string out;
  auto line = [&](const std::string& text) { out += text + "\n"; };
  line("tiltcal LiDAR-IMU calibration from " + c.source);
  line("verdict: " + c.verdict);
  for (const std::string& reason : c.verdict_reasons) out += CommentLines(reason, "  ");
  line(fmt::format("time offset tau = {} s: t_imu = t_lidar + tau (a LiDAR stamp plus tau is",
                   Num(c.time_offset_s)));
  line("  the same instant on the IMU clock; tau > 0: the LiDAR clock is behind the IMU's)");
  if (!c.clock_drift_advice.empty()) line("clock drift: " + c.clock_drift_advice);
  if (c.sigma) {
    const ExportedSigma& s = *c.sigma;
    line(fmt::format("1-sigma: rotation {:.3g} {:.3g} {:.3g} deg (about the LiDAR axes),",
                     s.rotation_deg.x(), s.rotation_deg.y(), s.rotation_deg.z()));
    line(fmt::format("  translation {:.3g} {:.3g} {:.3g} m (IMU axes), tau {:.3g} s",
                     s.translation_m.x(), s.translation_m.y(), s.translation_m.z(),
                     s.time_offset_s));
  } else {
    line("1-sigma: not in the calibration file");
  }
  return out;
}

}  // namespace tiltcal::exporter
