#include "stages/simulate/scan_simulator.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/geometry/angles.h"
#include "stages/simulate/random.h"

namespace tiltcal::simulate {

namespace {

using geometry::kTwoPi;

int VelodyneSequences(const ScanConfig& config) {
  return static_cast<int>(std::floor(1.0 / (config.scan_rate_hz * config.model.sequence_period_s)));
}

// Synthetic intensity: a per-surface reflectivity times |cos(incidence)|.
float Intensity(Surface surface, double cos_incidence, uint16_t* reflectivity) {
  double base = 0.0;
  switch (surface) {
    case Surface::kGround: base = 20.0; break;
    case Surface::kWall: base = 60.0; break;
    case Surface::kBox: base = 100.0; break;
    case Surface::kPillar: base = 140.0; break;
    case Surface::kPerson: base = 80.0; break;
    default: break;
  }
  *reflectivity = static_cast<uint16_t>(base);
  return static_cast<float>(std::round(base * (0.3 + 0.7 * std::abs(cos_incidence))));
}

}  // namespace

int LivoxPoints(const ScanConfig& config) {
  return static_cast<int>(std::floor(config.model.livox.point_rate_hz / config.scan_rate_hz));
}

int64_t SweepStartNs(const ScanConfig& config, int k) {
  return std::llround((config.first_scan_time_s + k / config.scan_rate_hz) * 1e9);
}

double SweepSpanS(const ScanConfig& config) {
  const LidarModel& m = config.model;
  if (m.kind == LidarModel::Kind::kOuster) {
    return (m.columns - 1) / (config.scan_rate_hz * m.columns);
  }
  if (m.kind == LidarModel::Kind::kLivox) {
    return (LivoxPoints(config) - 1) / m.livox.point_rate_hz;
  }
  return (VelodyneSequences(config) - 1) * m.sequence_period_s +
         *std::max_element(m.firing_offset_s.begin(), m.firing_offset_s.end());
}

namespace {

// Casts the lasers of one sweep into the world, with the range noise of the
// sweep's own random stream.
class LaserCaster {
 public:
  LaserCaster(const ScanConfig& config, const PlanarTrajectory& trajectory, const World& world,
              const Pedestrians* pedestrians, uint64_t seed, int k)
      : config_(config),
        trajectory_(trajectory),
        world_(world),
        pedestrians_(pedestrians != nullptr && !pedestrians->empty() ? pedestrians : nullptr),
        rng_(seed, kSweepStreamBase + static_cast<uint64_t>(k)),
        roughness_rng_(seed, kGroundRoughnessStreamBase + static_cast<uint64_t>(k)),
        cos_el_(config.model.num_lasers()),
        sin_el_(config.model.num_lasers()) {
    for (int i = 0; i < config.model.num_lasers(); ++i) {
      cos_el_[i] = std::cos(config.model.elevation_rad[i]);
      sin_el_[i] = std::sin(config.model.elevation_rad[i]);
    }
  }

  // Pose C_wl, r_wl of the LiDAR at true time t (s since the first IMU sample).
  void LidarPose(double t, Eigen::Matrix3d* c_wl, Eigen::Vector3d* r_wl) const {
    Eigen::Matrix3d c_wb;
    Eigen::Vector3d r_wb;
    trajectory_.Pose(t, &c_wb, &r_wb);
    *c_wl = c_wb * config_.imu_from_lidar_rotation;
    *r_wl = r_wb + c_wb * config_.imu_from_lidar_translation;
  }

  // Casts laser i at horizontal angle alpha from the pose of time t; fills
  // *p (valid when a surface is hit within the range limits after the noise).
  void Cast(const Eigen::Matrix3d& c_wl, const Eigen::Vector3d& r_wl, double t, int i,
            double alpha, ScanPoint* p) {
    CastDirection(c_wl, r_wl, t, cos_el_[i], sin_el_[i], alpha, config_.model.ring[i], p);
  }

