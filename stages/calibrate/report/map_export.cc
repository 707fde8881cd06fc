#include "stages/calibrate/report/map_export.h"

#include <algorithm>
#include <cstring>

#include "common/io/atomic_file.h"
#include "common/io/binary_pcd.h"

namespace tiltcal::calibrate {

std::vector<MapPoint> BuildMapPoints(const CalibrationState& state, const Rigid3d& imu_from_lidar,
                                     const std::vector<LidarScan>& scans,
                                     const proto::MapExportParams& params,
                                     double deskew_node_spacing_s) {
  CalibrationState with_extrinsic = state;
  with_extrinsic.SetImuFromLidarRotation(imu_from_lidar.rotation);
  with_extrinsic.SetImuFromLidarTranslation(imu_from_lidar.translation);
  const size_t step = std::max<size_t>(1, params.scan_step());
  std::vector<MapPoint> points;
  ScanPoseTable table;
  for (size_t k = 0; k < scans.size(); k += step) {
    const LidarScan& scan = scans[k];
    if (scan.points.empty() || !table.Build(with_extrinsic, scan, deskew_node_spacing_s)) continue;
    for (size_t j = 0; j < scan.points.size(); ++j) {
      points.push_back({table.ToWorld(scan, j).cast<float>(), static_cast<uint32_t>(scan.index)});
    }
  }
  return points;
}

Status WriteMapPcd(const std::string& path, const std::vector<MapPoint>& points) {
  std::string data =
      BinaryPcdHeader({{"x", 4, 'F'}, {"y", 4, 'F'}, {"z", 4, 'F'}, {"scan", 4, 'U'}}, points.size());
  const size_t offset = data.size();
  data.resize(offset + points.size() * 16);
  char* out = data.data() + offset;
  for (const MapPoint& p : points) {
    std::memcpy(out, p.position_m.data(), 12);
    std::memcpy(out + 12, &p.scan_index, 4);
    out += 16;
  }
  return WriteFileAtomically(path, data).WithContext("map " + path);
}

}  // namespace tiltcal::calibrate
