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

#include "stages/calibrate/problem/calibration_state.h"
#include "stages/calibrate/problem/lidar_scans.h"
#include "tiltcal/proto/calibrate_params.pb.h"
#include "tiltcal/proto/calibration.pb.h"

namespace tiltcal::calibrate {

proto::MapSharpness MeasureMapSharpness(const CalibrationState& state,
                                        const std::vector<LidarScan>& scans,
                                        const proto::SurfelMapParams& map_params,
                                        double deskew_node_spacing_s);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_REPORT_MAP_SHARPNESS_H_
