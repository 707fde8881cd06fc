// ROS frames: a URDF fixed joint and static_transform_publisher command
// lines. In all three the LiDAR frame is the child of the IMU frame and the
// numbers are the child's pose in the parent: x_imu = R x_lidar + t with
// R = C_bl = Rz(yaw) Ry(pitch) Rx(roll) and t = r_b^{lb}.
#include <fmt/format.h>

#include "common/io/escaping.h"
#include "stages/export/formats.h"

namespace tiltcal::exporter {
namespace {

constexpr char kTfDirection[] =
    "# static_transform_publisher: parent (frame_id) = IMU frame, child = LiDAR frame;\n"
    "#   x_imu = R x_lidar + (x y z), R = Rz(yaw) Ry(pitch) Rx(roll), angles in rad.\n"
    "# tf has no time offset: tau (above) belongs in the driver's or the estimator's\n"
    "#   time settings.\n";

}  // namespace

std::string WriteUrdf(const ExportedCalibration& c) {
  const Eigen::Vector3d t = c.imu_from_lidar.translation;
  const Eigen::Vector3d rpy = RollPitchYaw(c.imu_from_lidar.rotation);
  std::string out = XmlComment(
      HeaderText(c) +
      "The LiDAR link's pose in the IMU link: x_imu = R(rpy) x_lidar + xyz, with\n"
      "R(rpy) = Rz(yaw) Ry(pitch) Rx(roll) (fixed axes, rad) = C_bl and xyz = r_b^{lb} (m).\n"
      "URDF has no time offset: tau (above) belongs in the driver's or the estimator's\n"
      "time settings.");
  out += fmt::format("<joint name=\"{}\" type=\"fixed\">\n",
                     XmlAttribute(c.imu_frame + "_to_" + c.lidar_frame));
  out += fmt::format("  <parent link=\"{}\"/>\n", XmlAttribute(c.imu_frame));
  out += fmt::format("  <child link=\"{}\"/>\n", XmlAttribute(c.lidar_frame));
  out += fmt::format("  <origin xyz=\"{} {} {}\" rpy=\"{} {} {}\"/>\n", Num(t.x()), Num(t.y()),
                     Num(t.z()), Num(rpy.x()), Num(rpy.y()), Num(rpy.z()));
  out += "</joint>\n";
  return out;
}

std::string WriteTfRos1(const ExportedCalibration& c) {
  const Eigen::Vector3d t = c.imu_from_lidar.translation;
  const Eigen::Vector3d rpy = RollPitchYaw(c.imu_from_lidar.rotation);
  const Eigen::Quaterniond& q = c.imu_from_lidar.rotation;
  std::string out = CommentLines(HeaderText(c), "# ") + kTfDirection;
  out += "# ROS 1 argument order: x y z yaw pitch roll frame_id child_frame_id\n";
  out += fmt::format("rosrun tf2_ros static_transform_publisher {} {} {} {} {} {} {} {}\n",
                     Num(t.x()), Num(t.y()), Num(t.z()), Num(rpy.z()), Num(rpy.y()),
                     Num(rpy.x()), ShellWord(c.imu_frame), ShellWord(c.lidar_frame));
  out += "# the same with the quaternion: x y z qx qy qz qw frame_id child_frame_id\n";
  out += fmt::format("# rosrun tf2_ros static_transform_publisher {} {} {} {} {} {} {} {} {}\n",
                     Num(t.x()), Num(t.y()), Num(t.z()), Num(q.x()), Num(q.y()), Num(q.z()),
                     Num(q.w()), ShellWord(c.imu_frame), ShellWord(c.lidar_frame));
  return out;
}

std::string WriteTfRos2(const ExportedCalibration& c) {
  const Eigen::Vector3d t = c.imu_from_lidar.translation;
  const Eigen::Vector3d rpy = RollPitchYaw(c.imu_from_lidar.rotation);
  const Eigen::Quaterniond& q = c.imu_from_lidar.rotation;
  std::string out = CommentLines(HeaderText(c), "# ") + kTfDirection;
  out += fmt::format(
      "ros2 run tf2_ros static_transform_publisher --x {} --y {} --z {} --roll {} --pitch {} "
      "--yaw {} --frame-id {} --child-frame-id {}\n",
      Num(t.x()), Num(t.y()), Num(t.z()), Num(rpy.x()), Num(rpy.y()), Num(rpy.z()),
      ShellWord(c.imu_frame), ShellWord(c.lidar_frame));
  out += "# the same with the quaternion:\n";
  out += fmt::format(
      "# ros2 run tf2_ros static_transform_publisher --x {} --y {} --z {} --qx {} --qy {} "
      "--qz {} --qw {} --frame-id {} --child-frame-id {}\n",
      Num(t.x()), Num(t.y()), Num(t.z()), Num(q.x()), Num(q.y()), Num(q.z()), Num(q.w()),
      ShellWord(c.imu_frame), ShellWord(c.lidar_frame));
  return out;
}

}  // namespace tiltcal::exporter
