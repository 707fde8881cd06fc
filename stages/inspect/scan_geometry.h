#ifndef TILTCAL_STAGES_INSPECT_SCAN_GEOMETRY_H_
#define TILTCAL_STAGES_INSPECT_SCAN_GEOMETRY_H_

#include <cstddef>
#include <vector>

#include <Eigen/Core>

namespace tiltcal::inspect {

// No defaults: every field is set from the params file (check params: lidar).
struct ScanGeometryOptions {
  double ground_min_depth_m;
  double ground_max_range_m;
  double ground_inlier_distance_m;
  double ground_max_tilt_deg;
  double min_ground_fraction;
  int ground_fit_max_iterations;  // refits of the robust ground plane
  double structure_min_height_m;
  double structure_max_range_m;
};

// What one scan offers the calibration. Heights h = u · p along the unit up
// direction u in the LiDAR frame (the sensor at h = 0); horizontal range is
// the distance from the up axis.
//  ground: a robust plane through the points with h < −ground_min_depth_m and
//    horizontal range ≤ ground_max_range_m; the scan has ground when that
//    plane's normal is within ground_max_tilt_deg of u and at least
//    min_ground_fraction of all points lie within ground_inlier_distance_m.
//  structure: the share of all points with h > structure_min_height_m and
//    horizontal range ≤ structure_max_range_m (walls, poles, trees).
struct ScanGeometry {
  size_t num_points = 0;
  bool has_ground = false;
  double ground_fraction = 0.0;  // share of the points on the ground plane
  double ground_tilt_deg = 0.0;  // angle between the plane normal and u
  double structure_fraction = 0.0;
};
ScanGeometry MeasureScanGeometry(const std::vector<float>& x, const std::vector<float>& y,
                                 const std::vector<float>& z, const Eigen::Vector3d& up_in_lidar,
                                 const ScanGeometryOptions& options);

}  // namespace tiltcal::inspect

#endif  // TILTCAL_STAGES_INSPECT_SCAN_GEOMETRY_H_
