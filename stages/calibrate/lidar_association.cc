#include "stages/calibrate/lidar_association.h"

#include <algorithm>
#include <chrono>
#include <unordered_set>

#include "stages/calibrate/point_priority.h"

namespace tiltcal::calibrate {
namespace {

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Keeps `keep` evenly spaced elements of v (in order).
template <typename T>
void KeepEvenlySpaced(size_t keep, std::vector<T>* v) {
  if (v->size() <= keep) return;
  std::vector<T> out;
  out.reserve(keep);
  const double step = static_cast<double>(v->size()) / keep;
  for (size_t i = 0; i < keep; ++i) out.push_back((*v)[static_cast<size_t>(i * step)]);
  v->swap(out);
}

}  // namespace

void BuildMapAndAssociate(const CalibrationState& state, const std::vector<LidarScan>& scans,
                          const proto::SurfelMapParams& map_params,
                          const proto::AssociationParams& params,
                          std::vector<LidarPointResidual>* residuals,
                          AssociationStageSummary* summary) {
  *summary = AssociationStageSummary();
  residuals->clear();
  auto start = std::chrono::steady_clock::now();
  SurfelMap map(map_params);
  ScanPoseTable table;
  std::vector<Eigen::Vector3d> world;
  std::vector<char> usable(scans.size(), 0);
  for (size_t k = 0; k < scans.size(); ++k) {
    const LidarScan& scan = scans[k];
    if (scan.points.empty() || !table.Build(state, scan, params.deskew_node_spacing_s())) continue;
    usable[k] = 1;
    world.resize(scan.points.size());
    for (size_t j = 0; j < scan.points.size(); ++j) world[j] = table.ToWorld(scan, j);
    map.AddPointsInWorld(world);
    ++summary->scans_mapped;
    summary->points_mapped += static_cast<long long>(world.size());
  }
  summary->map = map.ExtractSurfels();
  summary->map_seconds = Seconds(start);

  start = std::chrono::steady_clock::now();
  const size_t stride = std::max<size_t>(params.point_stride(), 1);
  std::vector<size_t> index;
  std::vector<uint64_t> priorities;
  const bool fixed_priority = params.selection() == proto::AssociationParams::FIXED_PRIORITY;
  const size_t max_per_scan = std::max<size_t>(params.max_residuals_per_scan(), 1);
  std::unordered_set<int> surfels_used;
  for (size_t k = 0; k < scans.size(); ++k) {
    if (!usable[k]) continue;
    const LidarScan& scan = scans[k];
    table.Build(state, scan, params.deskew_node_spacing_s());
    world.clear();
    index.clear();
    priorities.clear();
    for (size_t j = 0; j < scan.points.size(); j += stride) {
      world.push_back(table.ToWorld(scan, j));
      index.push_back(j);
      if (fixed_priority) priorities.push_back(PointPriority(k, j));
    }
    std::vector<SurfelAssociation> found = map.Associate(world, params, priorities);
    if (fixed_priority) {
      KeepLowestPriority(
          max_per_scan,
          [&](const SurfelAssociation& a) { return priorities[static_cast<size_t>(a.point_index)]; },
          &found);
      std::sort(found.begin(), found.end(), [](const SurfelAssociation& a, const SurfelAssociation& b) {
        return a.point_index < b.point_index;
      });
    } else {
      KeepEvenlySpaced(max_per_scan, &found);
    }
    for (const SurfelAssociation& a : found) {
      const size_t j = index[a.point_index];
      const Surfel& s = map.surfels()[a.surfel_index];
      LidarPointResidual r;
      r.time_s = scan.stamp_s + scan.point_time_s[j];
      r.point_lidar_m = scan.points[j].cast<double>();
      r.plane_normal = s.normal;
      r.plane_offset_m = s.offset_m;
      residuals->push_back(r);
      surfels_used.insert(a.surfel_index);
    }
  }
  summary->residuals = static_cast<int>(residuals->size());
  summary->surfels_used = static_cast<int>(surfels_used.size());
  summary->associate_seconds = Seconds(start);
}

}  // namespace tiltcal::calibrate
