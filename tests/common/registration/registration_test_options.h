#ifndef TILTCAL_TESTS_COMMON_REGISTRATION_REGISTRATION_TEST_OPTIONS_H_
#define TILTCAL_TESTS_COMMON_REGISTRATION_REGISTRATION_TEST_OPTIONS_H_

#include "common/registration/point_to_plane_icp.h"
#include "common/registration/voxel_hash_map.h"

namespace tiltcal::registration::testing {

// The option structs have no defaults (the calibrate stage fills them from
// its params); these are the values the tests were written against.
inline VoxelHashMapOptions VoxelHashMapTestOptions() {
  VoxelHashMapOptions options;
  options.voxel_m = 1.0;
  options.max_points_per_voxel = 20;
  options.min_plane_points = 5;
  options.max_plane_thickness_m = 0.05;
  options.min_plane_spread_ratio = 0.05;
  return options;
}

inline PointToPlaneIcpOptions PointToPlaneIcpTestOptions() {
  PointToPlaneIcpOptions options;
  options.max_iterations = 20;
  options.max_correspondence_m = 1.0;
  options.kernel_scale_m = 0.1;
  options.convergence_rotation_rad = 1e-4;
  options.convergence_translation_m = 1e-4;
  options.min_correspondences = 20;
  options.num_threads = 1;
  return options;
}

}  // namespace tiltcal::registration::testing

#endif  // TILTCAL_TESTS_COMMON_REGISTRATION_REGISTRATION_TEST_OPTIONS_H_