  // Casts a ray at elevation (cos_el, sin_el) and horizontal angle alpha,
  // frame l, at time t (for the pedestrians), reported as `ring`.
  void CastDirection(const Eigen::Matrix3d& c_wl, const Eigen::Vector3d& r_wl, double t,
                     double cos_el, double sin_el, double alpha, int ring, ScanPoint* p) {
    const Eigen::Vector3d d_l(cos_el * std::cos(alpha), cos_el * std::sin(alpha), sin_el);
    const Eigen::Vector3d d_w = c_wl * d_l;
    RayHit hit;
    p->ring = static_cast<uint16_t>(ring);
    // Cast a little beyond the limits: noise may bring the range back inside.
    const double margin = 6.0 * config_.range_noise_m;
    const double min_range = std::max(0.0, config_.min_range_m - margin);
    const double max_range = config_.max_range_m + margin;
    bool hit_any = world_.Cast(r_wl, d_w, min_range, max_range, &hit);
    if (pedestrians_ != nullptr &&
        pedestrians_->Cast(world_, r_wl, d_w, t, min_range, hit_any ? hit.range : max_range,
                           &hit)) {
      hit_any = true;
    }
    if (!hit_any) return;
    double surface_range = hit.range;
    if (config_.ground_roughness_m > 0.0 && hit.surface == Surface::kGround) {
      // Height δ ~ N(0, σ²) along the plane normal n: n · d < 0 for a ground
      // hit, so the ray meets the raised surface at s + δ / (n · d).
      const double delta = config_.ground_roughness_m * roughness_rng_.Gaussian();
      surface_range += delta / world_.ground_normal().dot(d_w);
      if (surface_range <= 0.0) return;
    }
    const double range = surface_range + config_.range_noise_m * rng_.Gaussian();
    if (range < config_.min_range_m || range > config_.max_range_m) return;
    const Eigen::Vector3d q = range * d_l;
    p->x = static_cast<float>(q.x());
    p->y = static_cast<float>(q.y());
    p->z = static_cast<float>(q.z());
    p->intensity = Intensity(hit.surface, hit.normal.dot(d_w), &p->reflectivity);
    p->range_mm = static_cast<uint32_t>(std::llround(range * 1000.0));
    p->label = static_cast<uint8_t>(hit.surface);
    p->valid = true;
  }

  // Livox noise: with probability `fraction`, a valid point is moved to a
  // uniform random range along its ray and tagged 0x01.
  void MaybeNoise(double fraction, ScanPoint* p) {
    if (fraction <= 0.0 || rng_.Uniform(0.0, 1.0) >= fraction) return;
    const double range = std::sqrt(double{p->x} * p->x + double{p->y} * p->y + double{p->z} * p->z);
    const double scale = rng_.Uniform(config_.min_range_m, range) / range;
    p->x = static_cast<float>(p->x * scale);
    p->y = static_cast<float>(p->y * scale);
    p->z = static_cast<float>(p->z * scale);
    p->tag = 0x01;
  }

