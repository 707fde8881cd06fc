#include "stages/ground/deskew.h"

#include <algorithm>
#include <cmath>

namespace tiltcal::ground {

namespace {

Eigen::Vector3d Gyro(const proto::ImuSample& s) {
  return Eigen::Vector3d(s.angular_velocity_radps().x(), s.angular_velocity_radps().y(),
                         s.angular_velocity_radps().z());
}

// Exp of a rotation vector (rad) as a unit quaternion.
Eigen::Quaterniond ExpQ(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  if (angle < 1e-12) return Eigen::Quaterniond(1.0, 0.5 * phi.x(), 0.5 * phi.y(), 0.5 * phi.z()).normalized();
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, phi / angle));
}

}  // namespace

StaticStart EstimateStaticGyroBias(const std::vector<proto::ImuSample>& samples,
                                   double max_radps, double min_duration_s) {
  StaticStart result;
  size_t end = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  while (end < samples.size() && Gyro(samples[end]).norm() < max_radps) {
    sum += Gyro(samples[end]);
    ++end;
  }
  if (end < 2) return result;
  result.duration_s = 1e-9 * static_cast<double>(samples[end - 1].stamp_ns() -
                                                 samples[0].stamp_ns());
  result.num_samples = static_cast<int>(end);
  if (result.duration_s >= min_duration_s && min_duration_s > 0.0) {
    result.found = true;
    result.gyro_bias_radps = sum / static_cast<double>(end);
  }
  return result;
}

GyroIntegrator::GyroIntegrator(const std::vector<proto::ImuSample>& samples,
                               const Eigen::Vector3d& gyro_bias_radps) {
  const size_t n = samples.size();
  stamps_ns_.resize(n);
  orientation_.resize(n);
  rate_.resize(n);
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  for (size_t i = 0; i < n; ++i) {
    stamps_ns_[i] = samples[i].stamp_ns();
    orientation_[i] = q;
    if (i + 1 < n) {
      const Eigen::Vector3d w = 0.5 * (Gyro(samples[i]) + Gyro(samples[i + 1])) - gyro_bias_radps;
      const double dt = 1e-9 * static_cast<double>(samples[i + 1].stamp_ns() - samples[i].stamp_ns());
      rate_[i] = w;
      q = (q * ExpQ(w * dt)).normalized();
    } else {
      rate_[i] = n >= 2 ? rate_[i - 1] : Eigen::Vector3d::Zero();
    }
  }
}

bool GyroIntegrator::Covers(int64_t t0_ns, int64_t t1_ns) const {
  return !stamps_ns_.empty() && t0_ns >= stamps_ns_.front() && t1_ns <= stamps_ns_.back();
}

Eigen::Quaterniond GyroIntegrator::Orientation(int64_t t_ns) const {
  if (stamps_ns_.empty()) return Eigen::Quaterniond::Identity();
  t_ns = std::clamp(t_ns, stamps_ns_.front(), stamps_ns_.back());
  auto it = std::upper_bound(stamps_ns_.begin(), stamps_ns_.end(), t_ns);
  const size_t i = static_cast<size_t>(std::max<std::ptrdiff_t>(0, (it - stamps_ns_.begin()) - 1));
  const double dt = 1e-9 * static_cast<double>(t_ns - stamps_ns_[i]);
  return (orientation_[i] * ExpQ(rate_[i] * dt)).normalized();
}

Deskewer::Deskewer(const GyroIntegrator* integrator, const Eigen::Matrix3d& imu_from_lidar_rotation,
                   int64_t time_offset_ns, double node_spacing_s)
    : integrator_(integrator),
      c_bl_(imu_from_lidar_rotation),
      time_offset_ns_(time_offset_ns),
      node_spacing_ns_(std::max<int64_t>(1, static_cast<int64_t>(std::llround(node_spacing_s * 1e9)))) {}

bool Deskewer::Deskew(int64_t stamp_ns, const int32_t* time_offset_ns, size_t n, float* x,
                      float* y, float* z) {
  if (n == 0) return true;
  int32_t lo = time_offset_ns[0], hi = time_offset_ns[0];
  for (size_t j = 1; j < n; ++j) {
    lo = std::min(lo, time_offset_ns[j]);
    hi = std::max(hi, time_offset_ns[j]);
  }
  const int64_t t_ref = stamp_ns + time_offset_ns_;
  const int64_t t_lo = t_ref + std::min<int64_t>(lo, 0);
  const int64_t t_hi = t_ref + std::max<int64_t>(hi, 0);
  if (!integrator_->Covers(t_lo, t_hi)) return false;
  if (lo == 0 && hi == 0) return true;

  // Node k at offset lo + k·h: M_k = C_bl^T C_ab(t_ref)^T C_ab(t_k) C_bl.
  const int64_t h = node_spacing_ns_;
  const int64_t span = static_cast<int64_t>(hi) - lo;
  const size_t num_nodes = static_cast<size_t>(span / h) + 2;
  nodes_.resize(num_nodes);
  const Eigen::Matrix3d ref_inv = integrator_->Orientation(t_ref).conjugate().toRotationMatrix();
  for (size_t k = 0; k < num_nodes; ++k) {
    const int64_t t = t_ref + lo + static_cast<int64_t>(k) * h;
    const Eigen::Matrix3d m =
        c_bl_.transpose() * ref_inv * integrator_->Orientation(t).toRotationMatrix() * c_bl_;
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
