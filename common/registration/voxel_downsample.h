#ifndef TILTCAL_COMMON_REGISTRATION_VOXEL_DOWNSAMPLE_H_
#define TILTCAL_COMMON_REGISTRATION_VOXEL_DOWNSAMPLE_H_

// Voxel-grid downsampling that keeps, per cube of edge voxel_m (cells
// floor(p / voxel_m)), the first point that falls in it, in input order
// (KISS-ICP's choice: real points, no averaging across surfaces).

#include <vector>

#include <Eigen/Core>

namespace tiltcal::registration {

// voxel_m <= 0 returns the input unchanged.
std::vector<Eigen::Vector3d> VoxelDownsample(const std::vector<Eigen::Vector3d>& points,
                                             double voxel_m);

}  // namespace tiltcal::registration

#endif  // TILTCAL_COMMON_REGISTRATION_VOXEL_DOWNSAMPLE_H_
