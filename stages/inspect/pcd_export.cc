#include "stages/inspect/pcd_export.h"

#include <cstdio>
#include <cstring>

#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>

#include "common/io/atomic_file.h"
#include "common/io/record_stream.h"
#include "tiltcal/proto/ground.pb.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal::inspect {

namespace {

bool Bit(const google::protobuf::RepeatedField<uint64_t>& mask, size_t i) {
  const size_t word = i >> 6;
  return word < static_cast<size_t>(mask.size()) && ((mask.Get(word) >> (i & 63u)) & 1u);
}

void AddField(const std::string& name, uint32_t offset, uint8_t datatype,
              pcl::PCLPointCloud2* cloud) {
  pcl::PCLPointField field;
  field.name = name;
  field.offset = offset;
  field.datatype = datatype;
  field.count = 1;
  cloud->fields.push_back(field);
}

// Scan `record` of the stream at `scans_path`, with equal point columns.
Status ReadScan(const std::string& scans_path, int64_t record, proto::Scan* scan) {
  RecordReader reader;
  TILTCAL_RETURN_IF_ERROR(reader.Open(scans_path, proto::Scan::descriptor()->full_name()));
  for (int64_t i = 0;; ++i) {
    bool end = false;
    TILTCAL_RETURN_IF_ERROR(reader.Read(scan, &end));
    if (end) {
      return Status::Error(scans_path + ": has " + std::to_string(i) + " scans, no record " +
                           std::to_string(record));
    }
    if (i == record) break;
  }
  if (scan->y_size() != scan->x_size() || scan->z_size() != scan->x_size()) {
    return Status::Error(scans_path + ": record " + std::to_string(record) +
                         ": point columns differ in length");
  }
  return Status::Ok();
}

// The ground record of `scan` (same scan_index and stamp) with its point masks.
Status ReadGroundOfScan(const std::string& ground_path, const proto::Scan& scan,
                        proto::GroundPlane* plane) {
  RecordReader ground;
  TILTCAL_RETURN_IF_ERROR(ground.Open(ground_path, proto::GroundPlane::descriptor()->full_name()));
  for (;;) {
    bool end = false;
    TILTCAL_RETURN_IF_ERROR(ground.Read(plane, &end));
    if (end) {
      return Status::Error(ground_path + ": no ground record for scan index " +
                           std::to_string(scan.index()) + " stamp " +
                           std::to_string(scan.stamp_ns()));
    }
    if (plane->scan_index() == scan.index() && plane->stamp_ns() == scan.stamp_ns()) break;
  }
  const size_t n = static_cast<size_t>(scan.x_size());
  if (plane->num_points() != n || (n > 0 && plane->ground_mask_size() == 0 &&
                                   plane->reject_reason() != proto::GROUND_NO_IMU_COVERAGE)) {
    return Status::Error(ground_path + ": record for scan " + std::to_string(scan.index()) +
                         " has no point masks for this scan (params.store_point_masks)");
  }
  return Status::Ok();
}

struct LabelCounts {
  size_t ground = 0;   // labelled 1 or 2
  size_t inliers = 0;  // labelled 2
};

// Packed binary layout: x y z intensity ring time_offset_ns [label], the
// label from `plane`'s masks when it is given.
pcl::PCLPointCloud2 MakeCloud(const proto::Scan& scan, const proto::GroundPlane* plane,
                              LabelCounts* counts) {
  pcl::PCLPointCloud2 cloud;
  AddField("x", 0, pcl::PCLPointField::FLOAT32, &cloud);
  AddField("y", 4, pcl::PCLPointField::FLOAT32, &cloud);
  AddField("z", 8, pcl::PCLPointField::FLOAT32, &cloud);
  AddField("intensity", 12, pcl::PCLPointField::FLOAT32, &cloud);
  AddField("ring", 16, pcl::PCLPointField::UINT32, &cloud);
  AddField("time_offset_ns", 20, pcl::PCLPointField::INT32, &cloud);
  uint32_t step = 24;
  if (plane != nullptr) {
    AddField("label", 24, pcl::PCLPointField::UINT8, &cloud);
    step = 25;
  }
  const size_t n = static_cast<size_t>(scan.x_size());
  cloud.height = 1;
  cloud.width = static_cast<uint32_t>(n);
  cloud.point_step = step;
  cloud.row_step = step * cloud.width;
  cloud.is_dense = true;
  cloud.data.resize(static_cast<size_t>(cloud.row_step));
  for (size_t i = 0; i < n; ++i) {
    uint8_t* p = cloud.data.data() + i * step;
    const float xyz[4] = {scan.x(i), scan.y(i), scan.z(i),
                          i < static_cast<size_t>(scan.intensity_size()) ? scan.intensity(i)
                                                                         : 0.0f};
    const uint32_t ring = i < static_cast<size_t>(scan.ring_size()) ? scan.ring(i) : 0u;
    const int32_t t = i < static_cast<size_t>(scan.time_offset_ns_size()) ? scan.time_offset_ns(i)
                                                                          : 0;
    std::memcpy(p, xyz, 16);
    std::memcpy(p + 16, &ring, 4);
    std::memcpy(p + 20, &t, 4);
    if (plane != nullptr) {
      uint8_t label = 0;
      if (Bit(plane->inlier_mask(), i)) {
        label = 2;
        ++counts->inliers;
        ++counts->ground;
      } else if (Bit(plane->ground_mask(), i)) {
        label = 1;
        ++counts->ground;
      }
      p[24] = label;
    }
  }
  return cloud;
}

// Writes `cloud` as a binary PCD (PCL's header, then the packed points as
// PCDWriter::writeBinary lays them out) through WriteFileAtomically: a write
// error (a full disk) is reported, never a signal from a memory map.
Status WritePcdAtomically(const std::string& path, const pcl::PCLPointCloud2& cloud) {
  pcl::PCDWriter writer;
  std::string contents =
      writer.generateHeaderBinary(cloud, Eigen::Vector4f::Zero(), Eigen::Quaternionf::Identity());
  contents += "DATA binary\n";
  contents.append(reinterpret_cast<const char*>(cloud.data.data()), cloud.data.size());
  return WriteFileAtomically(path, contents);
}

}  // namespace

