#include "bag/ros1/messages.h"

#include <cstring>

namespace tiltcal::ros1 {

namespace {

// Bounds-checked cursor over a serialized message.
class WireReader {
 public:
  WireReader(const uint8_t* data, size_t size) : data_(data), size_(size) {}

  // Takes `n` bytes for `what`; an error when fewer remain.
  Status Take(size_t n, const char* what, const uint8_t** out) {
    if (n > size_ - pos_) {
      return Status::Error(std::string("message runs past its record: ") + what + " needs " +
                           std::to_string(n) + " bytes at byte " + std::to_string(pos_) +
                           ", the record has " + std::to_string(size_));
    }
    *out = data_ + pos_;
    pos_ += n;
    return Status::Ok();
  }
  Status U8(const char* what, uint8_t* v) {
    const uint8_t* p = nullptr;
    TILTCAL_RETURN_IF_ERROR(Take(1, what, &p));
    *v = *p;
    return Status::Ok();
  }
  Status U32(const char* what, uint32_t* v) {
    const uint8_t* p = nullptr;
    TILTCAL_RETURN_IF_ERROR(Take(4, what, &p));
    *v = LoadU32Le(p);
    return Status::Ok();
  }
  Status U64(const char* what, uint64_t* v) {
    const uint8_t* p = nullptr;
    TILTCAL_RETURN_IF_ERROR(Take(8, what, &p));
    std::memcpy(v, p, 8);
    return Status::Ok();
  }
  Status F64s(const char* what, double* v, size_t n) {
    const uint8_t* p = nullptr;
    TILTCAL_RETURN_IF_ERROR(Take(8 * n, what, &p));
    std::memcpy(v, p, 8 * n);
    return Status::Ok();
  }
  Status String(const char* what, std::string* s) {
    uint32_t len = 0;
    TILTCAL_RETURN_IF_ERROR(U32(what, &len));
    const uint8_t* p = nullptr;
    TILTCAL_RETURN_IF_ERROR(Take(len, what, &p));
    s->assign(reinterpret_cast<const char*>(p), len);
    return Status::Ok();
  }
  Status Header(ros1::Header* h) {
    TILTCAL_RETURN_IF_ERROR(U32("header.seq", &h->seq));
    TILTCAL_RETURN_IF_ERROR(U32("header.stamp.sec", &h->stamp.sec));
    TILTCAL_RETURN_IF_ERROR(U32("header.stamp.nsec", &h->stamp.nsec));
    return String("header.frame_id", &h->frame_id);
  }
  Status ExpectEnd(const char* type) const {
    if (pos_ != size_) {
      return Status::Error(std::string("record has ") + std::to_string(size_ - pos_) +
                           " bytes after the end of the " + type + " message (" +
                           std::to_string(size_) + " bytes; another message type?)");
    }
    return Status::Ok();
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
};

}  // namespace

Status DecodeImu(const uint8_t* data, size_t size, ImuMessage* imu) {
  WireReader r(data, size);
  TILTCAL_RETURN_IF_ERROR(r.Header(&imu->header));
  TILTCAL_RETURN_IF_ERROR(r.F64s("orientation", imu->orientation, 4));
  TILTCAL_RETURN_IF_ERROR(r.F64s("orientation_covariance", imu->orientation_covariance, 9));
  TILTCAL_RETURN_IF_ERROR(r.F64s("angular_velocity", imu->angular_velocity, 3));
  TILTCAL_RETURN_IF_ERROR(
      r.F64s("angular_velocity_covariance", imu->angular_velocity_covariance, 9));
  TILTCAL_RETURN_IF_ERROR(r.F64s("linear_acceleration", imu->linear_acceleration, 3));
  TILTCAL_RETURN_IF_ERROR(
      r.F64s("linear_acceleration_covariance", imu->linear_acceleration_covariance, 9));
  return r.ExpectEnd("sensor_msgs/Imu");
}

Status DecodePointCloud2(const uint8_t* data, size_t size, PointCloud2View* cloud) {
  WireReader r(data, size);
  TILTCAL_RETURN_IF_ERROR(r.Header(&cloud->header));
  TILTCAL_RETURN_IF_ERROR(r.U32("height", &cloud->height));
  TILTCAL_RETURN_IF_ERROR(r.U32("width", &cloud->width));
  uint32_t num_fields = 0;
  TILTCAL_RETURN_IF_ERROR(r.U32("fields", &num_fields));
  // Each PointField takes at least 13 bytes; refuse absurd counts before resizing.
  if (num_fields > size / 13) {
    return Status::Error("message runs past its record: " + std::to_string(num_fields) +
                         " point fields cannot fit in " + std::to_string(size) + " bytes");
  }
  cloud->fields.resize(num_fields);
  for (PointField& field : cloud->fields) {
    TILTCAL_RETURN_IF_ERROR(r.String("fields.name", &field.name));
    TILTCAL_RETURN_IF_ERROR(r.U32("fields.offset", &field.offset));
    TILTCAL_RETURN_IF_ERROR(r.U8("fields.datatype", &field.datatype));
    TILTCAL_RETURN_IF_ERROR(r.U32("fields.count", &field.count));
  }
  uint8_t flag = 0;
  TILTCAL_RETURN_IF_ERROR(r.U8("is_bigendian", &flag));
  cloud->is_bigendian = flag != 0;
  TILTCAL_RETURN_IF_ERROR(r.U32("point_step", &cloud->point_step));
  TILTCAL_RETURN_IF_ERROR(r.U32("row_step", &cloud->row_step));
  TILTCAL_RETURN_IF_ERROR(r.U32("data", &cloud->data_size));
  TILTCAL_RETURN_IF_ERROR(r.Take(cloud->data_size, "data", &cloud->data));
  TILTCAL_RETURN_IF_ERROR(r.U8("is_dense", &flag));
  cloud->is_dense = flag != 0;
  return r.ExpectEnd("sensor_msgs/PointCloud2");
}

Status DecodeLivoxCustomMsg(const uint8_t* data, size_t size, LivoxCustomMessage* msg) {
  constexpr size_t kPointBytes = 19;
  WireReader r(data, size);
  TILTCAL_RETURN_IF_ERROR(r.Header(&msg->header));
  TILTCAL_RETURN_IF_ERROR(r.U64("timebase", &msg->timebase));
  TILTCAL_RETURN_IF_ERROR(r.U32("point_num", &msg->point_num));
  TILTCAL_RETURN_IF_ERROR(r.U8("lidar_id", &msg->lidar_id));
  for (uint8_t& b : msg->rsvd) TILTCAL_RETURN_IF_ERROR(r.U8("rsvd", &b));
  uint32_t count = 0;
  TILTCAL_RETURN_IF_ERROR(r.U32("points", &count));
  const uint8_t* p = nullptr;
  TILTCAL_RETURN_IF_ERROR(r.Take(static_cast<size_t>(count) * kPointBytes, "points", &p));
  if (count != msg->point_num) {
    return Status::Error("point_num is " + std::to_string(msg->point_num) +
                         " but the points array holds " + std::to_string(count) + " points");
  }
  msg->points.resize(count);
  for (LivoxPoint& point : msg->points) {
    std::memcpy(&point.offset_time, p, 4);
    std::memcpy(&point.x, p + 4, 4);
    std::memcpy(&point.y, p + 8, 4);
    std::memcpy(&point.z, p + 12, 4);
    point.reflectivity = p[16];
    point.tag = p[17];
    point.line = p[18];
    p += kPointBytes;
  }
  return r.ExpectEnd(kLivoxCustomMsgType);
}

Status DecodeTfMessage(const uint8_t* data, size_t size, TfMessage* msg) {
  // A TransformStamped takes at least 12 (header) + 4 + 56 bytes.
  constexpr size_t kMinTransformBytes = 72;
  WireReader r(data, size);
  uint32_t count = 0;
  TILTCAL_RETURN_IF_ERROR(r.U32("transforms", &count));
  if (count > size / kMinTransformBytes) {
    return Status::Error("message runs past its record: " + std::to_string(count) +
                         " transforms cannot fit in " + std::to_string(size) + " bytes");
  }
  msg->transforms.resize(count);
  for (TransformStamped& t : msg->transforms) {
    TILTCAL_RETURN_IF_ERROR(r.Header(&t.header));
    TILTCAL_RETURN_IF_ERROR(r.String("transforms.child_frame_id", &t.child_frame_id));
    TILTCAL_RETURN_IF_ERROR(r.F64s("transforms.transform.translation", t.translation, 3));
    TILTCAL_RETURN_IF_ERROR(r.F64s("transforms.transform.rotation", t.rotation, 4));
  }
  return r.ExpectEnd(kTfMessageType);
}

}  // namespace tiltcal::ros1
