#ifndef TILTCAL_STAGES_GROUND_DESKEW_H_
#define TILTCAL_STAGES_GROUND_DESKEW_H_

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "common/imu/gyro_integrator.h"
#include "tiltcal/proto/ground_params.pb.h"

namespace tiltcal::ground {

// Moves the points of a sweep to the LiDAR frame at the scan stamp t_k:
//   p_l(t_k) = C_bl^T C_ab(t_k + τ)^T C_ab(t_j + τ) C_bl p_l(t_j)
// with rotation only (translation during a sweep moves ground points within
// the plane and is ignored; docs/design.md §5), C_ab(t) from the gyro
// integrator (common/imu) and τ = params.time_offset_s. The rotation is
// tabulated at nodes spaced params.node_spacing_s across the sweep and
// interpolated linearly per point (no per-point trigonometry, no allocation
// per point).
class Deskewer {
 public:
  // `integrator` times are seconds relative to imu_origin_ns (IMU clock).
  // Of `params` only time_offset_s and node_spacing_s are used here.
  Deskewer(const imu::GyroIntegrator* integrator, int64_t imu_origin_ns,
           const Eigen::Matrix3d& imu_from_lidar_rotation,
           const proto::GroundDeskewParams& params);

  // True when [t0_ns, t1_ns] (IMU clock) lies within the IMU samples.
  bool Covers(int64_t t0_ns, int64_t t1_ns) const;

  // Deskews the columns in place. Returns false (points untouched) when the
  // IMU does not cover the sweep; true without work when every offset is 0.
  // time_offset_ns[j] is t_j − t_k.
  bool Deskew(int64_t stamp_ns, const int32_t* time_offset_ns, size_t n, float* x, float* y,
              float* z);

 private:
  Eigen::Matrix3d Rotation(int64_t t_ns) const;  // C_ab(t), t in ns, IMU clock

  const imu::GyroIntegrator* integrator_;
  int64_t imu_origin_ns_;
  Eigen::Matrix3d c_bl_;
  int64_t time_offset_ns_;
  int64_t node_spacing_ns_;
  std::vector<Eigen::Matrix3f> nodes_;
};

}  // namespace tiltcal::ground

#endif  // TILTCAL_STAGES_GROUND_DESKEW_H_
