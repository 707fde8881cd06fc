#ifndef TILTCAL_STAGES_CALIBRATE_REPORT_MAP_SHARPNESS_H_
#define TILTCAL_STAGES_CALIBRATE_REPORT_MAP_SHARPNESS_H_

// How sharp the LiDAR map of a state is: every scan's kept points are moved
// to frame a with the state (trajectory, extrinsic, tau; each point at its
// own time, pose nodes every deskew_node_spacing_s), accumulated in the
// voxel surfel map of SurfelMapParams, and the planar surfels summarised:
// median thickness sqrt(l3) (RMS distance of a surfel's points to its
// plane, m) and their count. A wrong extrinsic smears a plane seen from
// several poses, so the same trajectory with a better extrinsic gives
// thinner surfels (and usually more of them pass the planarity gate).

#include <vector>

#include <Eigen/Geometry>

#include "stages/calibrate/problem/calibration_state.h"
#include "stages/calibrate/problem/lidar_scans.h"
#include "stages/calibrate/problem/surfel_map.h"
#include "tiltcal/proto/calibrate_params.pb.h"
#include "tiltcal/proto/calibration.pb.h"

namespace tiltcal::calibrate {

// Two maps of the same trajectory and tau, one with the state's extrinsic
// and one with other_imu_from_lidar (C_bl, r_b^{lb}), compared on the same
// voxels: median_thickness_m of each is taken over the voxels planar in both
// maps (common_surfels of them; 0 m when none). A blurred map loses its
// thickest voxels to the planarity gate, so the median over each map's own
// surfels would favour the blurred one; planar_surfels stays each map's
// own count.
struct MapSharpnessComparison {
  proto::MapSharpness state;
  proto::MapSharpness other;
};
MapSharpnessComparison CompareMapSharpness(const CalibrationState& state,
                                           const Eigen::Quaterniond& other_rotation,
                                           const Eigen::Vector3d& other_translation_m,
                                           const std::vector<LidarScan>& scans,
                                           const proto::SurfelMapParams& map_params,
                                           double deskew_node_spacing_s);

// The comparison of two surfel lists of the same voxel grid, each sorted by
// voxel (x, y, z) as SurfelMap::surfels() is.
MapSharpnessComparison CompareSurfelThickness(const std::vector<Surfel>& state,
                                              const std::vector<Surfel>& other);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_REPORT_MAP_SHARPNESS_H_
