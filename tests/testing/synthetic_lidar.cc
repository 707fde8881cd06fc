#include "tests/testing/synthetic_lidar.h"

#include <cmath>
#include <limits>
#include <random>

#include "common/geometry/angles.h"

namespace tiltcal::testing {

namespace {

Eigen::Matrix3d Exp(const Eigen::Vector3d& phi) {
  const double a = phi.norm();
  if (a < 1e-15) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(a, phi / a).toRotationMatrix();
}

// Ray (origin o, unit direction u) against the scene; +inf when nothing is hit.
double Hit(const SyntheticScene& scene, const Eigen::Vector3d& o, const Eigen::Vector3d& u) {
  double best = std::numeric_limits<double>::infinity();
  auto plane = [&](const Eigen::Vector3d& n, double d) {
    const double denom = n.dot(u);
    if (std::fabs(denom) < 1e-12) return;
    const double t = -(n.dot(o) + d) / denom;
    if (t > 1e-6 && t < best) best = t;
  };
  if (scene.ground) plane(Eigen::Vector3d::UnitZ(), 0.0);
  for (const Eigen::Vector4d& p : scene.planes) plane(p.head<3>(), p(3));
  for (const Eigen::AlignedBox3d& box : scene.boxes) {
    double t0 = 0.0, t1 = best;
    bool hit = true;
    for (int k = 0; k < 3 && hit; ++k) {
      if (std::fabs(u(k)) < 1e-12) {
        if (o(k) < box.min()(k) || o(k) > box.max()(k)) hit = false;
        continue;
      }
      double a = (box.min()(k) - o(k)) / u(k), b = (box.max()(k) - o(k)) / u(k);
      if (a > b) std::swap(a, b);
      t0 = std::max(t0, a);
      t1 = std::min(t1, b);
      if (t0 > t1) hit = false;
    }
    if (hit && t0 > 1e-6 && t0 < best) best = t0;
  }
  return best;
}

}  // namespace

SyntheticLidar SyntheticLidar::Vlp16() {
  SyntheticLidar lidar;
  for (int i = 0; i < 16; ++i) lidar.elevations_deg.push_back(-15.0 + 2.0 * i);
  return lidar;
}

proto::Scan CastScan(const SyntheticScene& scene, const SyntheticLidar& lidar,
                     const SyntheticPose& pose, int64_t stamp_ns, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, lidar.range_noise_m);
  proto::Scan scan;
  scan.set_stamp_ns(stamp_ns);
  scan.set_frame_id("lidar");
  scan.set_time_source(proto::POINT_TIME_SIMULATED);
  for (int a = 0; a < lidar.azimuth_steps; ++a) {
    const double fraction = static_cast<double>(a) / lidar.azimuth_steps;
    const double azimuth = 2.0 * M_PI * fraction;
    const double dt = lidar.sweep_s * (fraction - 0.5);
    const Eigen::Matrix3d r_gl = pose.g_from_lidar * Exp(pose.omega_lidar_radps * dt);
    for (size_t ring = 0; ring < lidar.elevations_deg.size(); ++ring) {
      const double el = geometry::DegToRad(lidar.elevations_deg[ring]);
      const Eigen::Vector3d u_l(std::cos(el) * std::cos(azimuth), std::cos(el) * std::sin(azimuth),
                                std::sin(el));
      const double t = Hit(scene, pose.position_g, r_gl * u_l);
      const double range = t + noise(rng);
      if (!(t < lidar.max_range_m) || range < lidar.min_range_m) continue;
      const Eigen::Vector3d p = range * u_l;
      scan.add_x(static_cast<float>(p.x()));
      scan.add_y(static_cast<float>(p.y()));
      scan.add_z(static_cast<float>(p.z()));
      scan.add_intensity(0.5f);
      scan.add_ring(static_cast<uint32_t>(ring));
      scan.add_time_offset_ns(static_cast<int32_t>(std::llround(dt * 1e9)));
    }
  }
  return scan;
}

Eigen::Vector3d TrueNormal(const SyntheticPose& pose) {
  return pose.g_from_lidar.transpose() * Eigen::Vector3d::UnitZ();
}

double TrueHeight(const SyntheticPose& pose) { return pose.position_g.z(); }

Eigen::Matrix3d RollPitchYaw(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

SyntheticScene StreetScene(uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  SyntheticScene scene;
  // Building fronts along the street at y = ±(7..10) m.
  scene.planes.push_back(Eigen::Vector4d(0, 1, 0, -(8.0 + 2.0 * u(rng))));
  scene.planes.push_back(Eigen::Vector4d(0, 1, 0, 8.0 + 2.0 * u(rng)));
  // Parked cars (4.5 x 1.8 x 1.5 m) and a few posts.
  for (int i = 0; i < 6; ++i) {
    const double x = 4.0 + 6.0 * i + 2.0 * u(rng);
    const double side = (i % 2 == 0) ? 1.0 : -1.0;
    const double y = side * (4.5 + 0.5 * u(rng));
    scene.boxes.emplace_back(Eigen::Vector3d(x - 2.25, y - 0.9, 0.0),
                             Eigen::Vector3d(x + 2.25, y + 0.9, 1.5));
  }
  for (int i = 0; i < 4; ++i) {
    const double x = -5.0 - 7.0 * i + u(rng);
    const double y = (i % 2 == 0 ? 1.0 : -1.0) * 6.0;
    scene.boxes.emplace_back(Eigen::Vector3d(x - 0.1, y - 0.1, 0.0),
                             Eigen::Vector3d(x + 0.1, y + 0.1, 3.0));
  }
  return scene;
}

}  // namespace tiltcal::testing
