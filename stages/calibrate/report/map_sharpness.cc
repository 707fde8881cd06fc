#include "stages/calibrate/report/map_sharpness.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace tiltcal::calibrate {
namespace {

// The planar surfels of the map of every scan with the state (the map's
// voxels and point samples are freed on return).
std::vector<Surfel> MapSurfels(const CalibrationState& state, const std::vector<LidarScan>& scans,
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
  return map.surfels();
}

// sqrt(l3): the RMS distance of the surfel's points to its plane, m.
double Thickness(const Surfel& s) { return std::sqrt(std::max(0.0, s.eigenvalues_m2.minCoeff())); }

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// Lexicographic (x, y, z): the order of SurfelMap::surfels().
bool VoxelLess(const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
  return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
}

}  // namespace

MapSharpnessComparison CompareMapSharpness(const CalibrationState& state,
                                           const Eigen::Quaterniond& other_rotation,
                                           const Eigen::Vector3d& other_translation_m,
                                           const std::vector<LidarScan>& scans,
                                           const proto::SurfelMapParams& map_params,
                                           double deskew_node_spacing_s) {
  CalibrationState with_other = state;
  with_other.SetImuFromLidarRotation(other_rotation);
  with_other.SetImuFromLidarTranslation(other_translation_m);
  const std::vector<Surfel> surfels =
      MapSurfels(state, scans, map_params, deskew_node_spacing_s);
  return CompareSurfelThickness(
      surfels, MapSurfels(with_other, scans, map_params, deskew_node_spacing_s));
}

MapSharpnessComparison CompareSurfelThickness(const std::vector<Surfel>& a,
                                              const std::vector<Surfel>& b) {
  // Both lists are sorted by voxel: walk them together.
  std::vector<double> thickness_a, thickness_b;
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    const Surfel& sa = a[i];
    const Surfel& sb = b[j];
    if (VoxelLess(sa.voxel, sb.voxel)) {
      ++i;
    } else if (VoxelLess(sb.voxel, sa.voxel)) {
      ++j;
    } else {
      thickness_a.push_back(Thickness(sa));
      thickness_b.push_back(Thickness(sb));
      ++i;
      ++j;
    }
  }
  MapSharpnessComparison out;
  const int common = static_cast<int>(thickness_a.size());
  out.state.set_planar_surfels(static_cast<int>(a.size()));
  out.state.set_common_surfels(common);
  out.state.set_median_thickness_m(Median(std::move(thickness_a)));
  out.other.set_planar_surfels(static_cast<int>(b.size()));
  out.other.set_common_surfels(common);
  out.other.set_median_thickness_m(Median(std::move(thickness_b)));
  return out;
}

}  // namespace tiltcal::calibrate
