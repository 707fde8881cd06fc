#ifndef TILTCAL_STAGES_CALIBRATE_REPORT_MAP_EXPORT_H_
#define TILTCAL_STAGES_CALIBRATE_REPORT_MAP_EXPORT_H_

// The before/after maps of a calibration, for a point-cloud viewer: the
// scans moved to frame a with the final trajectory and tau (each point at its
// own time, pose nodes every deskew_node_spacing_s, as CompareMapSharpness
// does) and one extrinsic, the rig's or the estimate. A wrong extrinsic
// shows as doubled or thick walls; their median surfel thickness is
// CalibrationResult.map_sharpness_rig / map_sharpness_estimate.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/io/eigen_proto.h"
#include "common/status.h"
#include "stages/calibrate/problem/calibration_state.h"
#include "stages/calibrate/problem/lidar_scans.h"
#include "tiltcal/proto/calibrate_params.pb.h"

namespace tiltcal::calibrate {

// One map point: p_a (m) and the record index of its scan.
struct MapPoint {
  Eigen::Vector3f position_m;
  uint32_t scan_index = 0;
};

// The points of every params.scan_step-th scan (the first included) moved
// to frame a with `state` and `imu_from_lidar` in place of the state's
// extrinsic. Scans whose sweep (+ tau) lies outside the spline are skipped.
std::vector<MapPoint> BuildMapPoints(const CalibrationState& state, const Rigid3d& imu_from_lidar,
                                     const std::vector<LidarScan>& scans,
                                     const proto::MapExportParams& params,
                                     double deskew_node_spacing_s);

// Writes `points` as a binary PCD (fields x y z float32, scan uint32) for
// pcl_viewer or CloudCompare, atomically.
Status WriteMapPcd(const std::string& path, const std::vector<MapPoint>& points);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_REPORT_MAP_EXPORT_H_
