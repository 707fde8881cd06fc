#ifndef TILTCAL_COMMON_IO_EIGEN_PROTO_H_
#define TILTCAL_COMMON_IO_EIGEN_PROTO_H_

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "tiltcal/proto/geometry.pb.h"

namespace tiltcal {

// Conversions between the on-disk geometry messages and Eigen. Quaternions
// convert field by field ({w x y z} on disk, Eigen stores x y z w), and are
// normalised when read.
Eigen::Vector3d ToEigen(const proto::Vector3& v);
Eigen::Quaterniond ToEigen(const proto::Quaternion& q);
proto::Vector3 ToProto(const Eigen::Vector3d& v);
proto::Quaternion ToProto(const Eigen::Quaterniond& q);

// A rigid transform b_from_a: x_b = rotation * x_a + translation.
struct Rigid3d {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const { return rotation * x + translation; }
  Rigid3d operator*(const Rigid3d& other) const {
    return {rotation * other.rotation, rotation * other.translation + translation};
  }
  Rigid3d inverse() const {
    const Eigen::Quaterniond inv = rotation.conjugate();
    return {inv, -(inv * translation)};
  }
};
Rigid3d ToEigen(const proto::Rigid3& t);
proto::Rigid3 ToProto(const Rigid3d& t);

// True when the quaternion of `t` is present and of non-zero norm.
bool HasValidRotation(const proto::Rigid3& t);

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_IO_EIGEN_PROTO_H_
