#ifndef TILTCAL_STAGES_REPORT_MAP_SNAPSHOTS_H_
#define TILTCAL_STAGES_REPORT_MAP_SNAPSHOTS_H_

// The before/after wall snapshots of one sequence for the page: both maps
// read (map_pcd.h), the wall found in the calibrated one and drawn from
// above and from the side in both (wall_snapshot.h, one shading
// saturation per view: the 99th percentile of the calibrated map's
// non-empty pixels), each as a PNG data: URI.

#include <string>

#include <Eigen/Core>

#include "common/status.h"
#include "stages/report/wall_snapshot.h"
#include "tiltcal/proto/report_params.pb.h"

namespace tiltcal::report {

struct SnapshotImage {
  std::string data_uri;  // data:image/png;base64,...
  int width = 0;
  int height = 0;
};

struct WallSnapshots {
  std::string note;  // why there are no images ("" when there are)
  WallSlab slab;
  SnapshotImage top_rig, top_calibrated, side_rig, side_calibrated;
  double spread_rig_m = 0.0;  // WallSpread of each map, m
  double spread_calibrated_m = 0.0;
};

// `up`: the maps' vertical, frame a (unit). An unreadable or malformed map
// is an error naming it; a map without a wall gives a note.
Status MakeWallSnapshots(const std::string& map_rig_path, const std::string& map_calibrated_path,
                         const Eigen::Vector3d& up, const proto::WallSnapshotParams& params,
                         WallSnapshots* snapshots);

}  // namespace tiltcal::report

#endif  // TILTCAL_STAGES_REPORT_MAP_SNAPSHOTS_H_
