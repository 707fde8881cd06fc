#ifndef TILTCAL_STAGES_EXPORT_FORMATS_H_
#define TILTCAL_STAGES_EXPORT_FORMATS_H_

#include <string>
#include <vector>

#include "stages/export/exported_calibration.h"

namespace tiltcal::exporter {

// One output format of tiltcal_export: the text a consumer pastes.
struct ExportFormat {
  std::string name;         // the --format value
  std::string description;  // one line for --help
  std::string (*write)(const ExportedCalibration&);
};

// Every format, in the order --help lists them.
const std::vector<ExportFormat>& ExportFormats();
// The format named `name`, or nullptr.
const ExportFormat* FindExportFormat(const std::string& name);
// "fast_lio, lio_sam, ..." for messages.
std::string ExportFormatNames();

// YAML for LiDAR-inertial odometry packages and Kalibr (yaml_formats.cc).
// FAST-LIO / FAST-LIVO: extrinsic_R = C_bl, extrinsic_T = r_b^{lb} (the
// LiDAR in the IMU frame), time_offset_lidar_to_imu = τ.
std::string WriteFastLio(const ExportedCalibration& c);
// LIO-SAM: extrinsicRot = extrinsicRPY = C_lb (IMU vectors into the LiDAR
// frame), extrinsicTrans = r_l^{bl} (the IMU's position in the LiDAR frame).
std::string WriteLioSam(const ExportedCalibration& c);
// Kalibr-style: T_imu_lidar and T_lidar_imu (4x4), timeshift_lidar_imu = τ.
std::string WriteKalibr(const ExportedCalibration& c);

// ROS frames (ros_formats.cc): the LiDAR frame as child of the IMU frame.
// URDF fixed joint: origin xyz = r_b^{lb}, rpy = 1-2-3 Euler angles of C_bl.
std::string WriteUrdf(const ExportedCalibration& c);
// static_transform_publisher command lines, ROS 1 and ROS 2 syntax.
std::string WriteTfRos1(const ExportedCalibration& c);
std::string WriteTfRos2(const ExportedCalibration& c);

// Plain numbers (plain_formats.cc): 4x4 both directions, quaternion +
// translation both directions; and everything as one JSON object.
std::string WriteMatrix(const ExportedCalibration& c);
std::string WriteJson(const ExportedCalibration& c);

// Shared by the formats (formats.cc).
// A number with 9 decimals, never "-0.000000000".
std::string Num(double value);
// Roll, pitch, yaw (rad) of `rotation`: rotation = Rz(yaw) Ry(pitch) Rx(roll)
// (fixed axes x, y, z; URDF's rpy and tf's setRPY).
Eigen::Vector3d RollPitchYaw(const Eigen::Quaterniond& rotation);
// The text every commented format starts with, as lines ending in '\n'
// (each format writes it with CommentLines or XmlComment, escaping.h):
// source, verdict and reasons (each line of a reason indented), τ's sign
// convention, σ.
std::string HeaderText(const ExportedCalibration& c);
// The 4x4 homogeneous matrix of a transform: [R t; 0 0 0 1].
Eigen::Matrix4d Homogeneous(const Rigid3d& transform);

}  // namespace tiltcal::exporter

#endif  // TILTCAL_STAGES_EXPORT_FORMATS_H_
