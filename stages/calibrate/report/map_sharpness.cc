#include "stages/calibrate/report/map_sharpness.h"

#include <algorithm>
#include <cmath>

#include "stages/calibrate/problem/surfel_map.h"

namespace tiltcal::calibrate {

proto::MapSharpness MeasureMapSharpness(const CalibrationState& state,
                                        const std::vector<LidarScan>& scans,
                                        const proto::SurfelMapParams& map_params,
                                        double deskew_node_spacing_s) {
  SurfelMap map(map_params);
  ScanPoseTable table;
  std::vector<Eigen::Vector3d> world;
  for (const LidarScan& scan : scans) {
    if (scan.points.empty() || !table.Build(state, scan, deskew_node_spacing_s)) continue;
    world.resize(scan.points.size());
    for (size_t j = 0; j < scan.points.size(); ++j) world[j] = table.ToWorld(scan, j);
    map.AddPointsInWorld(world);
  }
  map.ExtractSurfels();
  std::vector<double> thickness;
  thickness.reserve(map.surfels().size());
  for (const Surfel& s : map.surfels()) {
    thickness.push_back(std::sqrt(std::max(0.0, s.eigenvalues_m2.minCoeff())));
  }
  proto::MapSharpness out;
  out.set_planar_surfels(static_cast<int>(thickness.size()));
  if (!thickness.empty()) {
    const auto middle = thickness.begin() + static_cast<std::ptrdiff_t>(thickness.size() / 2);
    std::nth_element(thickness.begin(), middle, thickness.end());
    out.set_median_thickness_m(*middle);
  }
  return out;
}

}  // namespace tiltcal::calibrate
