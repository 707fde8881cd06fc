#ifndef TILTCAL_STAGES_GROUND_DESKEW_H_
#define TILTCAL_STAGES_GROUND_DESKEW_H_

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "tiltcal/proto/imu.pb.h"

namespace tiltcal::ground {

// Gyro bias from a static start: the longest prefix of samples with
// |ω_m| < max_radps; found when it spans at least min_duration_s.
struct StaticStart {
  bool found = false;
  double duration_s = 0.0;
  int num_samples = 0;
  Eigen::Vector3d gyro_bias_radps = Eigen::Vector3d::Zero();
};
StaticStart EstimateStaticGyroBias(const std::vector<proto::ImuSample>& samples,
                                   double max_radps, double min_duration_s);

// IMU orientation C_ab(t) from integrated, bias-corrected gyro readings
// (a = the IMU frame at the first sample). Between samples i and i+1 the rate
// is the midpoint (ω_i + ω_{i+1})/2 − b_g, so C_ab(t) = C_ab(t_i) Exp(ω̄_i (t − t_i)).
// Samples must have increasing stamps.
class GyroIntegrator {
 public:
  GyroIntegrator(const std::vector<proto::ImuSample>& samples,
                 const Eigen::Vector3d& gyro_bias_radps);

  // True when [t0_ns, t1_ns] (IMU clock) lies within the samples.
  bool Covers(int64_t t0_ns, int64_t t1_ns) const;
  // C_ab(t); t is clamped to the sample range.
  Eigen::Quaterniond Orientation(int64_t t_ns) const;

 private:
  std::vector<int64_t> stamps_ns_;
  std::vector<Eigen::Quaterniond> orientation_;  // C_ab(t_i)
  std::vector<Eigen::Vector3d> rate_;            // ω̄_i, rad/s
};

// Moves the points of a sweep to the LiDAR frame at the scan stamp t_k:
//   p_l(t_k) = C_bl^T C_ab(t_k + τ)^T C_ab(t_j + τ) C_bl p_l(t_j)
// with rotation only (translation during a sweep is ignored, DESIGN §5). The
// rotation is tabulated at nodes spaced node_spacing_s across the sweep and
// interpolated linearly per point (no per-point trigonometry, no allocation
// per point).
class Deskewer {
 public:
  Deskewer(const GyroIntegrator* integrator, const Eigen::Matrix3d& imu_from_lidar_rotation,
           int64_t time_offset_ns, double node_spacing_s);

  // Deskews the columns in place. Returns false (points untouched) when the
  // IMU does not cover the sweep. time_offset_ns[j] is t_j − t_k.
  bool Deskew(int64_t stamp_ns, const int32_t* time_offset_ns, size_t n, float* x, float* y,
              float* z);

 private:
  const GyroIntegrator* integrator_;
  Eigen::Matrix3d c_bl_;
  int64_t time_offset_ns_;
  int64_t node_spacing_ns_;
  std::vector<Eigen::Matrix3f> nodes_;
};

}  // namespace tiltcal::ground

#endif  // TILTCAL_STAGES_GROUND_DESKEW_H_
