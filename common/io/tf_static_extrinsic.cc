#include "common/io/tf_static_extrinsic.h"

#include <cmath>

#include "common/io/record_stream.h"

namespace tiltcal {

Status ReadTfStaticExtrinsic(const std::string& stream_path,
                             std::optional<Rigid3d>* imu_from_lidar,
                             proto::TfStaticExtrinsic* record) {
  imu_from_lidar->reset();
  RecordReader reader;
  TILTCAL_RETURN_IF_ERROR(reader.Open(stream_path));
  const proto::TfStaticExtrinsic& tf = reader.header().provenance().tf_static();
  if (record != nullptr) *record = tf;
  if (!tf.has_imu_from_lidar()) return Status::Ok();
  const proto::Rigid3& t = tf.imu_from_lidar();
  const proto::Quaternion& q = t.rotation();
  const proto::Vector3& r = t.translation();
  const double norm = std::sqrt(q.w() * q.w() + q.x() * q.x() + q.y() * q.y() + q.z() * q.z());
  if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-6 || !std::isfinite(r.x()) ||
      !std::isfinite(r.y()) || !std::isfinite(r.z())) {
    return Status::Error(stream_path +
                         ": provenance.tf_static.imu_from_lidar is not a finite rigid transform "
                         "with a unit quaternion");
  }
  *imu_from_lidar = ToEigen(t);
  return Status::Ok();
}

}  // namespace tiltcal
