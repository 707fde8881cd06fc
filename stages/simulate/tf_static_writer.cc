#include "stages/simulate/tf_static_writer.h"

#include <algorithm>
#include <string>

#include <Eigen/Geometry>

#include "bag/ros1/message_encoding.h"
#include "common/geometry/euler_angles.h"
#include "common/io/eigen_proto.h"

namespace tiltcal::simulate {

namespace {

std::string BaseFrameId(const proto::SimTfStaticParams& p) {
  return p.base_frame_id().empty() ? "base_link" : p.base_frame_id();
}

bag::TransformStamped MakeTransform(const std::string& parent, const std::string& child,
                                    const Eigen::Matrix3d& rotation,
                                    const Eigen::Vector3d& translation, int64_t stamp_ns) {
  bag::TransformStamped t;
  t.header.stamp.sec = static_cast<uint32_t>(stamp_ns / 1000000000);
  t.header.stamp.nsec = static_cast<uint32_t>(stamp_ns % 1000000000);
  t.header.frame_id = parent;
  t.child_frame_id = child;
  Eigen::Quaterniond q(rotation);
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const double wire_rotation[4] = {q.x(), q.y(), q.z(), q.w()};
  std::copy(wire_rotation, wire_rotation + 4, t.rotation);
  for (int i = 0; i < 3; ++i) t.translation[i] = translation[i];
  return t;
}

}  // namespace

Status TfStaticParamsAreValid(const proto::SimulateParams& params) {
  if (!params.tf_static().write()) return Status::Ok();
  const std::string base = BaseFrameId(params.tf_static());
  if (base == params.imu().frame_id() || base == params.lidar().frame_id()) {
    return Status::Error("field tf_static.base_frame_id = '" + base +
                         "' must differ from imu.frame_id and lidar.frame_id");
  }
  if (params.imu().frame_id() == params.lidar().frame_id()) {
    return Status::Error("field tf_static.write needs imu.frame_id and lidar.frame_id to differ");
  }
  return Status::Ok();
}

bag::TfMessage MakeTfStaticMessage(const proto::SimulateParams& params, int64_t stamp_ns) {
  const proto::SimTfStaticParams& p = params.tf_static();
  const std::string base = BaseFrameId(p);
  // T_vb = (C_vb, (0, 0, d_b)): the base frame's origin on the ground below the IMU.
  const Eigen::Matrix3d c_vb =
      geometry::RotationFromEuler123Deg(ToEigen(params.rig().imu_rotation_in_vehicle_deg()));
  const Eigen::Vector3d r_vb(0.0, 0.0, params.rig().imu_height_m());
  const Eigen::Matrix3d c_bl =
      geometry::RotationFromEuler123Deg(ToEigen(params.rig().lidar_rotation_in_imu_deg()));
  const Eigen::Vector3d r_bl = ToEigen(params.rig().lidar_translation_in_imu_m());
  // T_vl = T_vb T_bl, with the URDF's error.
  const Eigen::Matrix3d c_vl =
      c_vb * c_bl * geometry::RotationFromEuler123Deg(ToEigen(p.lidar_rotation_error_deg()));
  const Eigen::Vector3d r_vl = c_vb * r_bl + r_vb + ToEigen(p.lidar_translation_error_m());
  bag::TfMessage msg;
  msg.transforms.push_back(MakeTransform(base, params.imu().frame_id(), c_vb, r_vb, stamp_ns));
  msg.transforms.push_back(MakeTransform(base, params.lidar().frame_id(), c_vl, r_vl, stamp_ns));
  return msg;
}

Status WriteTfStatic(const proto::SimulateParams& params, const Scenario& scenario,
                     ros1::BagWriter* writer) {
  if (!params.tf_static().write()) return Status::Ok();
  // LiDAR stamps are IMU clock − τ and never negative (SetTiming).
  const int64_t stamp_ns = std::max<int64_t>(
      0, scenario.imu_start_stamp_ns - std::max<int64_t>(0, scenario.time_offset_ns));
  const ros1::MessageType& type = ros1::TfMessageType();
  const uint32_t connection =
      writer->AddConnection(bag::kTfStaticTopic, type.type, type.md5sum, type.definition);
  std::string message;
  ros1::SerializeTfMessage(MakeTfStaticMessage(params, stamp_ns), &message);
  return writer->Write(connection, stamp_ns, message);
}

}  // namespace tiltcal::simulate