Status RunPcd(const std::string& scans_path, const PcdOptions& options, std::ostream& log) {
  if (options.out_path.empty()) return Status::Error("pcd needs --out=FILE.pcd");
  if (options.record < 0) return Status::Error("pcd: --record must be >= 0");
  TILTCAL_RETURN_IF_ERROR(CheckOutputPath(options.out_path));
  proto::Scan scan;
  TILTCAL_RETURN_IF_ERROR(ReadScan(scans_path, options.record, &scan));
  proto::GroundPlane plane;
  const bool have_ground = !options.ground_path.empty();
  if (have_ground) TILTCAL_RETURN_IF_ERROR(ReadGroundOfScan(options.ground_path, scan, &plane));
  LabelCounts counts;
  const pcl::PCLPointCloud2 cloud = MakeCloud(scan, have_ground ? &plane : nullptr, &counts);
  TILTCAL_RETURN_IF_ERROR(WritePcdAtomically(options.out_path, cloud));
  log << "tiltcal_inspect pcd: scan " << options.record << " (index " << scan.index() << ", "
      << scan.x_size() << " points";
  if (have_ground) {
    log << ", " << counts.ground << " ground, " << counts.inliers << " in the plane fit, plane "
        << (plane.valid() ? "valid" : "rejected: " + proto::GroundRejectReason_Name(
                                                         plane.reject_reason()));
  }
  log << ") -> " << options.out_path << "\n";
  return Status::Ok();
}

}  // namespace tiltcal::inspect
