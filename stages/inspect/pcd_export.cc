#include "stages/inspect/pcd_export.h"

#include <cstdio>
#include <cstring>
#include <vector>

#include "common/io/atomic_file.h"
#include "common/io/binary_pcd.h"
#include "common/io/record_stream.h"
#include "tiltcal/proto/ground.pb.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal::inspect {

namespace {

bool Bit(const google::protobuf::RepeatedField<uint64_t>& mask, size_t i) {
  const size_t word = i >> 6;
  return word < static_cast<size_t>(mask.size()) && ((mask.Get(word) >> (i & 63u)) & 1u);
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

// The binary PCD of `scan`: the header, then per point x y z intensity
// (float32), ring (uint32), time_offset_ns (int32) and, when `plane` is
// given, label (uint8) from its masks, packed.
std::string MakePcd(const proto::Scan& scan, const proto::GroundPlane* plane,
                    LabelCounts* counts) {
  std::vector<PcdField> fields = {{"x", 4, 'F'},    {"y", 4, 'F'},    {"z", 4, 'F'},
                                  {"intensity", 4, 'F'}, {"ring", 4, 'U'},
                                  {"time_offset_ns", 4, 'I'}};
  if (plane != nullptr) fields.push_back({"label", 1, 'U'});
  const size_t step = plane != nullptr ? 25 : 24;
  const size_t n = static_cast<size_t>(scan.x_size());
  std::string pcd = BinaryPcdHeader(fields, n);
  const size_t begin = pcd.size();
  pcd.resize(begin + n * step);
  for (size_t i = 0; i < n; ++i) {
    char* p = pcd.data() + begin + i * step;
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
      p[24] = static_cast<char>(label);
    }
  }
  return pcd;
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
  TILTCAL_RETURN_IF_ERROR(WriteFileAtomically(
      options.out_path, MakePcd(scan, have_ground ? &plane : nullptr, &counts)));
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
