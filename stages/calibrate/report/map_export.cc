#include "stages/calibrate/report/map_export.h"

#include <algorithm>
#include <cstring>

#include <fmt/format.h>

#include "common/io/atomic_file.h"

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
  const std::string header = fmt::format(
      "# .PCD v0.7 - Point Cloud Data file format\n"
      "VERSION 0.7\n"
      "FIELDS x y z scan\n"
      "SIZE 4 4 4 4\n"
      "TYPE F F F U\n"
      "COUNT 1 1 1 1\n"
      "WIDTH {0}\n"
      "HEIGHT 1\n"
      "VIEWPOINT 0 0 0 1 0 0 0\n"
      "POINTS {0}\n"
      "DATA binary\n",
      points.size());
  std::string data(header);
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
