#include "stages/ground/deskew.h"

#include <algorithm>
#include <cmath>

namespace tiltcal::ground {

Deskewer::Deskewer(const imu::GyroIntegrator* integrator, int64_t imu_origin_ns,
                   const Eigen::Matrix3d& imu_from_lidar_rotation,
                   const proto::GroundDeskewParams& params)
    : integrator_(integrator),
      imu_origin_ns_(imu_origin_ns),
      c_bl_(imu_from_lidar_rotation),
      time_offset_ns_(std::llround(params.time_offset_s() * 1e9)),
      node_spacing_ns_(std::max<int64_t>(
          1, static_cast<int64_t>(std::llround(params.node_spacing_s() * 1e9)))) {}

bool Deskewer::Covers(int64_t t0_ns, int64_t t1_ns) const {
  if (integrator_ == nullptr || integrator_->empty()) return false;
  const double t0 = 1e-9 * static_cast<double>(t0_ns - imu_origin_ns_);
  const double t1 = 1e-9 * static_cast<double>(t1_ns - imu_origin_ns_);
  return t0 >= integrator_->begin_s() && t1 <= integrator_->end_s();
}

Eigen::Matrix3d Deskewer::Rotation(int64_t t_ns) const {
  return integrator_->Rotation(1e-9 * static_cast<double>(t_ns - imu_origin_ns_))
      .toRotationMatrix();
}

bool Deskewer::Deskew(int64_t stamp_ns, const int32_t* time_offset_ns, size_t n, float* x,
                      float* y, float* z) {
  if (n == 0) return true;
  int32_t lo = time_offset_ns[0], hi = time_offset_ns[0];
  for (size_t j = 1; j < n; ++j) {
    lo = std::min(lo, time_offset_ns[j]);
    hi = std::max(hi, time_offset_ns[j]);
  }
  // All points at the stamp (no point times): already in the stamp's frame.
  if (lo == 0 && hi == 0) return true;
  const int64_t t_ref = stamp_ns + time_offset_ns_;
  if (!Covers(t_ref + std::min<int64_t>(lo, 0), t_ref + std::max<int64_t>(hi, 0))) return false;

  // Node k at offset lo + k·h: M_k = C_bl^T C_ab(t_ref)^T C_ab(t_k) C_bl.
  const int64_t h = node_spacing_ns_;
  const int64_t span = static_cast<int64_t>(hi) - lo;
  const size_t num_nodes = static_cast<size_t>(span / h) + 2;
  nodes_.resize(num_nodes);
  const Eigen::Matrix3d ref_inv = Rotation(t_ref).transpose();
  for (size_t k = 0; k < num_nodes; ++k) {
    const int64_t t = t_ref + lo + static_cast<int64_t>(k) * h;
    const Eigen::Matrix3d m = c_bl_.transpose() * ref_inv * Rotation(t) * c_bl_;
    nodes_[k] = m.cast<float>();
  }
  const double inv_h = 1.0 / static_cast<double>(h);
  for (size_t j = 0; j < n; ++j) {
    const double u = static_cast<double>(static_cast<int64_t>(time_offset_ns[j]) - lo) * inv_h;
    size_t k = static_cast<size_t>(u);
    if (k > num_nodes - 2) k = num_nodes - 2;
    const float f = static_cast<float>(u - static_cast<double>(k));
    const Eigen::Matrix3f m = (1.0f - f) * nodes_[k] + f * nodes_[k + 1];
    const Eigen::Vector3f p = m * Eigen::Vector3f(x[j], y[j], z[j]);
    x[j] = p.x();
    y[j] = p.y();
    z[j] = p.z();
  }
  return true;
}

}  // namespace tiltcal::ground
