// Plain numbers: 4x4 matrices and quaternion + translation in both
// directions, and one JSON object with everything.
#include <fmt/format.h>

#include "common/io/escaping.h"
#include "stages/export/formats.h"

namespace tiltcal::exporter {
namespace {

std::string MatrixRows(const Eigen::Matrix4d& m) {
  std::string out;
  for (int r = 0; r < 4; ++r) {
    out += fmt::format("{} {} {} {}\n", Num(m(r, 0)), Num(m(r, 1)), Num(m(r, 2)), Num(m(r, 3)));
  }
  return out;
}

std::string JsonVector(const Eigen::VectorXd& v) {
  std::string out = "[";
  for (int i = 0; i < v.size(); ++i) out += (i > 0 ? ", " : "") + Num(v(i));
  return out + "]";
}

std::string JsonTransform(const Rigid3d& t, const std::string& meaning,
                          const std::string& indent) {
  const Eigen::Matrix4d m = Homogeneous(t);
  const Eigen::Quaterniond& q = t.rotation;
  std::string rows;
  for (int r = 0; r < 4; ++r) {
    rows += (r > 0 ? ",\n" + indent + "             " : "") +
            JsonVector(m.row(r).transpose());
  }
  return fmt::format(
      "{{\n{i}  \"meaning\": {},\n{i}  \"matrix\": [{}],\n{i}  \"quaternion_wxyz\": {},\n"
      "{i}  \"translation_m\": {},\n{i}  \"roll_pitch_yaw_rad\": {}\n{i}}}",
      QuotedString(meaning), rows, JsonVector(Eigen::Vector4d(q.w(), q.x(), q.y(), q.z())),
      JsonVector(t.translation), JsonVector(RollPitchYaw(q)), fmt::arg("i", indent));
}

}  // namespace

std::string WriteMatrix(const ExportedCalibration& c) {
  std::string out = CommentLines(HeaderText(c), "# ");
  const Eigen::Quaterniond& q = c.imu_from_lidar.rotation;
  const Eigen::Quaterniond& qi = c.lidar_from_imu.rotation;
  const Eigen::Vector3d& t = c.imu_from_lidar.translation;
  const Eigen::Vector3d& ti = c.lidar_from_imu.translation;
  out += "# T_imu_lidar (imu_from_lidar, C_bl and r_b^{lb}): x_imu = T_imu_lidar x_lidar\n";
  out += MatrixRows(Homogeneous(c.imu_from_lidar));
  out += "# T_lidar_imu (lidar_from_imu, its inverse): x_lidar = T_lidar_imu x_imu\n";
  out += MatrixRows(Homogeneous(c.lidar_from_imu));
  out += "# imu_from_lidar as a Hamilton unit quaternion (w x y z) and a translation (m)\n";
  out += fmt::format("{} {} {} {}\n{} {} {}\n", Num(q.w()), Num(q.x()), Num(q.y()), Num(q.z()),
                     Num(t.x()), Num(t.y()), Num(t.z()));
  out += "# lidar_from_imu as a Hamilton unit quaternion (w x y z) and a translation (m)\n";
  out += fmt::format("{} {} {} {}\n{} {} {}\n", Num(qi.w()), Num(qi.x()), Num(qi.y()),
                     Num(qi.z()), Num(ti.x()), Num(ti.y()), Num(ti.z()));
  out += "# time offset tau (s): t_imu = t_lidar + tau\n";
  out += Num(c.time_offset_s) + "\n";
  return out;
}

std::string WriteJson(const ExportedCalibration& c) {
  std::string reasons = "[";
  for (size_t i = 0; i < c.verdict_reasons.size(); ++i) {
    reasons += (i > 0 ? ", " : "") + QuotedString(c.verdict_reasons[i]);
  }
  reasons += "]";
  std::string out = "{\n";
  out += fmt::format("  \"source\": {},\n", QuotedString(c.source));
  out += fmt::format("  \"verdict\": {},\n  \"verdict_reasons\": {},\n", QuotedString(c.verdict),
                     reasons);
  out += fmt::format("  \"imu_frame\": {},\n  \"lidar_frame\": {},\n", QuotedString(c.imu_frame),
                     QuotedString(c.lidar_frame));
  out += "  \"imu_from_lidar\": " +
         JsonTransform(c.imu_from_lidar,
                       "x_imu = R x_lidar + t: the LiDAR's pose in the IMU frame (C_bl, r_b^{lb})",
                       "  ") +
         ",\n";
  out += "  \"lidar_from_imu\": " +
         JsonTransform(c.lidar_from_imu,
                       "x_lidar = R x_imu + t: the IMU's pose in the LiDAR frame (C_lb, r_l^{bl})",
                       "  ") +
         ",\n";
  out += fmt::format("  \"time_offset_s\": {},\n", Num(c.time_offset_s));
  out += "  \"time_offset_convention\": \"t_imu = t_lidar + time_offset_s\"";
  if (c.sigma) {
    const ExportedSigma& s = *c.sigma;
    out += fmt::format(
        ",\n  \"sigma\": {{\n"
        "    \"rotation_deg\": {},\n"
        "    \"rotation_axes\": \"LiDAR (right perturbation of C_bl)\",\n"
        "    \"translation_m\": {},\n"
        "    \"translation_axes\": \"IMU\",\n"
        "    \"time_offset_s\": {}\n  }}",
        JsonVector(s.rotation_deg), JsonVector(s.translation_m), Num(s.time_offset_s));
  }
  out += "\n}\n";
  return out;
}

}  // namespace tiltcal::exporter
