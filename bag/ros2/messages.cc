#include "bag/ros2/messages.h"

#include "bag/ros2/cdr_reader.h"

namespace tiltcal::ros2 {

namespace {

Status ReadHeader(CdrReader* r, bag::Header* h) {
  int32_t sec = 0;
  TILTCAL_RETURN_IF_ERROR(r->I32("header.stamp.sec", &sec));
  if (sec < 0) {
    return Status::Error("header.stamp.sec is negative (" + std::to_string(sec) +
                         "): a stamp before 1970");
  }
  h->seq = 0;
  h->stamp.sec = static_cast<uint32_t>(sec);
  TILTCAL_RETURN_IF_ERROR(r->U32("header.stamp.nanosec", &h->stamp.nsec));
  return r->String("header.frame_id", &h->frame_id);
}

}  // namespace

Status DecodeImu(const uint8_t* data, size_t size, bag::ImuMessage* imu) {
  CdrReader r;
  TILTCAL_RETURN_IF_ERROR(r.Open(data, size));
  TILTCAL_RETURN_IF_ERROR(ReadHeader(&r, &imu->header));
  TILTCAL_RETURN_IF_ERROR(r.F64s("orientation", imu->orientation, 4));
  TILTCAL_RETURN_IF_ERROR(r.F64s("orientation_covariance", imu->orientation_covariance, 9));
  TILTCAL_RETURN_IF_ERROR(r.F64s("angular_velocity", imu->angular_velocity, 3));
  TILTCAL_RETURN_IF_ERROR(
      r.F64s("angular_velocity_covariance", imu->angular_velocity_covariance, 9));
  TILTCAL_RETURN_IF_ERROR(r.F64s("linear_acceleration", imu->linear_acceleration, 3));
  TILTCAL_RETURN_IF_ERROR(
      r.F64s("linear_acceleration_covariance", imu->linear_acceleration_covariance, 9));
  return r.ExpectEnd(kImuType);
}

Status DecodePointCloud2(const uint8_t* data, size_t size, bag::PointCloud2View* cloud) {
  CdrReader r;
  TILTCAL_RETURN_IF_ERROR(r.Open(data, size));
  TILTCAL_RETURN_IF_ERROR(ReadHeader(&r, &cloud->header));
  TILTCAL_RETURN_IF_ERROR(r.U32("height", &cloud->height));
  TILTCAL_RETURN_IF_ERROR(r.U32("width", &cloud->width));
  uint32_t num_fields = 0;
  TILTCAL_RETURN_IF_ERROR(r.U32("fields", &num_fields));
  // Each PointField takes at least 13 bytes; refuse absurd counts before resizing.
  if (num_fields > size / 13) {
    return Status::Error("message runs past its end: " + std::to_string(num_fields) +
                         " point fields cannot fit in " + std::to_string(size) + " bytes");
  }
  cloud->fields.resize(num_fields);
  for (bag::PointField& field : cloud->fields) {
    TILTCAL_RETURN_IF_ERROR(r.String("fields.name", &field.name));
    TILTCAL_RETURN_IF_ERROR(r.U32("fields.offset", &field.offset));
    TILTCAL_RETURN_IF_ERROR(r.U8("fields.datatype", &field.datatype));
    TILTCAL_RETURN_IF_ERROR(r.U32("fields.count", &field.count));
  }
  TILTCAL_RETURN_IF_ERROR(r.Bool("is_bigendian", &cloud->is_bigendian));
  TILTCAL_RETURN_IF_ERROR(r.U32("point_step", &cloud->point_step));
  TILTCAL_RETURN_IF_ERROR(r.U32("row_step", &cloud->row_step));
  TILTCAL_RETURN_IF_ERROR(r.ByteSequence("data", &cloud->data, &cloud->data_size));
  TILTCAL_RETURN_IF_ERROR(r.Bool("is_dense", &cloud->is_dense));
  return r.ExpectEnd(kPointCloud2Type);
}

Status DecodeLivoxCustomMsg(const uint8_t* data, size_t size, bag::LivoxCustomMessage* msg) {
  CdrReader r;
  TILTCAL_RETURN_IF_ERROR(r.Open(data, size));
  TILTCAL_RETURN_IF_ERROR(ReadHeader(&r, &msg->header));
  TILTCAL_RETURN_IF_ERROR(r.U64("timebase", &msg->timebase));
  TILTCAL_RETURN_IF_ERROR(r.U32("point_num", &msg->point_num));
  TILTCAL_RETURN_IF_ERROR(r.U8("lidar_id", &msg->lidar_id));
  for (uint8_t& b : msg->rsvd) TILTCAL_RETURN_IF_ERROR(r.U8("rsvd", &b));
  uint32_t count = 0;
  TILTCAL_RETURN_IF_ERROR(r.U32("points", &count));
  // A CustomPoint takes at least 19 bytes; refuse absurd counts before resizing.
  if (count > size / 19) {
    return Status::Error("message runs past its end: " + std::to_string(count) +
                         " points cannot fit in " + std::to_string(size) + " bytes");
  }
  if (count != msg->point_num) {
    return Status::Error("point_num is " + std::to_string(msg->point_num) +
                         " but the points array holds " + std::to_string(count) + " points");
  }
  msg->points.resize(count);
  for (bag::LivoxPoint& p : msg->points) {
    TILTCAL_RETURN_IF_ERROR(r.U32("points.offset_time", &p.offset_time));
    TILTCAL_RETURN_IF_ERROR(r.F32("points.x", &p.x));
    TILTCAL_RETURN_IF_ERROR(r.F32("points.y", &p.y));
    TILTCAL_RETURN_IF_ERROR(r.F32("points.z", &p.z));
    TILTCAL_RETURN_IF_ERROR(r.U8("points.reflectivity", &p.reflectivity));
    TILTCAL_RETURN_IF_ERROR(r.U8("points.tag", &p.tag));
    TILTCAL_RETURN_IF_ERROR(r.U8("points.line", &p.line));
  }
  return r.ExpectEnd(kLivox2CustomMsgType);
}

Status DecodeTfMessage(const uint8_t* data, size_t size, bag::TfMessage* msg) {
  CdrReader r;
  TILTCAL_RETURN_IF_ERROR(r.Open(data, size));
  uint32_t count = 0;
  TILTCAL_RETURN_IF_ERROR(r.U32("transforms", &count));
  // A TransformStamped takes at least 8 (stamp) + 4 + 4 + 56 bytes.
  if (count > size / 72) {
    return Status::Error("message runs past its end: " + std::to_string(count) +
                         " transforms cannot fit in " + std::to_string(size) + " bytes");
  }
  msg->transforms.resize(count);
  for (bag::TransformStamped& t : msg->transforms) {
    TILTCAL_RETURN_IF_ERROR(ReadHeader(&r, &t.header));
    TILTCAL_RETURN_IF_ERROR(r.String("transforms.child_frame_id", &t.child_frame_id));
    TILTCAL_RETURN_IF_ERROR(r.F64s("transforms.transform.translation", t.translation, 3));
    TILTCAL_RETURN_IF_ERROR(r.F64s("transforms.transform.rotation", t.rotation, 4));
  }
  return r.ExpectEnd(kTfMessageType);
}

}  // namespace tiltcal::ros2
