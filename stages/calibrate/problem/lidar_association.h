#ifndef TILTCAL_STAGES_CALIBRATE_PROBLEM_LIDAR_ASSOCIATION_H_
#define TILTCAL_STAGES_CALIBRATE_PROBLEM_LIDAR_ASSOCIATION_H_

// One outer iteration's LiDAR data association (docs/design.md §7): every
// kept point of a scan is mapped to frame a with the current state (each
// point at its own time, ScanPoseTable with nodes every
// AssociationParams.deskew_node_spacing_s), the points go into a voxel surfel
// map (surfel_map.h: planarity gate, PCA plane fit; SurfelMapParams), and a
// subsample of the points is associated with the surfel of its voxel
// (AssociationParams):
//   - only every point_stride-th kept point of a scan is tried;
//   - at most max_points_per_surfel_per_scan points per surfel and scan;
//   - at most max_residuals_per_scan per scan;
//   both caps choose by AssociationParams.selection: evenly spaced in point
//   order, or the candidates of lowest fixed priority (point_priority.h), so
//   that the picks of one round stay picked in the next unless their own
//   candidates changed.
// The associations keep the raw LiDAR-frame point and its LiDAR time, so the
// residual moves with the trajectory, the extrinsic and tau.

#include <vector>

#include "common/status.h"
#include "stages/calibrate/problem/calibration_state.h"
#include "stages/calibrate/problem/lidar_scans.h"
#include "stages/calibrate/problem/problem_builder.h"
#include "stages/calibrate/problem/surfel_map.h"
#include "tiltcal/proto/calibrate_params.pb.h"

namespace tiltcal::calibrate {

struct AssociationStageSummary {
  SurfelExtractionSummary map;
  int scans_mapped = 0;
  long long points_mapped = 0;
  int residuals = 0;
  int surfels_used = 0;
  double map_seconds = 0.0;
  double associate_seconds = 0.0;
};

// num_threads: scans are put in frame a on a second thread while the map
// is built, and associated on num_threads threads; the result does not
// depend on it.
void BuildMapAndAssociate(const CalibrationState& state, const std::vector<LidarScan>& scans,
                          const proto::SurfelMapParams& map_params,
                          const proto::AssociationParams& params, int num_threads,
                          std::vector<LidarPointResidual>* residuals,
                          AssociationStageSummary* summary);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_PROBLEM_LIDAR_ASSOCIATION_H_
