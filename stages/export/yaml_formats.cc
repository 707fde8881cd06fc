// YAML for FAST-LIO, LIO-SAM and Kalibr-style consumers.
#include <fmt/format.h>

#include "common/io/escaping.h"
#include "stages/export/formats.h"

namespace tiltcal::exporter {
namespace {

// "[ a, b, c ]" of a 3-vector.
std::string FlowVector(const Eigen::Vector3d& v) {
  return fmt::format("[ {}, {}, {} ]", Num(v.x()), Num(v.y()), Num(v.z()));
}

// A 3x3 matrix as a flow sequence of 9 numbers, row-major, one row per line;
// `indent` is the column the first number's row starts at.
std::string FlowMatrix3(const Eigen::Matrix3d& m, int indent) {
  std::string out = "[ ";
  const std::string pad(indent + 2, ' ');
  for (int r = 0; r < 3; ++r) {
    if (r > 0) out += ",\n" + pad;
    out += fmt::format("{}, {}, {}", Num(m(r, 0)), Num(m(r, 1)), Num(m(r, 2)));
  }
  return out + " ]";
}

// A 4x4 matrix as a block sequence of rows, Kalibr's layout.
std::string BlockMatrix4(const Eigen::Matrix4d& m, const std::string& indent) {
  std::string out;
  for (int r = 0; r < 4; ++r) {
    out += fmt::format("{}- [ {}, {}, {}, {} ]\n", indent, Num(m(r, 0)), Num(m(r, 1)),
                       Num(m(r, 2)), Num(m(r, 3)));
  }
  return out;
}

}  // namespace

std::string WriteFastLio(const ExportedCalibration& c) {
  std::string out = CommentLines(HeaderText(c), "# ");
  out +=
      "# FAST-LIO / FAST-LIVO: the LiDAR's pose in the IMU frame,\n"
      "#   p_imu = extrinsic_R * p_lidar + extrinsic_T\n"
      "# (extrinsic_R = C_bl row-major, extrinsic_T = r_b^{lb} in m, IMU axes).\n"
      "# time_offset_lidar_to_imu: FAST-LIO subtracts it from every IMU stamp to put\n"
      "# the IMU on the LiDAR clock, t_lidar = t_imu - offset, so it equals tau.\n";
  const std::string key = "    extrinsic_R: ";
  out += "common:\n";
  out += fmt::format("    time_offset_lidar_to_imu: {}\n", Num(c.time_offset_s));
  out += "mapping:\n";
  out += "    extrinsic_est_en: false\n";
  out += fmt::format("    extrinsic_T: {}\n", FlowVector(c.imu_from_lidar.translation));
  out += key + FlowMatrix3(c.imu_from_lidar.rotation.toRotationMatrix(),
                           static_cast<int>(key.size())) + "\n";
  return out;
}

std::string WriteLioSam(const ExportedCalibration& c) {
  std::string out = CommentLines(HeaderText(c), "# ");
  out +=
      "# LIO-SAM: extrinsicRot and extrinsicRPY rotate IMU-frame vectors into the\n"
      "#   LiDAR frame, v_lidar = extrinsicRot * v_imu (C_lb = C_bl^T, row-major); LIO-SAM\n"
      "#   applies extrinsicRot to the IMU's acceleration and rate and extrinsicRPY to its\n"
      "#   orientation output, the same matrix for an IMU that reports orientation in its\n"
      "#   own axes.\n"
      "# extrinsicTrans: the IMU's position in the LiDAR frame, r_l^{bl} = -C_lb r_b^{lb} (m),\n"
      "#   the translation of LIO-SAM's lidar2Imu.\n"
      "# LIO-SAM has no time-offset parameter: add tau to the LiDAR stamps (t_imu = t_lidar\n"
      "#   + tau) before LIO-SAM sees them, or leave it if |tau| is below a millisecond.\n";
  const Eigen::Matrix3d lidar_from_imu = c.lidar_from_imu.rotation.toRotationMatrix();
  const std::string rot_key = "  extrinsicRot: ";
  const std::string rpy_key = "  extrinsicRPY: ";
  out += "lio_sam:\n";
  out += fmt::format("  extrinsicTrans: {}\n", FlowVector(c.lidar_from_imu.translation));
  out += rot_key + FlowMatrix3(lidar_from_imu, static_cast<int>(rot_key.size())) + "\n";
  out += rpy_key + FlowMatrix3(lidar_from_imu, static_cast<int>(rpy_key.size())) + "\n";
  return out;
}

std::string WriteKalibr(const ExportedCalibration& c) {
  std::string out = CommentLines(HeaderText(c), "# ");
  out +=
      "# Kalibr-style: T_a_b maps coordinates in frame b to frame a, x_a = T_a_b x_b\n"
      "#   (4x4 homogeneous, row by row, m): T_imu_lidar = [C_bl r_b^{lb}; 0 1], T_lidar_imu\n"
      "#   its inverse.\n"
      "# timeshift_lidar_imu: t_imu = t_lidar + timeshift (s), the convention of Kalibr's\n"
      "#   timeshift_cam_imu; it is tau.\n";
  out += "lidar0:\n";
  out += fmt::format("  frame_id: {}\n  parent_frame_id: {}\n", QuotedString(c.lidar_frame),
                     QuotedString(c.imu_frame));
  out += "  T_imu_lidar:\n" + BlockMatrix4(Homogeneous(c.imu_from_lidar), "  ");
  out += "  T_lidar_imu:\n" + BlockMatrix4(Homogeneous(c.lidar_from_imu), "  ");
  out += fmt::format("  timeshift_lidar_imu: {}\n", Num(c.time_offset_s));
  if (c.sigma) {
    const ExportedSigma& s = *c.sigma;
    out += "  # 1-sigma of C_bl about the LiDAR axes (deg), of r_b^{lb} (m), of tau (s)\n";
    out += fmt::format("  rotation_sigma_deg: {}\n", FlowVector(s.rotation_deg));
    out += fmt::format("  translation_sigma_m: {}\n", FlowVector(s.translation_m));
    out += fmt::format("  timeshift_sigma_s: {}\n", Num(s.time_offset_s));
  }
  out += fmt::format("  verdict: {}\n", c.verdict);
  return out;
}

}  // namespace tiltcal::exporter