 private:
  const ScanConfig& config_;
  const PlanarTrajectory& trajectory_;
  const World& world_;
  const Pedestrians* pedestrians_;  // nullptr: none
  Rng rng_;
  Rng roughness_rng_;
  std::vector<double> cos_el_, sin_el_;
};

// Velodyne: firing sequences, the valid returns in firing order; lasers
// sharing a firing slot share the pose.
void SimulateVelodyneSweep(const ScanConfig& config, int64_t start_ns, LaserCaster* caster,
                           SimulatedScan* scan) {
  const LidarModel& m = config.model;
  const int lasers = m.num_lasers();
  const int sequences = VelodyneSequences(config);
  const double span = SweepSpanS(config);
  const double start_s = start_ns * 1e-9;
  const int64_t stamp_ns =
      config.velodyne_stamp_at_start ? start_ns : start_ns + std::llround(span * 1e9);
  scan->stamp_true_ns = stamp_ns;
  const double start_minus_stamp_s = (start_ns - stamp_ns) * 1e-9;
  scan->points.reserve(static_cast<size_t>(sequences) * lasers);
  Eigen::Matrix3d c_wl;
  Eigen::Vector3d r_wl;
  double pose_offset = std::numeric_limits<double>::quiet_NaN();
  for (int j = 0; j < sequences; ++j) {
    for (int i = 0; i < lasers; ++i) {
      const double offset = j * m.sequence_period_s + m.firing_offset_s[i];
      if (offset != pose_offset) {
        caster->LidarPose(start_s + offset, &c_wl, &r_wl);
        pose_offset = offset;
      }
      const double alpha = -kTwoPi * config.scan_rate_hz * offset;
      ScanPoint p;
      caster->Cast(c_wl, r_wl, start_s + offset, i, alpha, &p);
      if (!p.valid) continue;
      p.time_s = static_cast<float>(start_minus_stamp_s + offset);
      ++scan->num_valid;
      if (p.label == static_cast<uint8_t>(Surface::kGround)) ++scan->num_ground;
      scan->points.push_back(p);
    }
  }
  scan->rows = 1;
  scan->columns = static_cast<int>(scan->points.size());
}

// Ouster: rows = beams x columns, all lasers of a column at once, invalid
// pixels kept with NaN coordinates.
void SimulateOusterSweep(const ScanConfig& config, int64_t start_ns, LaserCaster* caster,
                         SimulatedScan* scan) {
  const int lasers = config.model.num_lasers();
  const int columns = config.model.columns;
  scan->stamp_true_ns = start_ns;
  scan->rows = lasers;
  scan->columns = columns;
  scan->points.resize(static_cast<size_t>(lasers) * columns);
  const double column_period_ns = 1e9 / (config.scan_rate_hz * columns);
  Eigen::Matrix3d c_wl;
  Eigen::Vector3d r_wl;
  for (int c = 0; c < columns; ++c) {
    const int64_t t_ns = std::llround(c * column_period_ns);
    const double t = (start_ns + t_ns) * 1e-9;
    caster->LidarPose(t, &c_wl, &r_wl);
    const double alpha = -kTwoPi * c / columns;
    for (int i = 0; i < lasers; ++i) {
      ScanPoint& p = scan->points[static_cast<size_t>(i) * columns + c];
      caster->Cast(c_wl, r_wl, t, i, alpha, &p);
      p.time_ns = static_cast<uint32_t>(t_ns);
      if (!p.valid) {
        p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
        continue;
      }
      ++scan->num_valid;
      if (p.label == static_cast<uint8_t>(Surface::kGround)) ++scan->num_ground;
    }
  }
}

// Livox: every point of the frame in time order; a point without a return
// stays at the origin (the drivers publish it so).
void SimulateLivoxSweep(const ScanConfig& config, int64_t start_ns, LaserCaster* caster,
                        SimulatedScan* scan) {
  const LivoxPattern& pattern = config.model.livox;
  const int n = LivoxPoints(config);
  scan->stamp_true_ns = start_ns;
  scan->points.resize(static_cast<size_t>(n));
  const double period_ns = 1e9 / pattern.point_rate_hz;
  Eigen::Matrix3d c_wl;
  Eigen::Vector3d r_wl;
  for (int j = 0; j < n; ++j) {
    const int64_t offset_ns = std::llround(j * period_ns);
    const double t = (start_ns + offset_ns) * 1e-9;
    caster->LidarPose(t, &c_wl, &r_wl);
    const int line = j % pattern.lines;
    const double phase = kTwoPi * line / pattern.lines;
    double azimuth, elevation;
    if (pattern.rosette) {
      azimuth = pattern.half_azimuth_rad * 0.5 *
                (std::cos(kTwoPi * pattern.f1_hz * t + phase) + std::cos(kTwoPi * pattern.f2_hz * t));
      elevation = pattern.half_elevation_rad * 0.5 *
                  (std::sin(kTwoPi * pattern.f1_hz * t + phase) - std::sin(kTwoPi * pattern.f2_hz * t));
    } else {
      azimuth = kTwoPi * pattern.f1_hz * t + phase;
      elevation = pattern.min_elevation_rad +
                  (pattern.max_elevation_rad - pattern.min_elevation_rad) * 0.5 *
                      (1.0 - std::cos(kTwoPi * pattern.f2_hz * t + phase));
    }
    ScanPoint& p = scan->points[static_cast<size_t>(j)];
    caster->CastDirection(c_wl, r_wl, t, std::cos(elevation), std::sin(elevation), azimuth, line,
                          &p);
    p.time_ns = static_cast<uint32_t>(offset_ns);
    if (!p.valid) {
      p.x = p.y = p.z = 0.0f;
      continue;
    }
    caster->MaybeNoise(config.livox_noise_fraction, &p);
    ++scan->num_valid;
    if (p.tag == 0 && p.label == static_cast<uint8_t>(Surface::kGround)) ++scan->num_ground;
  }
  scan->rows = 1;
  scan->columns = n;
}

}  // namespace

SimulatedScan SimulateSweep(const ScanConfig& config, const PlanarTrajectory& trajectory,
                            const World& world, uint64_t seed, int k,
                            const Pedestrians* pedestrians) {
  LaserCaster caster(config, trajectory, world, pedestrians, seed, k);
  SimulatedScan scan;
  const int64_t start_ns = SweepStartNs(config, k);
  if (config.model.kind == LidarModel::Kind::kVelodyne) {
    SimulateVelodyneSweep(config, start_ns, &caster, &scan);
  } else if (config.model.kind == LidarModel::Kind::kLivox) {
    SimulateLivoxSweep(config, start_ns, &caster, &scan);
  } else {
    SimulateOusterSweep(config, start_ns, &caster, &scan);
  }
  return scan;
}

}  // namespace tiltcal::simulate
