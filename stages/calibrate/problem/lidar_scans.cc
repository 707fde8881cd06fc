#include "stages/calibrate/problem/lidar_scans.h"

#include <algorithm>
#include <cmath>

#include "common/io/record_stream.h"
#include "common/spline/so3_spline.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal::calibrate {

Status ReadLidarScans(const std::string& path, int64_t first_imu_stamp_ns,
                      const proto::LidarScanParams& params, std::vector<LidarScan>* scans) {
  scans->clear();
  RecordReader reader;
  TILTCAL_RETURN_IF_ERROR(reader.Open(path, proto::Scan::descriptor()->full_name()));
  proto::Scan scan;
  const double min_r2 = params.min_range_m() * params.min_range_m();
  const double max_r2 = params.max_range_m() * params.max_range_m();
  const int stride = std::max(1, static_cast<int>(params.point_stride()));
  for (int record = 0;; ++record) {
    bool end = false;
    scan.Clear();
    TILTCAL_RETURN_IF_ERROR(reader.Read(&scan, &end));
    if (end) break;
    const int n = scan.x_size();
    if (scan.y_size() != n || scan.z_size() != n || scan.time_offset_ns_size() != n) {
      return Status::Error(path + ": record " + std::to_string(record) +
                           ": point columns x, y, z, time_offset_ns differ in length");
    }
    LidarScan out;
    out.index = record;
    out.stamp_s = static_cast<double>(scan.stamp_ns() - first_imu_stamp_ns) * 1e-9;
    if (!scans->empty() && out.stamp_s < scans->back().stamp_s) {
      return Status::Error(path + ": record " + std::to_string(record) +
                           ": scan stamp goes back in time");
    }
    out.points.reserve(n / stride + 1);
    out.point_time_s.reserve(n / stride + 1);
    int kept = 0;
    for (int j = 0; j < n; ++j) {
      const Eigen::Vector3f p(scan.x(j), scan.y(j), scan.z(j));
      if (!p.allFinite()) continue;
      const double r2 = p.squaredNorm();
      if (r2 < min_r2 || r2 > max_r2) continue;
      if (kept++ % stride != 0) continue;
      out.points.push_back(p);
      out.point_time_s.push_back(static_cast<float>(scan.time_offset_ns(j) * 1e-9));
    }
    if (!out.point_time_s.empty()) {
      const auto [lo, hi] = std::minmax_element(out.point_time_s.begin(), out.point_time_s.end());
      out.min_time_s = *lo;
      out.max_time_s = *hi;
    }
    scans->push_back(std::move(out));
  }
  return Status::Ok();
}

bool ScanPoseTable::Build(const CalibrationState& state, const LidarScan& scan,
                          double node_spacing_s) {
  // One tau per sweep, tau(t_k) at the scan stamp (calibration_state.h): the
  // drift within a sweep (rho times 0.1 s: 30 us at 300 ppm) moves a point
  // by a fraction of a millimetre at vehicle speeds.
  const double tau = state.TimeOffsetAt(scan.stamp_s);
  const double begin = scan.stamp_s + scan.min_time_s + tau;
  const double end = scan.stamp_s + scan.max_time_s + tau;
  const spline::UniformKnotGrid& grid = state.trajectory.grid();
  if (begin < grid.t0_s() || end > grid.end_s()) return false;
  const int intervals = std::max(1, static_cast<int>(std::ceil((end - begin) / node_spacing_s)));
  begin_s_ = scan.min_time_s;
  spacing_s_ = (end - begin) / intervals;
  if (spacing_s_ <= 0.0) spacing_s_ = 1.0;
  rotations_.resize(intervals + 1);
  translations_.resize(intervals + 1);
  const Eigen::Quaterniond c_bl = state.ImuFromLidarRotation();
  const Eigen::Vector3d r_bl = state.ImuFromLidarTranslation();
  spline::So3SplineSample rot;
  spline::R3SplineSample pos;
  for (int i = 0; i <= intervals; ++i) {
    const double t = std::min(begin + i * spacing_s_, grid.end_s());
    state.trajectory.Evaluate(t, spline::kSo3Rotation, &rot, &pos);
    const Eigen::Quaterniond c_ab(rot.rotation);
    rotations_[i] = c_ab * c_bl;
    translations_[i] = c_ab * r_bl + pos.position;
  }
  return true;
}

void ScanPoseTable::Interpolate(double dt_s, Eigen::Quaterniond* rotation,
                                Eigen::Vector3d* translation) const {
  const int last = static_cast<int>(rotations_.size()) - 1;
  double x = (dt_s - begin_s_) / spacing_s_;
  int i = static_cast<int>(std::floor(x));
  i = std::clamp(i, 0, std::max(0, last - 1));
  if (last == 0) {
    *rotation = rotations_[0];
    *translation = translations_[0];
    return;
  }
  const double f = x - i;
  const Eigen::Quaterniond& q0 = rotations_[i];
  Eigen::Quaterniond q1 = rotations_[i + 1];
  if (q0.dot(q1) < 0.0) q1.coeffs() = -q1.coeffs();
  rotation->coeffs() = (1.0 - f) * q0.coeffs() + f * q1.coeffs();
  rotation->normalize();
  *translation = (1.0 - f) * translations_[i] + f * translations_[i + 1];
}

Eigen::Vector3d ScanPoseTable::ToWorld(const LidarScan& scan, size_t j) const {
  Eigen::Quaterniond q;
  Eigen::Vector3d t;
  Interpolate(scan.point_time_s[j], &q, &t);
  return q * scan.points[j].cast<double>() + t;
}

}  // namespace tiltcal::calibrate
