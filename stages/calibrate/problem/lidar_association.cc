#include "stages/calibrate/problem/lidar_association.h"

#include <algorithm>
#include <chrono>
#include <future>
#include <optional>
#include <unordered_set>

#include "stages/calibrate/problem/point_priority.h"

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

// Scan k's associations against the finished map, appended to *out (in
// point order); the surfels they use go into *surfels_used.
void AssociateScan(const CalibrationState& state, const LidarScan& scan, size_t k,
                   const SurfelMap& map, const proto::AssociationParams& params,
                   std::vector<LidarPointResidual>* out, std::unordered_set<int>* surfels_used) {
  ScanPoseTable table;
  table.Build(state, scan, params.deskew_node_spacing_s());
  const size_t stride = std::max<size_t>(params.point_stride(), 1);
  const bool fixed_priority = params.selection() == proto::AssociationParams::FIXED_PRIORITY;
  const size_t max_per_scan = std::max<size_t>(params.max_residuals_per_scan(), 1);
  std::vector<Eigen::Vector3d> world;
  std::vector<size_t> index;
  std::vector<uint64_t> priorities;
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
    out->push_back(r);
    surfels_used->insert(a.surfel_index);
  }
}

}  // namespace

void BuildMapAndAssociate(const CalibrationState& state, const std::vector<LidarScan>& scans,
                          const proto::SurfelMapParams& map_params,
                          const proto::AssociationParams& params, int num_threads,
                          std::vector<LidarPointResidual>* residuals,
                          AssociationStageSummary* summary) {
  *summary = AssociationStageSummary();
  residuals->clear();
  num_threads = std::max(num_threads, 1);
  auto start = std::chrono::steady_clock::now();
  // The map: scan k + 1's points are put in frame a (on a second thread,
  // with two or more) while scan k's go into the map, in scan order.
  SurfelMap map(map_params);
  std::vector<char> usable(scans.size(), 0);
  auto to_world = [&](size_t k) {
    std::optional<std::vector<Eigen::Vector3d>> world;
    const LidarScan& scan = scans[k];
    ScanPoseTable table;
    if (scan.points.empty() || !table.Build(state, scan, params.deskew_node_spacing_s())) {
      return world;
    }
    world.emplace(scan.points.size());
    for (size_t j = 0; j < scan.points.size(); ++j) (*world)[j] = table.ToWorld(scan, j);
    return world;
  };
  const std::launch ahead = num_threads > 1 ? std::launch::async : std::launch::deferred;
  std::future<std::optional<std::vector<Eigen::Vector3d>>> next;
  if (!scans.empty()) next = std::async(std::launch::deferred, to_world, size_t{0});
  for (size_t k = 0; k < scans.size(); ++k) {
    const std::optional<std::vector<Eigen::Vector3d>> world = next.get();
    if (k + 1 < scans.size()) next = std::async(ahead, to_world, k + 1);
    if (!world) continue;
    usable[k] = 1;
    map.AddPointsInWorld(*world);
    ++summary->scans_mapped;
    summary->points_mapped += static_cast<long long>(world->size());
  }
  summary->map = map.ExtractSurfels();
  summary->map_seconds = Seconds(start);

  // The association: the scans split into num_threads runs, each scan's
  // associations independent of the others', concatenated in scan order.
  start = std::chrono::steady_clock::now();
  const size_t runs =
      std::min<size_t>(static_cast<size_t>(num_threads), std::max<size_t>(scans.size(), 1));
  std::vector<std::vector<LidarPointResidual>> found(runs);
  std::vector<std::unordered_set<int>> surfels(runs);
  auto associate_run = [&](size_t run) {
    const size_t begin = scans.size() * run / runs;
    const size_t end = scans.size() * (run + 1) / runs;
    for (size_t k = begin; k < end; ++k) {
      if (usable[k]) AssociateScan(state, scans[k], k, map, params, &found[run], &surfels[run]);
    }
  };
  std::vector<std::future<void>> workers;
  for (size_t run = 1; run < runs; ++run) {
    workers.push_back(std::async(std::launch::async, associate_run, run));
  }
  associate_run(0);
  for (std::future<void>& w : workers) w.get();
  std::unordered_set<int> surfels_used;
  for (size_t run = 0; run < runs; ++run) {
    residuals->insert(residuals->end(), found[run].begin(), found[run].end());
    surfels_used.insert(surfels[run].begin(), surfels[run].end());
  }
  summary->residuals = static_cast<int>(residuals->size());
  summary->surfels_used = static_cast<int>(surfels_used.size());
  summary->associate_seconds = Seconds(start);
}

}  // namespace tiltcal::calibrate
