#include "common/io/eigen_proto.h"

namespace tiltcal {

Eigen::Vector3d ToEigen(const proto::Vector3& v) { return {v.x(), v.y(), v.z()}; }

Eigen::Quaterniond ToEigen(const proto::Quaternion& q) {
  return Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z()).normalized();
}

proto::Vector3 ToProto(const Eigen::Vector3d& v) {
  proto::Vector3 out;
  out.set_x(v.x());
  out.set_y(v.y());
  out.set_z(v.z());
  return out;
}

proto::Quaternion ToProto(const Eigen::Quaterniond& q) {
  proto::Quaternion out;
  out.set_w(q.w());
  out.set_x(q.x());
  out.set_y(q.y());
  out.set_z(q.z());
  return out;
}

Rigid3d ToEigen(const proto::Rigid3& t) {
  return {ToEigen(t.rotation()), ToEigen(t.translation())};
}

proto::Rigid3 ToProto(const Rigid3d& t) {
  proto::Rigid3 out;
  *out.mutable_rotation() = ToProto(t.rotation);
  *out.mutable_translation() = ToProto(t.translation);
  return out;
}

bool HasValidRotation(const proto::Rigid3& t) {
  const auto& q = t.rotation();
  return t.has_rotation() && q.w() * q.w() + q.x() * q.x() + q.y() * q.y() + q.z() * q.z() > 1e-12;
}

}  // namespace tiltcal
