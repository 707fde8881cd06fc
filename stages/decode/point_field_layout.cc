#include "stages/decode/point_field_layout.h"

#include <limits>
#include <string>

#include "stages/decode/point_cloud_conversion.h"

namespace tiltcal::decode {
namespace {

using ros1::PointCloud2View;
using ros1::PointField;

bool IsInteger(uint8_t type) { return type >= ros1::kInt8 && type <= ros1::kUint32; }
bool IsFloat(uint8_t type) { return type == ros1::kFloat32 || type == ros1::kFloat64; }

// Finds the first field named one of `names`; checks it fits in a point.
Status FindField(const PointCloud2View& cloud, std::initializer_list<const char*> names,
                 PointFieldAccessor* accessor) {
  for (const char* name : names) {
    for (const PointField& field : cloud.fields) {
      if (field.name != name) continue;
      const size_t size = ros1::PointFieldTypeSize(field.datatype);
      if (size == 0) {
        return Status::Error("point field '" + field.name + "' has unknown datatype " +
                             std::to_string(field.datatype));
      }
      if (field.count == 0) {
        return Status::Error("point field '" + field.name + "' has count 0");
      }
      if (uint64_t{field.offset} + size > cloud.point_step) {
        return Status::Error("point field '" + field.name + "' (" +
                             ros1::PointFieldTypeName(field.datatype) + " at offset " +
                             std::to_string(field.offset) + ") lies outside the point_step " +
                             std::to_string(cloud.point_step));
      }
      accessor->present = true;
      accessor->offset = field.offset;
      accessor->type = field.datatype;
      accessor->name = name;
      return Status::Ok();
    }
  }
  return Status::Ok();
}

Status RequireType(const PointFieldAccessor& a, bool ok, const char* expected) {
  if (!a.present || ok) return Status::Ok();
  return Status::Error(std::string("point field '") + a.name + "' has datatype " +
                       ros1::PointFieldTypeName(a.type) + ", expected " + expected);
}

// The per-point time: `time_sec` + `time_nsec`, else the first present of
// `timestamp`, `t`, `time`, `offset_time`, each with its datatype checked.
Status FindTimeFields(const PointCloud2View& cloud, CloudLayout* layout) {
  TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"time_sec"}, &layout->time_sec));
  TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"time_nsec"}, &layout->time_nsec));
  const PointFieldAccessor& sec = layout->time_sec;
  const PointFieldAccessor& nsec = layout->time_nsec;
  if (sec.present && nsec.present) {
    TILTCAL_RETURN_IF_ERROR(RequireType(sec, IsInteger(sec.type), "an integer type"));
    TILTCAL_RETURN_IF_ERROR(RequireType(nsec, IsInteger(nsec.type), "an integer type"));
    layout->source = proto::POINT_TIME_SEC_NSEC;
    return Status::Ok();
  }
  // The first of these names present decides the convention.
  PointFieldAccessor& time = layout->time;
  TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"timestamp", "t", "time", "offset_time"}, &time));
  if (!time.present) return Status::Ok();
  const std::string name = time.name;
  if (name == "timestamp") {
    TILTCAL_RETURN_IF_ERROR(RequireType(time, time.type == ros1::kFloat64, "FLOAT64"));
    layout->source = proto::POINT_TIME_ABSOLUTE_SECONDS;  // or ns, decided on the values
  } else if (name == "t") {
    TILTCAL_RETURN_IF_ERROR(RequireType(time, IsInteger(time.type), "an integer type (ns)"));
    layout->source = proto::POINT_TIME_OUSTER_T;
  } else if (name == "time") {
    TILTCAL_RETURN_IF_ERROR(RequireType(time, IsFloat(time.type), "FLOAT32 or FLOAT64 (s)"));
    layout->source = proto::POINT_TIME_VELODYNE_TIME;
  } else {
    TILTCAL_RETURN_IF_ERROR(RequireType(time, IsInteger(time.type), "an integer type (ns)"));
    layout->source = proto::POINT_TIME_OFFSET_TIME_NS;
  }
  return Status::Ok();
}

}  // namespace

Status FindCloudLayout(const PointCloud2View& cloud, CloudLayout* layout) {
  TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"x"}, &layout->x));
  TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"y"}, &layout->y));
  TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"z"}, &layout->z));
  if (!layout->x.present || !layout->y.present || !layout->z.present) {
    return Status::Error("PointCloud2 lacks an x, y or z field (fields: " +
                         DescribeFields(cloud) + ")");
  }
  for (const PointFieldAccessor* a : {&layout->x, &layout->y, &layout->z}) {
    TILTCAL_RETURN_IF_ERROR(RequireType(*a, IsFloat(a->type), "FLOAT32 or FLOAT64"));
  }
  TILTCAL_RETURN_IF_ERROR(
      FindField(cloud, {"intensity", "i", "reflectivity"}, &layout->intensity));
  TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"ring", "line", "laser_id"}, &layout->ring));
  return FindTimeFields(cloud, layout);
}

Status CheckCloudDataSize(const PointCloud2View& cloud) {
  const uint64_t width = cloud.width;
  const uint64_t height = cloud.height;
  if (cloud.point_step == 0) return Status::Error("PointCloud2 has point_step 0");
  if (uint64_t{cloud.row_step} < width * cloud.point_step && height > 1) {
    return Status::Error("PointCloud2 row_step " + std::to_string(cloud.row_step) +
                         " is smaller than width * point_step = " +
                         std::to_string(width * cloud.point_step));
  }
  // 128 bits: (2^32 - 1)^2 twice does not fit in 64.
  const unsigned __int128 needed =
      static_cast<unsigned __int128>(height - 1) * cloud.row_step +
      static_cast<unsigned __int128>(width) * cloud.point_step;
  if (needed > cloud.data_size) {
    return Status::Error("PointCloud2 data has " + std::to_string(cloud.data_size) +
                         " bytes, " + std::to_string(height) + " rows of " +
                         std::to_string(width) + " points (point_step " +
                         std::to_string(cloud.point_step) + ", row_step " +
                         std::to_string(cloud.row_step) + ") need " +
                         (needed > UINT64_MAX ? std::string("more than 2^64")
                                              : std::to_string(static_cast<uint64_t>(needed))));
  }
  if (width * height > static_cast<uint64_t>(std::numeric_limits<int>::max())) {
    return Status::Error("PointCloud2 has too many points: " + std::to_string(width * height));
  }
  return Status::Ok();
}

}  // namespace tiltcal::decode
